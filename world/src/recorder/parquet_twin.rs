//! The Parquet file written beside a record table's CSV file, from the same fields (`csv_line.rs` hands each
//! field to both), so that a run that ends normally has its Parquet records at once and the launcher only
//! removes the CSV files. The CSV file stays the run's journal: a world that dies leaves its Parquet file
//! unfinished (a temporary file) and the launcher converts the CSV file cut back to whole ticks instead.

use std::ops::Range;
use std::path::{Path, PathBuf};

use swarm_records::{Field, MAX_COLUMNS, Table, TableWriter, Value};

use crate::error::WorldError;

/// One field of the line being built.
#[derive(Clone, Debug)]
enum Slot {
    Int(u64),
    Float(f32),
    /// A range of [`ParquetTwin::text`].
    Text(Range<usize>),
}

/// The Parquet file of one table, fed line by line.
pub struct ParquetTwin {
    table: Table,
    path: PathBuf,
    writer: TableWriter,
    line: Vec<Slot>,
    text: String,
}

impl ParquetTwin {
    /// Starts `table`'s Parquet file in the run folder `dir`.
    pub fn create(table: Table, dir: &Path) -> Result<ParquetTwin, WorldError> {
        let path = dir.join(table.parquet_name());
        let writer = TableWriter::create(table, &path).map_err(|e| error(&path, e))?;
        Ok(ParquetTwin {
            table,
            path,
            writer,
            line: Vec::with_capacity(table.columns().len()),
            text: String::new(),
        })
    }

    /// An integer field.
    pub fn int(&mut self, value: u64) {
        self.line.push(Slot::Int(value));
    }

    /// A float field.
    pub fn float(&mut self, value: f32) {
        self.line.push(Slot::Float(value));
    }

    /// A text field.
    pub fn text(&mut self, value: &str) {
        let start = self.text.len();
        self.text.push_str(value);
        self.line.push(Slot::Text(start..self.text.len()));
    }

    /// Text appended to the text field just added (`within:` then `0.5`).
    pub fn append(&mut self, value: &str) {
        self.text.push_str(value);
        if let Some(Slot::Text(range)) = self.line.last_mut() {
            range.end = self.text.len();
        }
    }

    /// Ends the line: its fields become the next row of the file.
    pub fn end(&mut self) -> std::io::Result<()> {
        let columns = self.table.columns();
        let mut row = [Value::Null; MAX_COLUMNS];
        let pushed = (|| {
            if self.line.len() != columns.len() {
                return Err(format!(
                    "a line of {} fields, expected {}",
                    self.line.len(),
                    columns.len()
                ));
            }
            for ((slot, column), value) in self.line.iter().zip(columns).zip(row.iter_mut()) {
                let field = match slot {
                    Slot::Int(v) => Field::Int(*v),
                    Slot::Float(v) => Field::Float(*v),
                    Slot::Text(range) => Field::Text(&self.text[range.clone()]),
                };
                *value = column
                    .value_of(field)
                    .map_err(|e| format!("column `{}`: {e}", column.name))?;
            }
            self.writer
                .push(&row[..columns.len()])
                .map_err(|e| e.to_string())
        })();
        self.line.clear();
        self.text.clear();
        pushed.map_err(std::io::Error::other)
    }

    /// Writes the last row group and the footer, and renames the file into place.
    pub fn finish(self) -> Result<(), WorldError> {
        let path = self.path;
        self.writer.finish().map(drop).map_err(|e| error(&path, e))
    }
}

fn error(path: &Path, e: swarm_records::ExportError) -> WorldError {
    WorldError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    }
}
