//! Reading a record file that may still be growing: each call hands over the whole lines appended since the
//! previous call, with their line numbers and byte offsets, and keeps an unfinished last line for later.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// Bytes read per call at most, so that indexing a huge file never holds more than this in memory at once.
const MAX_READ: usize = 8 << 20;
/// Longest line accepted: a record row is a few dozen bytes, so a longer one means the file is not a record.
pub const MAX_LINE: usize = 1 << 20;

/// Where reading of one file stands.
pub struct GrowingLines {
    path: PathBuf,
    file: Option<File>,
    /// Offset of the first byte not yet handed over (the start of `pending`).
    offset: u64,
    /// Number of the next line, 1-based.
    next_line: u64,
    /// The start of a line whose end has not been written yet.
    pending: Vec<u8>,
}

/// One whole line.
pub struct Line<'a> {
    /// 1-based line number.
    pub number: u64,
    /// Byte offset of the line's first byte in the file.
    pub offset: u64,
    /// The line without its `\n`.
    pub text: &'a [u8],
}

impl GrowingLines {
    /// Reads `path` from its start; the file need not exist yet.
    pub fn new(path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            file: None,
            offset: 0,
            next_line: 1,
            pending: Vec::new(),
        }
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Bytes at the end of the file that do not form a whole line yet.
    pub fn unfinished_bytes(&self) -> usize {
        self.pending.len()
    }

    /// Hands every whole line written since the last call to `each`, stopping early when `each` returns `false`
    /// (the lines after it are handed over again next time). Returns whether the file exists.
    pub fn read_new(&mut self, mut each: impl FnMut(Line<'_>) -> bool) -> std::io::Result<bool> {
        if self.file.is_none() {
            match File::open(&self.path) {
                Ok(file) => self.file = Some(file),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
                Err(e) => return Err(e),
            }
        }
        let Some(file) = self.file.as_mut() else {
            return Ok(false);
        };
        loop {
            let already = self.pending.len();
            file.seek(SeekFrom::Start(self.offset + already as u64))?;
            let mut chunk = Vec::with_capacity(MAX_READ.min(1 << 20));
            let read = file.take(MAX_READ as u64).read_to_end(&mut chunk)?;
            if read == 0 {
                return Ok(true);
            }
            self.pending.extend_from_slice(&chunk);
            let mut start = 0;
            let mut stopped = false;
            while let Some(end) = self.pending[start..].iter().position(|&b| b == b'\n') {
                let line = Line {
                    number: self.next_line,
                    offset: self.offset + start as u64,
                    text: &self.pending[start..start + end],
                };
                if !each(line) {
                    stopped = true;
                    break;
                }
                self.next_line += 1;
                start += end + 1;
            }
            self.offset += start as u64;
            self.pending.drain(..start);
            if stopped {
                self.pending.clear();
                return Ok(true);
            }
            if self.pending.len() > MAX_LINE {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    format!(
                        "line {} is longer than {MAX_LINE} bytes: not a record file",
                        self.next_line
                    ),
                ));
            }
            if read < MAX_READ {
                return Ok(true);
            }
        }
    }

    /// Hands the new lines to `each` until it refuses one: the first refusal (or read error) becomes `problem`
    /// (`file:line: what`) and ends reading for good. Returns whether the file exists.
    pub fn read_until_problem(
        &mut self,
        problem: &mut Option<String>,
        mut each: impl FnMut(Line<'_>) -> Result<(), String>,
    ) -> bool {
        if problem.is_some() {
            return true;
        }
        let path = self.path.display().to_string();
        let read = self.read_new(|line| {
            let number = line.number;
            each(line)
                .map_err(|what| *problem = Some(format!("{path}:{number}: {what}")))
                .is_ok()
        });
        read.unwrap_or_else(|e| {
            *problem = Some(format!("{path}: {e}"));
            true
        })
    }
}

#[cfg(test)]
mod tests {
    use super::GrowingLines;
    use std::io::Write;

    fn collect(lines: &mut GrowingLines) -> Vec<(u64, u64, String)> {
        let mut out = Vec::new();
        lines
            .read_new(|l| {
                out.push((
                    l.number,
                    l.offset,
                    String::from_utf8_lossy(l.text).into_owned(),
                ));
                true
            })
            .expect("readable");
        out
    }

    #[test]
    fn hands_over_whole_lines_as_the_file_grows() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("f.csv");
        let mut lines = GrowingLines::new(&path);
        assert!(collect(&mut lines).is_empty(), "no file yet");
        let mut file = std::fs::File::create(&path).expect("created");
        file.write_all(b"a,1\nb,").expect("written");
        assert_eq!(collect(&mut lines), vec![(1, 0, "a,1".to_owned())]);
        assert_eq!(lines.unfinished_bytes(), 2);
        file.write_all(b"2\nc,3\n").expect("written");
        assert_eq!(
            collect(&mut lines),
            vec![(2, 4, "b,2".to_owned()), (3, 8, "c,3".to_owned())]
        );
        assert_eq!(lines.unfinished_bytes(), 0);
    }

    #[test]
    fn an_endless_line_is_refused_without_holding_the_file() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("f.csv");
        std::fs::write(&path, vec![b'x'; super::MAX_LINE + 10]).expect("written");
        let mut lines = GrowingLines::new(&path);
        let error = lines.read_new(|_| true).expect_err("refused");
        assert!(
            error.to_string().contains("line 1 is longer than"),
            "{error}"
        );
    }

    #[test]
    fn a_stop_hands_the_rest_over_again() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("f.csv");
        std::fs::write(&path, b"1\n2\n3\n").expect("written");
        let mut lines = GrowingLines::new(&path);
        let mut first = Vec::new();
        lines
            .read_new(|l| {
                first.push(l.number);
                l.number < 2
            })
            .expect("readable");
        assert_eq!(first, vec![1, 2]);
        let rest: Vec<u64> = collect(&mut lines).into_iter().map(|l| l.0).collect();
        assert_eq!(rest, vec![2, 3]);
    }
}
