//! Writing an output file atomically while streaming into it: into `.<name>.<pid>.tmp` beside it (the naming of
//! `swarm_contract::run_dir::write_atomically`), renamed over it once complete. A conversion that fails, or
//! unwinds, removes its temporary file and leaves any earlier output as it was.

use std::fs::File;
use std::path::{Path, PathBuf};

use super::ExportError;

/// An output file being written.
pub(super) struct AtomicFile {
    path: PathBuf,
    temporary: PathBuf,
    committed: bool,
}

impl AtomicFile {
    /// Creates the temporary file for `path`; write into the returned file, then [`AtomicFile::commit`] it.
    pub fn create(path: &Path) -> Result<(AtomicFile, File), ExportError> {
        let name = path
            .file_name()
            .map_or_else(|| "file".into(), |n| n.to_string_lossy().into_owned());
        let temporary = path.with_file_name(temporary_name(&name, std::process::id()));
        let file = File::create(&temporary).map_err(|source| ExportError::Io {
            path: temporary.clone(),
            source,
        })?;
        let atomic = AtomicFile {
            path: path.to_path_buf(),
            temporary,
            committed: false,
        };
        Ok((atomic, file))
    }

    /// The file's final path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Syncs `file` (the one [`AtomicFile::create`] returned, fully written) and renames it into place.
    pub fn commit(mut self, file: File) -> Result<(), ExportError> {
        let io = |source| ExportError::Io {
            path: self.temporary.clone(),
            source,
        };
        file.sync_all().map_err(io)?;
        drop(file);
        std::fs::rename(&self.temporary, &self.path).map_err(io)?;
        self.committed = true;
        Ok(())
    }
}

/// The temporary name process `pid` writes the file `name` under.
fn temporary_name(name: &str, pid: u32) -> String {
    format!(".{name}.{pid}.tmp")
}

/// Whether `file_name` is a temporary file some process wrote `name` under and left (it was killed before it
/// renamed it).
pub(super) fn is_temporary_of(file_name: &str, name: &str) -> bool {
    file_name
        .strip_prefix('.')
        .and_then(|rest| rest.strip_prefix(name))
        .and_then(|rest| rest.strip_prefix('.'))
        .and_then(|rest| rest.strip_suffix(".tmp"))
        .is_some_and(|pid| pid.parse::<u32>().is_ok())
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.temporary);
        }
    }
}
