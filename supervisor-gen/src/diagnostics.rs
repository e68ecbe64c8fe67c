//! Located diagnostics: the error and warning codes of docs/ptsct.md section 11, plus the two document-level codes
//! (`X1` malformed XML, `X2` not a model document), and the byte-offset to line:column mapping they rely on.
//!
//! Every problem found in a user's file is one [`Diagnostic`] that names the file, the 1-based line and column, the
//! code and what is wrong. This module only describes and renders problems; it never decides whether to stop.

use std::fmt;

use serde::Serialize;

/// How serious a diagnostic is. Errors stop the pipeline before synthesis; warnings never do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// The model is reported and the pipeline carries on.
    Warning,
    /// The model (and therefore the project) must not proceed to synthesis.
    Error,
}

/// The code of a diagnostic: `X1`/`X2` for documents that are not models at all, `V1`-`V15` and `W1`-`W6` exactly as
/// in docs/ptsct.md section 11.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub enum Code {
    /// The file is not well-formed XML (unclosed tag, bad quoting, mismatched end tag, ...).
    X1,
    /// Well-formed XML that is not a model document: wrong root, unknown element or attribute, missing required
    /// attribute, or a value that is not one of `1`, `0`, `true`, `false` where a flag is expected.
    X2,
    /// No initial state.
    V1,
    /// More than one initial state.
    V2,
    /// No marked state.
    V3,
    /// A transition uses an undeclared event.
    V4,
    /// A transition uses an undeclared state.
    V5,
    /// A declared state is used by no transition.
    V6,
    /// A declared event is used by no transition.
    V7,
    /// Two transitions with the same source state and event.
    V8,
    /// Duplicate state or event name (or Nadzoru2 id) within a file.
    V9,
    /// An event has different controllability in different files.
    V10,
    /// `prob` is not a finite real >= 0, or `time` is not an integer >= 0.
    V11,
    /// A state whose outgoing controllable transitions all have weight 0.
    V12,
    /// Unknown or missing model `type`, or a duplicate model name in the project.
    V13,
    /// The reserved event name `tick` is declared.
    V14,
    /// A limit of the compiled byte layout is exceeded.
    V15,
    /// `con` omitted: the event is treated as uncontrollable.
    W1,
    /// A state is unreachable from the initial state.
    W2,
    /// `prob` or `time` on an uncontrollable transition (ignored).
    W3,
    /// `prob` in a plant model (ignored).
    W4,
    /// An uncontrollable event appears in no plant.
    W5,
    /// A plant shares no event with any specification.
    W6,
}

impl Code {
    /// Warnings are the `W` codes; everything else is an error.
    pub fn severity(self) -> Severity {
        match self {
            Code::W1 | Code::W2 | Code::W3 | Code::W4 | Code::W5 | Code::W6 => Severity::Warning,
            _ => Severity::Error,
        }
    }
}

impl fmt::Display for Code {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self, f)
    }
}

/// A 1-based line and column (columns count characters, not bytes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default, Serialize)]
pub struct Position {
    /// 1-based line number.
    pub line: u32,
    /// 1-based column, in characters.
    pub column: u32,
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// One located problem in one file.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Diagnostic {
    /// What rule was broken.
    pub code: Code,
    /// Error or warning (always `code.severity()`).
    pub severity: Severity,
    /// The file as the user named it.
    pub file: String,
    /// 1-based line.
    pub line: u32,
    /// 1-based column.
    pub column: u32,
    /// What is wrong, in one sentence.
    pub message: String,
}

impl Diagnostic {
    /// A diagnostic with the severity implied by `code`.
    pub fn new(code: Code, file: &str, at: Position, message: impl Into<String>) -> Self {
        Diagnostic {
            code,
            severity: code.severity(),
            file: file.to_owned(),
            line: at.line,
            column: at.column,
            message: message.into(),
        }
    }

    /// True for errors (which stop the pipeline).
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        write!(
            f,
            "{}:{}:{}: {}[{}]: {}",
            self.file, self.line, self.column, kind, self.code, self.message
        )
    }
}

/// True if any diagnostic in the list is an error.
pub fn has_errors(diagnostics: &[Diagnostic]) -> bool {
    diagnostics.iter().any(Diagnostic::is_error)
}

/// Sorts diagnostics by file, line and column (stable for equal positions), the order in which they are printed.
pub fn sort(diagnostics: &mut [Diagnostic]) {
    diagnostics.sort_by(|a, b| (&a.file, a.line, a.column).cmp(&(&b.file, b.line, b.column)));
}

/// Maps byte offsets of one text to line:column positions.
#[derive(Debug, Clone)]
pub struct LineIndex<'a> {
    text: &'a str,
    line_starts: Vec<usize>,
}

impl<'a> LineIndex<'a> {
    /// Indexes the line starts of `text`.
    pub fn new(text: &'a str) -> Self {
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        LineIndex { text, line_starts }
    }

    /// The position of byte `offset` (clamped to the end of the text).
    pub fn position(&self, offset: usize) -> Position {
        let offset = offset.min(self.text.len());
        let line = self.line_starts.partition_point(|&start| start <= offset) - 1;
        let start = self.line_starts[line];
        let column = self
            .text
            .get(start..offset)
            .map_or(offset - start, |s| s.chars().count());
        Position {
            line: u32::try_from(line + 1).unwrap_or(u32::MAX),
            column: u32::try_from(column + 1).unwrap_or(u32::MAX),
        }
    }

    /// The position of a slice that borrows from the indexed text (for example a quick-xml attribute key), or of
    /// the text start if it does not.
    pub fn position_of(&self, slice: &[u8]) -> Position {
        self.position(self.offset_of(slice))
    }

    /// The byte offset of a slice that borrows from the indexed text (0 if it does not).
    pub fn offset_of(&self, slice: &[u8]) -> usize {
        let base = self.text.as_ptr() as usize;
        let at = slice.as_ptr() as usize;
        at.checked_sub(base)
            .filter(|&offset| offset <= self.text.len())
            .unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_are_one_based_and_count_characters() {
        let text = "ab\n  <é x>\n";
        let index = LineIndex::new(text);
        assert_eq!(index.position(0), Position { line: 1, column: 1 });
        assert_eq!(index.position(5), Position { line: 2, column: 3 });
        let x = text.find('x').unwrap();
        assert_eq!(index.position(x), Position { line: 2, column: 6 });
    }

    #[test]
    fn rendering_follows_compiler_style() {
        let d = Diagnostic::new(
            Code::V8,
            "models/e1.xml",
            Position {
                line: 12,
                column: 5,
            },
            "state `s1` has two transitions on event `go` (first at line 9)",
        );
        assert_eq!(
            d.to_string(),
            "models/e1.xml:12:5: error[V8]: state `s1` has two transitions on event `go` (first at line 9)"
        );
        assert!(!Diagnostic::new(Code::W1, "f", Position::default(), "").is_error());
    }
}
