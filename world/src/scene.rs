//! The bodies as the sensors see them after the last physics step: shapes, heights and a grid over them.
//!
//! Rebuilt once per tick after physics (robots first, so a robot's scene index is its robot index). Sensors
//! gather the few bodies near a robot with one grid query and test their rays against those shapes only.

use crate::entities::{Obstacle, Robot, Target, TargetState};
use crate::geometry::{Aabb, Placed, Shape, Vec2};
use crate::spatial::Grid;

/// Side of a scene grid cell in metres: an e-puck's proximity query (robot plus 5 cm) touches at most four cells,
/// a foot-bot's (robot plus 10 cm) at most nine.
pub const SCENE_CELL: f32 = 0.25;

/// What a scene body is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyRef {
    /// A robot, by robot index.
    Robot(u32),
    /// An obstacle, by obstacle index.
    Obstacle(u32),
    /// A target lying in the arena, by target index.
    Target(u32),
}

/// The sensed bodies of one tick.
#[derive(Debug, Clone)]
pub struct Scene {
    /// What each body is.
    pub refs: Vec<BodyRef>,
    /// Each body's outline at its pose.
    pub shapes: Vec<Placed>,
    /// Each body's height in metres.
    pub heights: Vec<f32>,
    aabbs: Vec<Aabb>,
    grid: Grid,
}

impl Scene {
    /// An empty scene over the arena rectangle `min..max`.
    pub fn new(min: Vec2, max: Vec2) -> Self {
        Self {
            refs: Vec::new(),
            shapes: Vec::new(),
            heights: Vec::new(),
            aabbs: Vec::new(),
            grid: Grid::new(min, max, SCENE_CELL),
        }
    }

    /// Refills the scene from the entity sets (targets only while they lie in the arena).
    pub fn rebuild(&mut self, robots: &[Robot], obstacles: &[Obstacle], targets: &[Target]) {
        self.refs.clear();
        self.shapes.clear();
        self.heights.clear();
        for (i, r) in robots.iter().enumerate() {
            self.refs.push(BodyRef::Robot(i as u32));
            self.shapes.push(Placed::new(
                Shape::Disc {
                    radius: r.body.radius,
                },
                r.position,
                r.heading,
            ));
            self.heights.push(r.body.height);
        }
        for (i, o) in obstacles.iter().enumerate() {
            self.refs.push(BodyRef::Obstacle(i as u32));
            self.shapes.push(o.placed);
            self.heights.push(o.height);
        }
        for (i, t) in targets
            .iter()
            .enumerate()
            .filter(|(_, t)| t.state == TargetState::InArena)
        {
            self.refs.push(BodyRef::Target(i as u32));
            self.shapes.push(t.placed);
            self.heights.push(t.height);
        }
        self.aabbs.clear();
        self.aabbs.extend(self.shapes.iter().map(Placed::aabb));
        // A removed body keeps its index (robot index = scene index) but is in no grid cell, so nothing finds it.
        for (aabb, _) in self.aabbs.iter_mut().zip(robots).filter(|(_, r)| r.removed) {
            *aabb = Aabb::NOWHERE;
        }
        self.grid.rebuild(&self.aabbs);
    }

    /// Appends to `out` every body whose cell touches `aabb` (possibly repeated).
    pub fn gather(&self, aabb: &Aabb, out: &mut Vec<u32>) {
        out.clear();
        self.grid.query(aabb, |i| out.push(i));
    }

    /// Fills `out` with the bodies other than `me` whose outline comes within `reach` of `centre` (possibly
    /// repeated; a ray of length `reach` from `centre` can meet only these).
    pub fn nearby(&self, centre: Vec2, reach: f32, me: u32, out: &mut Vec<u32>) {
        self.gather(&Aabb::around(centre, reach), out);
        out.retain(|&i| i != me && self.shapes[i as usize].signed_distance(centre) <= reach);
    }

    /// Distance along the ray from `origin` in direction `dir` (a unit vector) to the first of `bodies` it meets
    /// within `range`, or infinity.
    pub fn nearest_hit(&self, bodies: &[u32], origin: Vec2, dir: Vec2, range: f32) -> f32 {
        bodies
            .iter()
            .filter_map(|&b| self.shapes[b as usize].ray_hit(origin, dir, range))
            .fold(f32::INFINITY, f32::min)
    }

    /// Whether a sight line from `from` at height `z_from` to `to` at height `z_to` is blocked by a body other
    /// than `skip_a` and `skip_b`, that is, whether a body is crossed where the line runs below the body's top.
    /// `min_height` ignores bodies lower than it.
    pub fn blocked(
        &self,
        from: Vec2,
        z_from: f32,
        to: Vec2,
        z_to: f32,
        skip: [Option<BodyRef>; 2],
        min_height: f32,
    ) -> bool {
        let d = to - from;
        let len = d.length();
        if len <= f32::EPSILON {
            return false;
        }
        let dir = d / len;
        let mut hit = false;
        self.grid.query_segment(from, to, |i| {
            if hit {
                return;
            }
            let i = i as usize;
            let body = self.refs[i];
            if skip.contains(&Some(body)) || self.heights[i] < min_height {
                return;
            }
            if let Some(t) = self.shapes[i].ray_hit(from, dir, len) {
                let z = z_from + (z_to - z_from) * t / len;
                if z < self.heights[i] {
                    hit = true;
                }
            }
        });
        hit
    }
}
