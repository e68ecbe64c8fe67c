//! What a path planner plans in: the box the robot must stay in and disc obstacles, grown by the robot's
//! radius so that the robot can be planned for as a point (its configuration space).

use std::borrow::Cow;

use crate::V2;
use crate::apf::Disc;

/// An axis-aligned rectangle: the box constraint of a planner (paper D's `[X_min, X_max] x [Y_min, Y_max]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Lower-left corner.
    pub min: V2,
    /// Upper-right corner.
    pub max: V2,
}

impl Bounds {
    /// Whether `p` lies in the box (edges included).
    pub fn contains(&self, p: V2) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }

    /// `p` with each coordinate clamped into the box (paper D, step 7).
    pub fn clamp(&self, p: V2) -> V2 {
        V2::new(
            p.x.clamp(self.min.x, self.max.x),
            p.y.clamp(self.min.y, self.max.y),
        )
    }

    /// The box shrunk by `by` metres on every side (where the centre of a disc of radius `by` may be).
    pub fn inset(&self, by: f32) -> Bounds {
        Bounds {
            min: self.min + V2::new(by, by),
            max: self.max - V2::new(by, by),
        }
    }

    /// Length of the box's diagonal.
    pub fn diagonal(&self) -> f32 {
        (self.max - self.min).length()
    }

    /// Whether both corners are finite and `min` is below and left of `max`.
    pub fn is_valid(&self) -> bool {
        self.min.is_finite()
            && self.max.is_finite()
            && self.min.x < self.max.x
            && self.min.y < self.max.y
    }
}

/// Why a planner cannot plan between a start and a goal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum EndpointError {
    /// The start or the goal is not finite or lies outside the box.
    #[error("the {0} is outside the planning box")]
    OutOfBounds(&'static str),
    /// The goal lies inside an obstacle.
    #[error("the goal lies inside an obstacle")]
    GoalBlocked,
}

/// Disc obstacles inside a box, as a point robot sees them: every disc already grown by the robot's radius and
/// safety margin ([`Map::grown`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Map {
    /// Where the robot may be.
    pub bounds: Bounds,
    /// The obstacles.
    pub discs: Vec<Disc>,
}

/// Distance from `c` to the segment `a`-`b`.
pub fn segment_distance(a: V2, b: V2, c: V2) -> f32 {
    let ab = b - a;
    let len2 = ab.dot(ab);
    let t = if len2 > 0.0 {
        ((c - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - c).length()
}

/// Whether the segment `a`-`b` passes through the inside of `disc` (touching its edge is allowed).
pub fn segment_hits(a: V2, b: V2, disc: &Disc) -> bool {
    let r = disc.radius;
    let c = disc.centre;
    // The bounding boxes first: most discs of a map are far from any one segment.
    if c.x + r < a.x.min(b.x)
        || c.x - r > a.x.max(b.x)
        || c.y + r < a.y.min(b.y)
        || c.y - r > a.y.max(b.y)
    {
        return false;
    }
    segment_distance(a, b, c) < r
}

impl Map {
    /// The same map with every disc's radius replaced by `radius(disc)`.
    fn with_radii(&self, radius: impl Fn(&Disc) -> f32) -> Map {
        Map {
            bounds: self.bounds,
            discs: self
                .discs
                .iter()
                .map(|d| Disc {
                    centre: d.centre,
                    radius: radius(d),
                })
                .collect(),
        }
    }

    /// The map a disc robot of `radius` moves in as a point, among `discs` in `bounds`: the box shrunk by the
    /// radius (the centre keeps that far from the edges) and every disc grown by the radius plus `margin`.
    pub fn for_body(bounds: Bounds, discs: &[Disc], radius: f32, margin: f32) -> Map {
        Map {
            bounds: bounds.inset(radius),
            discs: discs.to_vec(),
        }
        .grown(radius + margin)
    }

    /// The same map with every disc's radius grown by `by` metres.
    pub fn grown(&self, by: f32) -> Map {
        self.with_radii(|d| d.radius + by)
    }

    /// Whether `start` and `goal` are finite points of the box and the goal lies outside every obstacle.
    pub fn check_endpoints(&self, start: V2, goal: V2) -> Result<(), EndpointError> {
        if !(start.is_finite() && self.bounds.contains(start)) {
            return Err(EndpointError::OutOfBounds("start"));
        }
        if !(goal.is_finite() && self.bounds.contains(goal)) {
            return Err(EndpointError::OutOfBounds("goal"));
        }
        if self.inside_obstacle(goal) {
            return Err(EndpointError::GoalBlocked);
        }
        Ok(())
    }

    /// Whether the point `p` lies strictly inside an obstacle.
    pub fn inside_obstacle(&self, p: V2) -> bool {
        self.discs
            .iter()
            .any(|d| (p - d.centre).length() < d.radius)
    }

    /// Whether `p` is in the box and outside every obstacle.
    pub fn free(&self, p: V2) -> bool {
        self.bounds.contains(p) && !self.inside_obstacle(p)
    }

    /// Whether the segment `a`-`b` stays in the box and clear of every obstacle.
    pub fn segment_free(&self, a: V2, b: V2) -> bool {
        self.bounds.contains(a)
            && self.bounds.contains(b)
            && !self.discs.iter().any(|d| segment_hits(a, b, d))
    }

    /// The map as a robot at `start` may use it: an obstacle that holds `start` (a robot inside its safety
    /// margin) is shrunk to leave `start` on its edge, so that the robot can move out but not further in.
    pub fn opened_at(&self, start: V2) -> Cow<'_, Map> {
        if !self.inside_obstacle(start) {
            return Cow::Borrowed(self);
        }
        Cow::Owned(self.with_radii(|d| d.radius.min((start - d.centre).length())))
    }

    /// Distance from `origin` along the unit vector `direction` to the first disc it meets within `range`, or
    /// infinity: what an ideal range-finder ray reads (the box's edges are not seen).
    pub fn ray(&self, origin: V2, direction: V2, range: f32) -> f32 {
        self.discs
            .iter()
            .filter_map(|d| {
                let oc = origin - d.centre;
                let b = oc.dot(direction);
                let c = oc.dot(oc) - d.radius * d.radius;
                let h = b * b - c;
                let t = -b - h.max(0.0).sqrt();
                (h >= 0.0 && t >= 0.0 && t <= range).then_some(t)
            })
            .fold(f32::INFINITY, f32::min)
    }

    /// Index of the first segment of `path` (segment `i` joins points `i` and `i + 1`) that is not free, if any.
    pub fn first_blocked_segment(&self, path: &[V2]) -> Option<usize> {
        path.windows(2).position(|w| !self.segment_free(w[0], w[1]))
    }
}

#[cfg(test)]
impl Map {
    /// A test map: the 10 m x 10 m box from the origin with discs `(x, y, radius)`.
    pub(crate) fn square_with(discs: &[(f32, f32, f32)]) -> Map {
        Map::box_with(V2::ZERO, V2::new(10.0, 10.0), discs)
    }

    /// A test map: the box from `min` to `max` with discs `(x, y, radius)`.
    pub(crate) fn box_with(min: V2, max: V2, discs: &[(f32, f32, f32)]) -> Map {
        Map {
            bounds: Bounds { min, max },
            discs: discs
                .iter()
                .map(|&(x, y, radius)| Disc {
                    centre: V2::new(x, y),
                    radius,
                })
                .collect(),
        }
    }
}

/// Length of a polyline.
pub fn path_length(path: &[V2]) -> f32 {
    path.windows(2).map(|w| (w[1] - w[0]).length()).sum()
}

/// The shortest polyline through `path`'s own points, in their order, whose every segment is free on `map`: the
/// consecutive segments of `path` are kept wherever nothing shorter is free. Never longer than `path`, free wherever
/// `path` was. Quadratic in the points (a shortest path over the in-order visibility graph), so that a path that
/// overshoots and comes back is cut where a greedy "farthest visible point" pruning would follow the overshoot.
pub fn shortcut(path: &[V2], map: &Map) -> Vec<V2> {
    let n = path.len();
    if n < 3 {
        return path.to_vec();
    }
    let mut best = vec![f32::INFINITY; n];
    let mut via = vec![0usize; n];
    best[0] = 0.0;
    for j in 1..n {
        for i in 0..j {
            let through = best[i] + (path[j] - path[i]).length();
            // Consecutive points are always joined: the path itself is the fallback.
            if through < best[j] && (i + 1 == j || map.segment_free(path[i], path[j])) {
                best[j] = through;
                via[j] = i;
            }
        }
    }
    let mut out = vec![path[n - 1]];
    let mut at = n - 1;
    while at != 0 {
        at = via[at];
        out.push(path[at]);
    }
    out.reverse();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(side: f32) -> Bounds {
        Bounds {
            min: V2::ZERO,
            max: V2::new(side, side),
        }
    }

    fn one_disc() -> Map {
        Map {
            bounds: square(4.0),
            discs: vec![Disc {
                centre: V2::new(2.0, 2.0),
                radius: 0.5,
            }],
        }
    }

    #[test]
    fn a_segment_through_a_disc_is_blocked_and_one_past_it_is_free() {
        let map = one_disc();
        assert!(!map.segment_free(V2::new(0.5, 2.0), V2::new(3.5, 2.0)));
        assert!(map.segment_free(V2::new(0.5, 2.6), V2::new(3.5, 2.6)));
        // A segment ending before the disc is free even though its line would cross it.
        assert!(map.segment_free(V2::new(0.5, 2.0), V2::new(1.4, 2.0)));
        // Leaving the box is not free.
        assert!(!map.segment_free(V2::new(0.5, 2.0), V2::new(4.5, 2.0)));
    }

    #[test]
    fn segment_distance_of_a_hand_computed_case() {
        assert!(
            (segment_distance(V2::ZERO, V2::new(4.0, 0.0), V2::new(1.0, 3.0)) - 3.0).abs() < 1e-6
        );
        assert!(
            (segment_distance(V2::ZERO, V2::new(4.0, 0.0), V2::new(7.0, 4.0)) - 5.0).abs() < 1e-6
        );
        assert!((segment_distance(V2::ZERO, V2::ZERO, V2::new(3.0, 4.0)) - 5.0).abs() < 1e-6);
    }

    #[test]
    fn growing_a_map_grows_every_disc() {
        let map = one_disc().grown(0.25);
        assert_eq!(map.discs[0].radius, 0.75);
        assert!(map.inside_obstacle(V2::new(2.7, 2.0)));
        assert!(!one_disc().inside_obstacle(V2::new(2.7, 2.0)));
    }

    #[test]
    fn a_ray_reads_the_nearest_disc_within_range() {
        let map = one_disc();
        assert!((map.ray(V2::new(0.5, 2.0), V2::new(1.0, 0.0), 3.0) - 1.0).abs() < 1e-5);
        assert_eq!(
            map.ray(V2::new(0.5, 2.0), V2::new(1.0, 0.0), 0.9),
            f32::INFINITY
        );
        assert_eq!(
            map.ray(V2::new(0.5, 2.0), V2::new(-1.0, 0.0), 3.0),
            f32::INFINITY
        );
    }

    #[test]
    fn a_map_opened_at_a_point_inside_a_disc_lets_it_out_but_not_further_in() {
        let map = one_disc();
        let start = V2::new(2.0, 2.4);
        let opened = map.opened_at(start);
        assert!((opened.discs[0].radius - 0.4).abs() < 1e-6);
        assert!(opened.segment_free(start, V2::new(2.0, 3.5)));
        assert!(!opened.segment_free(start, V2::new(2.0, 2.3)));
        assert!(matches!(map.opened_at(V2::new(0.5, 0.5)), Cow::Borrowed(_)));
    }

    #[test]
    fn shortcut_cuts_an_overshoot_that_greedy_pruning_would_follow() {
        // From (0.5, 2) past the disc to an overshoot at (3.8, 3.8), back to the goal (3, 2.4): the goal is hidden
        // from the start, the overshoot is not, so greedy pruning went start -> overshoot -> goal.
        let map = one_disc();
        let path = [
            V2::new(0.5, 2.0),
            V2::new(1.5, 2.9),
            V2::new(2.6, 3.4),
            V2::new(3.8, 3.8),
            V2::new(3.0, 2.4),
        ];
        assert!(!map.segment_free(path[0], path[4]) && map.segment_free(path[0], path[3]));
        let short = shortcut(&path, &map);
        assert_eq!(short.last(), Some(&V2::new(3.0, 2.4)));
        assert!(!short.contains(&V2::new(3.8, 3.8)), "{short:?}");
        assert_eq!(map.first_blocked_segment(&short), None);
    }

    #[test]
    fn shortcut_drops_corners_that_see_past_each_other_only() {
        let map = one_disc();
        let zigzag = [
            V2::new(0.5, 0.5),
            V2::new(1.0, 0.7),
            V2::new(1.5, 0.5),
            V2::new(3.5, 0.5),
            V2::new(3.5, 3.5),
        ];
        let short = shortcut(&zigzag, &map);
        assert_eq!(
            short,
            vec![V2::new(0.5, 0.5), V2::new(3.5, 0.5), V2::new(3.5, 3.5)]
        );
        assert!(path_length(&short) <= path_length(&zigzag));
        assert_eq!(map.first_blocked_segment(&short), None);
        // Around the disc no corner can go: the direct line crosses it.
        let around = [V2::new(0.5, 2.0), V2::new(2.0, 3.0), V2::new(3.5, 2.0)];
        assert_eq!(shortcut(&around, &map), around.to_vec());
        assert_eq!(
            map.first_blocked_segment(&[V2::new(0.5, 2.0), V2::new(3.5, 2.0)]),
            Some(0)
        );
    }
}
