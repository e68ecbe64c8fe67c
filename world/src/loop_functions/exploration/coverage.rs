//! The exploration judge's coverage grid: square cells over the arena, each counted once its centre has been
//! within a robot's discovery radius. Cells whose centre lies inside an obstacle (where the obstacles stand when
//! the run starts) or outside the arena (the last column and row when the arena's sides are no whole number of
//! cells) are not counted. Sight lines are not checked: a cell behind a wall within the radius counts as seen.
//!
//! Marking costs only the cells around each robot (the square around its disc), never the whole grid.

use crate::entities::Obstacle;
use crate::geometry::Vec2;

/// Most cells a grid may have (one byte each).
pub const MAX_CELLS: usize = 10_000_000;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Cell {
    /// Inside an obstacle or outside the arena: not counted.
    Blocked,
    /// Free, not seen yet.
    Unseen,
    /// Free and seen.
    Seen,
}

/// The seen and unseen free cells of the arena.
#[derive(Debug, Clone, Default)]
pub struct Coverage {
    origin: (f64, f64),
    far: (f64, f64),
    cell: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Cell>,
    free: usize,
    seen: usize,
}

impl Coverage {
    /// The grid of `cell`-metre cells over the arena `min..max` with its `obstacles`; an error message when the
    /// grid would be too large or has no free cell.
    pub fn new(min: Vec2, max: Vec2, cell: f64, obstacles: &[Obstacle]) -> Result<Self, String> {
        let nx = (f64::from(max.x - min.x) / cell).ceil();
        let ny = (f64::from(max.y - min.y) / cell).ceil();
        if nx * ny > MAX_CELLS as f64 {
            return Err(format!(
                "`coverage_cell` {cell} m makes {} cells over the arena; at most {MAX_CELLS}",
                nx * ny
            ));
        }
        // Saturating casts: a NaN or negative count is no cell.
        let (nx, ny) = (nx as usize, ny as usize);
        let mut grid = Coverage {
            origin: (f64::from(min.x), f64::from(min.y)),
            far: (f64::from(max.x), f64::from(max.y)),
            cell,
            nx,
            ny,
            cells: vec![Cell::Unseen; nx * ny],
            free: 0,
            seen: 0,
        };
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = grid.centre(i, j);
                if x > grid.far.0 || y > grid.far.1 {
                    grid.cells[j * nx + i] = Cell::Blocked;
                }
            }
        }
        for o in obstacles {
            let aabb = o.placed.aabb();
            let Some((xs, ys)) = grid.spans(
                (f64::from(aabb.min.x), f64::from(aabb.max.x)),
                (f64::from(aabb.min.y), f64::from(aabb.max.y)),
            ) else {
                continue;
            };
            for j in ys.0..=ys.1 {
                for i in xs.0..=xs.1 {
                    let (x, y) = grid.centre(i, j);
                    if o.placed.signed_distance(Vec2::new(x as f32, y as f32)) <= 0.0 {
                        grid.cells[j * nx + i] = Cell::Blocked;
                    }
                }
            }
        }
        grid.free = grid.cells.iter().filter(|c| **c == Cell::Unseen).count();
        if grid.free == 0 {
            return Err(format!(
                "no cell of the {cell} m coverage grid is free of obstacles"
            ));
        }
        Ok(grid)
    }

    /// The centre of cell (i, j).
    fn centre(&self, i: usize, j: usize) -> (f64, f64) {
        (
            self.origin.0 + (i as f64 + 0.5) * self.cell,
            self.origin.1 + (j as f64 + 0.5) * self.cell,
        )
    }

    /// The first and last cells along each axis whose centres may lie in `x` (from, to) and `y`, if any.
    fn spans(&self, x: (f64, f64), y: (f64, f64)) -> Option<((usize, usize), (usize, usize))> {
        let span = |(lo, hi): (f64, f64), origin: f64, n: usize| {
            let first = ((lo - origin) / self.cell - 0.5).ceil().max(0.0);
            let last = ((hi - origin) / self.cell - 0.5)
                .floor()
                .min(n as f64 - 1.0);
            (first <= last).then_some((first as usize, last as usize))
        };
        Some((
            span(x, self.origin.0, self.nx)?,
            span(y, self.origin.1, self.ny)?,
        ))
    }

    /// Marks seen every free cell whose centre is within `radius` of `at`.
    pub fn see(&mut self, at: Vec2, radius: f32) {
        let (cx, cy, r) = (f64::from(at.x), f64::from(at.y), f64::from(radius));
        let Some((xs, ys)) = self.spans((cx - r, cx + r), (cy - r, cy + r)) else {
            return;
        };
        for j in ys.0..=ys.1 {
            for i in xs.0..=xs.1 {
                let (x, y) = self.centre(i, j);
                let cell = &mut self.cells[j * self.nx + i];
                if *cell == Cell::Unseen && (x - cx).powi(2) + (y - cy).powi(2) <= r * r {
                    *cell = Cell::Seen;
                    self.seen += 1;
                }
            }
        }
    }

    /// The fraction of the free cells seen so far (0 for a grid without free cells).
    pub fn fraction(&self) -> f64 {
        if self.free == 0 {
            0.0
        } else {
            self.seen as f64 / self.free as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Placed, Shape};
    use crate::physics::Motion;
    use crate::world::WorldBuilder;

    /// A 1 x 1 m arena of 0.1 m cells with the given boxes (centre, half extents).
    fn grid(boxes: &[(Vec2, Vec2)]) -> Coverage {
        let mut b = WorldBuilder::new(Vec2::ZERO, Vec2::splat(1.0), 10, 1);
        for (k, &(centre, half)) in boxes.iter().enumerate() {
            b.obstacle(
                &format!("b{k}"),
                Placed::new(Shape::Rect { half }, centre, 0.0),
                0.1,
                Motion::Fixed,
            );
        }
        let w = b.build();
        Coverage::new(w.arena.min, w.arena.max, 0.1, &w.arena.obstacles).unwrap()
    }

    #[test]
    fn seen_cells_grow_and_obstacle_cells_are_not_counted() {
        // The left half is a box: 50 free cells.
        let mut g = grid(&[(Vec2::new(0.25, 0.5), Vec2::new(0.25, 0.5))]);
        assert_eq!(g.free, 50);
        assert_eq!(g.fraction(), 0.0);
        // A radius of 0.05 from a cell centre covers that cell only.
        g.see(Vec2::new(0.75, 0.75), 0.05);
        assert_eq!(g.fraction(), 1.0 / 50.0);
        g.see(Vec2::new(0.75, 0.75), 0.05);
        assert_eq!(g.seen, 1);
        // Seen from inside the box: its own cells never count.
        g.see(Vec2::new(0.25, 0.5), 0.2);
        assert_eq!(g.seen, 1);
        g.see(Vec2::new(0.5, 0.5), 2.0);
        assert_eq!(g.fraction(), 1.0);
    }

    #[test]
    fn a_partial_last_column_is_not_counted_and_far_robots_see_nothing() {
        let w = WorldBuilder::new(Vec2::ZERO, Vec2::new(1.0, 0.2), 10, 1).build();
        let mut g = Coverage::new(w.arena.min, w.arena.max, 0.3, &[]).unwrap();
        // Columns at 0.15, 0.45, 0.75 (1.05 is outside); one row at 0.15 (0.45 is outside).
        assert_eq!((g.nx, g.ny, g.free), (4, 1, 3));
        g.see(Vec2::new(50.0, -50.0), 1.0);
        g.see(Vec2::new(f32::NAN, 0.0), 1.0);
        assert_eq!(g.seen, 0);
        g.see(Vec2::new(1.05, 0.15), 0.01);
        assert_eq!(g.seen, 0);
    }

    #[test]
    fn a_grid_too_fine_or_without_free_cells_is_refused() {
        let w = WorldBuilder::new(Vec2::ZERO, Vec2::splat(10.0), 10, 1).build();
        assert_eq!(
            Coverage::new(w.arena.min, w.arena.max, 0.001, &[]).unwrap_err(),
            "`coverage_cell` 0.001 m makes 100000000 cells over the arena; at most 10000000"
        );
        let full = [(Vec2::new(0.5, 0.5), Vec2::new(0.6, 0.6))];
        let mut b = WorldBuilder::new(Vec2::ZERO, Vec2::splat(1.0), 10, 1);
        b.obstacle(
            "b0",
            Placed::new(Shape::Rect { half: full[0].1 }, full[0].0, 0.0),
            0.1,
            Motion::Fixed,
        );
        let w = b.build();
        assert_eq!(
            Coverage::new(w.arena.min, w.arena.max, 0.1, &w.arena.obstacles).unwrap_err(),
            "no cell of the 0.1 m coverage grid is free of obstacles"
        );
    }
}
