//! What can go wrong converting a run's records, each naming the file and, inside it, the CSV line or the Parquet
//! row group.

use std::path::PathBuf;

use super::Format;

/// Why `swarm export` could not convert a run's records.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The run folder does not exist (or is not a folder).
    #[error("{}: no such run folder", .0.display())]
    NoRunDir(PathBuf),
    /// The run folder holds none of the record files the conversion reads.
    #[error("{}: no record file to export as {format} (looked for {looked_for})", dir.display())]
    NoRecords {
        /// The run folder.
        dir: PathBuf,
        /// The format asked for.
        format: Format,
        /// The file names looked for, comma-separated.
        looked_for: String,
    },
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// A CSV line is not a row of its table.
    #[error("{}, line {line}: {what}", path.display())]
    Csv {
        /// The CSV file.
        path: PathBuf,
        /// The line, from 1 (the header).
        line: u64,
        /// What is wrong with it.
        what: String,
    },
    /// A Parquet file as a whole is unreadable or not one of the run's tables (footer, schema), or could not be
    /// written.
    #[error("{}: {what}", path.display())]
    Parquet {
        /// The Parquet file.
        path: PathBuf,
        /// What is wrong with it.
        what: String,
    },
    /// A row group of a Parquet file cannot be read or turned into CSV.
    #[error("{}, row group {row_group}: {what}", path.display())]
    RowGroup {
        /// The Parquet file.
        path: PathBuf,
        /// The row group, from 0.
        row_group: usize,
        /// What is wrong with it.
        what: String,
    },
}
