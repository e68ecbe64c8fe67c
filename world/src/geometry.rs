//! Planar shapes and the exact geometry the sensors and the placement need.
//!
//! Sensors are computed analytically against these shapes (rays against discs and oriented rectangles), not
//! through the physics engine's query pipeline: it is exact, allocation-free and keeps the sensor models
//! independent of how the physics resolves contacts. Everything here is pure and must stay free of world state.

pub use rapier2d::math::Vector as Vec2;

/// Unit vector at `angle` radians, counter-clockwise from +X.
pub fn unit(angle: f32) -> Vec2 {
    let (s, c) = angle.sin_cos();
    Vec2::new(c, s)
}

/// Wraps an angle into [-pi, pi].
pub fn wrap_angle(angle: f32) -> f32 {
    let two_pi = std::f32::consts::TAU;
    let mut a = angle % two_pi;
    if a > std::f32::consts::PI {
        a -= two_pi;
    } else if a < -std::f32::consts::PI {
        a += two_pi;
    }
    a
}

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec2,
    /// Upper corner.
    pub max: Vec2,
}

impl Aabb {
    /// The empty box: lies nowhere, so a grid lists it in no cell.
    pub const NOWHERE: Aabb = Aabb {
        min: Vec2::splat(f32::INFINITY),
        max: Vec2::splat(f32::NEG_INFINITY),
    };

    /// Whether this is [`Aabb::NOWHERE`] (or any box with a lower corner above its upper one).
    pub fn is_nowhere(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y
    }

    /// The box around a disc of `radius` at `centre`.
    pub fn around(centre: Vec2, radius: f32) -> Self {
        Self {
            min: centre - Vec2::splat(radius),
            max: centre + Vec2::splat(radius),
        }
    }
}

/// The outline of a body seen from above.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A disc (e-puck, cylinder, round target).
    Disc {
        /// Radius in metres.
        radius: f32,
    },
    /// A rectangle centred on the body origin (box, wall).
    Rect {
        /// Half extents along the body's own x and y axes, in metres.
        half: Vec2,
    },
}

impl Shape {
    /// Radius of the smallest disc around the body origin that contains the shape.
    pub fn bounding_radius(&self) -> f32 {
        match *self {
            Shape::Disc { radius } => radius,
            Shape::Rect { half } => half.length(),
        }
    }
}

/// A shape at a pose in the arena.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placed {
    /// The outline.
    pub shape: Shape,
    /// Position of the body origin.
    pub position: Vec2,
    angle: f32,
    /// (cos, sin) of `angle`, computed once per pose: sensors test many rays against the same body.
    rot: Vec2,
}

impl Placed {
    /// `shape` at `position`, rotated by `angle`.
    pub fn new(shape: Shape, position: Vec2, angle: f32) -> Self {
        Self {
            shape,
            position,
            angle,
            rot: unit(angle),
        }
    }

    /// Heading in radians.
    pub fn angle(&self) -> f32 {
        self.angle
    }

    /// Moves the shape to a new pose.
    pub fn set_pose(&mut self, position: Vec2, angle: f32) {
        self.position = position;
        if angle != self.angle {
            self.angle = angle;
            self.rot = unit(angle);
        }
    }

    /// A point of the body's own frame in the arena frame.
    pub fn to_world(&self, local: Vec2) -> Vec2 {
        let (c, s) = (self.rot.x, self.rot.y);
        self.position + Vec2::new(c * local.x - s * local.y, s * local.x + c * local.y)
    }

    fn local_point(&self, p: Vec2) -> Vec2 {
        self.dir_to_local(p - self.position)
    }

    fn dir_to_local(&self, v: Vec2) -> Vec2 {
        let (c, s) = (self.rot.x, self.rot.y);
        Vec2::new(c * v.x + s * v.y, -s * v.x + c * v.y)
    }

    /// The axis-aligned bounding box.
    pub fn aabb(&self) -> Aabb {
        match self.shape {
            Shape::Disc { radius } => Aabb::around(self.position, radius),
            Shape::Rect { half } => {
                let (c, s) = (self.rot.x, self.rot.y);
                let ext = Vec2::new(
                    c.abs() * half.x + s.abs() * half.y,
                    s.abs() * half.x + c.abs() * half.y,
                );
                Aabb {
                    min: self.position - ext,
                    max: self.position + ext,
                }
            }
        }
    }

    /// Signed distance from `p` to the outline: negative inside, zero on the edge.
    pub fn signed_distance(&self, p: Vec2) -> f32 {
        match self.shape {
            Shape::Disc { radius } => (p - self.position).length() - radius,
            Shape::Rect { half } => {
                let q = self.local_point(p).abs() - half;
                let outside = q.max(Vec2::ZERO).length();
                let inside = q.x.max(q.y).min(0.0);
                outside + inside
            }
        }
    }

    /// Distance along the ray `origin + t * dir` (`dir` a unit vector) to the first point of the shape, if it is
    /// at most `max`. A ray that starts inside the shape hits at 0.
    pub fn ray_hit(&self, origin: Vec2, dir: Vec2, max: f32) -> Option<f32> {
        let t = match self.shape {
            Shape::Disc { radius } => ray_disc(origin - self.position, dir, radius)?,
            Shape::Rect { half } => {
                ray_rect(self.local_point(origin), self.dir_to_local(dir), half)?
            }
        };
        (t <= max).then_some(t)
    }

    /// Edge-to-edge gap between a disc of `radius` at `centre` and this shape (negative when they overlap).
    pub fn gap_to_disc(&self, centre: Vec2, radius: f32) -> f32 {
        self.signed_distance(centre) - radius
    }

    /// Whether the two shapes overlap (touching counts as overlapping).
    pub fn overlaps(&self, other: &Placed) -> bool {
        match (self.shape, other.shape) {
            (Shape::Disc { radius }, _) => other.gap_to_disc(self.position, radius) <= 0.0,
            (_, Shape::Disc { radius }) => self.gap_to_disc(other.position, radius) <= 0.0,
            (Shape::Rect { half: a }, Shape::Rect { half: b }) => rects_overlap(self, a, other, b),
        }
    }
}

/// Ray against a disc centred at the origin; `o` is the ray origin relative to the centre.
fn ray_disc(o: Vec2, dir: Vec2, radius: f32) -> Option<f32> {
    let c = o.length_squared() - radius * radius;
    if c <= 0.0 {
        return Some(0.0);
    }
    let b = o.dot(dir);
    if b >= 0.0 {
        return None;
    }
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    Some(-b - disc.sqrt())
}

/// Ray against an axis-aligned rectangle centred at the origin (slab method).
fn ray_rect(o: Vec2, dir: Vec2, half: Vec2) -> Option<f32> {
    let mut t_min = 0.0f32;
    let mut t_max = f32::INFINITY;
    for (oi, di, hi) in [(o.x, dir.x, half.x), (o.y, dir.y, half.y)] {
        if di.abs() < 1e-12 {
            if oi.abs() > hi {
                return None;
            }
        } else {
            let inv = 1.0 / di;
            let (mut t1, mut t2) = ((-hi - oi) * inv, (hi - oi) * inv);
            if t1 > t2 {
                std::mem::swap(&mut t1, &mut t2);
            }
            t_min = t_min.max(t1);
            t_max = t_max.min(t2);
            if t_min > t_max {
                return None;
            }
        }
    }
    Some(t_min)
}

/// Separating-axis test for two oriented rectangles.
fn rects_overlap(a: &Placed, ha: Vec2, b: &Placed, hb: Vec2) -> bool {
    let axes = [a.rot, a.rot.perp(), b.rot, b.rot.perp()];
    let (ax, ay) = (axes[0], axes[1]);
    let (bx, by) = (axes[2], axes[3]);
    let d = b.position - a.position;
    axes.iter().all(|axis| {
        let ra = ha.x * ax.dot(*axis).abs() + ha.y * ay.dot(*axis).abs();
        let rb = hb.x * bx.dot(*axis).abs() + hb.y * by.dot(*axis).abs();
        d.dot(*axis).abs() <= ra + rb
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_hits_disc_at_its_near_edge() {
        let disc = Placed::new(Shape::Disc { radius: 0.1 }, Vec2::new(1.0, 0.0), 0.0);
        let t = disc.ray_hit(Vec2::ZERO, Vec2::X, 2.0).unwrap_or(f32::NAN);
        assert!((t - 0.9).abs() < 1e-6);
        assert_eq!(disc.ray_hit(Vec2::ZERO, -Vec2::X, 2.0), None);
        assert_eq!(disc.ray_hit(Vec2::ZERO, Vec2::X, 0.5), None);
    }

    #[test]
    fn ray_hits_rotated_rect_at_its_corner_distance() {
        // A 0.2 x 0.2 square turned by 45 degrees presents its corner at 1 - 0.1 * sqrt(2).
        let rect = Placed::new(
            Shape::Rect {
                half: Vec2::splat(0.1),
            },
            Vec2::new(1.0, 0.0),
            std::f32::consts::FRAC_PI_4,
        );
        let t = rect.ray_hit(Vec2::ZERO, Vec2::X, 2.0).unwrap_or(f32::NAN);
        assert!((t - (1.0 - 0.1 * 2f32.sqrt())).abs() < 1e-5);
    }

    #[test]
    fn disc_and_rect_gap_is_edge_to_edge() {
        let wall = Placed::new(
            Shape::Rect {
                half: Vec2::new(0.05, 1.0),
            },
            Vec2::new(1.0, 0.0),
            0.0,
        );
        assert!((wall.gap_to_disc(Vec2::new(0.9, 0.0), 0.035) - 0.015).abs() < 1e-6);
    }

    #[test]
    fn rotated_rects_overlap_only_when_separating_axes_fail() {
        let a = Placed::new(
            Shape::Rect {
                half: Vec2::splat(0.05),
            },
            Vec2::ZERO,
            0.0,
        );
        let near = Placed::new(
            Shape::Rect {
                half: Vec2::splat(0.05),
            },
            Vec2::new(0.12, 0.0),
            std::f32::consts::FRAC_PI_4,
        );
        let far = Placed::new(
            Shape::Rect {
                half: Vec2::splat(0.05),
            },
            Vec2::new(0.13, 0.0),
            std::f32::consts::FRAC_PI_4,
        );
        assert!(near.overlaps(&a));
        assert!(!far.overlaps(&a));
    }

    #[test]
    fn wrap_angle_stays_in_half_open_turn() {
        assert!((wrap_angle(3.0 * std::f32::consts::PI) - std::f32::consts::PI).abs() < 1e-5);
        assert!((wrap_angle(-0.5) + 0.5).abs() < 1e-6);
    }
}
