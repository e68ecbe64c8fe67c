//! Profiles `synchronisation` (ptSCT models) and `synchronisation_sct` (plain-SCT models with timer generators
//! 1-3), docs/tasks.md section 2: firefly-like synchronisation of a counter through LED flashes.
//!
//! Events and procedures (T = `top`, default 50; alpha = `alpha`, default 0.1):
//!
//! | event | kind | procedure |
//! |---|---|---|
//! | `reached_top` | u | counter >= T |
//! | `saw_led` | u | a blob of the flash colour is in the camera's view and the last `sync` is more than `refractory` ticks ago |
//! | `inc_counter` | c | counter + 1 |
//! | `timeout` | c | nothing: it only paces the count (one count per two ticks at best) |
//! | `reset` | c | counter to 0 |
//! | `led_on` | c | LEDs yellow (the flash) |
//! | `led_off` | c | LEDs off |
//! | `sync` | c | counter <- min(T, floor(counter * (1 + alpha))) |
//!
//! The update is applied once per seen flash: a neighbour's flash stays in view for several ticks and the check
//! is level-triggered, so `saw_led` is silent for `refractory` ticks (default 5, the models' flash length) after
//! each `sync`; flashes of several neighbours that overlap in that window count once. The camera never reports
//! the robot's own LEDs.
//!
//! The counter starts at a value in [1, T] drawn from (`phase_seed`, default the run seed; robot index) on the
//! robot's first tick: a profile is built before the robot's index is known to it, so the first frame supplies
//! it. The plain-SCT
//! profile adds timer generators 1 (before `timeout`), 2 (before `sync`) and 3 (before `led_off`), each a one-step
//! delay (`start_timer_x`, `timer_x_lw_1`, `inc_timer_x`, `timer_x_eq_1`, `end_timer_x`; see [`super::timer`]).

use swarm_contract::messages::{ActuatorCommand, Rgb, SensorFrame};

use super::timer::{self, StepTimer};
use crate::params::{ParamError, Params};
use crate::profile::{Procedure, Profile};

/// Default counter ceiling T (docs/tasks.md section 2).
pub const DEFAULT_TOP: u32 = 50;
/// Default coupling constant alpha (docs/tasks.md section 2).
pub const DEFAULT_ALPHA: f32 = 0.1;
/// Default silence of `saw_led` after a `sync`, in ticks: the ptSCT models' flash length.
pub const DEFAULT_REFRACTORY: u64 = 5;
/// The flash colour (docs/tasks.md section 2 recommends yellow).
pub const FLASH: Rgb = Rgb {
    r: 255,
    g: 255,
    b: 0,
};
/// Increments of each plain-SCT timer generator: one-step delays.
pub const SCT_TIMER_TICKS: u16 = 1;

/// One robot's firefly memory, shared by both profiles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Firefly {
    /// Counter ceiling T.
    pub top: u32,
    /// Coupling constant alpha in [0, 1].
    pub alpha: f32,
    /// Ticks after a `sync` during which `saw_led` stays silent.
    pub refractory: u64,
    /// Seed of the initial counter values (default: the run's seed).
    pub phase_seed: u64,
    counter: Option<u32>,
    last_sync: Option<u64>,
}

impl Firefly {
    /// Reads `top` (whole, 1 to 2^32 - 1), `alpha` (in [0, 1]), `refractory` (whole ticks) and `phase_seed`
    /// (whole; default the run's seed).
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        let top = params.whole_or("top", DEFAULT_TOP)?;
        if top == 0 {
            return Err(ParamError::OutOfRange {
                name: "top".to_owned(),
                value: params.get("top").unwrap_or_default().to_owned(),
                rule: "must be >= 1",
            });
        }
        Ok(Self {
            top,
            alpha: params.unit_f32_or("alpha", DEFAULT_ALPHA)?,
            refractory: params.whole_or("refractory", DEFAULT_REFRACTORY)?,
            phase_seed: params.whole_or("phase_seed", params.run_seed())?,
            counter: None,
            last_sync: None,
        })
    }

    /// The counter in the tick of `frame`: the stored value, or the initial one before the first action.
    pub fn counter(&self, frame: &SensorFrame) -> u32 {
        self.counter
            .unwrap_or_else(|| initial_counter(self.phase_seed, frame.robot, self.top))
    }
}

/// The initial counter of `robot`: uniform in [1, top], a pure function of (`seed`, `robot`) (SplitMix64's
/// finaliser over the pair, so neighbouring robot indices get unrelated values).
pub fn initial_counter(seed: u64, robot: u32, top: u32) -> u32 {
    let mut z = seed ^ u64::from(robot).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    let top = u64::from(top.max(1));
    // The remainder is below top <= u32::MAX, so the sum fits.
    (1 + z % top) as u32
}

/// The counter after a flash was seen: min(T, floor(counter * (1 + alpha))).
pub fn synchronised(counter: u32, alpha: f32, top: u32) -> u32 {
    let jumped = (f64::from(counter) * (1.0 + f64::from(alpha))).floor();
    if jumped >= f64::from(top) {
        top
    } else {
        jumped as u32
    }
}

/// `reached_top`: the counter is at the ceiling.
pub fn reached_top<S: AsRef<Firefly>>(s: &S, frame: &SensorFrame) -> bool {
    let f = s.as_ref();
    f.counter(frame) >= f.top
}

/// `saw_led`: another robot's flash is in view, and no `sync` answered one in the last `refractory` ticks.
pub fn saw_led<S: AsRef<Firefly>>(s: &S, frame: &SensorFrame) -> bool {
    let f = s.as_ref();
    let quiet = f
        .last_sync
        .is_none_or(|t| frame.tick > t.saturating_add(f.refractory));
    quiet && frame.camera_blobs().iter().any(|b| b.color == FLASH)
}

/// `inc_counter`: one count.
pub fn inc_counter<S: AsMut<Firefly>>(s: &mut S, frame: &SensorFrame, _: &mut ActuatorCommand) {
    let f = s.as_mut();
    f.counter = Some(f.counter(frame).saturating_add(1));
}

/// `timeout`: paces the count; no operational effect.
pub fn timeout<S: AsMut<Firefly>>(_: &mut S, _: &SensorFrame, _: &mut ActuatorCommand) {}

/// `reset`: the counter back to 0.
pub fn reset<S: AsMut<Firefly>>(s: &mut S, _: &SensorFrame, _: &mut ActuatorCommand) {
    s.as_mut().counter = Some(0);
}

/// `led_on`: start the flash.
pub fn led_on<S: AsMut<Firefly>>(_: &mut S, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.led = FLASH;
}

/// `led_off`: end the flash.
pub fn led_off<S: AsMut<Firefly>>(_: &mut S, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.led = Rgb::OFF;
}

/// `sync`: the firefly update, once per seen flash.
pub fn sync<S: AsMut<Firefly>>(s: &mut S, frame: &SensorFrame, _: &mut ActuatorCommand) {
    let f = s.as_mut();
    f.counter = Some(synchronised(f.counter(frame), f.alpha, f.top));
    f.last_sync = Some(frame.tick);
}

/// Profile `synchronisation`: the ptSCT models' events (the lower bounds are enforced by the player).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Synchronisation {
    /// The firefly memory.
    pub firefly: Firefly,
}

impl AsRef<Firefly> for Synchronisation {
    fn as_ref(&self) -> &Firefly {
        &self.firefly
    }
}

impl AsMut<Firefly> for Synchronisation {
    fn as_mut(&mut self) -> &mut Firefly {
        &mut self.firefly
    }
}

/// The procedure table of a firefly profile (inside its `impl Profile`): the events both models share, then
/// `extra` entries.
macro_rules! firefly_procedures {
    ($($extra:expr),* $(,)?) => {
        &[
            ("reached_top", Procedure::Check(reached_top::<Self>)),
            ("saw_led", Procedure::Check(saw_led::<Self>)),
            ("inc_counter", Procedure::Act(inc_counter::<Self>)),
            ("timeout", Procedure::Act(timeout::<Self>)),
            ("reset", Procedure::Act(reset::<Self>)),
            ("led_on", Procedure::Act(led_on::<Self>)),
            ("led_off", Procedure::Act(led_off::<Self>)),
            ("sync", Procedure::Act(sync::<Self>)),
            $($extra,)*
        ]
    };
}

impl Profile for Synchronisation {
    const NAME: &'static str = "synchronisation";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = firefly_procedures!();

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            firefly: Firefly::from_params(params)?,
        })
    }
}

/// Profile `synchronisation_sct`: the plain-SCT models' events; timer generator x is `timers[x - 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SynchronisationSct {
    /// The firefly memory.
    pub firefly: Firefly,
    /// Timer generators 1 (before `timeout`), 2 (before `sync`) and 3 (before `led_off`).
    pub timers: [StepTimer; 3],
}

impl AsRef<Firefly> for SynchronisationSct {
    fn as_ref(&self) -> &Firefly {
        &self.firefly
    }
}

impl AsMut<Firefly> for SynchronisationSct {
    fn as_mut(&mut self) -> &mut Firefly {
        &mut self.firefly
    }
}

fn start_timer<const X: usize>(
    s: &mut SynchronisationSct,
    f: &SensorFrame,
    c: &mut ActuatorCommand,
) {
    timer::start(&mut s.timers[X], f, c);
}

fn inc_timer<const X: usize>(s: &mut SynchronisationSct, f: &SensorFrame, c: &mut ActuatorCommand) {
    timer::inc(&mut s.timers[X], f, c);
}

fn end_timer<const X: usize>(s: &mut SynchronisationSct, f: &SensorFrame, c: &mut ActuatorCommand) {
    timer::end(&mut s.timers[X], f, c);
}

fn timer_lower<const X: usize>(s: &SynchronisationSct, f: &SensorFrame) -> bool {
    timer::lower(&s.timers[X], f)
}

fn timer_reached<const X: usize>(s: &SynchronisationSct, f: &SensorFrame) -> bool {
    timer::reached(&s.timers[X], f)
}

impl Profile for SynchronisationSct {
    const NAME: &'static str = "synchronisation_sct";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = firefly_procedures!(
        ("start_timer_1", Procedure::Act(start_timer::<0>)),
        ("timer_1_lw_1", Procedure::Check(timer_lower::<0>)),
        ("inc_timer_1", Procedure::Act(inc_timer::<0>)),
        ("timer_1_eq_1", Procedure::Check(timer_reached::<0>)),
        ("end_timer_1", Procedure::Act(end_timer::<0>)),
        ("start_timer_2", Procedure::Act(start_timer::<1>)),
        ("timer_2_lw_1", Procedure::Check(timer_lower::<1>)),
        ("inc_timer_2", Procedure::Act(inc_timer::<1>)),
        ("timer_2_eq_1", Procedure::Check(timer_reached::<1>)),
        ("end_timer_2", Procedure::Act(end_timer::<1>)),
        ("start_timer_3", Procedure::Act(start_timer::<2>)),
        ("timer_3_lw_1", Procedure::Check(timer_lower::<2>)),
        ("inc_timer_3", Procedure::Act(inc_timer::<2>)),
        ("timer_3_eq_1", Procedure::Check(timer_reached::<2>)),
        ("end_timer_3", Procedure::Act(end_timer::<2>)),
    );

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            firefly: Firefly::from_params(params)?,
            timers: [StepTimer::new(SCT_TIMER_TICKS); 3],
        })
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use swarm_contract::messages::CameraBlob;

    use super::*;
    use crate::profiles::bind_profile;
    use crate::supervisors;

    fn firefly() -> Firefly {
        Firefly::from_params(&Params::default()).unwrap()
    }

    fn frame(tick: u64, blobs: &[Rgb]) -> SensorFrame {
        let mut f = SensorFrame::empty(3);
        f.tick = tick;
        for (i, &color) in blobs.iter().enumerate() {
            f.camera[i] = CameraBlob {
                color,
                bearing: 0.0,
                distance_cm: 24.0,
            };
        }
        f.camera_len = blobs.len() as u8;
        f
    }

    fn act(
        s: &mut Firefly,
        procedure: fn(&mut Firefly, &SensorFrame, &mut ActuatorCommand),
        f: &SensorFrame,
    ) -> ActuatorCommand {
        let mut c = ActuatorCommand::idle(3, f.tick);
        procedure(s, f, &mut c);
        c
    }

    impl AsRef<Firefly> for Firefly {
        fn as_ref(&self) -> &Firefly {
            self
        }
    }

    impl AsMut<Firefly> for Firefly {
        fn as_mut(&mut self) -> &mut Firefly {
            self
        }
    }

    #[test]
    fn initial_counters_lie_in_1_to_t_and_differ_between_robots() {
        let values: Vec<u32> = (0..64).map(|r| initial_counter(0, r, 50)).collect();
        assert!(values.iter().all(|v| (1..=50).contains(v)), "{values:?}");
        let mut distinct = values.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert!(distinct.len() > 30, "{values:?}");
        assert_ne!(
            (0..64)
                .map(|r| initial_counter(1, r, 50))
                .collect::<Vec<_>>(),
            values,
            "another phase_seed gives other phases"
        );
    }

    #[test]
    fn phase_seed_defaults_to_the_run_seed_and_an_explicit_one_wins() {
        let params = Params::default().with_run_seed(7);
        assert_eq!(Firefly::from_params(&params).unwrap().phase_seed, 7);
        let params = Params::new([("phase_seed", "11")]).with_run_seed(7);
        assert_eq!(Firefly::from_params(&params).unwrap().phase_seed, 11);
    }

    #[test]
    fn first_count_starts_from_the_initial_counter() {
        let mut s = firefly();
        let f = frame(1, &[]);
        let start = initial_counter(0, 3, 50);
        act(&mut s, inc_counter, &f);
        assert_eq!(s.counter(&f), start + 1);
    }

    #[test]
    fn reached_top_fires_at_counter_50() {
        let mut s = firefly();
        let f = frame(1, &[]);
        act(&mut s, reset, &f);
        for _ in 0..49 {
            act(&mut s, inc_counter, &f);
            assert!(!reached_top(&s, &f));
        }
        act(&mut s, inc_counter, &f);
        assert!(reached_top(&s, &f));
        act(&mut s, reset, &f);
        assert_eq!(s.counter(&f), 0);
        assert!(!reached_top(&s, &f));
    }

    #[test]
    fn sync_multiplies_by_1_1_and_floors() {
        assert_eq!(synchronised(40, 0.1, 50), 44);
        assert_eq!(synchronised(9, 0.1, 50), 9);
        assert_eq!(synchronised(19, 0.1, 50), 20);
    }

    #[test]
    fn sync_never_passes_the_top() {
        assert_eq!(synchronised(47, 0.1, 50), 50);
        assert_eq!(synchronised(50, 1.0, 50), 50);
    }

    #[test]
    fn saw_led_needs_a_blob_of_the_flash_colour() {
        let s = firefly();
        assert!(!saw_led(&s, &frame(10, &[])));
        assert!(!saw_led(&s, &frame(10, &[Rgb { r: 255, g: 0, b: 0 }])));
        assert!(saw_led(&s, &frame(10, &[FLASH])));
    }

    #[test]
    fn saw_led_is_silent_for_5_ticks_after_a_sync() {
        let mut s = firefly();
        act(&mut s, sync, &frame(10, &[FLASH]));
        for tick in 11..=15 {
            assert!(!saw_led(&s, &frame(tick, &[FLASH])), "tick {tick}");
        }
        assert!(saw_led(&s, &frame(16, &[FLASH])));
    }

    #[test]
    fn led_on_flashes_yellow_and_led_off_darkens() {
        let mut s = firefly();
        let f = frame(1, &[]);
        assert_eq!(act(&mut s, led_on, &f).led, FLASH);
        assert_eq!(act(&mut s, led_off, &f).led, Rgb::OFF);
    }

    #[test]
    fn sct_timers_are_one_step_delays() {
        let mut s = SynchronisationSct::from_params(&Params::default()).unwrap();
        let f = frame(1, &[]);
        let mut c = ActuatorCommand::idle(3, 1);
        start_timer::<1>(&mut s, &f, &mut c);
        assert!(timer_lower::<1>(&s, &f) && !timer_reached::<1>(&s, &f));
        assert!(!timer_lower::<0>(&s, &f) && !timer_lower::<2>(&s, &f));
        inc_timer::<1>(&mut s, &f, &mut c);
        assert!(!timer_lower::<1>(&s, &f) && timer_reached::<1>(&s, &f));
        end_timer::<1>(&mut s, &f, &mut c);
        assert!(!timer_reached::<1>(&s, &f));
    }

    #[test]
    fn top_of_zero_is_rejected() {
        let err = bind_profile("synchronisation", &Params::new([("top", "0")]), &[])
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            "profile `synchronisation`: parameter `top` = 0 is out of range: must be >= 1"
        );
    }

    #[test]
    fn fractional_top_is_malformed() {
        let err = bind_profile("synchronisation", &Params::new([("top", "49.5")]), &[])
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            "profile `synchronisation`: parameter `top` = \"49.5\" is not a whole number >= 0"
        );
    }

    fn models(variant: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../configs/synchronisation/models")
            .join(variant)
    }

    #[test]
    fn synchronisation_binds_every_event_of_the_ptsct_models() {
        let set = supervisors::load(&[models("ptsct")]).unwrap();
        assert_eq!(set.events.len(), 8);
        assert!(bind_profile("synchronisation", &Params::default(), &set.events).is_ok());
    }

    #[test]
    fn synchronisation_sct_binds_every_event_of_the_sct_models() {
        let set = supervisors::load(&[models("sct")]).unwrap();
        assert_eq!(set.events.len(), 8 + 15);
        assert!(bind_profile("synchronisation_sct", &Params::default(), &set.events).is_ok());
    }

    #[test]
    fn ptsct_profile_does_not_fit_the_sct_models() {
        let set = supervisors::load(&[models("sct")]).unwrap();
        let err = bind_profile("synchronisation", &Params::default(), &set.events)
            .err()
            .unwrap();
        let message = err.to_string();
        assert!(
            message.contains("supervisor events without a callback:")
                && message.contains("`start_timer_1` (controllable)")
                && message.contains("`timer_3_eq_1` (uncontrollable)"),
            "{message}"
        );
    }
}
