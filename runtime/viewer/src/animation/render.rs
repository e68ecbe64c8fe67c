//! One frame of an animation, drawn with tiny-skia from above (+Y up) as the viewer's page draws it: the white
//! arena, the floor image, the pheromone field, targets, obstacles and lights (the background, redrawn only when
//! the field changes), then each robot's recent trail, the robots and a progress bar along the bottom edge.

use std::collections::VecDeque;

use tiny_skia::{
    Color, ColorU8, FillRule, FilterQuality, Paint, Path, PathBuilder, Pixmap, PixmapPaint, Rect,
    Stroke, Transform,
};

use super::AnimationError;
use super::scene::{Body, Bounds, FieldLayout, Scene, Shape};
use crate::frames::FrameRobot;
use crate::objects::{ObjectPlace, ObjectPlaces};

/// Largest side of an animation in pixels.
pub const MAX_SIDE_PX: u32 = 4096;
/// Frames whose positions make a robot's trail (the one shown included).
const TRAIL_SAMPLES: usize = 20;
/// Smallest radius a robot is drawn with, in pixels.
const MIN_ROBOT_PX: f32 = 2.0;

/// A colour of the drawing: red, green, blue, opacity.
pub type Rgba = [u8; 4];
/// A robot whose LED is off.
const LED_OFF: Rgba = [230, 230, 230, 255];
/// A dead robot.
const DEAD: Rgba = [60, 60, 60, 255];
/// Robot outlines and heading lines.
const OUTLINE: Rgba = [0, 0, 0, 255];
/// The ring of a frozen robot.
const FROZEN: Rgba = [0, 200, 230, 255];
/// The dot of a robot holding something.
const CARRYING: Rgba = [220, 0, 0, 255];
/// Trails, translucent so that they do not hide the floor.
const TRAIL: Rgba = [40, 90, 200, 120];
/// Fixed obstacles and walls.
const OBSTACLE: Rgba = [69, 69, 69, 255];
/// Obstacles robots can push.
const MOVABLE: Rgba = [139, 125, 112, 255];
/// A target whose colour is black (off).
const TARGET: Rgba = [200, 0, 0, 255];
/// The part of the progress bar up to the tick shown.
pub const PROGRESS: Rgba = [30, 90, 230, 255];
/// The rest of the progress bar.
const TRACK: Rgba = [0, 0, 0, 50];
/// Radius of a light's dot in metres.
const LIGHT_RADIUS: f32 = 0.05;
/// Radius of a light's glow in metres.
const GLOW_RADIUS: f32 = 0.15;

/// Draws the frames of one run, one at a time into the same picture.
pub struct Painter {
    scene: Scene,
    floor: Option<Pixmap>,
    view: View,
    /// Everything that moves at most once a simulated second.
    background: Pixmap,
    /// The tick of the pheromone frame drawn into `background`.
    field_tick: Option<u64>,
    canvas: Pixmap,
    /// Each robot's position in the last frames, oldest first; `NaN` while it is not in the run.
    trails: VecDeque<Vec<[f32; 2]>>,
}

/// World (metres, +Y up) to pixels (+Y down).
#[derive(Clone, Copy)]
struct View {
    transform: Transform,
    /// One pixel in metres.
    pixel: f32,
}

impl Painter {
    /// A painter of `scene` (and its `floor` image) `width` pixels wide, as high as the arena's aspect says.
    pub fn new(scene: Scene, floor: Option<Pixmap>, width: u32) -> Result<Self, AnimationError> {
        let [arena_width, arena_height] = scene.arena.size();
        let scale = width as f32 / arena_width;
        let height = (arena_height * scale).round().max(1.0);
        if height > MAX_SIDE_PX as f32 {
            return Err(AnimationError::Options(format!(
                "the arena is {arena_width} by {arena_height} m: {width} pixels wide it would be {height} high, \
                 more than {MAX_SIDE_PX}; choose a smaller width (--gif-width)"
            )));
        }
        let blank = || {
            Pixmap::new(width, height as u32).ok_or_else(|| {
                AnimationError::Options(format!("cannot draw a {width} x {height} picture"))
            })
        };
        let view = View {
            transform: Transform::from_row(
                scale,
                0.0,
                0.0,
                -scale,
                -scene.arena.min[0] * scale,
                scene.arena.max[1] * scale,
            ),
            pixel: 1.0 / scale,
        };
        let mut painter = Self {
            background: blank()?,
            canvas: blank()?,
            scene,
            floor,
            view,
            field_tick: None,
            trails: VecDeque::with_capacity(TRAIL_SAMPLES),
        };
        painter.paint_background(None);
        Ok(painter)
    }

    /// Width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.canvas.width(), self.canvas.height())
    }

    /// Shows the pheromone `frame` (`RunRecord::pheromone`) from now on.
    pub fn show_field(&mut self, frame: &[u8]) {
        let Some((tick, cells)) = frame.split_first_chunk::<8>() else {
            return;
        };
        let tick = u64::from_le_bytes(*tick);
        if self.field_tick == Some(tick) {
            return;
        }
        let field = self
            .scene
            .pheromone
            .as_ref()
            .and_then(|layout| field_image(layout, cells));
        self.paint_background(field.as_ref());
        self.field_tick = Some(tick);
    }

    fn paint_background(&mut self, field: Option<&Pixmap>) {
        let (pixmap, scene, view) = (&mut self.background, &self.scene, self.view);
        pixmap.fill(Color::WHITE);
        if let (Some(image), Some(bounds)) = (&self.floor, &scene.floor) {
            draw_image(pixmap, image, bounds, view);
        }
        if let (Some(image), Some(layout)) = (field, &scene.pheromone) {
            let max = [0, 1].map(|axis| {
                let cells = [layout.nx, layout.ny][axis] as f32;
                layout.min[axis] + cells * layout.cell
            });
            let bounds = Bounds {
                min: layout.min,
                max,
            };
            draw_image(pixmap, image, &bounds, view);
        }
        for obstacle in scene.obstacles.iter().filter(|o| !o.movable) {
            fill_body(pixmap, obstacle, OBSTACLE, view);
        }
        for light in &scene.lights {
            let [r, g, b] = light.colour;
            fill(
                pixmap,
                circle(light.x, light.y, GLOW_RADIUS),
                [r, g, b, 70],
                view,
            );
            let dot = circle(light.x, light.y, LIGHT_RADIUS.max(3.0 * view.pixel));
            fill(pixmap, dot.clone(), [r, g, b, 255], view);
            stroke(pixmap, dot, OUTLINE, view.pixel, view);
        }
    }

    /// Draws the `robots` of one frame over the background, with a progress bar `progress` (0 to 1) long, and
    /// answers the picture: RGBA, opaque, row by row from the top.
    pub fn draw(&mut self, robots: &[FrameRobot], places: &ObjectPlaces, progress: f32) -> &[u8] {
        self.canvas
            .data_mut()
            .copy_from_slice(self.background.data());
        self.draw_objects(places);
        if self.trails.len() == TRAIL_SAMPLES {
            self.trails.pop_front();
        }
        self.trails
            .push_back(robots.iter().map(|r| [r.pose.x, r.pose.y]).collect());
        self.draw_trails();
        for (index, robot) in robots.iter().enumerate() {
            let radius = self.scene.robots.get(index).map_or(0.0, |r| r.radius);
            draw_robot(&mut self.canvas, robot, radius, self.view);
        }
        self.draw_progress(progress);
        self.canvas.data()
    }

    /// Targets and movable obstacles where `places` puts them (where the scene placed those without a row); a
    /// target out of the arena is not drawn.
    fn draw_objects(&mut self, places: &ObjectPlaces) {
        let (canvas, scene, view) = (&mut self.canvas, &self.scene, self.view);
        let moved =
            |body: &Body, place: Option<&Option<ObjectPlace>>| match place.copied().flatten() {
                None => Some(body.clone()),
                Some(p) if p.in_arena => Some(Body {
                    x: p.x,
                    y: p.y,
                    angle: p.angle,
                    ..body.clone()
                }),
                Some(_) => None,
            };
        for (index, target) in scene.targets.iter().enumerate() {
            let colour = target
                .colour
                .filter(|&c| c != [0; 3])
                .map_or(TARGET, |[r, g, b]| [r, g, b, 255]);
            if let Some(body) = moved(target, places.targets.get(index)) {
                fill_body(canvas, &body, colour, view);
            }
        }
        for (index, obstacle) in scene
            .obstacles
            .iter()
            .enumerate()
            .filter(|(_, o)| o.movable)
        {
            if let Some(body) = moved(obstacle, places.obstacles.get(index)) {
                fill_body(canvas, &body, MOVABLE, view);
            }
        }
    }

    fn draw_trails(&mut self) {
        let mut path = PathBuilder::new();
        let robots = self.trails.back().map_or(0, Vec::len);
        for robot in 0..robots {
            let mut drawing = false;
            for sample in &self.trails {
                match sample.get(robot) {
                    Some(&[x, y]) if !x.is_nan() => {
                        if drawing {
                            path.line_to(x, y);
                        } else {
                            path.move_to(x, y);
                        }
                        drawing = true;
                    }
                    _ => drawing = false,
                }
            }
        }
        stroke(
            &mut self.canvas,
            path.finish(),
            TRAIL,
            1.2 * self.view.pixel,
            self.view,
        );
    }

    fn draw_progress(&mut self, progress: f32) {
        let (width, height) = (self.canvas.width() as f32, self.canvas.height() as f32);
        let bar = (height / 120.0).round().clamp(2.0, 6.0);
        let done = width * progress.clamp(0.0, 1.0);
        for (left, right, colour) in [(done, width, TRACK), (0.0, done, PROGRESS)] {
            if let Some(rect) = Rect::from_ltrb(left, height - bar, right, height) {
                self.canvas
                    .fill_rect(rect, &paint(colour), Transform::identity(), None);
            }
        }
    }
}

/// A robot as a disc in its LED colour (dark grey when dead, not at all when not in the run) with its outline
/// and a line from its centre along its heading; a ring when frozen, a dot when it holds something.
fn draw_robot(pixmap: &mut Pixmap, robot: &FrameRobot, radius: f32, view: View) {
    let pose = robot.pose;
    if pose.x.is_nan() {
        return;
    }
    let radius = radius.max(MIN_ROBOT_PX * view.pixel);
    let fill_colour = match pose.led {
        _ if !pose.alive => DEAD,
        [0, 0, 0] => LED_OFF,
        [r, g, b] => [r, g, b, 255],
    };
    fill(pixmap, circle(pose.x, pose.y, radius), fill_colour, view);
    let mut outline = PathBuilder::new();
    outline.push_circle(pose.x, pose.y, radius);
    outline.move_to(pose.x, pose.y);
    outline.line_to(
        pose.x + radius * pose.heading.cos(),
        pose.y + radius * pose.heading.sin(),
    );
    stroke(pixmap, outline.finish(), OUTLINE, view.pixel, view);
    if robot.frozen {
        let ring = circle(pose.x, pose.y, radius + 2.0 * view.pixel);
        stroke(pixmap, ring, FROZEN, 1.5 * view.pixel, view);
    }
    if robot.carrying {
        let dot = circle(pose.x, pose.y, (0.3 * radius).max(1.5 * view.pixel));
        fill(pixmap, dot, CARRYING, view);
    }
}

/// The pheromone grid as an image, row 0 at the top: each cell in the colour of its strongest channel, more
/// opaque as it is stronger. `None` when `cells` does not hold the whole grid.
fn field_image(layout: &FieldLayout, cells: &[u8]) -> Option<Pixmap> {
    let (nx, ny) = (layout.nx as usize, layout.ny as usize);
    let plane = nx * ny;
    if cells.len() != plane * layout.channels as usize {
        return None;
    }
    let mut image = Pixmap::new(layout.nx, layout.ny)?;
    let pixels = image.pixels_mut();
    for cell in 0..plane {
        let strongest = cells[cell..]
            .iter()
            .step_by(plane)
            .zip(&layout.colours)
            .max_by_key(|&(&value, _)| value);
        if let Some((&value, &[r, g, b])) = strongest.filter(|&(&value, _)| value > 0) {
            let alpha = (u16::from(value) * 200 / 255) as u8;
            let (row, column) = (cell / nx, cell % nx);
            pixels[(ny - 1 - row) * nx + column] = ColorU8::from_rgba(r, g, b, alpha).premultiply();
        }
    }
    Some(image)
}

/// Draws `image` (row 0 at the top) stretched over `bounds`, without smoothing.
fn draw_image(pixmap: &mut Pixmap, image: &Pixmap, bounds: &Bounds, view: View) {
    let [width, height] = bounds.size();
    let placed = Transform::from_row(
        width / image.width() as f32,
        0.0,
        0.0,
        -height / image.height() as f32,
        bounds.min[0],
        bounds.max[1],
    );
    let paint = PixmapPaint {
        quality: FilterQuality::Nearest,
        ..PixmapPaint::default()
    };
    pixmap.draw_pixmap(
        0,
        0,
        image.as_ref(),
        &paint,
        view.transform.pre_concat(placed),
        None,
    );
}

fn fill_body(pixmap: &mut Pixmap, body: &Body, colour: Rgba, view: View) {
    let path = match body.shape {
        Shape::Disc { radius } => circle(body.x, body.y, radius),
        Shape::Rect { half: [hx, hy] } => {
            let (sin, cos) = body.angle.sin_cos();
            let mut corners = [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]
                .map(|(dx, dy)| (body.x + dx * cos - dy * sin, body.y + dx * sin + dy * cos))
                .into_iter();
            let mut outline = PathBuilder::new();
            if let Some((x, y)) = corners.next() {
                outline.move_to(x, y);
            }
            corners.for_each(|(x, y)| outline.line_to(x, y));
            outline.close();
            outline.finish()
        }
    };
    fill(pixmap, path, colour, view);
}

fn circle(x: f32, y: f32, radius: f32) -> Option<Path> {
    PathBuilder::from_circle(x, y, radius)
}

fn fill(pixmap: &mut Pixmap, path: Option<Path>, colour: Rgba, view: View) {
    if let Some(path) = path {
        pixmap.fill_path(
            &path,
            &paint(colour),
            FillRule::Winding,
            view.transform,
            None,
        );
    }
}

/// Strokes `path` `width` metres wide.
fn stroke(pixmap: &mut Pixmap, path: Option<Path>, colour: Rgba, width: f32, view: View) {
    if let Some(path) = path {
        let stroke = Stroke {
            width,
            ..Stroke::default()
        };
        pixmap.stroke_path(&path, &paint(colour), &stroke, view.transform, None);
    }
}

fn paint([r, g, b, a]: Rgba) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color_rgba8(r, g, b, a);
    paint.anti_alias = true;
    paint
}
