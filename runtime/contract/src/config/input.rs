//! Reading an input file a person handed us, with limits: only regular files (a FIFO would block forever,
//! `/dev/zero` would never end), at most a given size (checked before and while reading), and text that is not
//! UTF-8 reported at the line and column of its first bad byte.

use std::io::Read;
use std::path::Path;

use super::diagnostic::Diagnostic;
use super::model::Location;
use super::xml::LineIndex;

/// Largest experiment configuration accepted: ARGoS files are a few kilobytes; a limit keeps a wrong or hostile
/// path from using unbounded memory or time.
pub const MAX_CONFIG_BYTES: u64 = 16 * 1024 * 1024;

/// Reads `path` as UTF-8 text of at most `max_bytes`; every refusal is a diagnostic naming the file.
pub fn read_text(path: &Path, max_bytes: u64) -> Result<String, Diagnostic> {
    let refuse = |location: Location, message: String| {
        Diagnostic::new(path.to_path_buf(), location, message)
    };
    let at_start = Location::default();
    let metadata = std::fs::metadata(path)
        .map_err(|e| refuse(at_start, format!("cannot read the file: {e}")))?;
    if !metadata.is_file() {
        return Err(refuse(
            at_start,
            "is not a regular file (a device, FIFO or folder cannot be an input)".into(),
        ));
    }
    if metadata.len() > max_bytes {
        return Err(refuse(
            at_start,
            format!(
                "is {} bytes, more than the {max_bytes} an input file may have",
                metadata.len()
            ),
        ));
    }
    let file = std::fs::File::open(path)
        .map_err(|e| refuse(at_start, format!("cannot read the file: {e}")))?;
    let mut bytes = Vec::new();
    // The file may grow between the size check and the read.
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| refuse(at_start, format!("cannot read the file: {e}")))?;
    if bytes.len() as u64 > max_bytes {
        return Err(refuse(
            at_start,
            format!("grew beyond the {max_bytes} bytes an input file may have while it was read"),
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let bytes = e.into_bytes();
        let prefix = String::from_utf8_lossy(&bytes[..valid]);
        let location = LineIndex::new(&prefix).locate(valid);
        refuse(
            location,
            format!(
                "invalid UTF-8 (byte 0x{:02x}): the file must be UTF-8 text",
                bytes[valid]
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_utf8_is_located_at_its_first_bad_byte() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("bad.argos");
        std::fs::write(&path, b"<a>\n  <b x=\"\xe9\"/>\n</a>\n").expect("write");
        let err = read_text(&path, MAX_CONFIG_BYTES).expect_err("not UTF-8");
        assert_eq!(
            err.to_string(),
            format!(
                "{}:2:9: invalid UTF-8 (byte 0xe9): the file must be UTF-8 text",
                path.display()
            )
        );
    }

    #[test]
    fn devices_fifos_folders_and_oversized_files_are_refused_without_reading_them() {
        let dir = tempfile::tempdir().expect("temp dir");
        let fifo = dir.path().join("fifo");
        let name = std::ffi::CString::new(std::os::unix::ffi::OsStrExt::as_bytes(fifo.as_os_str()))
            .expect("no NUL in a temporary path");
        // SAFETY: `name` is a valid NUL-terminated path for the duration of the call.
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0, "mkfifo");
        for path in [Path::new("/dev/zero"), &fifo, dir.path()] {
            let err = read_text(path, MAX_CONFIG_BYTES).expect_err("not a regular file");
            assert!(err.to_string().contains("is not a regular file"), "{err}");
        }
        let big = dir.path().join("big.argos");
        std::fs::write(&big, vec![b' '; 101]).expect("write");
        let err = read_text(&big, 100).expect_err("too big");
        assert!(
            err.to_string().contains("is 101 bytes, more than the 100"),
            "{err}"
        );
        std::fs::write(&big, vec![b' '; 100]).expect("write");
        assert_eq!(read_text(&big, 100).expect("at the limit").len(), 100);
    }
}
