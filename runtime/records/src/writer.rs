//! Writing one of the run's tables as a Parquet file, row by row: row groups of whole ticks, Snappy pages,
//! dictionary encoding for text and integers. `swarm export` feeds it parsed CSV lines; the world's recorder feeds
//! it the rows it writes to CSV, so that a run that ends normally has its Parquet files at once.
//!
//! A row group ends at the first row of a new tick once it holds [`ROW_GROUP_ROWS`] rows, so that a reader
//! wanting a few ticks (`swarm view`) decodes one group of about that size, found by its `tick` statistics.
//! Parquet writes a row group column after column, so one row group's values are held in memory. A row group also
//! ends early once its text reaches [`ROW_GROUP_TEXT_BYTES`], so long fields cannot grow it without bound. The
//! file is written under a temporary name and renamed into place by [`TableWriter::finish`]; a writer dropped
//! unfinished removes it.

use std::collections::HashMap;
use std::fs::File;
use std::hash::{BuildHasherDefault, Hasher};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use parquet::basic::Compression;
use parquet::column::writer::{ColumnWriter, ColumnWriterImpl};
use parquet::data_type::{ByteArray, DataType};
use parquet::errors::ParquetError;
use parquet::file::properties::{EnabledStatistics, WriterProperties};
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::ColumnPath;

use super::ExportError;
use super::atomic::AtomicFile;
use super::fields::{Value, Values};
use super::schema::{Column, Kind, Table};

/// Rows after which a row group ends with its tick: 65,536 rows decode in a few milliseconds, and are large
/// enough that pandas and polars read a file about as fast as with one group (BENCHMARKS.md, "Records").
pub(crate) const ROW_GROUP_ROWS: usize = 1 << 16;
/// Text bytes (and per-value overhead) after which a row group ends before [`ROW_GROUP_ROWS`].
const ROW_GROUP_TEXT_BYTES: usize = 256 << 20;
/// What a text value costs beside its bytes (the `ByteArray` and its allocation).
const TEXT_VALUE_OVERHEAD: usize = 48;
/// Columns of the widest table (the trajectory's ten), for rows held on the stack.
pub const MAX_COLUMNS: usize = 16;

/// A Parquet file of one table being written.
pub struct TableWriter {
    atomic: AtomicFile,
    out: ParquetOut,
    group: RowGroup,
    rows: u64,
}

impl TableWriter {
    /// Starts the Parquet file `output` of `table` (under a temporary name until [`TableWriter::finish`]).
    pub fn create(table: Table, output: &Path) -> Result<TableWriter, ExportError> {
        let (atomic, file) = AtomicFile::create(output)?;
        Ok(TableWriter {
            out: ParquetOut::create(table, file, output)?,
            atomic,
            group: RowGroup::new(table.columns()),
            rows: 0,
        })
    }

    /// Adds a row: one value per column of the table, in column order, each of its column's kind (a null only in
    /// an optional column).
    pub fn push(&mut self, row: &[Value<'_>]) -> Result<(), ExportError> {
        let tick = match row.first() {
            Some(Value::Int64(tick)) => Some(*tick),
            _ => None,
        };
        if self.group.rows >= ROW_GROUP_ROWS && self.group.last_tick() != tick {
            self.out.write(&mut self.group)?;
        }
        self.group
            .push_row(row)
            .map_err(|what| parquet_error(&self.out.path, ParquetError::General(what)))?;
        self.rows += 1;
        if self.group.is_full() {
            self.out.write(&mut self.group)?;
        }
        Ok(())
    }

    /// Writes the last row group and the footer and renames the file into place; returns the rows written.
    pub fn finish(mut self) -> Result<u64, ExportError> {
        if self.group.rows > 0 {
            self.out.write(&mut self.group)?;
        }
        let file = self.out.finish()?;
        self.atomic.commit(file)?;
        Ok(self.rows)
    }
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
            // Statistics cost a comparison per value; only `tick`'s are read (to find a tick's row group, by
            // `swarm view`, and by pandas and polars to skip groups when filtering on ticks).
            .set_statistics_enabled(EnabledStatistics::None)
            .set_column_statistics_enabled(ColumnPath::from("tick"), EnabledStatistics::Chunk)
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
    /// Text values seen before, shared rather than copied.
    interned: Interned,
}

/// Text values a column has held, each kept once: robot ids, event names and message outcomes repeat on nearly
/// every row, and copying each into an allocation of its own was a third of the world's recording thread.
#[derive(Default)]
struct Interned(HashMap<Vec<u8>, ByteArray, BuildHasherDefault<Fnv1a>>);

/// FNV-1a: the keys are a few bytes long and come from the run itself, so the default hasher's resistance to
/// chosen keys buys nothing, and its cost per lookup was most of the interning's.
struct Fnv1a(u64);

impl Default for Fnv1a {
    fn default() -> Self {
        Fnv1a(0xcbf2_9ce4_8422_2325)
    }
}

impl Hasher for Fnv1a {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.0 = (self.0 ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    }
}

/// Distinct text values kept per column at most; further ones are copied.
const MAX_INTERNED: usize = 1 << 16;

impl Interned {
    fn get(&mut self, text: &[u8]) -> ByteArray {
        if let Some(value) = self.0.get(text) {
            return value.clone();
        }
        let value = ByteArray::from(text.to_vec());
        if self.0.len() < MAX_INTERNED {
            self.0.insert(text.to_vec(), value.clone());
        }
        value
    }
}

impl RowGroup {
    fn new(columns: &[Column]) -> RowGroup {
        let columns = columns
            .iter()
            .map(|&column| ColumnValues {
                column,
                values: Values::new(column.kind),
                levels: column.optional.then(Vec::new),
                interned: Interned::default(),
            })
            .collect();
        RowGroup {
            columns,
            rows: 0,
            text_bytes: 0,
        }
    }

    /// Adds a row's values. On an error the row group is left part-filled: the writing ends there.
    fn push_row(&mut self, row: &[Value<'_>]) -> Result<(), String> {
        if row.len() != self.columns.len() {
            return Err(format!(
                "a row of {} values, expected {}",
                row.len(),
                self.columns.len()
            ));
        }
        for (column, &value) in self.columns.iter_mut().zip(row) {
            if value == Value::Null && !column.column.optional {
                return Err(format!("column `{}` has no value", column.column.name));
            }
            if let Value::Text(text) = value {
                self.text_bytes += text.len() + TEXT_VALUE_OVERHEAD;
            }
            column
                .push(value)
                .map_err(|e| format!("column `{}`: {e}", column.column.name))?;
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
    /// Appends `value`; a null has no value among the values (its definition level says it is missing).
    fn push(&mut self, value: Value<'_>) -> Result<(), String> {
        if let Some(levels) = &mut self.levels {
            levels.push(i16::from(value != Value::Null));
        }
        match (&mut self.values, value) {
            (_, Value::Null) => {}
            (Values::Int64(v), Value::Int64(x)) => v.push(x),
            (Values::Int32(v), Value::Int32(x)) => v.push(x),
            (Values::Float(v), Value::Float(x)) => v.push(x),
            (Values::Boolean(v), Value::Boolean(x)) => v.push(x),
            (Values::Text(v), Value::Text(x)) => v.push(self.interned.get(x)),
            (_, other) => return Err(format!("{other:?} is not a value of this column")),
        }
        Ok(())
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
