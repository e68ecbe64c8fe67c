//! The TrueType font that a run's pictures draw their text with (the experiment figures, the snapshots' labels),
//! read once per process at run time so that no build needs a font library: the file named by `SWARM_FONT`, else
//! by `SWARM_PLOT_FONT` (its older name, still honoured), else the first of [`CANDIDATES`] that exists.

use std::path::PathBuf;
use std::sync::OnceLock;

/// Environment variable naming the font file.
pub const FONT_ENV: &str = "SWARM_FONT";
/// The older name of [`FONT_ENV`], from when only the experiment figures drew text.
pub const LEGACY_FONT_ENV: &str = "SWARM_PLOT_FONT";
/// System fonts tried in order when neither variable names a usable file.
pub const CANDIDATES: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation2/LiberationSans-Regular.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
];

/// A font file read into memory for the rest of the process.
#[derive(Debug)]
pub struct Font {
    /// Where it was read from.
    pub path: PathBuf,
    /// The whole file (borrowed for `'static` through [`font`]).
    pub bytes: Vec<u8>,
}

/// No usable font was found.
#[derive(Debug, Clone, thiserror::Error)]
#[error(
    "no font found: set {FONT_ENV} to a .ttf file or install one (e.g. Debian's fonts-dejavu-core); tried {tried}"
)]
pub struct NoFont {
    /// The files tried, comma-separated.
    pub tried: String,
}

/// The process's font, looked up and read on the first call.
pub fn font() -> Result<&'static Font, &'static NoFont> {
    static FONT: OnceLock<Result<Font, NoFont>> = OnceLock::new();
    FONT.get_or_init(|| find(&candidates())).as_ref()
}

/// The files to try, in order.
fn candidates() -> Vec<PathBuf> {
    [FONT_ENV, LEGACY_FONT_ENV]
        .into_iter()
        .filter_map(std::env::var_os)
        .map(PathBuf::from)
        .chain(CANDIDATES.iter().map(PathBuf::from))
        .collect()
}

/// The first of `candidates` that reads as a TrueType or OpenType font.
fn find(candidates: &[PathBuf]) -> Result<Font, NoFont> {
    for path in candidates {
        if let Ok(bytes) = std::fs::read(path)
            && is_font(&bytes)
        {
            tracing::debug!(font = %path.display(), "text is drawn with this font");
            return Ok(Font {
                path: path.clone(),
                bytes,
            });
        }
    }
    Err(NoFont {
        tried: candidates
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
    })
}

/// Whether `bytes` start like a font file (TrueType, OpenType or a collection); a full parse is the drawer's job.
fn is_font(bytes: &[u8]) -> bool {
    const MAGICS: [&[u8; 4]; 4] = [b"\x00\x01\x00\x00", b"OTTO", b"true", b"ttcf"];
    MAGICS.iter().any(|magic| bytes.starts_with(*magic))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_readable_font_wins_and_a_miss_lists_every_file_tried() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let junk = dir.path().join("junk.ttf");
        let good = dir.path().join("good.ttf");
        std::fs::write(&junk, b"not a font").expect("write");
        std::fs::write(&good, b"\x00\x01\x00\x00rest of the font").expect("write");
        let missing = dir.path().join("missing.ttf");

        let font = find(&[missing.clone(), junk.clone(), good.clone()]).expect("a font");
        assert_eq!(font.path, good);

        let err = find(&[missing.clone(), junk.clone()]).expect_err("no font");
        assert_eq!(
            err.tried,
            format!("{}, {}", missing.display(), junk.display())
        );
    }
}
