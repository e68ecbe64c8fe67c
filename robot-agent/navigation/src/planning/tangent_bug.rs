//! TangentBug for a disc robot with a ring of range rays, and the bounded potential-field correction of
//! cooperative transport. The local planner of paper A (A.4, Multi Tangent Bug: each robot to its own task) and
//! of paper B (B.4: TangentBug proposes the way, the field keeps the body clear).
//!
//! Motion to the goal: straight at it while the way is clear; otherwise towards the discontinuity of the scan
//! (an end of a visible obstacle boundary, moved sideways by the clearance) that minimises `d(x, n) + d(n, goal)`.
//! The side chosen sticks unless the other side's best point is better by `hysteresis`, so that two nearly equal
//! ends of an obstacle do not make the robot dither. When the heuristic has not improved for `patience` steps the
//! robot follows the boundary on that side, remembering `d_followed`, the least distance to the goal of any
//! boundary point it has sensed while following, and goes back to the goal as soon as some point it can reach in
//! the scan (along a ray, up to the clearance before its hit) is closer to the goal than that (`d_reach <
//! d_followed`, the standard leave rule). The Bug2-like rule of exploration's text (leave once the robot is closer
//! to the goal than where following began) is the alternative [`LeaveRule::Closer`].

use crate::V2;

/// A scan of the ring: rays `k = 0..n` at `heading + 2 pi k / n`, distances from the robot's centre to what they
/// hit, infinity for nothing within `range`.
#[derive(Debug, Clone, Copy)]
pub struct Scan<'a> {
    /// The robot's centre.
    pub position: V2,
    /// Its heading (rad).
    pub heading: f32,
    /// The readings.
    pub ranges: &'a [f32],
    /// The rays' reach (m).
    pub range: f32,
}

impl Scan<'_> {
    fn direction(&self, k: usize) -> V2 {
        V2::from_angle(self.heading + std::f32::consts::TAU * k as f32 / self.ranges.len() as f32)
    }

    fn reading(&self, k: usize) -> f32 {
        let r = self.ranges[k];
        if r.is_finite() && r <= self.range {
            r
        } else {
            f32::INFINITY
        }
    }

    fn hits(&self) -> impl Iterator<Item = (usize, V2)> + '_ {
        (0..self.ranges.len())
            .filter(|&k| self.reading(k).is_finite())
            .map(|k| (k, self.position + self.direction(k) * self.reading(k)))
    }

    /// Whether every hit keeps `clearance` from the segment from the robot to `to`.
    fn clear(&self, to: V2, clearance: f32) -> bool {
        self.hits()
            .all(|(_, h)| super::map::segment_distance(self.position, to, h) >= clearance)
    }

    /// The nearest hit: its ray and point.
    fn nearest(&self) -> Option<(usize, V2)> {
        self.hits().min_by(|a, b| {
            let (da, db) = (
                (a.1 - self.position).length(),
                (b.1 - self.position).length(),
            );
            da.total_cmp(&db)
        })
    }
}

/// TangentBug's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BugParams {
    /// Distance the robot's centre keeps from every hit: its radius plus a margin (m).
    pub clearance: f32,
    /// Two neighbouring readings further apart than this mark a discontinuity (m).
    pub jump: f32,
    /// Steps without a better heuristic before boundary following.
    pub patience: u32,
    /// Boundary following holds the nearest hit at this many clearances.
    pub standoff: f32,
    /// The other side's discontinuity must be this much better (m of heuristic) to switch sides.
    pub hysteresis: f32,
    /// When boundary following ends.
    pub leave: LeaveRule,
}

/// When a robot stops following a boundary and heads for the goal again.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LeaveRule {
    /// TangentBug's: some point it can reach in the scan is closer to the goal than any boundary point it
    /// sensed while following (`d_reach < d_followed`).
    Reach,
    /// Bug2-like: the robot is closer to the goal than where following began.
    Closer,
}

impl Default for BugParams {
    fn default() -> Self {
        BugParams {
            clearance: 0.2,
            jump: 0.3,
            patience: 10,
            standoff: 1.3,
            hysteresis: 0.2,
            leave: LeaveRule::Reach,
        }
    }
}

/// Which way round an obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Counter-clockwise round it, seen from the goal direction: the robot turns left.
    Left,
    /// Clockwise: the robot turns right.
    Right,
}

/// What the robot is doing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mode {
    /// Motion to the goal.
    ToGoal,
    /// Following a boundary.
    Following {
        /// The side it goes round.
        side: Side,
        /// The least distance to the goal of a boundary point sensed while following.
        d_followed: f32,
        /// The robot's distance to the goal when following began.
        began: f32,
    },
}

/// One robot's TangentBug.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bug {
    mode: Mode,
    best: f32,
    stalls: u32,
    side: Option<Side>,
}

impl Default for Bug {
    fn default() -> Self {
        Bug::new()
    }
}

impl Bug {
    /// A bug in motion to the goal.
    pub fn new() -> Bug {
        Bug {
            mode: Mode::ToGoal,
            best: f32::INFINITY,
            stalls: 0,
            side: None,
        }
    }

    /// What it is doing.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The unit direction to move in now, towards `goal` (zero at the goal).
    pub fn step(&mut self, params: &BugParams, scan: &Scan<'_>, goal: V2) -> V2 {
        let x = scan.position;
        if (goal - x).length() < 1e-3 {
            return V2::ZERO;
        }
        if let Mode::Following {
            side,
            d_followed,
            began,
        } = self.mode
        {
            let d_followed = d_followed.min(boundary_distance(scan, goal));
            let leave = match params.leave {
                LeaveRule::Reach => reach(params, scan, goal) < d_followed - 1e-3,
                LeaveRule::Closer => (goal - x).length() < began - 1e-3,
            };
            if !leave && let Some(direction) = follow(params, scan, side) {
                self.mode = Mode::Following {
                    side,
                    d_followed,
                    began,
                };
                return direction;
            }
            self.mode = Mode::ToGoal;
            self.best = f32::INFINITY;
            self.stalls = 0;
            self.side = None;
        }
        self.motion_to_goal(params, scan, goal)
    }

    fn motion_to_goal(&mut self, params: &BugParams, scan: &Scan<'_>, goal: V2) -> V2 {
        let x = scan.position;
        let to_goal = goal - x;
        let distance = to_goal.length();
        let ahead = x + to_goal * (distance.min(scan.range) / distance);
        if scan.clear(ahead, params.clearance) {
            self.best = self.best.min(distance);
            self.stalls = 0;
            return to_goal * (1.0 / distance);
        }
        let Some((n, side)) = best_discontinuity(params, scan, goal, self.side) else {
            // Boxed in on every side the scan shows: go round whatever is nearest.
            return self.start_following(params, scan, goal, Side::Left);
        };
        self.side = Some(side);
        let heuristic = (n - x).length() + (goal - n).length();
        if heuristic < self.best - 1e-3 {
            self.best = heuristic;
            self.stalls = 0;
        } else {
            self.stalls += 1;
            if self.stalls > params.patience {
                return self.start_following(params, scan, goal, side);
            }
        }
        let d = n - x;
        d * (1.0 / d.length())
    }

    fn start_following(&mut self, params: &BugParams, scan: &Scan<'_>, goal: V2, side: Side) -> V2 {
        self.mode = Mode::Following {
            side,
            d_followed: boundary_distance(scan, goal),
            began: (goal - scan.position).length(),
        };
        follow(params, scan, side).unwrap_or(V2::ZERO)
    }
}

/// The least distance to the goal of a sensed boundary point.
fn boundary_distance(scan: &Scan<'_>, goal: V2) -> f32 {
    scan.hits()
        .map(|(_, h)| (h - goal).length())
        .fold(f32::INFINITY, f32::min)
}

/// The discontinuity point of least heuristic that the robot can head for, and the side it lies on; the side
/// `sticky` keeps its point unless the other side's is better by the hysteresis.
fn best_discontinuity(
    params: &BugParams,
    scan: &Scan<'_>,
    goal: V2,
    sticky: Option<Side>,
) -> Option<(V2, Side)> {
    let n = scan.ranges.len();
    let x = scan.position;
    let goal_angle = (goal - x).angle();
    // The best point on each side: [Left, Right].
    let mut best: [Option<(f32, V2)>; 2] = [None, None];
    for k in 0..n {
        let next = (k + 1) % n;
        let (a, b) = (
            scan.reading(k).min(scan.range),
            scan.reading(next).min(scan.range),
        );
        if (a - b).abs() <= params.jump {
            continue;
        }
        // The nearer ray ends at the boundary; the point is moved towards the farther ray by the clearance.
        let (near, far, d) = if a < b { (k, next, a) } else { (next, k, b) };
        let near_angle = scan.direction(near).angle();
        let toward_far = crate::vec2::wrap(scan.direction(far).angle() - near_angle).signum();
        let offset = (params.clearance / d.max(params.clearance)).min(1.0).asin();
        let angle = near_angle + toward_far * offset;
        let point = x + V2::from_angle(angle) * d;
        // The offset clears the edge's own hit; a robot already close to the obstacle may pass its curved side a
        // little nearer, so only a way through the clearance's inner half is refused.
        if !scan.clear(point, params.clearance * 0.5) {
            continue;
        }
        let h = (point - x).length() + (goal - point).length();
        let slot = &mut best[usize::from(crate::vec2::wrap(angle - goal_angle) < 0.0)];
        if slot.is_none_or(|(bh, _)| h < bh) {
            *slot = Some((h, point));
        }
    }
    let pick =
        |i: usize| best[i].map(|(h, p)| (h, p, if i == 0 { Side::Left } else { Side::Right }));
    let (left, right) = (pick(0), pick(1));
    let bonus = |side: Side| {
        if sticky == Some(side) {
            params.hysteresis
        } else {
            0.0
        }
    };
    let chosen = match (left, right) {
        (Some(l), Some(r)) => {
            if l.0 - bonus(Side::Left) <= r.0 - bonus(Side::Right) {
                l
            } else {
                r
            }
        }
        (one, other) => one.or(other)?,
    };
    Some((chosen.1, chosen.2))
}

/// The least distance to the goal of the points the robot can reach in the scan: the goal itself when it is in
/// sight and in range, else along each ray up to the clearance before its hit.
fn reach(params: &BugParams, scan: &Scan<'_>, goal: V2) -> f32 {
    let x = scan.position;
    if (goal - x).length() <= scan.range && scan.clear(goal, params.clearance) {
        return 0.0;
    }
    (0..scan.ranges.len())
        .map(|k| {
            let free = (scan.reading(k).min(scan.range) - params.clearance).max(0.0);
            (x + scan.direction(k) * free - goal).length()
        })
        .fold(f32::INFINITY, f32::min)
}

/// The direction that keeps the nearest hit on the given side at the standoff distance; `None` with nothing in
/// sight.
fn follow(params: &BugParams, scan: &Scan<'_>, side: Side) -> Option<V2> {
    let (_, hit) = scan.nearest()?;
    let away = scan.position - hit;
    let distance = away.length();
    let away = away * (1.0 / distance.max(1e-6));
    let tangent = match side {
        Side::Left => away.rotated(-std::f32::consts::FRAC_PI_2),
        Side::Right => away.rotated(std::f32::consts::FRAC_PI_2),
    };
    let standoff = params.clearance * params.standoff;
    let d = tangent + away * ((standoff - distance) / params.clearance);
    Some(d * (1.0 / d.length()))
}

/// The bounded potential field of B.4 that corrects a direction away from the nearest hit: full strength
/// `alpha` at contact falling to `beta` at `range1` and to 0 at `range2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correction {
    /// Inner threshold (m, from the robot's centre).
    pub range1: f32,
    /// Outer threshold (m).
    pub range2: f32,
    /// Gain inside `range1`.
    pub alpha: f32,
    /// Gain between the thresholds.
    pub beta: f32,
    /// Weight W of the proposed direction.
    pub weight: f32,
}

impl Default for Correction {
    fn default() -> Self {
        Correction {
            range1: 0.3,
            range2: 0.6,
            alpha: 1.5,
            beta: 0.5,
            weight: 1.0,
        }
    }
}

impl Correction {
    /// `W unit(direction) + value(d) unit(robot - nearest hit)`, d the nearest reading (eq. 7-10 with the
    /// bounded law).
    pub fn apply(&self, direction: V2, scan: &Scan<'_>) -> V2 {
        let length = direction.length();
        let proposed = if length > 0.0 {
            direction * (self.weight / length)
        } else {
            V2::ZERO
        };
        let Some((_, hit)) = scan.nearest() else {
            return proposed;
        };
        let away = scan.position - hit;
        let d = away.length();
        let value = if d < self.range1 {
            self.alpha * (self.range1 - d) / self.range1
        } else if d < self.range2 {
            self.beta * (self.range2 - d) / (self.range2 - self.range1)
        } else {
            0.0
        };
        proposed + away * (value / d.max(1e-6))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::map::Map;

    const RAYS: usize = 24;
    const RANGE: f32 = 1.0;
    const STEP: f32 = 0.05;
    const BODY: f32 = 0.1;

    /// Drives a holonomic robot with TangentBug (`params`, and the correction when given) from `start` until it
    /// is within 0.1 m of `goal` or `steps` have passed; returns the positions visited.
    fn drive(
        params: &BugParams,
        map: &Map,
        start: V2,
        goal: V2,
        steps: usize,
        correction: Option<Correction>,
    ) -> Vec<V2> {
        let mut bug = Bug::new();
        let mut at = start;
        let mut visited = vec![at];
        let mut ranges = [0.0f32; RAYS];
        for _ in 0..steps {
            if (goal - at).length() < 0.1 {
                break;
            }
            for (k, r) in ranges.iter_mut().enumerate() {
                *r = map.ray(
                    at,
                    V2::from_angle(std::f32::consts::TAU * k as f32 / RAYS as f32),
                    RANGE,
                );
            }
            let scan = Scan {
                position: at,
                heading: 0.0,
                ranges: &ranges,
                range: RANGE,
            };
            let mut d = bug.step(params, &scan, goal);
            if let Some(c) = correction {
                d = c.apply(d, &scan);
            }
            let l = d.length();
            if l > 0.0 {
                at = at + d * (STEP.min((goal - at).length()) / l);
            }
            visited.push(at);
        }
        visited
    }

    /// The drive ended at the goal and the body never touched a disc.
    fn assert_arrived_untouched(map: &Map, visited: &[V2], goal: V2) {
        let last = *visited.last().unwrap();
        assert!((last - goal).length() < 0.1, "stuck at {last:?}");
        let closest = closest_to_an_edge(map, visited);
        assert!(
            closest > BODY,
            "the body's edge came within {} m",
            closest - BODY
        );
    }

    fn closest_to_an_edge(map: &Map, visited: &[V2]) -> f32 {
        visited
            .iter()
            .flat_map(|p| {
                map.discs
                    .iter()
                    .map(move |d| (*p - d.centre).length() - d.radius)
            })
            .fold(f32::INFINITY, f32::min)
    }

    #[test]
    fn in_the_open_it_drives_straight_to_the_goal() {
        let map = Map::square_with(&[(8.0, 2.0, 0.5)]);
        let visited = drive(
            &BugParams::default(),
            &map,
            V2::new(1.0, 1.0),
            V2::new(5.0, 4.0),
            500,
            None,
        );
        let last = *visited.last().unwrap();
        assert!((last - V2::new(5.0, 4.0)).length() < 0.1);
        assert!(visited.len() <= 102, "{} steps for 5 m", visited.len());
    }

    #[test]
    fn it_goes_round_a_wall_without_touching_it() {
        let wall: Vec<(f32, f32, f32)> =
            (0..7).map(|k| (2.0 + 0.6 * k as f32, 5.0, 0.35)).collect();
        let map = Map::square_with(&wall);
        let goal = V2::new(4.0, 8.0);
        let visited = drive(
            &BugParams::default(),
            &map,
            V2::new(3.5, 2.0),
            goal,
            2000,
            None,
        );
        assert_arrived_untouched(&map, &visited, goal);
        // The Bug2-like leave rule gets round too.
        let closer = BugParams {
            leave: LeaveRule::Closer,
            ..BugParams::default()
        };
        let visited = drive(&closer, &map, V2::new(3.5, 2.0), goal, 2000, None);
        assert_arrived_untouched(&map, &visited, goal);
    }

    #[test]
    fn it_leaves_a_cup_that_traps_a_potential_field() {
        // A cup of discs round the start, open at the bottom, the goal beyond its closed top.
        let cup: Vec<(f32, f32, f32)> = (0..=10)
            .map(|k| {
                let a = std::f32::consts::PI * k as f32 / 10.0 - 0.3;
                let a = a.min(std::f32::consts::PI + 0.3);
                (5.0 + 1.3 * a.cos(), 4.0 + 1.3 * a.sin(), 0.3)
            })
            .collect();
        let map = Map::square_with(&cup);
        let goal = V2::new(5.0, 8.0);
        let visited = drive(
            &BugParams::default(),
            &map,
            V2::new(5.0, 4.0),
            goal,
            4000,
            Some(Correction::default()),
        );
        // Measured: 139 steps of 5 cm, 64 of them following the cup's inside and out round its rim.
        assert_arrived_untouched(&map, &visited, goal);
    }

    #[test]
    fn the_correction_pushes_away_from_a_near_hit_and_not_from_a_far_one() {
        let c = Correction::default();
        // A hit 0.15 m ahead (+x).
        let ranges = [0.15, f32::INFINITY, f32::INFINITY, f32::INFINITY];
        let scan = Scan {
            position: V2::ZERO,
            heading: 0.0,
            ranges: &ranges,
            range: 1.0,
        };
        // Heading straight at it: alpha (0.3 - 0.15) / 0.3 = 0.75 back against W = 1.
        let d = c.apply(V2::new(1.0, 0.0), &scan);
        assert!((d.x - 0.25).abs() < 1e-5 && d.y.abs() < 1e-6, "{d:?}");
        let far = [0.8, f32::INFINITY, f32::INFINITY, f32::INFINITY];
        let scan = Scan {
            ranges: &far,
            ..scan
        };
        assert_eq!(c.apply(V2::new(0.0, 2.0), &scan), V2::new(0.0, 1.0));
    }
}
