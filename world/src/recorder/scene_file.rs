//! `scene.json` and `floor.png`: what a viewer needs besides the per-tick records to draw a run. Written once,
//! when recording starts (tick 0): the arena rectangle, every obstacle, target and light as placed, and each
//! participant's id, controller and body. Where targets and movable obstacles go later is in `objects.csv`
//! ([`super::objects_file`]).
//!
//! The layout is described in docs/records.md; `format` grows when a field changes meaning.

use std::path::Path;

use serde_json::{Value, json};
use swarm_contract::messages::Rgb;
use swarm_contract::run_dir::{FLOOR_IMAGE_FILE, SCENE_FILE, write_atomically};
use tiny_skia::{Pixmap, PremultipliedColorU8};

use crate::error::WorldError;
use crate::geometry::{Placed, Shape, Vec2};
use crate::physics::Motion;
use crate::world::World;

/// The layout version written into `scene.json`.
pub const SCENE_FORMAT: u64 = 1;

/// Side of a floor image cell in metres, unless the arena is so large that the image would pass
/// [`MAX_FLOOR_SIDE`] cells.
const FLOOR_CELL: f32 = 0.02;
/// Largest floor image side in cells.
const MAX_FLOOR_SIDE: f32 = 1024.0;

/// Writes `scene.json` (and `floor.png` when some of the floor is not white) into `dir`; `pheromone` is the
/// pheromone file's entry (`null` without one).
pub fn write(dir: &Path, world: &World, pheromone: Value) -> Result<(), WorldError> {
    let floor = write_floor(dir, world)?;
    let arena = &world.arena;
    let robots: Vec<Value> = arena
        .robots
        .iter()
        .enumerate()
        .map(|(index, r)| {
            json!({
                "index": index,
                "id": r.name,
                "controller": r.controller,
                "body": r.body.kind.tag(),
                "radius": short(r.body.radius),
            })
        })
        .collect();
    let coordinators: Vec<Value> = (world.robot_count()..)
        .zip(world.coordinators())
        .map(|(index, c)| json!({"index": index, "id": c.id, "controller": c.controller}))
        .collect();
    let obstacles: Vec<Value> = arena
        .obstacles
        .iter()
        .map(|o| {
            let mut body = placed(&o.placed);
            body["id"] = json!(o.name);
            body["movable"] = json!(matches!(o.motion, Motion::Movable { .. }));
            body
        })
        .collect();
    let targets: Vec<Value> = arena
        .targets
        .iter()
        .map(|t| {
            let mut body = placed(&t.placed);
            body["id"] = json!(t.name);
            body["colour"] = colour(t.led);
            body
        })
        .collect();
    let lights: Vec<Value> = arena
        .lights
        .iter()
        .map(|l| json!({"id": l.name, "x": short(l.position.x), "y": short(l.position.y), "colour": colour(l.color)}))
        .collect();
    let scene = json!({
        "format": SCENE_FORMAT,
        "arena": {"min": point(arena.min), "max": point(arena.max)},
        "ticks_per_second": arena.ticks_per_second,
        "robots": robots,
        "coordinators": coordinators,
        "obstacles": obstacles,
        "targets": targets,
        "lights": lights,
        "floor": floor,
        "pheromone": pheromone,
    });
    let path = dir.join(SCENE_FILE);
    let text = serde_json::to_string(&scene).unwrap_or_default();
    write_atomically(&path, text.as_bytes()).map_err(|source| WorldError::Io { path, source })
}

fn point(p: Vec2) -> Value {
    json!([short(p.x), short(p.y)])
}

/// `value` as the shortest decimal that reads back as the same `f32` (1.6, not 1.600000023841858).
pub(super) fn short(value: f32) -> f64 {
    value.to_string().parse().unwrap_or(f64::NAN)
}

fn colour(c: Rgb) -> Value {
    json!([c.r, c.g, c.b])
}

fn placed(body: &Placed) -> Value {
    let mut value = match body.shape {
        Shape::Disc { radius } => json!({"shape": "disc", "radius": short(radius)}),
        Shape::Rect { half } => json!({"shape": "rect", "half": point(half)}),
    };
    value["x"] = json!(short(body.position.x));
    value["y"] = json!(short(body.position.y));
    value["angle"] = json!(short(body.angle()));
    value
}

/// Samples the floor at the centre of every cell and writes it as a grey image, row 0 at the top (largest y),
/// if any sample is not white. Returns the image's entry of `scene.json` (`null` for an all-white floor).
fn write_floor(dir: &Path, world: &World) -> Result<Value, WorldError> {
    let (min, max) = (world.arena.min, world.arena.max);
    let size = max - min;
    let cell = FLOOR_CELL.max(size.x.max(size.y) / MAX_FLOOR_SIDE);
    let (nx, ny) = (
        (size.x / cell).ceil().max(1.0) as u32,
        (size.y / cell).ceil().max(1.0) as u32,
    );
    let path = dir.join(FLOOR_IMAGE_FILE);
    let render_error = |message: String| WorldError::Render {
        path: path.clone(),
        message,
    };
    let mut image = Pixmap::new(nx, ny)
        .ok_or_else(|| render_error(format!("cannot allocate a {nx} x {ny} image")))?;
    let mut all_white = true;
    for (i, pixel) in image.pixels_mut().iter_mut().enumerate() {
        let (col, row) = (i as u32 % nx, i as u32 / nx);
        let centre = Vec2::new(
            min.x + (col as f32 + 0.5) * cell,
            max.y - (row as f32 + 0.5) * cell,
        );
        let grey = (world.floor_at(centre).clamp(0.0, 1.0) * 255.0).round() as u8;
        all_white &= grey == 255;
        *pixel = PremultipliedColorU8::from_rgba(grey, grey, grey, 255)
            .unwrap_or(PremultipliedColorU8::TRANSPARENT);
    }
    if all_white {
        return Ok(Value::Null);
    }
    image
        .save_png(&path)
        .map_err(|e| render_error(e.to_string()))?;
    Ok(
        json!({"image": FLOOR_IMAGE_FILE, "min": point(min), "max": point(max), "cell": short(cell)}),
    )
}
