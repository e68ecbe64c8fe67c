//! The foot-bot's distance scanner: four rays on a rotating turret, 90 degrees apart, two short-range (rays 0
//! and 2, from the body edge out to 0.26 m beyond it) and two long-range (rays 1 and 3, out to 1.42 m, blind
//! closer than 0.12 m), at 0.123 m above the ground, so bodies lower than that pass under them (ARGoS' numbers).
//!
//! Held at an angle, each ray gives one reading per tick; turning, each gives six, spread over the angle the
//! turret swept since the last tick. The readings go into the frame's `ranges`, ray by ray, with `scan_start`
//! and `scan_span` (swarm_contract::messages::SensorFrame): metres from the body centre, 0 for a body closer
//! than the ray's minimum distance, infinity when nothing is in reach.

use std::f32::consts::{FRAC_PI_2, TAU};

use swarm_contract::messages::{Scanner, SensorFrame};

use crate::geometry::unit;
use crate::scene::Scene;
use crate::sensors::Observer;

/// Height of the rays above the ground in metres.
pub const ELEVATION: f32 = 0.123_199_87;
/// Reach of a short-range ray beyond the body edge, in metres.
pub const SHORT_REACH: f32 = 0.26;
/// Reach of a long-range ray beyond the body edge, in metres.
pub const LONG_REACH: f32 = 1.42;
/// Distance beyond the body edge below which a long-range ray cannot measure, in metres.
pub const LONG_MIN: f32 = 0.12;
/// Readings per ray per tick while the turret turns.
pub const SAMPLES_WHILE_TURNING: usize = 6;

/// The scanner's mode and turret angle, kept between ticks.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ScannerState {
    /// Off, held, or turning.
    pub mode: Scanner,
    /// Turret angle in radians from the heading, in [0, 2 pi).
    pub rotation: f32,
    /// The turret angle when the scanner last read.
    pub last_read: f32,
}

impl ScannerState {
    /// Applies the actuator's command for a tick of `dt` seconds: the mode, and the angle (`Angle`, radians) or
    /// the speed (`Speed`, revolutions per minute) the turret turns at through the tick.
    pub fn command(&mut self, mode: Scanner, setting: f32, dt: f32) {
        self.mode = mode;
        if !setting.is_finite() {
            return;
        }
        match mode {
            Scanner::Off => {}
            Scanner::Angle => self.rotation = setting.rem_euclid(TAU),
            Scanner::Speed => {
                self.rotation = (self.rotation + setting * TAU / 60.0 * dt).rem_euclid(TAU);
            }
        }
    }
}

/// Fills the scanner part of `frame` for robot `me`, whose scanner is in `state`; `scratch` receives the gathered
/// nearby bodies.
pub fn sense(
    scene: &Scene,
    observer: Observer,
    state: &mut ScannerState,
    scratch: &mut Vec<u32>,
    frame: &mut SensorFrame,
) {
    let Observer {
        me,
        position,
        heading,
        body,
    } = observer;
    let (start, span, samples) = match state.mode {
        Scanner::Off => return,
        Scanner::Angle => (state.rotation, 0.0, 1),
        Scanner::Speed => (
            state.last_read,
            (state.rotation - state.last_read).rem_euclid(TAU),
            SAMPLES_WHILE_TURNING,
        ),
    };
    state.last_read = state.rotation;
    let radius = body.radius;
    scene.nearby(position, radius + LONG_REACH, me, scratch);
    scratch.retain(|&i| scene.heights[i as usize] > ELEVATION);
    frame.scan_start = start;
    frame.scan_span = span;
    frame.ranges_len = (4 * samples) as u8;
    for ray in 0..4 {
        let (reach, min) = if ray % 2 == 0 {
            (SHORT_REACH, 0.0)
        } else {
            (LONG_REACH, LONG_MIN)
        };
        for sample in 0..samples {
            let angle = start + ray as f32 * FRAC_PI_2 + sample as f32 * span / samples as f32;
            let dir = unit(heading + angle);
            let t = scene.nearest_hit(scratch, position + dir * radius, dir, reach);
            frame.ranges[ray * samples + sample] = if !t.is_finite() {
                f32::INFINITY
            } else if t <= min {
                0.0
            } else {
                radius + t
            };
        }
    }
}
