//! The end of a run's recording: each table ends up as a Parquet file only, its CSV file gone.
//!
//! The world writes each table's Parquet file beside the CSV file as the run goes and completes it when the run
//! ends normally; such a table only loses its CSV file here. A table without its Parquet file (the world died, or
//! wrote CSV only) is converted from the CSV file, which the launcher has cut back to whole ticks by then.

use std::path::Path;

use crate::atomic::is_temporary_of;
use crate::{ExportError, ExportReport, Format, Table, convert};

/// Leaves every record table of the ended run in `run_dir` as a Parquet file: a table whose Parquet file the
/// world completed keeps it, the others are converted from their CSV files on threads of their own; then the CSV
/// files are removed, and so are unfinished Parquet files a dead world left. Returns the conversions made. On an
/// error nothing is removed: the CSV files stay, whole, and the Parquet files converted by this call are taken
/// away again, so the folder never holds a table's Parquet file without its CSV file unless it is complete.
pub fn finish_run_records(run_dir: &Path) -> Result<ExportReport, ExportError> {
    remove_unfinished(run_dir);
    let present = |name: &str| run_dir.join(name).is_file();
    let (complete, to_convert): (Vec<Table>, Vec<Table>) = Table::ALL
        .into_iter()
        .filter(|table| present(table.csv_name()))
        .partition(|table| present(table.parquet_name()));
    let converted: Vec<_> = std::thread::scope(|scope| {
        let threads: Vec<_> = to_convert
            .iter()
            .map(|&table| {
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
    let sources = complete
        .iter()
        .map(|table| run_dir.join(table.csv_name()))
        .chain(report.files.iter().map(|file| file.source.clone()));
    for source in sources {
        std::fs::remove_file(&source).map_err(|e| ExportError::Io {
            path: source,
            source: e,
        })?;
    }
    Ok(report)
}

/// Removes the temporary Parquet files (`.<table>.parquet.<pid>.tmp`) of a world that did not complete them.
fn remove_unfinished(run_dir: &Path) {
    let Ok(entries) = std::fs::read_dir(run_dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        let unfinished = Table::ALL
            .iter()
            .any(|table| is_temporary_of(&name, table.parquet_name()));
        if unfinished {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}
