//! An animated GIF of a recorded run, for `swarm view <run> --gif out.gif` (docs/viewer.md, "An animation of a
//! run"): ticks spread evenly over the run, read through [`RunRecord`], each drawn with tiny-skia (`render`),
//! mapped to a fixed palette (`palette`) and encoded with the `gif` crate, one frame at a time.

mod palette;
mod render;
mod scene;
#[cfg(test)]
mod tests;

use std::borrow::Cow;
use std::ffi::OsString;
use std::fmt;
use std::fs::{self, File};
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde_json::Value;

use crate::run::{Refusal, RunRecord};
use palette::Indexer;
use render::{MAX_SIDE_PX, Painter};
use scene::Scene;

/// Frames of an animation unless asked otherwise.
pub const DEFAULT_FRAMES: u32 = 200;
/// Width of an animation in pixels unless asked otherwise.
pub const DEFAULT_WIDTH_PX: u32 = 480;
/// Narrowest animation in pixels.
pub const MIN_WIDTH_PX: u32 = 16;
/// Seconds a whole animation plays at least and at most: a run that took less or more simulated time plays
/// slower or faster than it ran.
const PLAY_SECONDS: (f64, f64) = (10.0, 20.0);
/// Shortest frame delay in hundredths of a second (50 frames a second; browsers slow shorter delays down).
const MIN_DELAY_CS: u16 = 2;

/// What to animate.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GifOptions {
    /// Frames, spread evenly over the ticks (one per tick when there are fewer ticks).
    pub frames: u32,
    /// Width in pixels; the height follows the arena's aspect ratio.
    pub width_px: u32,
    /// The first tick drawn; `None`: the run's first.
    pub from: Option<u64>,
    /// The last tick drawn; `None`: the run's last complete tick.
    pub to: Option<u64>,
}

impl Default for GifOptions {
    fn default() -> Self {
        Self {
            frames: DEFAULT_FRAMES,
            width_px: DEFAULT_WIDTH_PX,
            from: None,
            to: None,
        }
    }
}

/// What [`write_gif`] wrote.
#[derive(Clone, Debug)]
pub struct GifReport {
    /// The animation.
    pub path: PathBuf,
    /// Frames in it.
    pub frames: u32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Size of the file.
    pub bytes: u64,
    /// Wall-clock seconds it took.
    pub seconds: f64,
}

impl fmt::Display for GifReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let size = match self.bytes {
            b if b >= 1_000_000 => format!("{:.1} MB", b as f64 / 1e6),
            b if b >= 1_000 => format!("{:.0} kB", b as f64 / 1e3),
            b => format!("{b} bytes"),
        };
        write!(
            f,
            "{}: {} frames, {} x {}, {size} in {:.1} s",
            self.path.display(),
            self.frames,
            self.width,
            self.height,
            self.seconds
        )
    }
}

/// Why an animation cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum AnimationError {
    /// The options cannot make an animation (a sentence saying why).
    #[error("{0}")]
    Options(String),
    /// The folder is not a run directory.
    #[error("{0}")]
    NotARun(String),
    /// The run has no scene to draw (a sentence naming `scene.json`).
    #[error("{0}")]
    NoScene(String),
    /// The run has no complete tick.
    #[error("{0}")]
    NoTicks(String),
    /// A record file cannot be read (the sentence names it).
    #[error("{0}")]
    Read(String),
    /// The floor image cannot be read.
    #[error("{}: cannot read the floor image: {reason}", path.display())]
    Floor {
        /// `floor.png`.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The animation cannot be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The animation asked for.
        path: PathBuf,
        /// The cause.
        #[source]
        source: io::Error,
    },
}

impl From<Refusal> for AnimationError {
    fn from(refusal: Refusal) -> Self {
        match refusal {
            Refusal::BadRequest(why) | Refusal::NotFound(why) | Refusal::Unavailable(why) => {
                Self::Read(why)
            }
        }
    }
}

/// Draws the run in `run_dir` as an animated GIF at `out`, looping forever. The file is written beside `out`
/// under a temporary name and renamed when complete, so `out` is never half written.
pub fn write_gif(
    run_dir: &Path,
    out: &Path,
    options: &GifOptions,
) -> Result<GifReport, AnimationError> {
    let started = Instant::now();
    check(options)?;
    let temporary = temporary_path(out)?;
    let record = RunRecord::open(run_dir, false).map_err(AnimationError::NotARun)?;
    let mut overview = record.overview();
    let scene = Scene::of(&mut overview, run_dir)?;
    let frames = Frames::chosen(&overview, options)?;
    for problem in record.problems() {
        tracing::warn!("{problem}");
    }
    let delay = frames.delay(scene.ticks_per_second);
    let floor = record
        .floor_image()
        .map(|path| scene::read_floor(&path))
        .transpose()?;
    let mut painter = Painter::new(scene, floor, options.width_px)?;
    let written = encode(&record, &mut painter, &frames, delay, &temporary, out)
        .and_then(|()| fs::rename(&temporary, out).map_err(write_failed(out)));
    if let Err(error) = written {
        let _ = fs::remove_file(&temporary);
        return Err(error);
    }
    let bytes = fs::metadata(out).map_err(write_failed(out))?.len();
    let (width, height) = painter.size();
    Ok(GifReport {
        path: out.to_path_buf(),
        frames: frames.count as u32,
        width,
        height,
        bytes,
        seconds: started.elapsed().as_secs_f64(),
    })
}

fn check(options: &GifOptions) -> Result<(), AnimationError> {
    if options.frames == 0 {
        return Err(AnimationError::Options(
            "an animation needs at least 1 frame".to_owned(),
        ));
    }
    if !(MIN_WIDTH_PX..=MAX_SIDE_PX).contains(&options.width_px) {
        return Err(AnimationError::Options(format!(
            "an animation is {MIN_WIDTH_PX} to {MAX_SIDE_PX} pixels wide, not {}",
            options.width_px
        )));
    }
    Ok(())
}

/// `.<name>.<process id>.tmp` beside `out`.
fn temporary_path(out: &Path) -> Result<PathBuf, AnimationError> {
    let name = out
        .file_name()
        .ok_or_else(|| AnimationError::Options(format!("{}: not a file name", out.display())))?;
    let mut temporary = OsString::from(".");
    temporary.push(name);
    temporary.push(format!(".{}.tmp", std::process::id()));
    Ok(out.with_file_name(temporary))
}

/// The ticks drawn: `count` ticks spread evenly over `from..=to`, both included.
struct Frames {
    from: u64,
    to: u64,
    count: u64,
}

impl Frames {
    /// The ticks `options` ask for among the complete ticks of `overview` (`RunRecord::overview`).
    fn chosen(overview: &Value, options: &GifOptions) -> Result<Self, AnimationError> {
        let ticks = &overview["ticks"];
        let (Some(first), Some(last)) = (ticks["first"].as_u64(), ticks["last"].as_u64()) else {
            let problems: Vec<&str> = overview["problems"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(Value::as_str)
                .collect();
            return Err(AnimationError::NoTicks(format!(
                "{}: no complete tick to draw{}{}",
                overview["dir"].as_str().unwrap_or_default(),
                if problems.is_empty() { "" } else { ": " },
                problems.join("; ")
            )));
        };
        let (from, to) = (options.from.unwrap_or(first), options.to.unwrap_or(last));
        if from > to || from < first || to > last {
            return Err(AnimationError::Options(format!(
                "ticks {from} to {to} cannot be drawn: the run has ticks {first} to {last}"
            )));
        }
        Ok(Self {
            from,
            to,
            count: u64::from(options.frames).min(to - from + 1),
        })
    }

    /// The tick of frame `frame` (`0..count`).
    fn tick(&self, frame: u64) -> u64 {
        let Some(gaps) = self.count.checked_sub(1).filter(|&g| g > 0) else {
            return self.from;
        };
        let span = u128::from(self.to - self.from);
        let offset = (u128::from(frame) * span + u128::from(gaps / 2)) / u128::from(gaps);
        self.from + offset as u64
    }

    /// How far `tick` is from the first tick drawn to the last, 0 to 1.
    fn progress(&self, tick: u64) -> f32 {
        if self.to == self.from {
            1.0
        } else {
            ((tick - self.from) as f64 / (self.to - self.from) as f64) as f32
        }
    }

    /// Hundredths of a second each frame shows: the run plays in the simulated time it took when that is 10 to
    /// 20 s, else as fast or as slow as makes it 10 or 20 s, never faster than 50 frames a second.
    fn delay(&self, ticks_per_second: f64) -> u16 {
        let (shortest, longest) = PLAY_SECONDS;
        let seconds = ((self.to - self.from) as f64 / ticks_per_second).clamp(shortest, longest);
        // A NaN (no ticks per second) becomes 0 and so the shortest delay.
        ((seconds * 100.0 / self.count as f64).round() as u16).max(MIN_DELAY_CS)
    }
}

/// Draws and encodes every frame into a new file at `path`, the animation asked for at `out`.
fn encode(
    record: &RunRecord,
    painter: &mut Painter,
    frames: &Frames,
    delay: u16,
    path: &Path,
    out: &Path,
) -> Result<(), AnimationError> {
    let failed = |error: gif::EncodingError| {
        write_failed(out)(match error {
            gif::EncodingError::Io(error) => error,
            other => io::Error::other(other),
        })
    };
    let (width, height) = painter.size();
    let (width16, height16) = (width as u16, height as u16);
    let file = BufWriter::new(File::create(path).map_err(write_failed(out))?);
    let mut encoder =
        gif::Encoder::new(file, width16, height16, &palette::rgb_table()).map_err(failed)?;
    encoder.set_repeat(gif::Repeat::Infinite).map_err(failed)?;
    let mut indexer = Indexer::new(width as usize * height as usize);
    let mut entries = Vec::new();
    for frame in 0..frames.count {
        let tick = frames.tick(frame);
        indexer.index(
            draw(record, painter, tick, frames.progress(tick))?,
            &mut entries,
        );
        let frame = gif::Frame {
            width: width16,
            height: height16,
            delay,
            dispose: gif::DisposalMethod::Keep,
            transparent: Some(palette::TRANSPARENT),
            buffer: Cow::Borrowed(&entries),
            ..gif::Frame::default()
        };
        encoder.write_frame(&frame).map_err(failed)?;
    }
    encoder
        .into_inner()
        .map_err(failed)?
        .into_inner()
        .map_err(|e| write_failed(out)(e.into_error()))?;
    Ok(())
}

/// The picture of `tick`.
fn draw<'p>(
    record: &RunRecord,
    painter: &'p mut Painter,
    tick: u64,
    progress: f32,
) -> Result<&'p [u8], AnimationError> {
    if let Some(field) = record.pheromone(tick)? {
        painter.show_field(&field);
    }
    Ok(painter.draw(&record.poses(tick)?, &record.object_places(tick), progress))
}

fn write_failed(out: &Path) -> impl Fn(io::Error) -> AnimationError + '_ {
    |source| AnimationError::Write {
        path: out.to_path_buf(),
        source,
    }
}
