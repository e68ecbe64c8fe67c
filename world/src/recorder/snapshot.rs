//! PNG snapshots of the arena drawn with tiny-skia, seen from above with +Y up: the floor as the ground sensors see
//! it (sampled every `FLOOR_SAMPLE` metres), the pheromone heat map, each robot's trail so far (thin blue lines,
//! `trails`), obstacles, targets, lights, and robots in their LED colours with a heading tick (dead robots dark
//! grey; a red dot marks a carried target). On top, `snapshot_labels` draws the tick and time, a scale bar
//! and a legend; the colours and shapes here are also its swatches.

use std::path::Path;

use swarm_contract::messages::{PHEROMONE_CHANNELS, Rgb};
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use crate::arena::Arena;
use crate::entities::TargetState;
use crate::error::WorldError;
use crate::geometry::{Placed, Shape, Vec2, unit};
use crate::world::World;

use super::snapshot_labels;
use super::trail_lines::TrailPen;
use super::trails::Trails;

/// Pixels per metre of a snapshot.
pub const PIXELS_PER_METRE: f32 = 100.0;
/// Largest snapshot side in pixels; larger arenas are drawn at a lower resolution.
pub const MAX_SIDE_PX: f32 = 2000.0;

/// A colour of the drawing: red, green, blue, opacity.
pub(super) type Rgba = [u8; 4];
/// A robot whose LED is off.
pub(super) const ROBOT: Rgba = [230, 230, 230, 255];
/// A dead robot.
pub(super) const DEAD_ROBOT: Rgba = [60, 60, 60, 255];
/// The dot on a robot that carries a target.
const CARRIED: Rgba = [200, 0, 0, 255];
/// Robot outlines and heading ticks.
const OUTLINE: Rgba = [0, 0, 0, 255];
/// Trails, translucent so that crowded paths look darker.
const TRAIL: Rgba = [40, 90, 200, 120];
/// Obstacles.
pub(super) const OBSTACLE: Rgba = [90, 90, 90, 255];
/// A target whose LED is off.
pub(super) const TARGET: Rgba = [200, 0, 0, 255];
/// Lights.
const LIGHT: Rgba = [255, 200, 0, 255];
/// Radius of a light's dot in metres.
const LIGHT_RADIUS: f32 = 0.05;
/// Colours of the pheromone channels in the heat map.
pub const PHEROMONE_COLOURS: [(u8, u8, u8); PHEROMONE_CHANNELS] = [(220, 60, 20), (30, 90, 220)];

/// An anti-aliased paint of `colour`.
pub(super) fn paint([r, g, b, a]: Rgba) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(r, g, b, a);
    p.anti_alias = true;
    p
}

/// Side of the floor sampling cells in metres.
pub const FLOOR_SAMPLE: f32 = 0.05;

/// Draws the world, with the robots' `trails`, into a PNG file at `path`.
pub fn render(world: &World, trails: &Trails, path: &Path) -> Result<(), WorldError> {
    let arena = &world.arena;
    let err = |message: String| WorldError::Render {
        path: path.to_path_buf(),
        message,
    };
    let size = arena.max - arena.min;
    let scale = PIXELS_PER_METRE.min(MAX_SIDE_PX / size.x.max(size.y).max(0.01));
    let (w, h) = (
        (size.x * scale).ceil().max(1.0) as u32,
        (size.y * scale).ceil().max(1.0) as u32,
    );
    let mut pixmap =
        Pixmap::new(w, h).ok_or_else(|| err(format!("cannot allocate a {w} x {h} image")))?;
    pixmap.fill(Color::WHITE);
    // World (metres, +Y up) to pixels (+Y down).
    let tf = Transform::from_row(
        scale,
        0.0,
        0.0,
        -scale,
        -arena.min.x * scale,
        arena.max.y * scale,
    );

    draw_floor(world, &mut pixmap, tf);
    draw_pheromone(arena, &mut pixmap, tf);
    draw_trails(arena, trails, &mut pixmap, tf);
    for o in &arena.obstacles {
        fill_placed(&mut pixmap, &o.placed, &paint(OBSTACLE), tf);
    }
    for t in arena
        .targets
        .iter()
        .filter(|t| t.state == TargetState::InArena)
    {
        fill_placed(&mut pixmap, &t.placed, &led_paint(t.led, TARGET), tf);
    }
    for l in &arena.lights {
        draw_light(&mut pixmap, l.position, tf);
    }
    for r in arena.robots.iter().filter(|r| !r.removed) {
        let fill = if r.alive {
            led_paint(r.led, ROBOT)
        } else {
            paint(DEAD_ROBOT)
        };
        let disc = RobotDisc {
            centre: r.position,
            heading: r.heading,
            radius: r.body.radius,
        };
        draw_robot(&mut pixmap, disc, &fill, r.carrying.is_some(), tf);
    }
    snapshot_labels::annotate(&mut pixmap, world, trails, scale);
    pixmap.save_png(path).map_err(|e| err(e.to_string()))
}

fn led_paint(led: Rgb, off: Rgba) -> Paint<'static> {
    if led.is_on() {
        paint([led.r, led.g, led.b, 255])
    } else {
        paint(off)
    }
}

/// Where a robot's body is, in metres and radians.
#[derive(Debug, Clone, Copy)]
pub(super) struct RobotDisc {
    /// Centre.
    pub centre: Vec2,
    /// Heading.
    pub heading: f32,
    /// Radius.
    pub radius: f32,
}

/// A robot's `disc` in `fill` with an outline and a tick from its centre along its heading, and a red dot at its
/// centre if it is `carrying` a target.
pub(super) fn draw_robot(
    pixmap: &mut Pixmap,
    disc: RobotDisc,
    fill: &Paint,
    carrying: bool,
    tf: Transform,
) {
    let RobotDisc {
        centre,
        heading,
        radius,
    } = disc;
    if let Some(body) = PathBuilder::from_circle(centre.x, centre.y, radius) {
        pixmap.fill_path(&body, fill, FillRule::Winding, tf, None);
    }
    let outline = Stroke {
        width: 0.004,
        ..Stroke::default()
    };
    let mut pb = PathBuilder::new();
    pb.push_circle(centre.x, centre.y, radius);
    let tip = centre + unit(heading) * radius;
    pb.move_to(centre.x, centre.y);
    pb.line_to(tip.x, tip.y);
    if let Some(path) = pb.finish() {
        pixmap.stroke_path(&path, &paint(OUTLINE), &outline, tf, None);
    }
    if carrying && let Some(path) = PathBuilder::from_circle(centre.x, centre.y, 0.012) {
        pixmap.fill_path(&path, &paint(CARRIED), FillRule::Winding, tf, None);
    }
}

/// A light's yellow dot at `position`.
pub(super) fn draw_light(pixmap: &mut Pixmap, position: Vec2, tf: Transform) {
    if let Some(path) = PathBuilder::from_circle(position.x, position.y, LIGHT_RADIUS) {
        pixmap.fill_path(&path, &paint(LIGHT), FillRule::Winding, tf, None);
    }
}

/// Strokes `path` in the trails' colour (the legend's swatch; the trails themselves are drawn by
/// [`TrailPen`]).
pub(super) fn stroke_trail(pixmap: &mut Pixmap, path: &tiny_skia::Path, tf: Transform) {
    let stroke = Stroke {
        width: 0.01,
        ..Stroke::default()
    };
    pixmap.stroke_path(path, &paint(TRAIL), &stroke, tf, None);
}

/// Fills `placed`'s shape with `paint`.
pub(super) fn fill_placed(pixmap: &mut Pixmap, placed: &Placed, paint: &Paint, tf: Transform) {
    let path = match placed.shape {
        Shape::Disc { radius } => {
            PathBuilder::from_circle(placed.position.x, placed.position.y, radius)
        }
        Shape::Rect { half } => {
            let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(sx, sy)| placed.to_world(Vec2::new(sx * half.x, sy * half.y)));
            let mut pb = PathBuilder::new();
            pb.move_to(corners[0].x, corners[0].y);
            for p in &corners[1..] {
                pb.line_to(p.x, p.y);
            }
            pb.close();
            pb.finish()
        }
    };
    if let Some(path) = path {
        pixmap.fill_path(&path, paint, FillRule::Winding, tf, None);
    }
}

/// Each robot's trail as a thin translucent line, broken where the robot was out of the run.
fn draw_trails(arena: &Arena, trails: &Trails, pixmap: &mut Pixmap, tf: Transform) {
    let pen = TrailPen::new(TRAIL);
    for index in 0..arena.robots.len() {
        for piece in trails.pieces(index) {
            pen.polyline(pixmap, piece, tf);
        }
    }
}

/// Each pheromone cell tinted by its channel colour with opacity growing with concentration (saturating at 1).
fn draw_pheromone(arena: &Arena, pixmap: &mut Pixmap, tf: Transform) {
    let (nx, ny, cell) = arena.pheromone.dimensions();
    for (ch, &(r, g, b)) in PHEROMONE_COLOURS.iter().enumerate() {
        for y in 0..ny {
            for x in 0..nx {
                let v = arena.pheromone.cell_value(ch, x, y);
                if v <= 0.0 {
                    continue;
                }
                let alpha = (v.min(1.0) * 200.0) as u8;
                let (x0, y0) = (arena.min.x + x as f32 * cell, arena.min.y + y as f32 * cell);
                if let Some(rect) = Rect::from_xywh(x0, y0, cell, cell) {
                    pixmap.fill_rect(rect, &paint([r, g, b, alpha]), tf, None);
                }
            }
        }
    }
}

/// Every floor sample that is not white, in its grey level.
fn draw_floor(world: &World, pixmap: &mut Pixmap, tf: Transform) {
    let (min, max) = (world.arena.min, world.arena.max);
    let (nx, ny) = (
        ((max.x - min.x) / FLOOR_SAMPLE).ceil() as usize,
        ((max.y - min.y) / FLOOR_SAMPLE).ceil() as usize,
    );
    for y in 0..ny {
        for x in 0..nx {
            let corner = min + Vec2::new(x as f32, y as f32) * FLOOR_SAMPLE;
            let grey = world
                .floor_at(corner + Vec2::splat(FLOOR_SAMPLE / 2.0))
                .clamp(0.0, 1.0);
            if grey < 1.0
                && let Some(rect) = Rect::from_xywh(corner.x, corner.y, FLOOR_SAMPLE, FLOOR_SAMPLE)
            {
                let g = (grey * 255.0) as u8;
                pixmap.fill_rect(rect, &paint([g, g, g, 255]), tf, None);
            }
        }
    }
}
