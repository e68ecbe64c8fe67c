//! The annotations on a snapshot: the tick and simulated time top-left, a scale bar bottom-left and a legend of
//! the kinds of things drawn top-right, each on a translucent white box. Text is set in the font of
//! [`swarm_contract::fonts`], parsed once per process, with glyph coverage from ab_glyph blended into the pixmap;
//! without a font the scale bar and the legend's swatches are drawn without their text (and one warning says so).
//!
//! Sizes follow the image: the text grows with the square root of the shorter side, so labels stay readable on a
//! 300-pixel snapshot without crowding a 2,000-pixel one. The annotations are drawn over the picture and never
//! enlarge it; a legend that would not fit beside the other boxes, or an image under [`MIN_LEGEND_WIDTH`], goes
//! without a legend.

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, Glyph, GlyphId, PxScale, PxScaleFont, ScaleFont, point};
use swarm_contract::fonts;
use tiny_skia::{LineCap, PathBuilder, Pixmap, PremultipliedColorU8, Rect, Stroke, Transform};

use crate::entities::TargetState;
use crate::geometry::{Placed, Shape, Vec2};
use crate::world::World;

use super::snapshot::{self, Rgba, RobotDisc, paint};
use super::trails::Trails;

/// Narrowest image, in pixels, that gets a legend.
const MIN_LEGEND_WIDTH: u32 = 200;
/// Smallest and largest text size in pixels.
const TEXT_PX: (f32, f32) = (11.0, 40.0);
/// Text size per square root of the image's shorter side in pixels: 14 px at 300 px, 36 px at 2,000 px.
const TEXT_PX_PER_ROOT_PX: f32 = 0.8;
/// The boxes behind the annotations.
const BACKDROP: Rgba = [255, 255, 255, 200];
/// Text and the scale bar.
const INK: Rgba = [0, 0, 0, 255];
/// Half the side of a legend swatch's square, in the metres its shapes are drawn in.
const SWATCH_HALF: f32 = 0.06;

/// Draws the tick and time, the scale bar and the legend of `world` (with its `trails`) over `pixmap`, a snapshot
/// drawn at `px_per_metre`.
pub(super) fn annotate(pixmap: &mut Pixmap, world: &World, trails: &Trails, px_per_metre: f32) {
    let layout = Layout::new(pixmap.width(), pixmap.height());
    draw_annotations(
        pixmap,
        &layout,
        Text::new(layout.em),
        world,
        trails,
        px_per_metre,
    );
}

/// [`annotate`] with the font at the layout's size, or without text when `text` is `None`.
fn draw_annotations(
    pixmap: &mut Pixmap,
    layout: &Layout,
    text: Option<Text>,
    world: &World,
    trails: &Trails,
    px_per_metre: f32,
) {
    let clock = tick_label(world.tick(), world.arena.ticks_per_second);
    let taken = [
        text.and_then(|t| draw_clock(pixmap, layout, &t, &clock)),
        draw_scale_bar(pixmap, layout, text.as_ref(), px_per_metre),
    ];
    if pixmap.width() >= MIN_LEGEND_WIDTH {
        let kinds = Kind::present(world, trails);
        draw_legend(pixmap, layout, text.as_ref(), &kinds, &taken);
    }
}

/// `tick 300  ·  15.0 s`.
fn tick_label(tick: u64, ticks_per_second: u32) -> String {
    let seconds = tick as f64 / f64::from(ticks_per_second.max(1));
    format!("tick {tick}  ·  {seconds:.1} s")
}

/// The scale bar's length in metres for an image `width_px` wide drawn at `px_per_metre`: 1, 2 or 5 times a power
/// of ten, the one nearest (by ratio) to a fifth of the width.
fn scale_bar_metres(width_px: u32, px_per_metre: f32) -> f32 {
    let target = width_px as f32 / 5.0 / px_per_metre;
    let decade = 10f32.powf(target.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .map(|step| step * decade)
        .into_iter()
        .min_by(|a, b| {
            let off = |length: f32| (length / target).ln().abs();
            off(*a).total_cmp(&off(*b))
        })
        .unwrap_or(decade)
}

/// `metres` as the scale bar writes it: `5 mm`, `50 cm`, `2 m`.
fn length_label(metres: f32) -> String {
    let (value, unit) = if metres >= 1.0 {
        (metres, "m")
    } else if metres >= 0.01 {
        (metres * 100.0, "cm")
    } else {
        (metres * 1000.0, "mm")
    };
    format!("{} {unit}", value.round())
}

/// Sizes of the annotations in pixels, all following the text size.
#[derive(Debug, Clone, Copy)]
struct Layout {
    /// Text size (a line's height).
    em: f32,
    /// Space inside a box around its content.
    pad: f32,
    /// Space between a box and the image's edge.
    margin: f32,
    /// The image's width.
    width: f32,
    /// The image's height.
    height: f32,
}

impl Layout {
    /// The layout of an image `width` x `height` pixels.
    fn new(width: u32, height: u32) -> Self {
        let shorter = width.min(height) as f32;
        let em = (TEXT_PX_PER_ROOT_PX * shorter.sqrt()).clamp(TEXT_PX.0, TEXT_PX.1);
        Self {
            em,
            pad: 0.35 * em,
            margin: 0.5 * em,
            width: width as f32,
            height: height as f32,
        }
    }

    /// Space between a swatch and its label, or a label and the scale bar.
    fn gap(&self) -> f32 {
        0.3 * self.em
    }

    /// Height of a legend row.
    fn row(&self) -> f32 {
        1.25 * self.em
    }

    /// Whether `rect` lies wholly inside the image.
    fn contains(&self, rect: Rect) -> bool {
        rect.left() >= 0.0
            && rect.top() >= 0.0
            && rect.right() <= self.width
            && rect.bottom() <= self.height
    }
}

/// The snapshot font, parsed on first use; `None`, after one warning, when there is no usable font.
fn face() -> Option<&'static FontRef<'static>> {
    static FACE: OnceLock<Option<FontRef<'static>>> = OnceLock::new();
    FACE.get_or_init(|| {
        let parsed = fonts::font().map_err(ToString::to_string).and_then(|font| {
            FontRef::try_from_slice(&font.bytes).map_err(|_| {
                format!(
                    "{} is not a font we can read: set {} to another .ttf file",
                    font.path.display(),
                    fonts::FONT_ENV
                )
            })
        });
        parsed
            .inspect_err(|why| {
                tracing::warn!("snapshots get no text (tick, scale length, legend words): {why}")
            })
            .ok()
    })
    .as_ref()
}

/// The snapshot font at one size.
#[derive(Clone, Copy)]
struct Text(PxScaleFont<&'static FontRef<'static>>);

impl Text {
    /// The font at `em` pixels, if there is a font.
    fn new(em: f32) -> Option<Self> {
        face().map(|font| Self(font.as_scaled(PxScale::from(em))))
    }

    /// A line's height in pixels.
    fn height(&self) -> f32 {
        self.0.height()
    }

    /// `text`'s width in pixels.
    fn width(&self, text: &str) -> f32 {
        self.glyphs(text, (0.0, 0.0)).1
    }

    /// `text`'s glyphs placed with the top-left corner of its line at `(x, y)`, and the line's width.
    fn glyphs(&self, text: &str, (x, y): (f32, f32)) -> (Vec<Glyph>, f32) {
        let baseline = y + self.0.ascent();
        let mut caret = x;
        let mut previous: Option<GlyphId> = None;
        let mut glyphs = Vec::with_capacity(text.len());
        for c in text.chars() {
            let mut glyph = self.0.scaled_glyph(c);
            if let Some(previous) = previous {
                caret += self.0.kern(previous, glyph.id);
            }
            glyph.position = point(caret, baseline);
            caret += self.0.h_advance(glyph.id);
            previous = Some(glyph.id);
            glyphs.push(glyph);
        }
        (glyphs, caret - x)
    }

    /// Draws `text` in ink with the top-left corner of its line at `top_left`.
    fn draw(&self, pixmap: &mut Pixmap, text: &str, top_left: (f32, f32)) {
        for glyph in self.glyphs(text, top_left).0 {
            if let Some(outline) = self.0.outline_glyph(glyph) {
                let corner = outline.px_bounds().min;
                outline.draw(|x, y, coverage| {
                    let at = (corner.x as i32 + x as i32, corner.y as i32 + y as i32);
                    blend(pixmap, at, INK, coverage);
                });
            }
        }
    }
}

/// Blends opaque `colour` over the pixel `at` with `coverage` (0 to 1); pixels outside the image are skipped.
fn blend(pixmap: &mut Pixmap, (x, y): (i32, i32), [r, g, b, _]: Rgba, coverage: f32) {
    let (width, height) = (pixmap.width() as i32, pixmap.height() as i32);
    if !(0..width).contains(&x) || !(0..height).contains(&y) {
        return;
    }
    let pixel = &mut pixmap.pixels_mut()[(y * width + x) as usize];
    let a = coverage.clamp(0.0, 1.0);
    // Pixels are premultiplied; an opaque source is its own premultiplied colour.
    let mix = |source: u8, under: u8| {
        (f32::from(source) * a + f32::from(under) * (1.0 - a)).round() as u8
    };
    let mixed = PremultipliedColorU8::from_rgba(
        mix(r, pixel.red()),
        mix(g, pixel.green()),
        mix(b, pixel.blue()),
        mix(255, pixel.alpha()),
    );
    if let Some(mixed) = mixed {
        *pixel = mixed;
    }
}

/// Fills `rect` (pixels) with the translucent white backdrop.
fn draw_backdrop(pixmap: &mut Pixmap, rect: Rect) {
    pixmap.fill_rect(rect, &paint(BACKDROP), Transform::identity(), None);
}

/// Draws the tick and time top-left; returns its box.
fn draw_clock(pixmap: &mut Pixmap, layout: &Layout, text: &Text, clock: &str) -> Option<Rect> {
    let rect = Rect::from_xywh(
        layout.margin,
        layout.margin,
        text.width(clock) + 2.0 * layout.pad,
        text.height() + 2.0 * layout.pad,
    )?;
    draw_backdrop(pixmap, rect);
    text.draw(
        pixmap,
        clock,
        (rect.x() + layout.pad, rect.y() + layout.pad),
    );
    Some(rect)
}

/// Draws the scale bar bottom-left: a black bar with ticks at its ends, its length written above it when there
/// is a font; returns its box.
fn draw_scale_bar(
    pixmap: &mut Pixmap,
    layout: &Layout,
    text: Option<&Text>,
    px_per_metre: f32,
) -> Option<Rect> {
    let metres = scale_bar_metres(pixmap.width(), px_per_metre);
    let label = length_label(metres);
    let bar = metres * px_per_metre;
    let thickness = (layout.em / 6.0).max(2.0);
    let tick = 0.6 * layout.em;
    let (label_width, label_height) =
        text.map_or((0.0, 0.0), |t| (t.width(&label), t.height() + layout.gap()));
    let rect = Rect::from_xywh(
        layout.margin,
        layout.height - layout.margin - (label_height + tick + thickness + 2.0 * layout.pad),
        (bar + thickness).max(label_width) + 2.0 * layout.pad,
        label_height + tick + thickness + 2.0 * layout.pad,
    )?;
    draw_backdrop(pixmap, rect);
    let left = rect.x() + layout.pad + thickness / 2.0;
    if let Some(t) = text {
        let x = (left + (bar - label_width) / 2.0).max(rect.x() + layout.pad);
        t.draw(pixmap, &label, (x, rect.y() + layout.pad));
    }
    let bottom = rect.bottom() - layout.pad - thickness / 2.0;
    let mut pb = PathBuilder::new();
    pb.move_to(left, bottom - tick);
    pb.line_to(left, bottom);
    pb.line_to(left + bar, bottom);
    pb.line_to(left + bar, bottom - tick);
    let stroke = Stroke {
        width: thickness,
        line_cap: LineCap::Square,
        ..Stroke::default()
    };
    if let Some(path) = pb.finish() {
        pixmap.stroke_path(&path, &paint(INK), &stroke, Transform::identity(), None);
    }
    Some(rect)
}

/// Draws the legend of `kinds` top-right, unless it would leave the image or cover a box in `taken`.
fn draw_legend(
    pixmap: &mut Pixmap,
    layout: &Layout,
    text: Option<&Text>,
    kinds: &[Kind],
    taken: &[Option<Rect>],
) {
    let labels = text.map_or(0.0, |t| {
        let widest = kinds.iter().map(|k| t.width(k.label())).fold(0.0, f32::max);
        layout.gap() + widest
    });
    let width = layout.em + labels + 2.0 * layout.pad;
    let height = kinds.len() as f32 * layout.row() + 2.0 * layout.pad;
    let Some(rect) = Rect::from_xywh(
        layout.width - layout.margin - width,
        layout.margin,
        width,
        height,
    ) else {
        return;
    };
    let overlaps = |other: &Rect| {
        rect.intersect(other)
            .is_some_and(|r| r.width() > 0.0 && r.height() > 0.0)
    };
    if kinds.is_empty() || !layout.contains(rect) || taken.iter().flatten().any(overlaps) {
        return;
    }
    draw_backdrop(pixmap, rect);
    for (row, kind) in kinds.iter().enumerate() {
        let top = rect.y() + layout.pad + row as f32 * layout.row();
        let middle = top + layout.row() / 2.0;
        kind.draw_swatch(
            pixmap,
            (rect.x() + layout.pad + layout.em / 2.0, middle),
            layout.em / 2.0,
        );
        if let Some(t) = text {
            let x = rect.x() + layout.pad + layout.em + layout.gap();
            t.draw(pixmap, kind.label(), (x, middle - t.height() / 2.0));
        }
    }
}

/// A kind of thing a snapshot draws, as the legend lists it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Robot,
    Dead,
    Carrying,
    Trail,
    Obstacle,
    Target,
    Light,
}

impl Kind {
    /// Every kind, in legend order.
    const ALL: [Kind; 7] = [
        Kind::Robot,
        Kind::Dead,
        Kind::Carrying,
        Kind::Trail,
        Kind::Obstacle,
        Kind::Target,
        Kind::Light,
    ];

    /// The kinds `world`'s snapshot with `trails` shows, in legend order.
    fn present(world: &World, trails: &Trails) -> Vec<Kind> {
        Self::ALL
            .into_iter()
            .filter(|kind| kind.is_in(world, trails))
            .collect()
    }

    /// Whether the snapshot of `world` with `trails` draws anything of this kind.
    fn is_in(self, world: &World, trails: &Trails) -> bool {
        let arena = &world.arena;
        let mut drawn_robots = arena.robots.iter().filter(|r| !r.removed);
        match self {
            Kind::Robot => drawn_robots.any(|r| r.alive),
            Kind::Dead => drawn_robots.any(|r| !r.alive),
            Kind::Carrying => drawn_robots.any(|r| r.carrying.is_some()),
            Kind::Trail => (0..arena.robots.len()).any(|i| trails.pieces(i).next().is_some()),
            Kind::Obstacle => !arena.obstacles.is_empty(),
            Kind::Target => arena
                .targets
                .iter()
                .any(|t| t.state == TargetState::InArena),
            Kind::Light => !arena.lights.is_empty(),
        }
    }

    /// The legend's word for it.
    fn label(self) -> &'static str {
        match self {
            Kind::Robot => "robot",
            Kind::Dead => "dead",
            Kind::Carrying => "carrying",
            Kind::Trail => "trail",
            Kind::Obstacle => "obstacle",
            Kind::Target => "target",
            Kind::Light => "light",
        }
    }

    /// Draws its swatch, the snapshot's own shape and colour, in a square of half side `half_px` around `centre`.
    fn draw_swatch(self, pixmap: &mut Pixmap, centre: (f32, f32), half_px: f32) {
        let s = half_px / SWATCH_HALF;
        // Swatch metres (+Y up) around the origin to pixels around `centre`, as the snapshot's own transform.
        let tf = Transform::from_row(s, 0.0, 0.0, -s, centre.0, centre.1);
        let mut robot = |fill: Rgba, carrying: bool| {
            let disc = RobotDisc {
                centre: Vec2::ZERO,
                heading: 0.0,
                radius: 0.75 * SWATCH_HALF,
            };
            snapshot::draw_robot(pixmap, disc, &paint(fill), carrying, tf);
        };
        match self {
            Kind::Robot => robot(snapshot::ROBOT, false),
            Kind::Dead => robot(snapshot::DEAD_ROBOT, false),
            Kind::Carrying => robot(snapshot::ROBOT, true),
            Kind::Trail => {
                let mut pb = PathBuilder::new();
                pb.move_to(-SWATCH_HALF, -0.5 * SWATCH_HALF);
                pb.cubic_to(
                    0.0,
                    -SWATCH_HALF,
                    0.0,
                    SWATCH_HALF,
                    SWATCH_HALF,
                    0.5 * SWATCH_HALF,
                );
                if let Some(path) = pb.finish() {
                    snapshot::stroke_trail(pixmap, &path, tf);
                }
            }
            Kind::Obstacle => {
                let half = Vec2::splat(0.75 * SWATCH_HALF);
                let square = Placed::new(Shape::Rect { half }, Vec2::ZERO, 0.0);
                snapshot::fill_placed(pixmap, &square, &paint(snapshot::OBSTACLE), tf);
            }
            Kind::Target => {
                let radius = 0.6 * SWATCH_HALF;
                let disc = Placed::new(Shape::Disc { radius }, Vec2::ZERO, 0.0);
                snapshot::fill_placed(pixmap, &disc, &paint(snapshot::TARGET), tf);
            }
            Kind::Light => snapshot::draw_light(pixmap, Vec2::ZERO, tf),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::WorldBuilder;
    use crate::devices::Devices;
    use crate::recorder::snapshot::render;

    #[test]
    fn the_scale_bar_is_a_round_length_near_a_fifth_of_the_width() {
        let cases = [
            (300, 100.0, 0.5, "50 cm"),
            (150, 100.0, 0.2, "20 cm"),
            (1000, 100.0, 2.0, "2 m"),
            (2000, 100.0, 5.0, "5 m"),
            (2000, 40.0, 10.0, "10 m"),
            (40, 100.0, 0.1, "10 cm"),
            (1, 100.0, 0.002, "2 mm"),
        ];
        for (width, px_per_metre, metres, label) in cases {
            let length = scale_bar_metres(width, px_per_metre);
            assert!(
                (length - metres).abs() < 1e-6 * metres,
                "{width} px: {length} m"
            );
            assert_eq!(length_label(length), label);
        }
    }

    #[test]
    fn the_clock_reads_tick_and_seconds() {
        assert_eq!(tick_label(300, 20), "tick 300  ·  15.0 s");
    }

    /// A 3 x 3 m arena (300 x 300 px) with one robot right of the centre and one target below it.
    fn small_world() -> crate::World {
        let mut b = WorldBuilder::new(Vec2::splat(-1.5), Vec2::splat(1.5), 10, 1);
        b.robot("ep0", "fc", Vec2::new(0.5, 0.0), 0.0, Devices::ALL);
        let food = Placed::new(Shape::Disc { radius: 0.02 }, Vec2::new(0.5, -0.5), 0.0);
        b.target(
            "food0",
            food,
            0.05,
            swarm_contract::messages::Rgb::OFF,
            0.06,
        );
        b.build()
    }

    /// How many pixels of `image` inside `x0..x1`, `y0..y1` have every channel under `level`.
    fn pixels_under(
        image: &Pixmap,
        level: u8,
        (x0, x1): (u32, u32),
        (y0, y1): (u32, u32),
    ) -> usize {
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter_map(|(x, y)| image.pixel(x, y))
            .filter(|p| p.red() < level && p.green() < level && p.blue() < level)
            .count()
    }

    /// Pixels dark enough to be ink.
    fn dark_pixels(image: &Pixmap, xs: (u32, u32), ys: (u32, u32)) -> usize {
        pixels_under(image, 100, xs, ys)
    }

    #[test]
    fn a_snapshot_shows_the_scale_bar_and_the_clock_without_growing() {
        let world = small_world();
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("snapshot.png");
        render(&world, &Trails::default(), &path).expect("renders");
        let image = Pixmap::load_png(&path).expect("a PNG");
        assert_eq!((image.width(), image.height()), (300, 300));

        // The 50 cm bar is 50 px long and at least 2 px thick, in the bottom-left corner.
        assert!(dark_pixels(&image, (0, 100), (240, 300)) >= 80);
        if face().is_some() {
            assert!(
                dark_pixels(&image, (0, 150), (0, 40)) >= 50,
                "no text in the clock's box"
            );
        }
    }

    #[test]
    fn without_a_font_the_scale_bar_and_the_swatches_are_still_drawn() {
        let world = small_world();
        let mut pixmap = Pixmap::new(300, 300).expect("a pixmap");
        pixmap.fill(tiny_skia::Color::WHITE);
        let layout = Layout::new(300, 300);
        draw_annotations(
            &mut pixmap,
            &layout,
            None,
            &world,
            &Trails::default(),
            100.0,
        );
        assert!(
            dark_pixels(&pixmap, (0, 100), (240, 300)) >= 80,
            "no scale bar"
        );
        assert_eq!(
            dark_pixels(&pixmap, (0, 150), (0, 40)),
            0,
            "text without a font"
        );
        // The robot's outline and the target's red disc, in the top-right corner.
        assert!(
            pixels_under(&pixmap, 255, (270, 300), (0, 60)) > 0,
            "no robot swatch"
        );
    }

    #[test]
    fn the_legend_lists_only_what_the_snapshot_draws() {
        let mut world = small_world();
        assert_eq!(
            Kind::present(&world, &Trails::default()),
            [Kind::Robot, Kind::Target]
        );
        world.arena.robots[0].alive = false;
        let mut trails = Trails::default();
        for tick in 0..2 {
            trails.sample(tick, [Some(Vec2::new(tick as f32, 0.0))].into_iter());
        }
        assert_eq!(
            Kind::present(&world, &trails),
            [Kind::Dead, Kind::Trail, Kind::Target]
        );
    }
}
