//! CSV -> Parquet: row groups of whole ticks, Snappy pages, dictionary encoding for text and integers.
//!
//! A row group ends at the first row of a new tick once it holds [`ROW_GROUP_ROWS`] rows, so that a reader
//! wanting a few ticks (`swarm view`) decodes one group of about that size, found by its `tick` statistics.
//! Parquet writes a row group column after column, so one row group's values are held in memory. A row group also
//! ends early once its text reaches [`ROW_GROUP_TEXT_BYTES`], so long fields cannot grow it without bound.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use parquet::basic::Compression;
use parquet::column::writer::{ColumnWriter, ColumnWriterImpl};
use parquet::data_type::DataType;
use parquet::errors::ParquetError;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::ColumnPath;

use super::ExportError;
use super::atomic::AtomicFile;
use super::csv_lines::CsvLines;
use super::fields::{Value, Values};
use super::schema::{Column, Kind, Table};

/// Rows after which a row group ends with its tick: 65,536 rows decode in a few milliseconds, and are large
/// enough that pandas and polars read a file as fast as with one group (BENCHMARKS.md, "Records").
pub(super) const ROW_GROUP_ROWS: usize = 1 << 16;
/// Text bytes (and per-value overhead) after which a row group ends before [`ROW_GROUP_ROWS`].
const ROW_GROUP_TEXT_BYTES: usize = 256 << 20;
/// What a text value costs beside its bytes (the `ByteArray` and its allocation).
const TEXT_VALUE_OVERHEAD: usize = 48;

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

    let (atomic, file) = AtomicFile::create(output)?;
    let mut writer = ParquetOut::create(table, file, output)?;
    let mut group = RowGroup::new(table.columns());
    let mut rows = 0u64;
    while let Some(line) = lines.next_line()? {
        if group.rows >= ROW_GROUP_ROWS && group.last_tick() != tick_field(line) {
            writer.write(&mut group)?;
        }
        let added = group.push_line(line);
        added.map_err(|what| lines.error(what))?;
        rows += 1;
        if group.is_full() {
            writer.write(&mut group)?;
        }
    }
    if group.rows > 0 {
        writer.write(&mut group)?;
    }
    let file = writer.finish()?;
    atomic.commit(file)?;
    Ok(rows)
}

/// The `tick` field of a CSV line (its first), as stored; `None` when it is not a number (the line is then
/// refused when added).
fn tick_field(line: &[u8]) -> Option<i64> {
    let field = line.split(|&b| b == b',').next()?;
    std::str::from_utf8(field)
        .ok()?
        .parse::<u64>()
        .ok()
        .map(|tick| tick as i64)
}

/// The Parquet file being written, errors naming it.
struct ParquetOut {
    writer: SerializedFileWriter<File>,
    path: PathBuf,
}

impl ParquetOut {
    fn create(table: Table, file: File, path: &Path) -> Result<ParquetOut, ExportError> {
        // Poses rarely repeat: a float column's dictionary fills up and falls back to plain pages, which made
        // the trajectory larger (12.9 MB against 12.0 MB for 1,001,000 rows) and slower to write.
        let properties = table
            .columns()
            .iter()
            .filter(|column| column.kind == Kind::Float)
            .fold(WriterProperties::builder(), |builder, column| {
                builder.set_column_dictionary_enabled(ColumnPath::from(column.name), false)
            })
            .set_compression(Compression::SNAPPY)
            .build();
        let writer = table
            .parquet_schema()
            .and_then(|schema| SerializedFileWriter::new(file, schema, Arc::new(properties)));
        Ok(ParquetOut {
            writer: writer.map_err(|e| parquet_error(path, e))?,
            path: path.to_path_buf(),
        })
    }

    /// Writes `group` as the next row group and empties it.
    fn write(&mut self, group: &mut RowGroup) -> Result<(), ExportError> {
        let written = (|| {
            let mut row_group = self.writer.next_row_group()?;
            for column in &group.columns {
                let mut writer = row_group
                    .next_column()?
                    .ok_or_else(|| ParquetError::General("fewer columns than the table".into()))?;
                column.write(writer.untyped())?;
                writer.close()?;
            }
            row_group.close().map(drop)
        })();
        written.map_err(|e| parquet_error(&self.path, e))?;
        group.clear();
        Ok(())
    }

    /// Writes the footer; returns the file.
    fn finish(self) -> Result<File, ExportError> {
        self.writer
            .into_inner()
            .map_err(|e| parquet_error(&self.path, e))
    }
}

fn parquet_error(path: &Path, error: ParquetError) -> ExportError {
    ExportError::Parquet {
        path: path.to_path_buf(),
        what: error.to_string(),
    }
}

/// The rows of the row group being filled, column by column.
struct RowGroup {
    columns: Vec<ColumnValues>,
    rows: usize,
    text_bytes: usize,
}

/// One column's values of the row group.
struct ColumnValues {
    column: Column,
    values: Values,
    /// Definition levels of an optional column: 1 for a value, 0 for a null.
    levels: Option<Vec<i16>>,
}

impl RowGroup {
    fn new(columns: &[Column]) -> RowGroup {
        let columns = columns
            .iter()
            .map(|&column| ColumnValues {
                column,
                values: Values::new(column.kind),
                levels: column.optional.then(Vec::new),
            })
            .collect();
        RowGroup {
            columns,
            rows: 0,
            text_bytes: 0,
        }
    }

    /// Adds a CSV line's fields. On an error the row group is left part-filled: the conversion ends there.
    fn push_line(&mut self, line: &[u8]) -> Result<(), String> {
        let expected = self.columns.len();
        let mut fields = line.split(|&b| b == b',');
        for (index, column) in self.columns.iter_mut().enumerate() {
            let field = fields
                .next()
                .ok_or_else(|| format!("{index} fields, expected {expected}"))?;
            let value = column
                .column
                .parse(field)
                .map_err(|e| format!("column `{}`: {e}", column.column.name))?;
            if let Value::Text(text) = value {
                self.text_bytes += text.len() + TEXT_VALUE_OVERHEAD;
            }
            column.push(value)?;
        }
        if fields.next().is_some() {
            let found = line.split(|&b| b == b',').count();
            return Err(format!("{found} fields, expected {expected}"));
        }
        self.rows += 1;
        Ok(())
    }

    /// Whether the row group must end now, whatever the next row's tick.
    fn is_full(&self) -> bool {
        self.text_bytes >= ROW_GROUP_TEXT_BYTES
    }

    /// The `tick` of the last row added (every table's first column).
    fn last_tick(&self) -> Option<i64> {
        match self.columns.first().map(|c| &c.values) {
            Some(Values::Int64(ticks)) => ticks.last().copied(),
            _ => None,
        }
    }

    fn clear(&mut self) {
        for column in &mut self.columns {
            column.values.clear();
            if let Some(levels) = &mut column.levels {
                levels.clear();
            }
        }
        self.rows = 0;
        self.text_bytes = 0;
    }
}

impl ColumnValues {
    fn push(&mut self, value: Value<'_>) -> Result<(), String> {
        if let Some(levels) = &mut self.levels {
            levels.push(i16::from(value != Value::Null));
        }
        self.values.push(value)
    }

    fn write(&self, writer: &mut ColumnWriter<'_>) -> Result<(), ParquetError> {
        let levels = self.levels.as_deref();
        match (&self.values, writer) {
            (Values::Int64(v), ColumnWriter::Int64ColumnWriter(w)) => write(w, v, levels),
            (Values::Int32(v), ColumnWriter::Int32ColumnWriter(w)) => write(w, v, levels),
            (Values::Float(v), ColumnWriter::FloatColumnWriter(w)) => write(w, v, levels),
            (Values::Boolean(v), ColumnWriter::BoolColumnWriter(w)) => write(w, v, levels),
            (Values::Text(v), ColumnWriter::ByteArrayColumnWriter(w)) => write(w, v, levels),
            _ => Err(ParquetError::General(format!(
                "column `{}` does not have the schema's type",
                self.column.name
            ))),
        }
    }
}

fn write<T: DataType>(
    writer: &mut ColumnWriterImpl<'_, T>,
    values: &[T::T],
    levels: Option<&[i16]>,
) -> Result<(), ParquetError> {
    writer.write_batch(values, levels, None).map(drop)
}
