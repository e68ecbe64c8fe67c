//! `messages.csv`: every decision of the messages medium (`crate::media::mail`), one row per message and
//! recipient, or one row for a message refused as a whole (docs/records.md).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use swarm_contract::mail::Address;
use swarm_contract::run_dir::MESSAGES_FILE;

use super::csv_line::CsvLine;
use crate::error::WorldError;
use crate::media::mail::MessageRecord;

/// Writes `messages.csv`.
pub struct MessagesWriter {
    path: PathBuf,
    out: BufWriter<File>,
}

impl MessagesWriter {
    /// Creates `messages.csv` in `dir` with its header line.
    pub fn create(dir: &Path) -> Result<MessagesWriter, WorldError> {
        let path = dir.join(MESSAGES_FILE);
        let io_error = |source| WorldError::Io {
            path: path.clone(),
            source,
        };
        let mut out = BufWriter::new(File::create(&path).map_err(io_error)?);
        writeln!(out, "tick,from,to,address,bytes,outcome,reason").map_err(io_error)?;
        Ok(MessagesWriter { path, out })
    }

    /// Formats `row` into the file's buffer.
    pub fn write_row(&mut self, row: &MessageRecord) -> Result<(), WorldError> {
        self.format(row).map_err(|source| self.error(source))
    }

    /// Writes the buffer to the file.
    pub fn flush(&mut self) -> Result<(), WorldError> {
        self.out.flush().map_err(|source| self.error(source))
    }

    fn error(&self, source: std::io::Error) -> WorldError {
        WorldError::Io {
            path: self.path.clone(),
            source,
        }
    }

    fn format(&mut self, row: &MessageRecord) -> std::io::Result<()> {
        let line = CsvLine::new(&mut self.out).int(row.tick)?.int(row.from)?;
        let line = match row.to {
            Some(to) => line.int(to)?,
            None => line.text("")?,
        };
        let line = match row.address {
            Address::To(_) => line.text("one")?,
            Address::All => line.text("all")?,
            Address::Within(range) => line.text("within:")?.float_joined(range)?,
        };
        line.int(row.bytes)?
            .text(row.fate.outcome())?
            .text(row.fate.reason())?
            .end()
    }
}
