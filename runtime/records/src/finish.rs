//! The end of a run's recording: the CSV files the world appended to become Parquet files, and the CSV files go.

use std::path::Path;

use crate::{ExportError, ExportReport, Format, Table, convert};

/// Turns every CSV record file of the finished run in `run_dir` into its Parquet file, the tables on threads of
/// their own, then removes the CSV files. On an error nothing is removed: the CSV files stay, whole, and the
/// Parquet files written by this call are taken away again, so the folder never holds two versions of a table.
pub fn finish_run_records(run_dir: &Path) -> Result<ExportReport, ExportError> {
    let converted: Vec<_> = std::thread::scope(|scope| {
        let threads: Vec<_> = Table::ALL
            .into_iter()
            .map(|table| {
                (
                    table,
                    scope.spawn(move || convert(run_dir, table, Format::Parquet)),
                )
            })
            .collect();
        threads
            .into_iter()
            .map(|(table, thread)| {
                thread.join().unwrap_or_else(|_| {
                    Err(ExportError::Parquet {
                        path: run_dir.join(table.parquet_name()),
                        what: "the conversion stopped on an internal error".to_owned(),
                    })
                })
            })
            .collect()
    });
    let mut report = ExportReport::default();
    let mut failure = None;
    for file in converted {
        match file {
            Ok(file) => report.files.extend(file),
            Err(e) => failure = failure.or(Some(e)),
        }
    }
    if let Some(failure) = failure {
        for file in &report.files {
            let _ = std::fs::remove_file(&file.output);
        }
        return Err(failure);
    }
    for file in &report.files {
        std::fs::remove_file(&file.source).map_err(|source| ExportError::Io {
            path: file.source.clone(),
            source,
        })?;
    }
    Ok(report)
}
