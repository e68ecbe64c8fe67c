//! A shared, writable mapping of a whole file of the run in `/dev/shm`: the sync block and the command slots
//! are such files, created by the world and mapped by every agent.

use std::fs::{File, OpenOptions};
use std::io;
use std::os::fd::AsRawFd;
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;
use std::ptr::NonNull;

/// A shared mapping of the first `len` bytes of a file; unmapped on drop.
pub(crate) struct SharedMap {
    base: NonNull<u8>,
    len: usize,
}

// SAFETY: the mapping is plain memory that stays mapped until the SharedMap is dropped; what may be done with it
// concurrently is up to the types that lay out their data in it (atomics, or data guarded by them).
unsafe impl Send for SharedMap {}
// SAFETY: as above.
unsafe impl Sync for SharedMap {}

impl SharedMap {
    /// Creates the file at `path` (failing if it exists) with `len` zero bytes and maps it. Only the run's user
    /// may read or write the file (mode 0600, as iceoryx2 makes its own files): the words in it start, stop and
    /// steer the run.
    pub(crate) fn create(path: &Path, len: usize) -> io::Result<SharedMap> {
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .mode(0o600)
            .open(path)?;
        file.set_len(len as u64)?;
        SharedMap::map(&file, len)
    }

    /// Opens the existing file at `path` for reading and writing, with its length.
    pub(crate) fn open_file(path: &Path) -> io::Result<(File, u64)> {
        let file = OpenOptions::new().read(true).write(true).open(path)?;
        let len = file.metadata()?.len();
        Ok((file, len))
    }

    /// Maps the first `len` bytes of `file`, shared and writable.
    pub(crate) fn map(file: &File, len: usize) -> io::Result<SharedMap> {
        // SAFETY: a fresh shared mapping of an open file descriptor; the kernel picks the address.
        let ptr = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                len,
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_SHARED,
                file.as_raw_fd(),
                0,
            )
        };
        if ptr == libc::MAP_FAILED {
            return Err(io::Error::last_os_error());
        }
        let base =
            NonNull::new(ptr.cast::<u8>()).ok_or_else(|| io::Error::other("mmap returned null"))?;
        Ok(SharedMap { base, len })
    }

    /// The start of the mapping (page-aligned).
    pub(crate) fn base(&self) -> *mut u8 {
        self.base.as_ptr()
    }

    /// The mapped length in bytes.
    pub(crate) fn len(&self) -> usize {
        self.len
    }
}

impl Drop for SharedMap {
    fn drop(&mut self) {
        // SAFETY: base/len are exactly what mmap returned; nothing borrows the mapping past its owner.
        unsafe {
            libc::munmap(self.base.as_ptr().cast(), self.len);
        }
    }
}

#[cfg(test)]
mod tests {
    use std::os::unix::fs::PermissionsExt;
    use std::path::PathBuf;

    use super::SharedMap;

    #[test]
    fn a_created_file_is_open_to_its_owner_only() {
        let path = PathBuf::from(format!(
            "/dev/shm/swarm-test-{}-shared-map",
            std::process::id()
        ));
        let created = SharedMap::create(&path, 4096);
        let mode = std::fs::metadata(&path).map(|m| m.permissions().mode() & 0o777);
        let _ = std::fs::remove_file(&path);
        created.expect("create the file");
        assert_eq!(mode.expect("the file's mode"), 0o600);
    }
}
