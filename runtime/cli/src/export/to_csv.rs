//! Parquet -> CSV: the world's CSV again, byte for byte, read [`BATCH_ROWS`] rows at a time from every column of a
//! row group.
//!
//! Only Parquet files of the run's own tables are read: a file whose columns are not exactly the table's (names,
//! types, nullability) is refused before anything is written. The parquet crate can panic on some malformed pages
//! (a dictionary-encoded page without its dictionary), so the reading runs under `catch_unwind` and such a panic
//! becomes an error naming the file and row group (the panic's own message still reaches standard error).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use parquet::column::reader::{ColumnReader, ColumnReaderImpl};
use parquet::data_type::{BoolType, ByteArrayType, DataType, FloatType, Int32Type, Int64Type};
use parquet::errors::ParquetError;
use parquet::file::metadata::RowGroupMetaData;
use parquet::file::reader::{FileReader, RowGroupReader};
use parquet::file::serialized_reader::SerializedFileReader;

use super::ExportError;
use super::atomic::AtomicFile;
use super::fields::{Value, Values};
use super::schema::{Column, Table, describe_found};

/// Rows read from each column at a time.
const BATCH_ROWS: usize = 1 << 14;

/// Converts the Parquet file `source` of `table` into the CSV file `output`; returns the rows converted.
pub(super) fn parquet_to_csv(
    table: Table,
    source: &Path,
    output: &Path,
) -> Result<u64, ExportError> {
    let file_error = |what: String| ExportError::Parquet {
        path: source.to_path_buf(),
        what,
    };
    let io = |e| ExportError::Io {
        path: source.to_path_buf(),
        source: e,
    };
    let file = File::open(source).map_err(io)?;
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

    let (atomic, file) = AtomicFile::create(output)?;
    let mut out = CsvOut {
        out: BufWriter::with_capacity(1 << 16, file),
        line: Vec::new(),
        path: atomic.path().to_path_buf(),
    };
    out.line.extend_from_slice(table.header().as_bytes());
    out.end_line()?;
    let mut rows = 0u64;
    for index in 0..reader.num_row_groups() {
        let group_error = |what: String| ExportError::RowGroup {
            path: source.to_path_buf(),
            row_group: index,
            what,
        };
        let converted = || {
            check_chunks(reader.metadata().row_group(index), file_bytes).map_err(group_error)?;
            let group = reader
                .get_row_group(index)
                .map_err(|e| group_error(e.to_string()))?;
            convert_row_group(table.columns(), group.as_ref(), &mut out, group_error)
        };
        rows += unpanicked(converted, group_error)?;
    }
    let file = out.out.into_inner().map_err(|e| ExportError::Io {
        path: out.path.clone(),
        source: e.into_error(),
    })?;
    atomic.commit(file)?;
    Ok(rows)
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

/// The CSV file being written, errors naming it.
struct CsvOut {
    out: BufWriter<File>,
    /// The line being formatted.
    line: Vec<u8>,
    path: PathBuf,
}

impl CsvOut {
    /// Writes the line formatted in `line` and a line end.
    fn end_line(&mut self) -> Result<(), ExportError> {
        self.line.push(b'\n');
        self.out
            .write_all(&self.line)
            .map_err(|source| ExportError::Io {
                path: self.path.clone(),
                source,
            })
    }
}

/// Writes one row group's rows; returns how many. `error` names the row group.
fn convert_row_group(
    columns: &[Column],
    group: &dyn RowGroupReader,
    out: &mut CsvOut,
    error: impl Fn(String) -> ExportError,
) -> Result<u64, ExportError> {
    let claimed = group.metadata().num_rows();
    let expected = u64::try_from(claimed).map_err(|_| error(format!("{claimed} rows")))?;
    let mut cursors = columns
        .iter()
        .enumerate()
        .map(|(index, &column)| {
            let reader = group.get_column_reader(index).map_err(|e| e.to_string())?;
            ColumnCursor::new(column, reader)
        })
        .collect::<Result<Vec<_>, String>>()
        .map_err(&error)?;
    let mut rows = 0u64;
    loop {
        let counts = cursors
            .iter_mut()
            .map(ColumnCursor::read_batch)
            .collect::<Result<Vec<usize>, String>>()
            .map_err(&error)?;
        let batch = counts.first().copied().unwrap_or_default();
        if let Some(odd) = counts.iter().position(|&count| count != batch) {
            let (short, long) = if counts[odd] < batch {
                (odd, 0)
            } else {
                (0, odd)
            };
            return Err(error(format!(
                "column `{}` has fewer rows than column `{}`",
                columns[short].name, columns[long].name
            )));
        }
        if batch == 0 {
            break;
        }
        for row in 0..batch {
            out.line.clear();
            for (index, cursor) in cursors.iter_mut().enumerate() {
                if index > 0 {
                    out.line.push(b',');
                }
                let column = cursor.column;
                let formatted = cursor
                    .value(row)
                    .and_then(|value| column.format(value, &mut out.line));
                formatted.map_err(|e| {
                    error(format!(
                        "row {}, column `{}`: {e}",
                        rows + row as u64,
                        column.name
                    ))
                })?;
            }
            out.end_line()?;
        }
        rows += batch as u64;
    }
    if rows != expected {
        return Err(error(format!(
            "{rows} rows where its metadata says {expected}"
        )));
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

    /// The value of row `row` of the batch; rows are asked for in order.
    fn value(&mut self, row: usize) -> Result<Value<'_>, String> {
        let present = match &self.levels {
            Some(levels) => levels.get(row).is_some_and(|&level| level > 0),
            None => true,
        };
        if !present {
            return Ok(Value::Null);
        }
        let index = self.next_value;
        self.next_value += 1;
        self.values
            .get(index)
            .ok_or_else(|| format!("column `{}` has fewer values than rows", self.column.name))
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
