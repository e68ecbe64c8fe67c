//! Reading a Parquet file of one of the run's tables, row group by row group: `swarm export --format csv` turns
//! the rows into CSV lines, `swarm view` into poses and events.
//!
//! Only Parquet files of the run's own tables are read: a file whose columns are not exactly the table's (names,
//! types, nullability) is refused when opened. The parquet crate can panic on some malformed pages (a
//! dictionary-encoded page without its dictionary), so every read runs under `catch_unwind` and such a panic
//! becomes an error naming the file and row group (the panic's own message still reaches standard error).

use std::fs::File;
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use parquet::column::reader::{ColumnReader, ColumnReaderImpl};
use parquet::data_type::{BoolType, ByteArrayType, DataType, FloatType, Int32Type, Int64Type};
use parquet::errors::ParquetError;
use parquet::file::metadata::RowGroupMetaData;
use parquet::file::reader::{FileReader, RowGroupReader};
use parquet::file::serialized_reader::SerializedFileReader;
use parquet::file::statistics::Statistics;

use crate::ExportError;
use crate::fields::{Value, Values};
use crate::schema::{Column, Table, describe_found};
use crate::writer::MAX_COLUMNS;

/// Rows read from each column at a time.
const BATCH_ROWS: usize = 1 << 14;

/// An open Parquet file of one of the run's tables, its schema checked.
pub struct ParquetTable {
    table: Table,
    path: PathBuf,
    reader: SerializedFileReader<File>,
    file_bytes: u64,
}

impl ParquetTable {
    /// Opens the Parquet file at `path` as `table`: its footer is read and its columns compared with the table's.
    pub fn open(table: Table, path: &Path) -> Result<ParquetTable, ExportError> {
        let file_error = |what: String| ExportError::Parquet {
            path: path.to_path_buf(),
            what,
        };
        let io = |e| ExportError::Io {
            path: path.to_path_buf(),
            source: e,
        };
        let file = File::open(path).map_err(io)?;
        let file_bytes = file.metadata().map_err(io)?.len();
        let reader = unpanicked(
            || {
                let reader = SerializedFileReader::new(file)
                    .map_err(|e| file_error(format!("not a readable Parquet file: {e}")))?;
                check_schema(table, &reader).map_err(file_error)?;
                Ok(reader)
            },
            file_error,
        )?;
        Ok(ParquetTable {
            table,
            path: path.to_path_buf(),
            reader,
            file_bytes,
        })
    }

    /// Row groups in the file.
    pub fn row_groups(&self) -> usize {
        self.reader.num_row_groups()
    }

    /// Rows of row group `index`, as its metadata says.
    pub fn rows(&self, index: usize) -> u64 {
        u64::try_from(self.reader.metadata().row_group(index).num_rows()).unwrap_or(0)
    }

    /// The first and last `tick` of row group `index`, from its statistics (the writer keeps them; `None` when
    /// a file has none).
    pub fn ticks(&self, index: usize) -> Option<(u64, u64)> {
        let chunk = self.reader.metadata().row_group(index).columns().first()?;
        match chunk.statistics()? {
            Statistics::Int64(s) => Some((*s.min_opt()? as u64, *s.max_opt()? as u64)),
            _ => None,
        }
    }

    /// Reads row group `index`, handing each row's values (in column order; nulls as [`Value::Null`]) to `row`
    /// with its number in the group; returns the rows read. An error of `row` ends the reading and is reported
    /// with the row group and row.
    pub fn read_row_group(
        &self,
        index: usize,
        mut row: impl FnMut(u64, &[Value<'_>]) -> Result<(), String>,
    ) -> Result<u64, ExportError> {
        let error = |what: String| ExportError::RowGroup {
            path: self.path.clone(),
            row_group: index,
            what,
        };
        unpanicked(
            || {
                check_chunks(self.reader.metadata().row_group(index), self.file_bytes)
                    .map_err(error)?;
                let group = self
                    .reader
                    .get_row_group(index)
                    .map_err(|e| error(e.to_string()))?;
                read_rows(self.table.columns(), group.as_ref(), &mut row).map_err(error)
            },
            error,
        )
    }
}

/// Runs `read`, turning a panic of the parquet crate into `error`'s.
fn unpanicked<T>(
    read: impl FnOnce() -> Result<T, ExportError>,
    error: impl FnOnce(String) -> ExportError,
) -> Result<T, ExportError> {
    panic::catch_unwind(AssertUnwindSafe(read)).unwrap_or_else(|panic| {
        let message = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Err(error(format!(
            "malformed Parquet data, the reader failed: {message}"
        )))
    })
}

/// Refuses a file whose columns are not exactly `table`'s.
fn check_schema(table: Table, reader: &SerializedFileReader<File>) -> Result<(), String> {
    let schema = reader.metadata().file_metadata().schema_descr();
    let columns = table.columns();
    if schema.num_columns() != columns.len() {
        return Err(format!(
            "{} columns, expected the {} of {}",
            schema.num_columns(),
            columns.len(),
            table.csv_name()
        ));
    }
    for (index, (column, found)) in columns.iter().zip(schema.columns()).enumerate() {
        if !column.matches(found) {
            return Err(format!(
                "column {index} is {}, expected {}",
                describe_found(found),
                column.describe()
            ));
        }
    }
    Ok(())
}

/// Refuses a row group whose column chunks do not lie inside the file (the parquet crate asserts on negative
/// offsets, and would allocate what a corrupt length says before finding the file shorter).
fn check_chunks(group: &RowGroupMetaData, file_bytes: u64) -> Result<(), String> {
    for chunk in group.columns() {
        let start = chunk
            .dictionary_page_offset()
            .unwrap_or(chunk.data_page_offset());
        let length = chunk.compressed_size();
        let end = u64::try_from(start)
            .ok()
            .zip(u64::try_from(length).ok())
            .and_then(|(start, length)| start.checked_add(length));
        if end.is_none_or(|end| end > file_bytes) {
            return Err(format!(
                "column `{}` claims bytes {start} to {start} + {length}, outside the file's {file_bytes}",
                chunk.column_path()
            ));
        }
    }
    Ok(())
}

/// Hands one row group's rows to `row`; returns how many.
fn read_rows(
    columns: &[Column],
    group: &dyn RowGroupReader,
    row: &mut impl FnMut(u64, &[Value<'_>]) -> Result<(), String>,
) -> Result<u64, String> {
    if columns.len() > MAX_COLUMNS {
        return Err(format!(
            "{} columns, more than {MAX_COLUMNS}",
            columns.len()
        ));
    }
    let claimed = group.metadata().num_rows();
    let expected = u64::try_from(claimed).map_err(|_| format!("{claimed} rows"))?;
    let mut cursors = columns
        .iter()
        .enumerate()
        .map(|(index, &column)| {
            let reader = group.get_column_reader(index).map_err(|e| e.to_string())?;
            ColumnCursor::new(column, reader)
        })
        .collect::<Result<Vec<_>, String>>()?;
    let mut rows = 0u64;
    let mut places = [None; MAX_COLUMNS];
    loop {
        let counts = cursors
            .iter_mut()
            .map(ColumnCursor::read_batch)
            .collect::<Result<Vec<usize>, String>>()?;
        let batch = counts.first().copied().unwrap_or_default();
        if let Some(odd) = counts.iter().position(|&count| count != batch) {
            let (short, long) = if counts[odd] < batch {
                (odd, 0)
            } else {
                (0, odd)
            };
            return Err(format!(
                "column `{}` has fewer rows than column `{}`",
                columns[short].name, columns[long].name
            ));
        }
        if batch == 0 {
            break;
        }
        for in_batch in 0..batch {
            for (place, cursor) in places.iter_mut().zip(cursors.iter_mut()) {
                *place = cursor.next_place(in_batch);
            }
            let mut values = [Value::Null; MAX_COLUMNS];
            for (index, cursor) in cursors.iter().enumerate() {
                if let Some(place) = places[index] {
                    values[index] = cursor.values.get(place).ok_or_else(|| {
                        format!("column `{}` has fewer values than rows", cursor.column.name)
                    })?;
                }
            }
            let number = rows + in_batch as u64;
            row(number, &values[..columns.len()]).map_err(|e| format!("row {number}, {e}"))?;
        }
        rows += batch as u64;
    }
    if rows != expected {
        return Err(format!("{rows} rows where its metadata says {expected}"));
    }
    Ok(rows)
}

/// One column's reader within a row group and its current batch.
struct ColumnCursor {
    column: Column,
    reader: TypedReader,
    values: Values,
    /// Definition levels of an optional column (0: null).
    levels: Option<Vec<i16>>,
    /// The next value of `values` to hand out.
    next_value: usize,
}

/// The reader of a column's physical type.
enum TypedReader {
    Int64(ColumnReaderImpl<Int64Type>),
    Int32(ColumnReaderImpl<Int32Type>),
    Float(ColumnReaderImpl<FloatType>),
    Boolean(ColumnReaderImpl<BoolType>),
    Text(ColumnReaderImpl<ByteArrayType>),
}

impl ColumnCursor {
    fn new(column: Column, reader: ColumnReader) -> Result<ColumnCursor, String> {
        let reader = match reader {
            ColumnReader::Int64ColumnReader(r) => TypedReader::Int64(r),
            ColumnReader::Int32ColumnReader(r) => TypedReader::Int32(r),
            ColumnReader::FloatColumnReader(r) => TypedReader::Float(r),
            ColumnReader::BoolColumnReader(r) => TypedReader::Boolean(r),
            ColumnReader::ByteArrayColumnReader(r) => TypedReader::Text(r),
            _ => {
                return Err(format!(
                    "column `{}` has another physical type",
                    column.name
                ));
            }
        };
        Ok(ColumnCursor {
            column,
            reader,
            values: Values::new(column.kind),
            levels: column.optional.then(Vec::new),
            next_value: 0,
        })
    }

    /// Reads the next batch of rows; returns how many (0 at the end of the column chunk).
    fn read_batch(&mut self) -> Result<usize, String> {
        self.values.clear();
        self.next_value = 0;
        if let Some(levels) = &mut self.levels {
            levels.clear();
        }
        let levels = self.levels.as_mut();
        let read = match (&mut self.reader, &mut self.values) {
            (TypedReader::Int64(r), Values::Int64(v)) => read(r, levels, v),
            (TypedReader::Int32(r), Values::Int32(v)) => read(r, levels, v),
            (TypedReader::Float(r), Values::Float(v)) => read(r, levels, v),
            (TypedReader::Boolean(r), Values::Boolean(v)) => read(r, levels, v),
            (TypedReader::Text(r), Values::Text(v)) => read(r, levels, v),
            _ => {
                return Err(format!(
                    "column `{}` does not have its table's type",
                    self.column.name
                ));
            }
        };
        read.map_err(|e| format!("column `{}`: {e}", self.column.name))
    }

    /// Where in `values` row `in_batch` of the batch is, `None` for a null; rows are asked for in order.
    fn next_place(&mut self, in_batch: usize) -> Option<usize> {
        let present = match &self.levels {
            Some(levels) => levels.get(in_batch).is_some_and(|&level| level > 0),
            None => true,
        };
        present.then(|| {
            self.next_value += 1;
            self.next_value - 1
        })
    }
}

fn read<T: DataType>(
    reader: &mut ColumnReaderImpl<T>,
    levels: Option<&mut Vec<i16>>,
    values: &mut Vec<T::T>,
) -> Result<usize, ParquetError> {
    let (rows, _, _) = reader.read_records(BATCH_ROWS, levels, None, values)?;
    Ok(rows)
}
