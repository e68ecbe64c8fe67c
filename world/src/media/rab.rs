//! The range-and-bearing medium: the messages robots broadcast this tick, placed at the senders' positions after
//! the physics step, with a grid for the receivers' range queries. Dead robots send nothing.

use swarm_contract::messages::RAB_PAYLOAD_BYTES;

use crate::entities::Robot;
use crate::geometry::{Aabb, Vec2};
use crate::spatial::Grid;

/// One broadcast message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Emission {
    /// Index of the sending robot.
    pub sender: u32,
    /// Sender's position after the physics step.
    pub position: Vec2,
    /// Sender's emitter range in metres.
    pub range: f32,
    /// Payload.
    pub payload: [u8; RAB_PAYLOAD_BYTES],
    /// Meaningful payload bytes.
    pub len: u8,
}

/// The messages in flight.
#[derive(Debug, Clone)]
pub struct RabMedium {
    /// The messages broadcast in the last tick.
    pub messages: Vec<Emission>,
    max_range: f32,
    points: Vec<Aabb>,
    grid: Grid,
}

impl RabMedium {
    /// An empty medium over the arena rectangle `min..max`, with grid cells of side `cell`.
    pub fn new(min: Vec2, max: Vec2, cell: f32) -> Self {
        Self {
            messages: Vec::new(),
            max_range: 0.0,
            points: Vec::new(),
            grid: Grid::new(min, max, cell),
        }
    }

    /// Starts a tick: forgets the previous tick's messages.
    pub fn clear(&mut self) {
        self.messages.clear();
    }

    /// Queues a broadcast by robot `sender` (its position is filled in by [`RabMedium::commit`]).
    pub fn send(&mut self, sender: u32, range: f32, payload: [u8; RAB_PAYLOAD_BYTES], len: u8) {
        self.messages.push(Emission {
            sender,
            position: Vec2::ZERO,
            range,
            payload,
            len,
        });
    }

    /// After physics: places the queued messages at their senders' new positions and indexes them.
    pub fn commit(&mut self, robots: &[Robot]) {
        self.max_range = 0.0;
        for m in &mut self.messages {
            if let Some(r) = robots.get(m.sender as usize) {
                m.position = r.position;
            }
            self.max_range = self.max_range.max(m.range);
        }
        self.points.clear();
        self.points
            .extend(self.messages.iter().map(|m| Aabb::around(m.position, 0.0)));
        self.grid.rebuild(&self.points);
    }

    /// Calls `f` with every message whose sender may be within range of `receiver` (each once; callers check the
    /// exact distance against the sender's range).
    pub fn near(&self, receiver: Vec2, mut f: impl FnMut(&Emission)) {
        if self.messages.is_empty() {
            return;
        }
        self.grid
            .query(&Aabb::around(receiver, self.max_range), |i| {
                f(&self.messages[i as usize])
            });
    }
}
