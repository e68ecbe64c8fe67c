//! Native controller `footbot_synchronization`: a port of ARGoS' foot-bot synchronization example (fireflies),
//! written from its documented behaviour.
//!
//! Each robot keeps a counter, first drawn uniformly from 0..100 (here a pure function of the run's seed and the
//! robot's index). Each tick, if the camera sees a red blob (another robot flashing), the counter jumps by a tenth
//! of itself, else it grows by one. When it passes 100 the robot flashes: all its LEDs (ring and beacon) red for
//! that tick, and the counter restarts from 0. Flashes pull neighbours' counters forward, so the swarm's flashes
//! converge to the same tick.

use swarm_contract::messages::{ActuatorCommand, Rgb, SensorFrame};

use crate::params::{ParamError, Params};
use crate::profiles::synchronisation::initial_counter;

use super::NativeController;

/// Red, the flash colour.
const RED: Rgb = Rgb { r: 255, g: 0, b: 0 };
/// The counter's ceiling: passing it makes the robot flash.
pub const COUNT_MAX: u32 = 100;

/// The ARGoS example controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootbotSynchronization {
    seed: u64,
    counter: Option<u32>,
}

impl FootbotSynchronization {
    /// Registry name.
    pub const NAME: &'static str = "footbot_synchronization";

    /// Takes no parameters of its own; the run's seed draws the initial counters.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            seed: params.run_seed(),
            counter: None,
        })
    }
}

impl NativeController for FootbotSynchronization {
    fn step(&mut self, frame: &SensorFrame, command: &mut ActuatorCommand) {
        // initial_counter draws from 1..=COUNT_MAX + 1; ARGoS draws from 0..=COUNT_MAX.
        let counter = self
            .counter
            .unwrap_or_else(|| initial_counter(self.seed, frame.robot, COUNT_MAX + 1) - 1);
        let someone_flashed = frame.camera_blobs().iter().any(|b| b.color == RED);
        let counter = if someone_flashed {
            counter + counter / 10
        } else {
            counter + 1
        };
        let flash = counter > COUNT_MAX;
        self.counter = Some(if flash { 0 } else { counter });
        let color = if flash { RED } else { Rgb::OFF };
        command.led = color;
        command.beacon = color;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use swarm_contract::messages::CameraBlob;

    fn flash_ticks(robot: u32, seen: impl Fn(u64) -> bool, ticks: u64) -> Vec<u64> {
        let mut c =
            FootbotSynchronization::from_params(&Params::default().with_run_seed(9)).unwrap();
        let mut flashes = Vec::new();
        for tick in 1..=ticks {
            let mut f = SensorFrame::empty(robot);
            f.tick = tick;
            if seen(tick) {
                f.camera_len = 1;
                f.camera[0] = CameraBlob {
                    color: RED,
                    bearing: 0.0,
                    distance_cm: 30.0,
                };
            }
            let mut cmd = ActuatorCommand::idle(robot, tick);
            c.step(&f, &mut cmd);
            if cmd.led == RED {
                assert_eq!(cmd.beacon, RED, "a flash lights every LED");
                flashes.push(tick);
            }
        }
        flashes
    }

    #[test]
    fn alone_it_flashes_every_101_ticks() {
        let flashes = flash_ticks(3, |_| false, 400);
        assert!(flashes.len() >= 3);
        for pair in flashes.windows(2) {
            assert_eq!(pair[1] - pair[0], 101);
        }
    }

    #[test]
    fn seeing_flashes_brings_its_own_flash_forward() {
        let alone = flash_ticks(3, |_| false, 400);
        let pushed = flash_ticks(3, |t| t % 7 == 0, 400);
        assert!(pushed.len() > alone.len(), "{pushed:?} vs {alone:?}");
    }

    #[test]
    fn the_first_counter_depends_on_the_robot() {
        assert_ne!(
            flash_ticks(0, |_| false, 200)[0],
            flash_ticks(1, |_| false, 200)[0]
        );
    }
}
