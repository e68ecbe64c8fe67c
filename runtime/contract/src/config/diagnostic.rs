//! Located messages about a configuration file: `file:line:column: message (hint)`.
//!
//! Used for parser errors and warnings and, through [`super::Experiment::diagnostic`], for semantic errors found
//! later (e.g. by the world while placing entities).

use std::fmt;
use std::path::PathBuf;

use super::model::Location;

/// One located error or warning.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// The configuration file.
    pub path: PathBuf,
    /// Where in the file; line 0 means the whole file (e.g. it cannot be read).
    pub location: Location,
    /// What is wrong.
    pub message: String,
    /// What to do about it, e.g. `did you mean 'epuck_proximity'?`.
    pub hint: Option<String>,
}

impl Diagnostic {
    /// A diagnostic without a hint.
    pub fn new(path: PathBuf, location: Location, message: impl Into<String>) -> Self {
        Self {
            path,
            location,
            message: message.into(),
            hint: None,
        }
    }

    /// Adds a hint, shown in parentheses after the message.
    pub fn with_hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = Some(hint.into());
        self
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.location.line == 0 {
            write!(f, "{}: {}", self.path.display(), self.message)?;
        } else {
            write!(
                f,
                "{}:{}: {}",
                self.path.display(),
                self.location,
                self.message
            )?;
        }
        if let Some(hint) = &self.hint {
            write!(f, " ({hint})")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostic {}

/// Every error found in one configuration file, in file order (never empty).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct ConfigErrors {
    /// The errors, sorted by location.
    pub errors: Vec<Diagnostic>,
}

impl fmt::Display for ConfigErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.errors.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        Ok(())
    }
}
