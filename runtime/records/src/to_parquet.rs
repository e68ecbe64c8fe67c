//! CSV -> Parquet: each line's fields read as their column's values (`fields.rs`) and handed to a
//! [`TableWriter`], which decides the row groups.

use std::path::Path;

use super::ExportError;
use super::csv_lines::CsvLines;
use super::fields::Value;
use super::schema::Table;
use super::writer::{MAX_COLUMNS, TableWriter};

/// Converts the CSV file `source` of `table` into the Parquet file `output`; returns the rows converted.
pub(super) fn csv_to_parquet(
    table: Table,
    source: &Path,
    output: &Path,
) -> Result<u64, ExportError> {
    let mut lines = CsvLines::open(source)?;
    let header = table.header();
    match lines.next_line()? {
        Some(line) if line == header.as_bytes() => {}
        Some(line) => {
            let found = String::from_utf8_lossy(&line[..line.len().min(200)]).into_owned();
            return Err(lines.error(format!("the header is `{found}`, expected `{header}`")));
        }
        None => return Err(lines.error("the file is empty: no header line")),
    }
    let mut writer = TableWriter::create(table, output)?;
    while let Some(line) = lines.next_line()? {
        let mut values = [Value::Null; MAX_COLUMNS];
        let row = &mut values[..table.columns().len()];
        match parse_line(table, line, row) {
            Ok(()) => writer.push(row)?,
            Err(what) => return Err(lines.error(what)),
        }
    }
    writer.finish()
}

/// Reads a CSV line's fields into `row`, one per column.
fn parse_line<'a>(table: Table, line: &'a [u8], row: &mut [Value<'a>]) -> Result<(), String> {
    let expected = row.len();
    let mut fields = line.split(|&b| b == b',');
    for (index, (column, value)) in table.columns().iter().zip(row.iter_mut()).enumerate() {
        let field = fields
            .next()
            .ok_or_else(|| format!("{index} fields, expected {expected}"))?;
        *value = column
            .parse(field)
            .map_err(|e| format!("column `{}`: {e}", column.name))?;
    }
    if fields.next().is_some() {
        let found = line.split(|&b| b == b',').count();
        return Err(format!("{found} fields, expected {expected}"));
    }
    Ok(())
}
