//! `messages.csv`: every decision of the messages medium (`crate::media::mail`), one row per message and
//! recipient, or one row for a message refused as a whole (docs/records.md).

use std::path::Path;

use swarm_contract::mail::{Address, FROM_WORLD, TO_WORLD};

use super::csv_line::CsvFile;
use crate::error::WorldError;
use crate::media::mail::MessageRecord;

/// Writes `messages.csv`.
pub struct MessagesWriter {
    file: CsvFile,
}

impl MessagesWriter {
    /// Creates `messages.csv` in `dir` with its header line; with `parquet`, also the table's Parquet file.
    pub fn create(dir: &Path, parquet: bool) -> Result<MessagesWriter, WorldError> {
        let file = CsvFile::for_table(dir, swarm_records::Table::Messages, 1 << 13, parquet)?;
        Ok(MessagesWriter { file })
    }

    /// Formats `row` into the file's buffer.
    pub fn write_row(&mut self, row: &MessageRecord) -> Result<(), WorldError> {
        self.format(row).map_err(|source| self.file.error(source))
    }

    /// Writes the buffer to the file.
    pub fn flush(&mut self) -> Result<(), WorldError> {
        self.file.flush()
    }

    /// Flushes the file and completes its Parquet file.
    pub fn close(&mut self) -> Result<(), WorldError> {
        self.file.close()
    }

    fn format(&mut self, row: &MessageRecord) -> std::io::Result<()> {
        let line = self.file.line().int(row.tick)?;
        let line = if row.from == FROM_WORLD {
            line.text("world")?
        } else {
            line.int(row.from)?
        };
        let line = match row.to {
            Some(TO_WORLD) => line.text("world")?,
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
