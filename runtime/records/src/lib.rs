//! swarm-records: a run's record tables (trajectory, events, messages) in the two formats a run folder can hold
//! them in, and the conversions between them.
//!
//! The world writes the tables as CSV while the run goes (`world/src/recorder/`): appended tick by tick, so that a
//! run cut short keeps every whole tick and `swarm run --view` can follow the files. It hands the same fields to a
//! [`TableWriter`] per table, whose Parquet file it completes when the run ends normally. The launcher then
//! removes the CSV files, converting first any table the world could not complete ([`finish_run_records`]),
//! unless the run was asked for CSV (`swarm run --records csv`). `swarm export` converts either way
//! ([`export`]); `swarm view` reads the Parquet files row group by row group ([`ParquetTable`]).
//!
//! The Parquet files keep the CSV columns, names and order (docs/records.md) with typed columns, so that
//! `pd.read_parquet` and `pl.read_parquet` need no dtype arguments (`schema.rs`): unsigned integers with their
//! width (`tick` UINT_64, `robot` UINT_32, LEDs UINT_8), 32-bit floats (a pose that is `NaN` stays NaN, not null),
//! `alive` BOOLEAN, text UTF8 and dictionary-encoded. In `messages`, the empty `to` of a broadcast and the empty
//! `reason` of a delivered message are nulls, and the world's own `from`/`to`, spelt `world` in CSV, is stored as
//! the contract's number for it (`swarm_contract::mail::FROM_WORLD`, `TO_WORLD`).
//!
//! Parquet -> CSV gives back the world's file byte for byte (`fields.rs` spells every value as the recorder does).
//! Both ways stream: memory holds one row group at most, whatever the file's size, and every output is written to
//! a temporary file renamed into place once complete (`atomic.rs`). A malformed CSV line, a header that is not the
//! table's, or a Parquet file that is truncated or not one of the run's tables is an [`ExportError`] naming the
//! file and the line or row group.

#![warn(missing_docs)]

mod atomic;
mod csv_lines;
mod error;
mod fields;
mod finish;
mod reader;
mod schema;
mod to_csv;
mod to_parquet;
mod writer;

#[cfg(test)]
mod tests;

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

pub use error::ExportError;
pub use fields::{Field, Value};
pub use finish::finish_run_records;
pub use reader::ParquetTable;
pub use schema::{Column, Kind, Table};
pub use writer::{MAX_COLUMNS, TableWriter};

/// A format of a run's record files.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// CSV, as the world writes the files while the run goes.
    Csv,
    /// Apache Parquet.
    #[default]
    Parquet,
}

impl Format {
    /// The format converted from when converting into this one.
    pub fn other(self) -> Format {
        match self {
            Format::Csv => Format::Parquet,
            Format::Parquet => Format::Csv,
        }
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::Csv => "CSV",
            Format::Parquet => "Parquet",
        })
    }
}

/// What [`export`] converted.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExportReport {
    /// One entry per converted file, in the order the world writes them (trajectory, events, messages).
    pub files: Vec<FileReport>,
}

/// One converted file.
#[derive(Clone, Debug, PartialEq)]
pub struct FileReport {
    /// The file read.
    pub source: PathBuf,
    /// The file written.
    pub output: PathBuf,
    /// Data rows (the CSV header not counted).
    pub rows: u64,
    /// Size of the file read.
    pub source_bytes: u64,
    /// Size of the file written.
    pub output_bytes: u64,
    /// Wall seconds the conversion took.
    pub seconds: f64,
}

impl fmt::Display for FileReport {
    /// `trajectory.csv -> trajectory.parquet: 1001000 rows, 54.6 MB -> 9.9 MB in 1.20 s`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = |path: &Path| {
            path.file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned()
        };
        let megabytes = |bytes: u64| bytes as f64 / 1e6;
        write!(
            f,
            "{} -> {}: {} rows, {:.1} MB -> {:.1} MB in {:.2} s",
            name(&self.source),
            name(&self.output),
            self.rows,
            megabytes(self.source_bytes),
            megabytes(self.output_bytes),
            self.seconds
        )
    }
}

/// Converts every record file of `run_dir` that exists in the other format into `format`, beside it, replacing
/// an earlier output of the same name. Files are converted one after the other; on an error, the files before it
/// are converted and the failing one's output is untouched.
pub fn export(run_dir: &Path, format: Format) -> Result<ExportReport, ExportError> {
    if !run_dir.is_dir() {
        return Err(ExportError::NoRunDir(run_dir.to_path_buf()));
    }
    let mut report = ExportReport::default();
    for table in Table::ALL {
        report.files.extend(convert(run_dir, table, format)?);
    }
    if report.files.is_empty() {
        let looked_for: Vec<&str> = Table::ALL
            .iter()
            .map(|table| table.file_name(format.other()))
            .collect();
        return Err(ExportError::NoRecords {
            dir: run_dir.to_path_buf(),
            format,
            looked_for: looked_for.join(", "),
        });
    }
    Ok(report)
}

/// Converts `table`'s file of `run_dir` in the other format into `format`, beside it; `None` when the run has no
/// such file.
fn convert(
    run_dir: &Path,
    table: Table,
    format: Format,
) -> Result<Option<FileReport>, ExportError> {
    let source = run_dir.join(table.file_name(format.other()));
    let source_bytes = match std::fs::metadata(&source) {
        Ok(metadata) if metadata.is_file() => metadata.len(),
        Ok(_) => return Ok(None),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => {
            return Err(ExportError::Io {
                path: source,
                source: e,
            });
        }
    };
    let output = run_dir.join(table.file_name(format));
    let started = Instant::now();
    let rows = match format {
        Format::Parquet => to_parquet::csv_to_parquet(table, &source, &output)?,
        Format::Csv => to_csv::parquet_to_csv(table, &source, &output)?,
    };
    let seconds = started.elapsed().as_secs_f64();
    let output_bytes = std::fs::metadata(&output)
        .map_err(|e| ExportError::Io {
            path: output.clone(),
            source: e,
        })?
        .len();
    Ok(Some(FileReport {
        source,
        output,
        rows,
        source_bytes,
        output_bytes,
        seconds,
    }))
}
