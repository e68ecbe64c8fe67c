//! Parquet -> CSV: the world's CSV again, byte for byte (`fields.rs` spells every value as the recorder does),
//! read row group by row group through [`ParquetTable`].

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::ExportError;
use crate::atomic::AtomicFile;
use crate::fields::Value;
use crate::reader::ParquetTable;
use crate::schema::Table;

/// Converts the Parquet file `source` of `table` into the CSV file `output`; returns the rows converted.
pub(super) fn parquet_to_csv(
    table: Table,
    source: &Path,
    output: &Path,
) -> Result<u64, ExportError> {
    let parquet = ParquetTable::open(table, source)?;
    let (atomic, file) = AtomicFile::create(output)?;
    let mut out = CsvOut {
        out: BufWriter::with_capacity(1 << 16, file),
        line: table.header().into_bytes(),
        path: atomic.path().to_path_buf(),
        failure: None,
    };
    out.end_line()?;
    let mut rows = 0u64;
    for index in 0..parquet.row_groups() {
        let read = parquet.read_row_group(index, |_, values| out.row(table, values));
        rows += match (read, out.failure.take()) {
            (_, Some(failure)) => return Err(failure),
            (read, None) => read?,
        };
    }
    let file = out.out.into_inner().map_err(|e| ExportError::Io {
        path: out.path.clone(),
        source: e.into_error(),
    })?;
    atomic.commit(file)?;
    Ok(rows)
}

/// The CSV file being written, errors naming it.
struct CsvOut {
    out: BufWriter<File>,
    /// The line being formatted.
    line: Vec<u8>,
    path: PathBuf,
    /// Why writing failed, when it did in the middle of a row group.
    failure: Option<ExportError>,
}

impl CsvOut {
    /// Formats and writes one row of `table`.
    fn row(&mut self, table: Table, values: &[Value<'_>]) -> Result<(), String> {
        for (position, (column, &value)) in table.columns().iter().zip(values).enumerate() {
            if position > 0 {
                self.line.push(b',');
            }
            column
                .format(value, &mut self.line)
                .map_err(|e| format!("column `{}`: {e}", column.name))?;
        }
        self.end_line().map_err(|e| {
            let what = e.to_string();
            self.failure = Some(e);
            what
        })
    }

    /// Writes the line formatted in `line` and a line end, and empties it.
    fn end_line(&mut self) -> Result<(), ExportError> {
        self.line.push(b'\n');
        let written = self.out.write_all(&self.line);
        self.line.clear();
        written.map_err(|source| ExportError::Io {
            path: self.path.clone(),
            source,
        })
    }
}
