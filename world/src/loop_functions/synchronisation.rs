//! Firefly-synchronisation metrics (docs/tasks.md 2), observed from the robots' LEDs only: a flash starts in the tick
//! a robot's LED goes from off to on.
//!
//! - **Window fraction** (docs/tasks.md's synchrony measure): at tick t, the fraction of the live robots whose latest
//!   flash started within the last `window` ticks (default w = 5), t - window < start <= t. The series reports
//!   its largest value in each sample interval, i.e. the size of the best-synchronised flash of that interval.
//! - **Time to synchrony**: the first tick at which the window fraction reaches 1.
//! - **Phase spread**: each robot that flashed at least twice has the phase (t - last start) / (its last period)
//!   at tick t; the Kuramoto order parameter R = |mean(exp(2 pi i phase))| is 1 when all flash together, near 0
//!   when phases are spread evenly; the spread is the circular standard deviation sqrt(-2 ln R) turned into ticks
//!   with the mean period (0 when synchronised, null when R = 0).
//! - **Time to order**: the first tick at which R reaches `order` (default 0.9) with every live robot having a
//!   phase; a gentler synchrony measure than the window fraction, which a wave of flashes crossing the grid a
//!   few ticks per robot never brings to 1.
//!
//! Configuration: `<loop_functions label="synchronisation_loop_functions"><synchronisation window="5"
//! sample_interval="5" order="0.9"/></loop_functions>` (optional). docs/tasks.md gives no stop condition. A tick
//! allocates nothing once the per-robot record exists (made on the first tick); the series is reserved.

use std::f64::consts::TAU;

use serde::Serialize;
use serde_json::json;
use swarm_contract::messages::ActuatorCommand;

use crate::arena::Arena;
use crate::error::WorldError;
use crate::loop_functions::{LoopFunctions, LoopFunctionsParams, params::ParamReader};

/// The label under which the configuration selects these loop functions.
pub const LABEL: &str = "synchronisation_loop_functions";
/// Default synchrony window w in ticks (docs/tasks.md 2).
pub const DEFAULT_WINDOW: u64 = 5;
/// Default time between two samples of the series, in seconds.
pub const DEFAULT_SAMPLE_INTERVAL: f64 = 5.0;
/// Default order parameter R that counts as phase-synchronised.
pub const DEFAULT_ORDER: f64 = 0.9;
/// Samples the series holds before it would have to grow (one hour at the default interval).
const RESERVED_SAMPLES: usize = 720;

/// The flash history one robot's LED shows.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Flashes {
    lit: bool,
    last: Option<u64>,
    previous: Option<u64>,
}

impl Flashes {
    /// Records the LED state of `tick`; returns whether a flash started.
    fn observe(&mut self, lit: bool, tick: u64) -> bool {
        let started = lit && !self.lit;
        if started {
            self.previous = self.last;
            self.last = Some(tick);
        }
        self.lit = lit;
        started
    }

    /// (latest start, period) once the robot has flashed twice.
    fn timing(&self) -> Option<(u64, u64)> {
        match (self.last, self.previous) {
            (Some(last), Some(previous)) if last > previous => Some((last, last - previous)),
            _ => None,
        }
    }
}

/// How spread the robots' phases are at one tick.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PhaseSpread {
    /// Kuramoto order parameter R in [0, 1].
    pub order_parameter: f64,
    /// Circular standard deviation of the phases in ticks of the mean period; `None` when R = 0.
    pub spread_ticks: Option<f64>,
    /// Robots that have a phase (flashed at least twice).
    pub robots: u32,
}

/// The phase spread at `tick` of robots given as (latest flash start, last period in ticks); `None` without any.
pub fn phase_spread(
    timings: impl IntoIterator<Item = (u64, u64)>,
    tick: u64,
) -> Option<PhaseSpread> {
    let (mut re, mut im, mut periods, mut n) = (0.0f64, 0.0f64, 0.0f64, 0u32);
    for (last, period) in timings {
        let phase = (tick.saturating_sub(last) as f64 / period as f64).rem_euclid(1.0);
        re += (TAU * phase).cos();
        im += (TAU * phase).sin();
        periods += period as f64;
        n += 1;
    }
    if n == 0 {
        return None;
    }
    let r = (re.hypot(im) / f64::from(n)).min(1.0);
    let mean_period = periods / f64::from(n);
    let spread_ticks = (r > 0.0).then(|| (-2.0 * r.ln()).max(0.0).sqrt() * mean_period / TAU);
    Some(PhaseSpread {
        order_parameter: r,
        spread_ticks,
        robots: n,
    })
}

/// One sample of the series.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sample {
    /// Tick of the sample.
    pub tick: u64,
    /// Simulated time in seconds.
    pub time_s: f64,
    /// Largest window fraction since the previous sample.
    pub window_fraction: f64,
    /// Phase spread at the sample tick (`None` before any robot flashed twice).
    pub phase: Option<PhaseSpread>,
}

/// Flash synchrony over time.
#[derive(Debug, Clone)]
pub struct Synchronisation {
    window: u64,
    sample_interval_s: f64,
    order: f64,
    robots: Vec<Flashes>,
    flashes: u64,
    best_since_sample: f64,
    synchrony_at: Option<u64>,
    order_at: Option<u64>,
    series: Vec<Sample>,
}

impl Synchronisation {
    /// Loop functions with a synchrony window of `window` ticks, a sample every `sample_interval_s` seconds, and
    /// `order` as the order parameter that counts as synchronised.
    pub fn new(window: u64, sample_interval_s: f64, order: f64) -> Self {
        Self {
            window,
            sample_interval_s,
            order,
            robots: Vec::new(),
            flashes: 0,
            best_since_sample: 0.0,
            synchrony_at: None,
            order_at: None,
            series: Vec::with_capacity(RESERVED_SAMPLES),
        }
    }

    /// The factory registered under [`LABEL`]: reads the optional `<synchronisation window sample_interval
    /// order>`.
    pub fn factory(params: &LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError> {
        let reader = ParamReader::new(
            params,
            "synchronisation",
            &["window", "sample_interval", "order"],
        )?;
        Ok(Box::new(Self::new(
            reader.u64_at_least("window", DEFAULT_WINDOW, 1)?,
            reader.positive("sample_interval", DEFAULT_SAMPLE_INTERVAL)?,
            reader.unit("order", DEFAULT_ORDER)?,
        )))
    }

    /// The first tick at which every live robot's latest flash started within the window.
    pub fn synchrony_at(&self) -> Option<u64> {
        self.synchrony_at
    }

    fn phase_at(&self, arena: &Arena) -> Option<PhaseSpread> {
        let timings = self
            .robots
            .iter()
            .zip(&arena.robots)
            .filter(|(_, r)| r.alive)
            .filter_map(|(f, _)| f.timing());
        phase_spread(timings, arena.tick)
    }
}

impl LoopFunctions for Synchronisation {
    fn post_step(
        &mut self,
        arena: &mut Arena,
        _commands: &[ActuatorCommand],
        _has_command: &[bool],
    ) {
        if self.robots.len() != arena.robots.len() {
            self.robots.resize(arena.robots.len(), Flashes::default());
        }
        let tick = arena.tick;
        let (mut alive, mut in_window) = (0u32, 0u32);
        for (flashes, robot) in self.robots.iter_mut().zip(&arena.robots) {
            if flashes.observe(robot.alive && robot.led.is_on(), tick) {
                self.flashes += 1;
            }
            if robot.alive {
                alive += 1;
                if flashes.last.is_some_and(|s| tick - s < self.window) {
                    in_window += 1;
                }
            }
        }
        if alive > 0 {
            let fraction = f64::from(in_window) / f64::from(alive);
            self.best_since_sample = self.best_since_sample.max(fraction);
            if in_window == alive && self.synchrony_at.is_none() {
                self.synchrony_at = Some(tick);
            }
            if self.order_at.is_none()
                && let Some(phase) = self.phase_at(arena)
                && phase.robots == alive
                && phase.order_parameter >= self.order
            {
                self.order_at = Some(tick);
            }
        }
        let every =
            ((self.sample_interval_s * f64::from(arena.ticks_per_second)).round() as u64).max(1);
        if tick.is_multiple_of(every) {
            self.series.push(Sample {
                tick,
                time_s: tick as f64 / f64::from(arena.ticks_per_second),
                window_fraction: self.best_since_sample,
                phase: self.phase_at(arena),
            });
            self.best_since_sample = 0.0;
        }
    }

    fn metrics(&self, arena: &Arena) -> serde_json::Value {
        let tps = f64::from(arena.ticks_per_second);
        let phase = self.phase_at(arena);
        json!({
            "ticks": arena.tick,
            "window_ticks": self.window,
            "flashes": self.flashes,
            "time_to_synchrony_tick": self.synchrony_at,
            "time_to_synchrony_s": self.synchrony_at.map(|t| t as f64 / tps),
            "order_threshold": self.order,
            "time_to_order_tick": self.order_at,
            "time_to_order_s": self.order_at.map(|t| t as f64 / tps),
            "final_window_fraction": self.series.last().map(|s| s.window_fraction),
            "final_order_parameter": phase.map(|p| p.order_parameter),
            "final_phase_spread_ticks": phase.and_then(|p| p.spread_ticks),
            "series": self.series,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::devices::Devices;
    use crate::geometry::Vec2;
    use crate::world::{World, WorldBuilder};
    use swarm_contract::messages::Rgb;

    const YELLOW: Rgb = Rgb {
        r: 255,
        g: 255,
        b: 0,
    };

    /// Robots in a row whose LEDs are on for 5 ticks from each tick in `starts[robot]`.
    fn run(starts: &[&[u64]], ticks: u64, lf: Synchronisation) -> World {
        let mut b = WorldBuilder::new(Vec2::new(-2.0, -2.0), Vec2::new(2.0, 2.0), 20, 1);
        for i in 0..starts.len() {
            let x = -1.5 + 0.24 * i as f32;
            b.robot(&format!("r{i}"), "c", Vec2::new(x, 0.0), 0.0, Devices::ALL);
        }
        b.loop_functions(Box::new(lf));
        let mut world = b.build();
        world.run_in_process(ticks, |frame, c| {
            let on = starts[frame.robot as usize]
                .iter()
                .any(|&s| frame.tick >= s && frame.tick < s + 5);
            c.led = if on { YELLOW } else { Rgb::OFF };
        });
        world
    }

    #[test]
    fn flashes_starting_4_ticks_apart_are_synchronous_with_w_5() {
        let world = run(
            &[&[10], &[12], &[14]],
            30,
            Synchronisation::new(5, 1.0, 0.9),
        );
        let m = world.metrics();
        assert_eq!(m["flashes"], 3);
        assert_eq!(m["time_to_synchrony_tick"], 14);
        assert_eq!(m["time_to_synchrony_s"], 0.7);
    }

    #[test]
    fn flashes_starting_5_ticks_apart_are_not_synchronous_with_w_5() {
        let world = run(&[&[10], &[15]], 40, Synchronisation::new(5, 1.0, 0.9));
        let m = world.metrics();
        assert!(m["time_to_synchrony_tick"].is_null());
        assert_eq!(m["final_window_fraction"], 0.0);
        let first = &m["series"][0];
        assert_eq!(first["tick"], 20);
        assert_eq!(first["window_fraction"], 0.5);
    }

    #[test]
    fn a_long_flash_starts_once() {
        let world = run(&[&[10, 12]], 30, Synchronisation::new(5, 1.0, 0.9));
        assert_eq!(world.metrics()["flashes"], 1);
    }

    #[test]
    fn equal_phases_give_order_1_and_no_spread() {
        let p = phase_spread([(100, 50), (100, 50), (100, 50)], 120).unwrap();
        assert!((p.order_parameter - 1.0).abs() < 1e-12);
        assert!(p.spread_ticks.unwrap() < 1e-5);
        assert_eq!(p.robots, 3);
    }

    #[test]
    fn opposite_phases_give_order_0() {
        // Periods of 100 ticks: at tick 200 one robot is at phase 0, the other at phase 0.5.
        let p = phase_spread([(200, 100), (150, 100)], 200).unwrap();
        assert!(p.order_parameter < 1e-12);
    }

    #[test]
    fn phases_10_ticks_apart_in_a_100_tick_period_spread_by_about_5_ticks() {
        // Phases 0 and 0.1: R = cos(pi * 0.1) = 0.951, circular sd = sqrt(-2 ln R) = 0.3168 rad = 5.042 ticks.
        let p = phase_spread([(200, 100), (190, 100)], 200).unwrap();
        assert!((p.order_parameter - 0.951_057).abs() < 1e-5);
        assert!((p.spread_ticks.unwrap() - 5.042).abs() < 0.001, "{p:?}");
    }

    #[test]
    fn robots_that_flashed_once_have_no_phase() {
        assert_eq!(phase_spread([], 10), None);
        let world = run(&[&[3], &[4]], 20, Synchronisation::new(5, 1.0, 0.9));
        assert!(world.metrics()["final_order_parameter"].is_null());
    }

    #[test]
    fn periodic_flashing_one_tick_apart_reports_order_near_1() {
        // Period 40, phases 15/40 and 14/40 at tick 60: R = cos(pi / 40) = 0.99692.
        let world = run(&[&[5, 45], &[6, 46]], 60, Synchronisation::new(5, 1.0, 0.9));
        let m = world.metrics();
        assert_eq!(m["time_to_synchrony_tick"], 6);
        let r = m["final_order_parameter"].as_f64().unwrap();
        assert!((r - 0.996_917).abs() < 1e-5, "{r}");
    }

    #[test]
    fn order_reached_when_every_robot_has_a_phase_near_the_others() {
        // At tick 46 both robots have a phase: R = cos(pi / 40) = 0.997 >= 0.9. Before it robot 1 has none.
        let world = run(&[&[5, 45], &[6, 46]], 60, Synchronisation::new(5, 1.0, 0.9));
        let m = world.metrics();
        assert_eq!(m["time_to_order_tick"], 46);
        assert_eq!(m["time_to_order_s"], 2.3);
    }

    #[test]
    fn order_not_reached_with_opposite_phases() {
        let world = run(
            &[&[5, 45], &[25, 65]],
            80,
            Synchronisation::new(5, 1.0, 0.9),
        );
        assert!(world.metrics()["time_to_order_tick"].is_null());
    }

    #[test]
    fn window_of_zero_is_rejected_with_its_location() {
        let params = LoopFunctionsParams {
            label: LABEL.to_owned(),
            location: "s.argos:20:3".to_owned(),
            attributes: [("synchronisation.window".to_owned(), "0".to_owned())]
                .into_iter()
                .collect(),
            ..LoopFunctionsParams::default()
        };
        let err = Synchronisation::factory(&params).err().unwrap();
        assert_eq!(
            err.to_string(),
            "s.argos:20:3: <synchronisation window=\"0\">: must be a whole number >= 1"
        );
    }
}
