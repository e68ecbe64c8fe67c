//! The front door of the toolchain: read model files from disk, then validate them as one project.
//!
//! Shape problems of one file do not hide problems of the others: every readable file is validated, and all
//! diagnostics come back together. Only I/O failures are errors of this function.

use std::path::{Path, PathBuf};

use crate::automaton::ModelKind;
use crate::diagnostics::{self, Code, Diagnostic, LineIndex};
use crate::validate::{ValidateOptions, Validation, validate};
use crate::xml_read::read_model;

/// One model file and the role it was given (`None` when the file's own `type` decides).
#[derive(Debug, Clone)]
pub struct Input {
    /// Path of the file; diagnostics name it as written here.
    pub path: PathBuf,
    /// `Some(Plant)` for `--plant`, `Some(Spec)` for `--spec`.
    pub role: Option<ModelKind>,
}

impl Input {
    /// An input with an explicit role.
    pub fn new(path: impl Into<PathBuf>, role: Option<ModelKind>) -> Self {
        Input {
            path: path.into(),
            role,
        }
    }
}

/// A model file could not be read.
#[derive(Debug, thiserror::Error)]
#[error("cannot read {path}")]
pub struct LoadError {
    /// The file.
    pub path: String,
    /// The I/O error.
    pub source: std::io::Error,
}

/// Reads and validates all inputs. The result's `models` is `None` if any file has an error.
pub fn load(inputs: &[Input], options: ValidateOptions) -> Result<Validation, LoadError> {
    let mut read_problems = Vec::new();
    let mut sources = Vec::new();
    for input in inputs {
        let name = display(&input.path);
        let bytes = read_limited(&input.path).map_err(|source| LoadError {
            path: name.clone(),
            source,
        })?;
        let text = match String::from_utf8(bytes) {
            Ok(text) => text,
            Err(err) => {
                read_problems.push(not_utf8(&name, err.as_bytes(), err.utf8_error()));
                continue;
            }
        };
        match read_model(&name, &text, input.role) {
            Ok(source) => sources.push(source),
            Err(mut problems) => read_problems.append(&mut problems),
        }
    }
    let mut validation = validate(&sources, options);
    if !read_problems.is_empty() {
        validation.diagnostics.append(&mut read_problems);
        diagnostics::sort(&mut validation.diagnostics);
        validation.models = None;
    }
    Ok(validation)
}

/// Largest model file read: far above any hand-written model, and a bound on the memory a wrong path (a device
/// such as `/dev/zero`) can take.
pub const MAX_MODEL_BYTES: u64 = 512 * 1024 * 1024;

/// The bytes of a model or compiled supervisor file: a regular file of at most [`MAX_MODEL_BYTES`]; a FIFO, a
/// device or a folder is refused before it is read (a FIFO would block forever, a device never end).
pub fn read_limited(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let refuse = |message: String| std::io::Error::new(std::io::ErrorKind::InvalidInput, message);
    let metadata = std::fs::metadata(path)?;
    if !metadata.is_file() {
        return Err(refuse(
            "not a regular file (a device, FIFO or folder cannot be a model)".into(),
        ));
    }
    if metadata.len() > MAX_MODEL_BYTES {
        return Err(refuse(format!(
            "{} bytes, more than the {MAX_MODEL_BYTES} a model file may have",
            metadata.len()
        )));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(MAX_MODEL_BYTES + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_MODEL_BYTES {
        return Err(refuse(format!(
            "grew beyond the {MAX_MODEL_BYTES} bytes a model file may have while it was read"
        )));
    }
    Ok(bytes)
}

/// An `X1` diagnostic at the first byte that is not UTF-8.
fn not_utf8(file: &str, bytes: &[u8], err: std::str::Utf8Error) -> Diagnostic {
    let valid = err.valid_up_to();
    let prefix = std::str::from_utf8(&bytes[..valid]).unwrap_or_default();
    Diagnostic::new(
        Code::X1,
        file,
        LineIndex::new(prefix).position(valid),
        "the file is not valid UTF-8 (model files must be UTF-8)",
    )
}

fn display(path: &Path) -> String {
    path.display().to_string()
}
