//! Reading a record CSV file line by line, with the line numbers errors name, in bounded memory: a line longer than
//! [`MAX_LINE`] (a file that is not a record, or has no line ends) is an error, not a growing buffer.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use super::ExportError;

/// The longest line accepted, line end included. A trajectory row is about 60 bytes; robot ids are short.
pub(super) const MAX_LINE: usize = 1 << 20;

/// The lines of one CSV file.
pub(super) struct CsvLines {
    path: PathBuf,
    reader: BufReader<File>,
    line: Vec<u8>,
    number: u64,
}

impl CsvLines {
    /// Opens `path`.
    pub fn open(path: &Path) -> Result<CsvLines, ExportError> {
        let file = File::open(path).map_err(|source| ExportError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(CsvLines {
            path: path.to_path_buf(),
            reader: BufReader::with_capacity(1 << 16, file),
            line: Vec::new(),
            number: 0,
        })
    }

    /// The next line without its line end; `None` at the end of the file. A last line without a line end is an
    /// error: the world ends every line, so such a file was cut short (a run whose launcher was killed, or one still
    /// being written).
    pub fn next_line(&mut self) -> Result<Option<&[u8]>, ExportError> {
        self.line.clear();
        let read = (&mut self.reader)
            .take(MAX_LINE as u64)
            .read_until(b'\n', &mut self.line)
            .map_err(|source| ExportError::Io {
                path: self.path.clone(),
                source,
            })?;
        if read == 0 {
            return Ok(None);
        }
        self.number += 1;
        match self.line.pop() {
            Some(b'\n') => Ok(Some(&self.line)),
            _ if read == MAX_LINE => Err(self.error(format!("longer than {MAX_LINE} bytes"))),
            _ => Err(self.error(
                "cut short: the file ends inside this line (a run cut short, or still going?)",
            )),
        }
    }

    /// An error about the line last read.
    pub fn error(&self, what: impl Into<String>) -> ExportError {
        ExportError::Csv {
            path: self.path.clone(),
            line: self.number,
            what: what.into(),
        }
    }
}
