//! Seeded random streams: one ChaCha8 stream per (run seed, purpose, robot).
//!
//! Every random draw of the world comes from a stream named by its purpose, so turning a sensor on or off, or
//! adding a robot, never shifts the numbers any other part draws. Streams are ChaCha8 because its output is stable
//! across platforms and releases: the same seed gives bit-identical runs everywhere.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// What a stream is used for; part of the stream number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum Purpose {
    /// `<distribute>` positions and orientations.
    Placement = 1,
    /// Proximity sensor noise.
    Proximity = 2,
    /// Light sensor noise.
    Light = 3,
    /// Ground sensor noise.
    Ground = 4,
    /// Multiplicative wheel noise.
    Wheels = 5,
    /// Range-and-bearing message loss.
    Rab = 6,
    /// Camera blob position noise.
    Camera = 7,
    /// Range-finder distance noise.
    RangeFinder = 8,
    /// The loop functions' own draws (e.g. where food items appear).
    LoopFunctions = 9,
    /// Addressed-message loss (`<messages loss>`).
    Messages = 10,
}

/// The stream for `purpose` and `index` (a robot index, or 0 for world-wide purposes) of the run `seed`.
pub fn stream(seed: u64, purpose: Purpose, index: u32) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream((u64::from(purpose as u32) << 32) | u64::from(index));
    rng
}

/// The per-robot streams.
#[derive(Debug, Clone)]
pub struct RobotStreams {
    /// Proximity noise.
    pub proximity: ChaCha8Rng,
    /// Light noise.
    pub light: ChaCha8Rng,
    /// Ground noise.
    pub ground: ChaCha8Rng,
    /// Wheel noise.
    pub wheels: ChaCha8Rng,
    /// Range-and-bearing loss.
    pub rab: ChaCha8Rng,
    /// Camera noise.
    pub camera: ChaCha8Rng,
    /// Range-finder noise.
    pub range_finder: ChaCha8Rng,
}

impl RobotStreams {
    /// The streams of robot `robot` in the run `seed`.
    pub fn new(seed: u64, robot: u32) -> Self {
        Self {
            proximity: stream(seed, Purpose::Proximity, robot),
            light: stream(seed, Purpose::Light, robot),
            ground: stream(seed, Purpose::Ground, robot),
            wheels: stream(seed, Purpose::Wheels, robot),
            rab: stream(seed, Purpose::Rab, robot),
            camera: stream(seed, Purpose::Camera, robot),
            range_finder: stream(seed, Purpose::RangeFinder, robot),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    #[test]
    fn streams_differ_by_purpose_and_robot_and_repeat_by_seed() {
        let draw = |mut r: ChaCha8Rng| r.random::<u64>();
        assert_eq!(
            draw(stream(7, Purpose::Proximity, 3)),
            draw(stream(7, Purpose::Proximity, 3))
        );
        assert_ne!(
            draw(stream(7, Purpose::Proximity, 3)),
            draw(stream(7, Purpose::Proximity, 4))
        );
        assert_ne!(
            draw(stream(7, Purpose::Proximity, 3)),
            draw(stream(7, Purpose::Light, 3))
        );
        assert_ne!(
            draw(stream(7, Purpose::Proximity, 3)),
            draw(stream(8, Purpose::Proximity, 3))
        );
    }
}
