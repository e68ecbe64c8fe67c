//! A uniform grid over the arena that answers "which items may lie in this box" for the sensors.
//!
//! It is rebuilt from a slice of bounding boxes with a counting sort into preallocated buffers, so a rebuild per
//! tick allocates nothing once the buffers have grown to the world's size. An item whose box spans several cells is
//! listed in each of them: queries may report it more than once, and callers must tolerate that (minimum distances
//! do; counting callers insert only points).

use crate::geometry::{Aabb, Vec2};

/// A uniform grid of item indices.
#[derive(Debug, Clone)]
pub struct Grid {
    origin: Vec2,
    cell: f32,
    nx: usize,
    ny: usize,
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    /// A grid covering the rectangle `min..max` with square cells of side `cell` (at least 1 cm).
    pub fn new(min: Vec2, max: Vec2, cell: f32) -> Self {
        let cell = cell.max(0.01);
        let size = (max - min).max(Vec2::splat(cell));
        let nx = ((size.x / cell).ceil() as usize).clamp(1, 4096);
        let ny = ((size.y / cell).ceil() as usize).clamp(1, 4096);
        Self {
            origin: min,
            cell,
            nx,
            ny,
            starts: vec![0; nx * ny + 1],
            items: Vec::new(),
        }
    }

    fn cell_range(&self, aabb: &Aabb) -> (usize, usize, usize, usize) {
        let to_cell = |v: f32, n: usize| ((v / self.cell).floor().max(0.0) as usize).min(n - 1);
        let lo = aabb.min - self.origin;
        let hi = aabb.max - self.origin;
        (
            to_cell(lo.x, self.nx),
            to_cell(hi.x, self.nx),
            to_cell(lo.y, self.ny),
            to_cell(hi.y, self.ny),
        )
    }

    /// Replaces the contents with `aabbs`; item `i` is `aabbs[i]`. Boxes outside the grid land in its border cells;
    /// [`Aabb::NOWHERE`] items are in no cell.
    pub fn rebuild(&mut self, aabbs: &[Aabb]) {
        self.starts.iter_mut().for_each(|s| *s = 0);
        let mut total = 0usize;
        for aabb in aabbs.iter().filter(|a| !a.is_nowhere()) {
            let (x0, x1, y0, y1) = self.cell_range(aabb);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    self.starts[y * self.nx + x + 1] += 1;
                    total += 1;
                }
            }
        }
        for i in 1..self.starts.len() {
            self.starts[i] += self.starts[i - 1];
        }
        self.items.resize(total, 0);
        // Fill backwards from each cell's end so the prefix sums double as write cursors.
        for (i, aabb) in aabbs
            .iter()
            .enumerate()
            .rev()
            .filter(|(_, a)| !a.is_nowhere())
        {
            let (x0, x1, y0, y1) = self.cell_range(aabb);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let end = &mut self.starts[y * self.nx + x + 1];
                    *end -= 1;
                    self.items[*end as usize] = i as u32;
                }
            }
        }
        // Each cursor starts[c + 1] now holds the start of cell c: shift them down and close the last cell.
        let n = self.nx * self.ny;
        for c in 0..n {
            self.starts[c] = self.starts[c + 1];
        }
        self.starts[n] = total as u32;
    }

    /// Calls `f` with every item listed in a cell that `aabb` touches (possibly several times per item).
    pub fn query(&self, aabb: &Aabb, mut f: impl FnMut(u32)) {
        let (x0, x1, y0, y1) = self.cell_range(aabb);
        for y in y0..=y1 {
            let row = y * self.nx;
            let (start, end) = (
                self.starts[row + x0] as usize,
                self.starts[row + x1 + 1] as usize,
            );
            self.items[start..end].iter().for_each(|&i| f(i));
        }
    }

    /// Calls `f` with every item listed in a cell that the segment `a..b` passes through (grid traversal).
    pub fn query_segment(&self, a: Vec2, b: Vec2, mut f: impl FnMut(u32)) {
        let seg = Aabb {
            min: a.min(b),
            max: a.max(b),
        };
        let (x0, x1, y0, y1) = self.cell_range(&seg);
        let d = b - a;
        let len = d.length();
        // Cells are visited along the segment's dominant axis; on each column (or row) only the cells the
        // segment crosses within it are listed.
        if d.x.abs() >= d.y.abs() {
            for x in x0..=x1 {
                let cx0 = self.origin.x + x as f32 * self.cell;
                let (ya, yb) = segment_span(a, d, len, cx0, cx0 + self.cell, true);
                let band = Aabb {
                    min: Vec2::new(cx0, ya),
                    max: Vec2::new(cx0, yb),
                };
                let (_, _, ry0, ry1) = self.cell_range(&band);
                for y in ry0.max(y0)..=ry1.min(y1) {
                    let c = y * self.nx + x;
                    self.items[self.starts[c] as usize..self.starts[c + 1] as usize]
                        .iter()
                        .for_each(|&i| f(i));
                }
            }
        } else {
            for y in y0..=y1 {
                let cy0 = self.origin.y + y as f32 * self.cell;
                let (xa, xb) = segment_span(a, d, len, cy0, cy0 + self.cell, false);
                let band = Aabb {
                    min: Vec2::new(xa, cy0),
                    max: Vec2::new(xb, cy0),
                };
                let (rx0, rx1, _, _) = self.cell_range(&band);
                let row = y * self.nx;
                let (start, end) = (
                    self.starts[row + rx0.max(x0)] as usize,
                    self.starts[row + rx1.min(x1) + 1] as usize,
                );
                self.items[start..end].iter().for_each(|&i| f(i));
            }
        }
    }
}

/// The range of the other coordinate the segment `a + t d` (t in [0, 1]) covers while its major coordinate is in
/// `[lo, hi]`.
fn segment_span(a: Vec2, d: Vec2, len: f32, lo: f32, hi: f32, major_is_x: bool) -> (f32, f32) {
    let (am, dm, ao, d_o) = if major_is_x {
        (a.x, d.x, a.y, d.y)
    } else {
        (a.y, d.y, a.x, d.x)
    };
    if dm.abs() <= f32::EPSILON * len.max(1.0) {
        return (ao.min(ao + d_o), ao.max(ao + d_o));
    }
    let t0 = ((lo - am) / dm).clamp(0.0, 1.0);
    let t1 = ((hi - am) / dm).clamp(0.0, 1.0);
    let (o0, o1) = (ao + d_o * t0, ao + d_o * t1);
    (o0.min(o1), o0.max(o1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid_with(items: &[Aabb]) -> Grid {
        let mut g = Grid::new(Vec2::splat(-1.0), Vec2::splat(1.0), 0.25);
        g.rebuild(items);
        g
    }

    #[test]
    fn query_finds_items_in_touched_cells_only() {
        let items = [
            Aabb::around(Vec2::new(-0.9, -0.9), 0.01),
            Aabb::around(Vec2::new(0.6, 0.6), 0.01),
        ];
        let g = grid_with(&items);
        let mut seen = Vec::new();
        g.query(&Aabb::around(Vec2::new(0.6, 0.6), 0.05), |i| seen.push(i));
        assert_eq!(seen, vec![1]);
    }

    #[test]
    fn wide_item_is_found_from_every_cell_it_covers() {
        let wall = Aabb {
            min: Vec2::new(-1.0, 0.9),
            max: Vec2::new(1.0, 1.0),
        };
        let g = grid_with(&[wall]);
        for x in [-0.9, 0.0, 0.9] {
            let mut n = 0;
            g.query(&Aabb::around(Vec2::new(x, 0.95), 0.01), |_| n += 1);
            assert!(n >= 1, "wall not found at x = {x}");
        }
    }

    #[test]
    fn rebuild_replaces_previous_contents() {
        let mut g = grid_with(&[Aabb::around(Vec2::ZERO, 0.01)]);
        g.rebuild(&[Aabb::around(Vec2::new(0.8, 0.8), 0.01)]);
        let mut n = 0;
        g.query(&Aabb::around(Vec2::ZERO, 0.05), |_| n += 1);
        assert_eq!(n, 0);
    }

    #[test]
    fn segment_query_visits_cells_along_a_diagonal() {
        let items = [
            Aabb::around(Vec2::new(0.5, 0.5), 0.01),
            Aabb::around(Vec2::new(0.5, -0.5), 0.01),
        ];
        let g = grid_with(&items);
        let mut seen = Vec::new();
        g.query_segment(Vec2::new(-0.9, -0.9), Vec2::new(0.9, 0.9), |i| seen.push(i));
        assert!(seen.contains(&0));
        assert!(!seen.contains(&1));
    }
}
