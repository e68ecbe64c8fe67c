//! Where the formation may go: the global planner's map, and the checks of the goal against it.
//!
//! The map holds every static (not movable) obstacle as a disc: a cylinder as itself, a box as its circumscribed
//! disc. A static box that lies wholly outside the arena inset by the formation's radius (a wall along the
//! arena's edge) is left out; the side of the arena it lies along is moved in to the box's inner edge instead, so
//! that the bounds keep the formation off it. The box being carried and other movable obstacles are not on the
//! map. The formation is planned for as its centre, a point: the map is [`Map::for_body`] of these discs and
//! bounds with the formation's radius.

use swarm_navigation::V2;
use swarm_navigation::apf::Disc;
use swarm_navigation::planning::{Bounds, Map};

use crate::arena::Arena;
use crate::geometry::{Shape, Vec2};
use crate::physics::Motion;

/// The planner's map for the formation, and what it was made from.
#[derive(Debug, Clone)]
pub(super) struct Area {
    /// The arena, its sides moved in past the walls along them.
    pub bounds: Bounds,
    /// The static obstacles as discs (not grown).
    pub discs: Vec<Disc>,
    /// For each disc, the index of its obstacle.
    owners: Vec<usize>,
    /// The discs grown and the bounds shrunk by the formation's radius.
    pub map: Map,
    /// The formation's radius.
    radius: f32,
}

fn v2(p: Vec2) -> V2 {
    V2::new(p.x, p.y)
}

impl Area {
    /// The map of `arena` for a formation of `radius`.
    pub fn new(arena: &Arena, radius: f32) -> Area {
        let inner = Bounds {
            min: v2(arena.min),
            max: v2(arena.max),
        }
        .inset(radius);
        let (mut lo, mut hi) = (v2(arena.min), v2(arena.max));
        let (mut discs, mut owners) = (Vec::new(), Vec::new());
        for (i, o) in arena.obstacles.iter().enumerate() {
            if o.motion != Motion::Fixed {
                continue;
            }
            let centre = v2(o.placed.position);
            let radius = match o.placed.shape {
                Shape::Disc { radius } => radius,
                Shape::Rect { half } => {
                    let b = o.placed.aabb();
                    let (below, above) = (b.max.y <= inner.min.y, b.min.y >= inner.max.y);
                    let (left, right) = (b.max.x <= inner.min.x, b.min.x >= inner.max.x);
                    if below || above || left || right {
                        if below {
                            lo.y = lo.y.max(b.max.y);
                        }
                        if above {
                            hi.y = hi.y.min(b.min.y);
                        }
                        if left {
                            lo.x = lo.x.max(b.max.x);
                        }
                        if right {
                            hi.x = hi.x.min(b.min.x);
                        }
                        continue;
                    }
                    half.length()
                }
            };
            discs.push(Disc { centre, radius });
            owners.push(i);
        }
        let bounds = Bounds { min: lo, max: hi };
        Area {
            map: Map::for_body(bounds, &discs, radius, 0.0),
            bounds,
            discs,
            owners,
            radius,
        }
    }

    /// Why the formation cannot stand with its centre at `goal`, if it cannot: it would overlap a static obstacle
    /// (its outline, or the disc the planner keeps clear of for a box; the one the goal lies deepest in is named),
    /// or leave the arena.
    pub fn goal_problem(&self, arena: &Arena, goal: V2) -> Option<String> {
        let r = self.radius;
        let at = format!("the goal ({}, {})", goal.x, goal.y);
        let p = Vec2::new(goal.x, goal.y);
        if let Some((o, _)) = arena
            .obstacles
            .iter()
            .filter(|o| o.motion == Motion::Fixed)
            .map(|o| (o, o.placed.signed_distance(p)))
            .filter(|(_, d)| *d < r)
            .min_by(|a, b| a.1.total_cmp(&b.1))
        {
            return Some(format!(
                "{at} is inside obstacle `{}` for the formation: a disc of radius {r} m there overlaps it",
                o.name
            ));
        }
        if let Some((disc, &owner, _)) = self
            .discs
            .iter()
            .zip(&self.owners)
            .map(|(d, owner)| (d, owner, (goal - d.centre).length() - d.radius))
            .filter(|(_, _, d)| *d < r)
            .min_by(|a, b| a.2.total_cmp(&b.2))
        {
            let name = arena.obstacles.get(owner).map_or("?", |o| o.name.as_str());
            return Some(format!(
                "{at} is inside obstacle `{name}` for the formation: the planner keeps the formation's centre \
                 {} m from its centre (its circumscribed disc of radius {} m plus the formation's radius {r} m)",
                disc.radius + r,
                disc.radius
            ));
        }
        if !self.map.bounds.contains(goal) {
            let (lo, hi) = (self.bounds.min, self.bounds.max);
            return Some(format!(
                "{at} is off the arena for the formation: a disc of radius {r} m there would leave ({}, {}) to \
                 ({}, {})",
                lo.x, lo.y, hi.x, hi.y
            ));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::WorldBuilder;
    use crate::devices::Devices;
    use crate::geometry::Placed;

    fn arena_with_walls() -> crate::World {
        let mut b = WorldBuilder::new(Vec2::splat(-0.1), Vec2::splat(5.1), 10, 1);
        let rect =
            |half: Vec2, x: f32, y: f32| Placed::new(Shape::Rect { half }, Vec2::new(x, y), 0.0);
        b.obstacle(
            "south",
            rect(Vec2::new(2.6, 0.05), 2.5, -0.05),
            0.5,
            Motion::Fixed,
        );
        b.obstacle(
            "west",
            rect(Vec2::new(0.05, 2.5), -0.05, 2.5),
            0.5,
            Motion::Fixed,
        );
        b.obstacle(
            "block",
            rect(Vec2::new(0.3, 0.4), 2.5, 2.5),
            0.5,
            Motion::Fixed,
        );
        b.obstacle(
            "post",
            Placed::new(Shape::Disc { radius: 0.1 }, Vec2::new(4.0, 4.0), 0.0),
            0.5,
            Motion::Fixed,
        );
        b.obstacle(
            "crate",
            rect(Vec2::new(0.2, 0.2), 1.0, 1.0),
            0.2,
            Motion::Movable { mass: 1.0 },
        );
        b.robot(
            "fb0",
            "c",
            Vec2::new(1.0, 4.0),
            0.0,
            Devices::PROXIMITY_ONLY,
        );
        b.build()
    }

    #[test]
    fn map_holds_static_obstacles_as_discs_and_walls_as_bounds() {
        let w = arena_with_walls();
        let area = Area::new(&w.arena, 0.3);
        assert_eq!(
            area.owners,
            vec![2, 3],
            "the walls and the movable crate are not discs"
        );
        assert!(
            (area.discs[0].radius - 0.5).abs() < 1e-6,
            "the block's circumscribed disc"
        );
        assert_eq!(area.discs[1].radius, 0.1);
        // The walls move the south and west sides in to their inner edges; the others stay.
        assert_eq!(area.bounds.min, V2::new(0.0, 0.0));
        assert_eq!(area.bounds.max, V2::new(5.1, 5.1));
        assert!((area.map.bounds.min.x - 0.3).abs() < 1e-6);
        assert!((area.map.discs[0].radius - 0.8).abs() < 1e-6);
    }

    #[test]
    fn goal_problems_name_the_obstacle_or_the_arena() {
        let w = arena_with_walls();
        let area = Area::new(&w.arena, 0.3);
        let problem = |x, y| area.goal_problem(&w.arena, V2::new(x, y));
        assert_eq!(problem(1.5, 1.5), None);
        assert_eq!(
            problem(2.5, 3.1).unwrap(),
            "the goal (2.5, 3.1) is inside obstacle `block` for the formation: a disc of radius 0.3 m there \
             overlaps it"
        );
        // Clear of the block's outline (0.35 m from its east side) but in its circumscribed disc.
        assert_eq!(
            problem(3.15, 2.5).unwrap(),
            "the goal (3.15, 2.5) is inside obstacle `block` for the formation: the planner keeps the formation's \
             centre 0.8 m from its centre (its circumscribed disc of radius 0.5 m plus the formation's radius 0.3 m)"
        );
        assert!(problem(4.2, 4.2).unwrap().contains("obstacle `post`"));
        // Near the south wall and the west wall, deeper in the west one.
        assert!(problem(0.1, 0.2).unwrap().contains("obstacle `west`"));
        assert!(problem(1.0, 0.2).unwrap().contains("obstacle `south`"));
        assert_eq!(
            problem(4.9, 1.0).unwrap(),
            "the goal (4.9, 1) is off the arena for the formation: a disc of radius 0.3 m there would leave (0, \
             0) to (5.1, 5.1)"
        );
        assert_eq!(problem(1.0, 1.0), None, "the crate is not an obstacle");
    }
}
