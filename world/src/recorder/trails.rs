//! Where each robot has been, for the snapshots' trails. Positions are sampled every `stride` ticks, at most
//! [`MAX_POINTS`] per robot; when the trails are full every other point is dropped and the stride doubles, so a
//! trail covers the whole run at a resolution that halves as the run grows, and memory stays bounded (8 bytes x
//! 1,024 points per robot). A robot out of the run (dead, not joined, removed) leaves a gap.

use crate::geometry::Vec2;

/// Most points kept per robot.
pub const MAX_POINTS: usize = 1024;

/// A break in a trail: the robot was out of the run at that sample.
const GAP: Vec2 = Vec2 {
    x: f32::NAN,
    y: f32::NAN,
};

/// Every robot's trail.
#[derive(Debug, Clone)]
pub struct Trails {
    stride: u64,
    points: Vec<Vec<Vec2>>,
}

impl Default for Trails {
    fn default() -> Self {
        Trails {
            stride: 1,
            points: Vec::new(),
        }
    }
}

impl Trails {
    /// Samples the robots' `positions` (in robot order; `None` for a robot out of the run) if `tick` falls on
    /// the stride.
    pub fn sample(&mut self, tick: u64, positions: impl ExactSizeIterator<Item = Option<Vec2>>) {
        if !tick.is_multiple_of(self.stride) {
            return;
        }
        self.points.resize_with(positions.len(), Vec::new);
        for (trail, position) in self.points.iter_mut().zip(positions) {
            trail.push(position.unwrap_or(GAP));
        }
        if self.points.iter().any(|t| t.len() >= MAX_POINTS) {
            for trail in &mut self.points {
                let mut k = 0;
                trail.retain(|_| {
                    k += 1;
                    k % 2 == 1
                });
            }
            self.stride *= 2;
        }
    }

    /// The pieces of robot `index`'s trail between gaps.
    pub fn pieces(&self, index: usize) -> impl Iterator<Item = &[Vec2]> {
        self.points
            .get(index)
            .map_or(&[][..], Vec::as_slice)
            .split(|p| p.x.is_nan())
            .filter(|piece| piece.len() >= 2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trails_break_at_gaps_and_halve_when_full() {
        let mut trails = Trails::default();
        let at = |x: f32| Some(Vec2::new(x, 0.0));
        for tick in 0..5 {
            let second = if tick == 2 { None } else { at(tick as f32) };
            trails.sample(tick, [at(tick as f32), second].into_iter());
        }
        assert_eq!(
            trails.pieces(0).map(<[Vec2]>::len).collect::<Vec<_>>(),
            vec![5]
        );
        // Robot 1 was out at tick 2: two pieces of two points.
        assert_eq!(
            trails.pieces(1).map(<[Vec2]>::len).collect::<Vec<_>>(),
            vec![2, 2]
        );
        for tick in 5..(MAX_POINTS as u64 + 100) {
            trails.sample(tick, [at(tick as f32)].into_iter());
        }
        let points: usize = trails.pieces(0).map(<[Vec2]>::len).sum();
        assert!(points < MAX_POINTS, "{points}");
        assert_eq!(trails.stride, 2);
        // The whole run is still covered: from the start to the latest sample.
        let first = trails.pieces(0).next().unwrap()[0];
        assert_eq!(first, Vec2::new(0.0, 0.0));
        assert!(trails.pieces(0).last().unwrap().last().unwrap().x > 1000.0);
        assert!(trails.pieces(5).next().is_none());
    }
}
