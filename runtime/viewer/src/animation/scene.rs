//! What an animation draws that does not move: `scene.json` as `RunRecord::overview` gives it and the floor image
//! (docs/records.md, "scene.json and floor.png").

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use serde::Deserialize;
use serde_json::Value;
use tiny_skia::{ColorU8, Pixmap};

use super::AnimationError;

/// The scene of a run.
#[derive(Deserialize)]
pub struct Scene {
    /// The arena's corners.
    pub arena: Bounds,
    /// Ticks per simulated second.
    #[serde(default = "default_ticks_per_second")]
    pub ticks_per_second: f64,
    /// The robots, by index.
    pub robots: Vec<Robot>,
    /// Walls and obstacles as placed.
    #[serde(default)]
    pub obstacles: Vec<Body>,
    /// Targets as placed.
    #[serde(default)]
    pub targets: Vec<Body>,
    /// Lights.
    #[serde(default)]
    pub lights: Vec<Light>,
    /// Where the floor image lies; `None` for an all-white floor.
    pub floor: Option<Bounds>,
    /// The pheromone grid; `None` in runs without a pheromone medium.
    pub pheromone: Option<FieldLayout>,
}

/// Two corners, in metres.
#[derive(Clone, Copy, Deserialize)]
pub struct Bounds {
    /// The corner of smallest x and y.
    pub min: [f32; 2],
    /// The corner of largest x and y.
    pub max: [f32; 2],
}

impl Bounds {
    /// Width and height in metres.
    pub fn size(&self) -> [f32; 2] {
        [self.max[0] - self.min[0], self.max[1] - self.min[1]]
    }
}

/// What the scene says of a robot.
#[derive(Deserialize)]
pub struct Robot {
    /// Body radius in metres.
    #[serde(default = "default_radius")]
    pub radius: f32,
}

/// An obstacle or a target as placed.
#[derive(Clone, Deserialize)]
pub struct Body {
    /// Centre x in metres.
    pub x: f32,
    /// Centre y in metres.
    pub y: f32,
    /// Radians, counter-clockwise.
    #[serde(default)]
    pub angle: f32,
    /// Its outline.
    #[serde(flatten)]
    pub shape: Shape,
    /// An obstacle that robots can push.
    #[serde(default)]
    pub movable: bool,
    /// A target's colour.
    pub colour: Option<[u8; 3]>,
}

/// A body's outline.
#[derive(Clone, Copy, Deserialize)]
#[serde(tag = "shape", rename_all = "lowercase")]
pub enum Shape {
    /// A disc.
    Disc {
        /// Metres.
        radius: f32,
    },
    /// A rectangle.
    Rect {
        /// Half its width and height, in metres.
        half: [f32; 2],
    },
}

/// A light.
#[derive(Deserialize)]
pub struct Light {
    /// Metres.
    pub x: f32,
    /// Metres.
    pub y: f32,
    /// Its colour.
    pub colour: [u8; 3],
}

/// The pheromone grid of `pheromone.bin`.
#[derive(Deserialize)]
pub struct FieldLayout {
    /// The corner of cell 0, in metres.
    pub min: [f32; 2],
    /// A cell's side in metres.
    pub cell: f32,
    /// Columns.
    pub nx: u32,
    /// Rows.
    pub ny: u32,
    /// Channels.
    pub channels: u32,
    /// Each channel's colour.
    pub colours: Vec<[u8; 3]>,
}

fn default_ticks_per_second() -> f64 {
    10.0
}

fn default_radius() -> f32 {
    0.035
}

impl Scene {
    /// The scene of `RunRecord::overview`'s answer; `dir` names the run in messages.
    pub fn of(overview: &mut Value, dir: &Path) -> Result<Self, AnimationError> {
        let scene = overview["scene"].take();
        if scene.is_null() {
            return Err(AnimationError::NoScene(
                overview["problems"][0]
                    .as_str()
                    .unwrap_or("the run has no scene.json")
                    .to_owned(),
            ));
        }
        let path = dir.join(swarm_contract::run_dir::SCENE_FILE);
        let scene: Scene = serde_json::from_value(scene).map_err(|e| {
            AnimationError::NoScene(format!("{}: cannot draw this scene: {e}", path.display()))
        })?;
        let [width, height] = scene.arena.size();
        if !(width > 0.0 && height > 0.0 && width.is_finite() && height.is_finite()) {
            return Err(AnimationError::NoScene(format!(
                "{}: the arena is {width} by {height} m: nothing to draw",
                path.display()
            )));
        }
        Ok(scene)
    }
}

/// The floor image at `path` (any PNG), its row 0 at the top.
pub fn read_floor(path: &Path) -> Result<Pixmap, AnimationError> {
    let bad = |reason: String| AnimationError::Floor {
        path: path.to_path_buf(),
        reason,
    };
    let file = File::open(path).map_err(|e| bad(e.to_string()))?;
    let mut decoder = png::Decoder::new(BufReader::new(file));
    decoder.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = decoder.read_info().map_err(|e| bad(e.to_string()))?;
    let mut bytes = vec![0; reader.output_buffer_size()];
    let info = reader
        .next_frame(&mut bytes)
        .map_err(|e| bad(e.to_string()))?;
    let mut pixmap = Pixmap::new(info.width, info.height)
        .ok_or_else(|| bad(format!("{} x {} pixels", info.width, info.height)))?;
    let samples = info.color_type.samples();
    let pixels = bytes[..info.buffer_size()].chunks_exact(samples);
    for (pixel, target) in pixels.zip(pixmap.pixels_mut()) {
        let [r, g, b, a] = match *pixel {
            [grey] => [grey, grey, grey, 255],
            [grey, alpha] => [grey, grey, grey, alpha],
            [r, g, b] => [r, g, b, 255],
            [r, g, b, a, ..] => [r, g, b, a],
            [] => [0; 4],
        };
        *target = ColorU8::from_rgba(r, g, b, a).premultiply();
    }
    Ok(pixmap)
}
