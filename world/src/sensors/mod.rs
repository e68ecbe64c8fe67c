//! The sensors, each a function from the world's state after the last physics step to one part of a robot's
//! `SensorFrame`, placed as the robot's body says. Sensors only read the world; they never move or change
//! anything.

pub mod camera;
pub mod distance_scanner;
pub mod ground;
pub mod light;
pub mod noise;
pub mod proximity;
pub mod rab;
pub mod range_finder;

use swarm_contract::bodies::BodyModel;

use crate::geometry::Vec2;

/// The robot a sensor reads for: its index (robots are the first bodies of the scene), its pose and its body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observer<'a> {
    /// Its body: where its sensors sit.
    pub body: &'a BodyModel,
    /// Robot index, equal to its scene index.
    pub me: u32,
    /// Position of the point between the wheels.
    pub position: Vec2,
    /// Heading in radians.
    pub heading: f32,
}

impl Observer<'_> {
    /// A point given in the robot frame (x forward, y left), in the arena frame.
    pub fn to_arena(&self, local: Vec2) -> Vec2 {
        let (s, c) = self.heading.sin_cos();
        self.position + Vec2::new(c * local.x - s * local.y, s * local.x + c * local.y)
    }
}

/// Inserts `item` into the first `len` entries of `items`, kept sorted by ascending `key` (nearest first); when
/// the array is full the farthest entry falls off. Allocation-free.
pub(crate) fn insert_nearest<T: Copy, const N: usize>(
    items: &mut [T; N],
    len: &mut usize,
    item: T,
    key: impl Fn(&T) -> f32,
) {
    let k = key(&item);
    let pos = items[..*len].partition_point(|x| key(x) <= k);
    if pos >= N {
        return;
    }
    let end = (*len).min(N - 1);
    items.copy_within(pos..end, pos + 1);
    items[pos] = item;
    *len = (*len + 1).min(N);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_first_buffer_drops_the_farthest_when_full() {
        let mut items = [0.0f32; 4];
        let mut len = 0;
        for d in [5.0, 1.0, 4.0, 2.0, 3.0, 0.5] {
            insert_nearest(&mut items, &mut len, d, |x| *x);
        }
        assert_eq!(len, 4);
        assert_eq!(items, [0.5, 1.0, 2.0, 3.0]);
    }
}
