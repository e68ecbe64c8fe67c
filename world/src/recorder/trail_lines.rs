//! Trails drawn straight into a snapshot's pixels as one-pixel anti-aliased lines (Xiaolin Wu's algorithm).
//!
//! Why not tiny-skia, which draws everything else: a trail is a polyline of segments about a pixel long, and
//! tiny-skia strokes an anti-aliased hairline through its general raster pipeline at about 110 ns a segment. The
//! final snapshot of a 1,000-robot, 600-tick run spent 70 ms of its 100 ms on the trails, after the last tick,
//! where the user waits for it (BENCHMARKS.md, "Shut-down"). Here a segment costs a few pixel blends.
//!
//! Consecutive segments share an end pixel; each segment covers the pixels from its start up to, not including,
//! its end, and the polyline's last point is drawn once, so a translucent trail is not darker at its joints.

use tiny_skia::{Pixmap, Transform};

use crate::geometry::Vec2;

/// A trail colour, straight (not premultiplied) red, green, blue and opacity as fractions.
#[derive(Debug, Clone, Copy)]
pub struct TrailPen {
    rgb: [f32; 3],
    opacity: f32,
}

impl TrailPen {
    /// The pen of colour `[r, g, b, a]`.
    pub fn new([r, g, b, a]: [u8; 4]) -> TrailPen {
        let unit = |v: u8| f32::from(v) / 255.0;
        TrailPen {
            rgb: [unit(r), unit(g), unit(b)],
            opacity: unit(a),
        }
    }

    /// Draws the polyline through `points` (world coordinates, mapped to pixels by `tf`).
    pub fn polyline(&self, pixmap: &mut Pixmap, points: &[Vec2], tf: Transform) {
        let mut canvas = Canvas::of(pixmap);
        let to_pixels = |p: &Vec2| {
            (
                tf.sx * p.x + tf.kx * p.y + tf.tx,
                tf.ky * p.x + tf.sy * p.y + tf.ty,
            )
        };
        let mut pixels = points.iter().map(to_pixels);
        let Some(mut from) = pixels.next() else {
            return;
        };
        for to in pixels {
            self.segment(&mut canvas, from, to);
            from = to;
        }
        self.plot(&mut canvas, from.0.round(), from.1.round(), 1.0);
    }

    /// The pixels of the segment from `from` up to, not including, `to`'s column (or row, for a steep segment).
    fn segment(&self, canvas: &mut Canvas<'_>, from: (f32, f32), to: (f32, f32)) {
        let steep = (to.1 - from.1).abs() > (to.0 - from.0).abs();
        // Along the major axis `u`, across it `v`.
        let (u0, v0, u1, v1) = if steep {
            (from.1, from.0, to.1, to.0)
        } else {
            (from.0, from.1, to.0, to.1)
        };
        let (start, end) = (u0.round(), u1.round());
        if start == end || !(start.is_finite() && end.is_finite()) {
            return;
        }
        let step = if end > start { 1.0 } else { -1.0 };
        let slope = (v1 - v0) / (u1 - u0);
        let mut u = start;
        while u != end {
            let v = v0 + slope * (u - u0);
            let below = v.floor();
            let fraction = v - below;
            let (near, far) = (1.0 - fraction, fraction);
            if steep {
                self.plot(canvas, below, u, near);
                self.plot(canvas, below + 1.0, u, far);
            } else {
                self.plot(canvas, u, below, near);
                self.plot(canvas, u, below + 1.0, far);
            }
            u += step;
        }
    }

    /// Blends the pen over pixel (`x`, `y`) at `coverage` (0 to 1); pixels off the image are skipped.
    fn plot(&self, canvas: &mut Canvas<'_>, x: f32, y: f32, coverage: f32) {
        let alpha = self.opacity * coverage;
        let inside = x >= 0.0 && y >= 0.0 && x < canvas.width && y < canvas.height;
        if alpha <= 0.0 || !inside {
            return;
        }
        let at = (y as usize * canvas.width as usize + x as usize) * 4;
        let pixel = &mut canvas.data[at..at + 4];
        let keep = 1.0 - alpha;
        for (channel, value) in pixel.iter_mut().zip(self.rgb.iter().chain([&1.0])) {
            *channel = (value * alpha * 255.0 + f32::from(*channel) * keep).round() as u8;
        }
    }
}

/// A pixmap's premultiplied RGBA bytes with its size.
struct Canvas<'a> {
    data: &'a mut [u8],
    width: f32,
    height: f32,
}

impl<'a> Canvas<'a> {
    fn of(pixmap: &'a mut Pixmap) -> Canvas<'a> {
        let (width, height) = (pixmap.width() as f32, pixmap.height() as f32);
        Canvas {
            data: pixmap.data_mut(),
            width,
            height,
        }
    }
}

#[cfg(test)]
mod tests {
    use tiny_skia::{Color, Paint, PathBuilder, Stroke};

    use super::*;

    const TRAIL: [u8; 4] = [40, 90, 200, 120];

    fn white(side: u32) -> Pixmap {
        let mut pixmap = Pixmap::new(side, side).expect("a pixmap");
        pixmap.fill(Color::WHITE);
        pixmap
    }

    /// How much darker than white the image is, summed over every pixel and channel.
    fn ink(pixmap: &Pixmap) -> f64 {
        pixmap.data().iter().map(|&v| f64::from(255 - v)).sum()
    }

    fn points(pixels: &[(f32, f32)]) -> Vec<Vec2> {
        pixels.iter().map(|&(x, y)| Vec2::new(x, y)).collect()
    }

    #[test]
    fn a_trail_puts_as_much_ink_as_tiny_skias_hairline_and_only_near_its_path() {
        // A wobbly path of one-pixel steps, as a robot's trail is, in pixel coordinates.
        let path: Vec<(f32, f32)> = (0..200)
            .map(|i| {
                let t = i as f32;
                (10.0 + 0.9 * t, 100.0 + 40.0 * (t / 25.0).sin())
            })
            .collect();
        let mut ours = white(200);
        TrailPen::new(TRAIL).polyline(&mut ours, &points(&path), Transform::identity());

        let mut theirs = white(200);
        let mut pb = PathBuilder::new();
        pb.move_to(path[0].0, path[0].1);
        for &(x, y) in &path[1..] {
            pb.line_to(x, y);
        }
        let [r, g, b, a] = TRAIL;
        let mut paint = Paint::default();
        paint.set_color_rgba8(r, g, b, a);
        paint.anti_alias = true;
        let stroke = Stroke {
            width: 1.0,
            ..Stroke::default()
        };
        let line = pb.finish().expect("a path");
        theirs.stroke_path(&line, &paint, &stroke, Transform::identity(), None);

        let ratio = ink(&ours) / ink(&theirs);
        assert!((0.8..1.25).contains(&ratio), "ink ratio {ratio}");
        for (index, pixel) in ours.pixels().iter().enumerate() {
            let (x, y) = ((index % 200) as f32, (index / 200) as f32);
            let near = path
                .iter()
                .any(|&(px, py)| (px - x).abs() <= 2.0 && (py - y).abs() <= 2.0);
            assert!(
                near || pixel.red() == 255,
                "ink at ({x}, {y}) far from the trail"
            );
        }
    }

    #[test]
    fn joints_are_not_darker_than_the_rest_of_a_straight_trail() {
        // A horizontal trail through pixel centres, in ten one-pixel segments.
        let mut pixmap = white(20);
        let path: Vec<(f32, f32)> = (0..=10).map(|i| (2.0 + i as f32, 5.0)).collect();
        TrailPen::new(TRAIL).polyline(&mut pixmap, &points(&path), Transform::identity());
        let row: Vec<u8> = (2..=12)
            .map(|x| pixmap.pixel(x, 5).expect("in the image").red())
            .collect();
        assert!(row.iter().all(|&red| red == row[0] && red < 255), "{row:?}");
        assert_eq!(pixmap.pixel(13, 5).map(|p| p.red()), Some(255));
    }

    #[test]
    fn the_world_transform_places_the_trail_and_pixels_off_the_image_are_skipped() {
        let mut pixmap = white(10);
        // Metres with +Y up, 10 px per metre, as snapshots map the arena; the trail runs far off the image.
        let tf = Transform::from_row(10.0, 0.0, 0.0, -10.0, 0.0, 10.0);
        let path = [(0.05, 0.55), (0.55, 0.55), (5.0, -3.0), (-4.0, 9.0)];
        TrailPen::new(TRAIL).polyline(&mut pixmap, &points(&path), tf);
        assert!(pixmap.pixel(3, 4).expect("in the image").red() < 255);
        assert_eq!(pixmap.pixel(3, 8).map(|p| p.red()), Some(255));
    }

    #[test]
    fn gaps_and_repeated_points_draw_nothing_wrong() {
        let mut pixmap = white(10);
        let path = [
            (f32::NAN, f32::NAN),
            (3.0, 3.0),
            (3.0, 3.0),
            (3.2, 3.1),
            (f32::NAN, 1.0),
        ];
        TrailPen::new(TRAIL).polyline(&mut pixmap, &points(&path), Transform::identity());
        let inked = pixmap.pixels().iter().filter(|p| p.red() < 255).count();
        assert_eq!(
            inked, 0,
            "a trail that ends in a gap has no last pixel to draw"
        );
        let mut pixmap = white(10);
        TrailPen::new(TRAIL).polyline(&mut pixmap, &points(&path[..4]), Transform::identity());
        let inked = pixmap.pixels().iter().filter(|p| p.red() < 255).count();
        assert_eq!(inked, 1);
    }
}
