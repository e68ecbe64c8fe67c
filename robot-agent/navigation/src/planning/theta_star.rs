//! The reference optimum for a planner: Theta*, an any-angle A* on a grid of the map's free cell centres whose
//! edges may skip cells wherever the straight line is free (checked exactly against the discs, not the grid).
//! Its path is collision-free and at most a few per cent longer than the true shortest path (docs/planning.md
//! measures it against a case solved by hand).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::map::{EndpointError, Map, path_length};
use crate::V2;

/// Most grid cells a search may use (about 40 MB of search state).
pub const MAX_CELLS: usize = 4_000_000;

/// Why there is no reference path.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum SearchError {
    /// The start or the goal is not a place to plan between.
    #[error(transparent)]
    Endpoints(#[from] EndpointError),
    /// The resolution is not positive or the grid would exceed [`MAX_CELLS`].
    #[error("a grid of resolution {0} m over this box is too fine or not positive")]
    Resolution(f32),
    /// Obstacles separate the start from the goal.
    #[error("the goal cannot be reached from the start")]
    Unreachable,
}

struct Grid<'a> {
    map: &'a Map,
    cols: usize,
    rows: usize,
    resolution: f32,
    start: (usize, V2),
    goal: (usize, V2),
}

impl Grid<'_> {
    fn cell_of(&self, p: V2) -> usize {
        let c = (((p.x - self.map.bounds.min.x) / self.resolution) as usize).min(self.cols - 1);
        let r = (((p.y - self.map.bounds.min.y) / self.resolution) as usize).min(self.rows - 1);
        r * self.cols + c
    }

    /// Where node `i` stands: its cell centre, but the exact start and goal for their cells.
    fn point(&self, i: usize) -> V2 {
        if i == self.start.0 {
            return self.start.1;
        }
        if i == self.goal.0 {
            return self.goal.1;
        }
        let (r, c) = (i / self.cols, i % self.cols);
        self.map.bounds.min
            + V2::new(
                (c as f32 + 0.5) * self.resolution,
                (r as f32 + 0.5) * self.resolution,
            )
    }

    fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let (r, c) = ((i / self.cols) as isize, (i % self.cols) as isize);
        (-1isize..=1)
            .flat_map(move |dr| (-1isize..=1).map(move |dc| (r + dr, c + dc)))
            .filter(move |&(nr, nc)| {
                (nr, nc) != (r, c)
                    && nr >= 0
                    && nc >= 0
                    && (nr as usize) < self.rows
                    && (nc as usize) < self.cols
            })
            .map(|(nr, nc)| nr as usize * self.cols + nc as usize)
    }
}

/// The shortest any-angle path from `start` to `goal` on `map` that Theta* finds on a grid of `resolution`
/// metres, from `start` to `goal` exactly, on the map opened at the start ([`Map::opened_at`]).
pub fn shortest_path(
    start: V2,
    goal: V2,
    map: &Map,
    resolution: f32,
) -> Result<Vec<V2>, SearchError> {
    let map = &*map.opened_at(start);
    map.check_endpoints(start, goal)?;
    let size = map.bounds.max - map.bounds.min;
    let (cols, rows) = ((size.x / resolution).ceil(), (size.y / resolution).ceil());
    if !(resolution > 0.0 && cols * rows <= MAX_CELLS as f32) {
        return Err(SearchError::Resolution(resolution));
    }
    let mut grid = Grid {
        map,
        cols: (cols as usize).max(1),
        rows: (rows as usize).max(1),
        resolution,
        start: (0, start),
        goal: (0, goal),
    };
    grid.start.0 = grid.cell_of(start);
    grid.goal.0 = grid.cell_of(goal);
    if grid.start.0 == grid.goal.0 || map.segment_free(start, goal) {
        return Ok(vec![start, goal]);
    }
    let cells = grid.cols * grid.rows;
    let mut cost = vec![f32::INFINITY; cells];
    let mut parent = vec![usize::MAX; cells];
    let mut closed = vec![false; cells];
    let mut open = BinaryHeap::new();
    let heuristic = |p: V2| (goal - p).length();
    let s = grid.start.0;
    cost[s] = 0.0;
    parent[s] = s;
    // Costs are non-negative, so their bit patterns order like the numbers.
    open.push(Reverse((heuristic(start).to_bits(), s)));
    while let Some(Reverse((_, u))) = open.pop() {
        if closed[u] {
            continue;
        }
        closed[u] = true;
        if u == grid.goal.0 {
            break;
        }
        let (pu, grand) = (grid.point(u), parent[u]);
        let pg = grid.point(grand);
        for n in grid.neighbours(u) {
            let pn = grid.point(n);
            if closed[n] || !map.free(pn) {
                continue;
            }
            let (via, from) = if map.segment_free(pg, pn) {
                (grand, pg)
            } else if map.segment_free(pu, pn) {
                (u, pu)
            } else {
                continue;
            };
            let candidate = cost[via] + (pn - from).length();
            if candidate < cost[n] {
                cost[n] = candidate;
                parent[n] = via;
                open.push(Reverse(((candidate + heuristic(pn)).to_bits(), n)));
            }
        }
    }
    if !closed[grid.goal.0] {
        return Err(SearchError::Unreachable);
    }
    let mut path = vec![goal];
    let mut at = grid.goal.0;
    while at != s {
        at = parent[at];
        path.push(grid.point(at));
    }
    path.reverse();
    Ok(path)
}

/// Length of [`shortest_path`]'s path.
pub fn shortest_length(
    start: V2,
    goal: V2,
    map: &Map,
    resolution: f32,
) -> Result<f32, SearchError> {
    shortest_path(start, goal, map, resolution).map(|p| path_length(&p))
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use super::*;

    fn map(discs: &[(f32, f32, f32)]) -> Map {
        Map::box_with(V2::new(-5.0, -5.0), V2::new(5.0, 5.0), discs)
    }

    #[test]
    fn round_one_disc_it_is_within_two_per_cent_of_the_tangent_arc_tangent_optimum() {
        // From (-2, 0) to (2, 0) round the unit disc: two tangents of sqrt(3) and an arc of pi/3.
        let optimum = 2.0 * 3f32.sqrt() + PI / 3.0;
        let m = map(&[(0.0, 0.0, 1.0)]);
        let path = shortest_path(V2::new(-2.0, 0.0), V2::new(2.0, 0.0), &m, 0.05).unwrap();
        let length = path_length(&path);
        assert!(
            length >= optimum - 1e-3 && length < 1.02 * optimum,
            "{length} vs {optimum}"
        );
        assert_eq!(m.first_blocked_segment(&path), None);
        assert_eq!(path.first(), Some(&V2::new(-2.0, 0.0)));
        assert_eq!(path.last(), Some(&V2::new(2.0, 0.0)));
    }

    #[test]
    fn a_start_inside_an_obstacle_leaves_it() {
        let m = map(&[(0.0, 0.0, 1.0)]);
        let path = shortest_path(V2::new(-0.9, 0.0), V2::new(-3.0, 0.0), &m, 0.1).unwrap();
        assert_eq!(path.len(), 2);
        let across = shortest_path(V2::new(-0.9, 0.0), V2::new(3.0, 0.0), &m, 0.1).unwrap();
        assert!(path_length(&across) > 4.0);
    }

    #[test]
    fn a_free_line_is_the_path() {
        let m = map(&[(0.0, 3.0, 1.0)]);
        let path = shortest_path(V2::new(-3.0, 0.0), V2::new(3.0, 0.5), &m, 0.1).unwrap();
        assert_eq!(path.len(), 2);
    }

    #[test]
    fn a_walled_in_goal_is_unreachable_and_bad_inputs_are_errors() {
        // A ring of overlapping discs round the goal.
        let ring: Vec<(f32, f32, f32)> = (0..12)
            .map(|k| {
                let a = k as f32 * PI / 6.0;
                (2.0 * a.cos(), 2.0 * a.sin(), 0.6)
            })
            .collect();
        let m = map(&ring);
        assert_eq!(
            shortest_path(V2::new(-4.0, -4.0), V2::ZERO, &m, 0.1),
            Err(SearchError::Unreachable)
        );
        assert_eq!(
            shortest_path(V2::new(-4.0, -4.0), V2::new(2.0, 0.0), &m, 0.1),
            Err(SearchError::Endpoints(EndpointError::GoalBlocked))
        );
        assert_eq!(
            shortest_path(V2::new(-6.0, 0.0), V2::ZERO, &m, 0.1),
            Err(SearchError::Endpoints(EndpointError::OutOfBounds("start")))
        );
        assert_eq!(
            shortest_path(V2::new(-4.0, 0.0), V2::ZERO, &m, 0.0),
            Err(SearchError::Resolution(0.0))
        );
        assert_eq!(
            shortest_path(V2::new(-4.0, 0.0), V2::ZERO, &m, 1e-4),
            Err(SearchError::Resolution(1e-4))
        );
    }
}
