//! Writing a CSV line field by field, straight into the file's buffer, and the same fields into the table's
//! Parquet file when the run keeps one (`parquet_twin.rs`).
//!
//! The recorder's thread writes one trajectory row per robot per tick; with `write!` the `core::fmt` machinery
//! (shortest float digits by Grisu, padding, one adapter call per piece) took about 1.3 µs per row at N = 1,000,
//! more than a quarter of the world process's CPU. `itoa` and `ryu` format into stack buffers, and the pieces go
//! into the `BufWriter` as byte slices. Floats are written in `ryu`'s shortest round-trip form (`1.0`, `0.25`,
//! `1.5e-7`), which every CSV reader parses.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use swarm_records::Table;

use super::parquet_twin::ParquetTwin;
use crate::error::WorldError;

/// One record file: created with its header line, written through [`CsvLine`]s, errors naming its path.
pub struct CsvFile {
    path: PathBuf,
    out: BufWriter<File>,
    twin: Option<ParquetTwin>,
}

impl CsvFile {
    /// Creates (truncates) `path` with a buffer of `capacity` bytes and writes `header` as its first line.
    pub fn create(path: &Path, header: &str, capacity: usize) -> Result<CsvFile, WorldError> {
        let file = File::create(path).map_err(|source| WorldError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let mut csv = CsvFile {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(capacity, file),
            twin: None,
        };
        writeln!(csv.out, "{header}").map_err(|source| csv.error(source))?;
        Ok(csv)
    }

    /// Creates the run folder `dir`'s CSV file of `table`, with the table's header; with `parquet`, every line
    /// also goes into the table's Parquet file.
    pub fn for_table(
        dir: &Path,
        table: Table,
        capacity: usize,
        parquet: bool,
    ) -> Result<CsvFile, WorldError> {
        let mut csv = CsvFile::create(&dir.join(table.csv_name()), &table.header(), capacity)?;
        csv.twin = parquet
            .then(|| ParquetTwin::create(table, dir))
            .transpose()?;
        Ok(csv)
    }

    /// Starts a line.
    pub fn line(&mut self) -> CsvLine<'_, File> {
        CsvLine::new(&mut self.out, self.twin.as_mut())
    }

    /// Writes the buffer to the file.
    pub fn flush(&mut self) -> Result<(), WorldError> {
        self.out.flush().map_err(|source| self.error(source))
    }

    /// Flushes the file and finishes its Parquet twin (the record is complete).
    pub fn close(&mut self) -> Result<(), WorldError> {
        self.flush()?;
        match self.twin.take() {
            Some(twin) => twin.finish(),
            None => Ok(()),
        }
    }

    /// `source` as an error of this file.
    pub fn error(&self, source: std::io::Error) -> WorldError {
        WorldError::Io {
            path: self.path.clone(),
            source,
        }
    }
}

/// Writes one line's fields, separated by commas, into `out` (and into `twin`); [`CsvLine::end`] ends the line.
pub struct CsvLine<'a, W: Write> {
    out: &'a mut BufWriter<W>,
    twin: Option<&'a mut ParquetTwin>,
    first: bool,
}

impl<'a, W: Write> CsvLine<'a, W> {
    /// Starts a line.
    pub fn new(out: &'a mut BufWriter<W>, twin: Option<&'a mut ParquetTwin>) -> Self {
        CsvLine {
            out,
            twin,
            first: true,
        }
    }

    fn separate(&mut self) -> std::io::Result<()> {
        if !std::mem::take(&mut self.first) {
            self.out.write_all(b",")?;
        }
        Ok(())
    }

    /// An integer field.
    pub fn int(mut self, value: impl itoa::Integer + Into<u64>) -> std::io::Result<Self> {
        self.separate()?;
        self.out
            .write_all(itoa::Buffer::new().format(value).as_bytes())?;
        if let Some(twin) = &mut self.twin {
            twin.int(value.into());
        }
        Ok(self)
    }

    /// A float field, shortest round-trip digits.
    pub fn float(mut self, value: f32) -> std::io::Result<Self> {
        self.separate()?;
        self.out
            .write_all(ryu::Buffer::new().format(value).as_bytes())?;
        if let Some(twin) = &mut self.twin {
            twin.float(value);
        }
        Ok(self)
    }

    /// A float appended to the text field just written (`within:` then `0.5`), shortest round-trip digits.
    pub fn float_joined(mut self, value: f32) -> std::io::Result<Self> {
        let mut digits = ryu::Buffer::new();
        let digits = digits.format(value);
        self.out.write_all(digits.as_bytes())?;
        if let Some(twin) = &mut self.twin {
            twin.append(digits);
        }
        Ok(self)
    }

    /// A text field, as is (the caller's text holds no comma, quote or line break).
    pub fn text(mut self, value: &str) -> std::io::Result<Self> {
        self.separate()?;
        self.out.write_all(value.as_bytes())?;
        if let Some(twin) = &mut self.twin {
            twin.text(value);
        }
        Ok(self)
    }

    /// A text field made of `prefix` and an integer (`#7`).
    pub fn prefixed_int(
        mut self,
        prefix: &str,
        value: impl itoa::Integer,
    ) -> std::io::Result<Self> {
        self.separate()?;
        let mut digits = itoa::Buffer::new();
        let digits = digits.format(value);
        self.out.write_all(prefix.as_bytes())?;
        self.out.write_all(digits.as_bytes())?;
        if let Some(twin) = &mut self.twin {
            twin.text(prefix);
            twin.append(digits);
        }
        Ok(self)
    }

    /// Ends the line.
    pub fn end(self) -> std::io::Result<()> {
        self.out.write_all(b"\n")?;
        match self.twin {
            Some(twin) => twin.end(),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use std::io::BufWriter;

    use super::CsvLine;

    fn line(write: impl FnOnce(CsvLine<'_, Vec<u8>>) -> std::io::Result<()>) -> String {
        let mut out = BufWriter::new(Vec::new());
        write(CsvLine::new(&mut out, None)).expect("writes");
        String::from_utf8(out.into_inner().expect("flushes")).expect("utf-8")
    }

    #[test]
    fn fields_are_comma_separated_and_floats_read_back_exactly() {
        let values = [0.0f32, -1.25, 1.0 / 3.0, 1.5e-7, 2.0e9, f32::MIN_POSITIVE];
        let text = line(|l| {
            let mut l = l.int(42u64)?.text("ep3")?;
            for v in values {
                l = l.float(v)?;
            }
            l.prefixed_int("#", 7u8)?.int(255u8)?.end()
        });
        let fields: Vec<&str> = text.trim_end_matches('\n').split(',').collect();
        assert_eq!(&fields[..2], ["42", "ep3"]);
        let floats: Vec<f32> = fields[2..8]
            .iter()
            .map(|f| f.parse().expect("a float"))
            .collect();
        assert_eq!(floats, values);
        assert_eq!(&fields[8..], ["#7", "255"]);
        assert!(text.ends_with('\n') && text.matches('\n').count() == 1);
    }
}
