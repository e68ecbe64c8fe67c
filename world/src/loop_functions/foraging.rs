//! Foraging loop functions (docs/tasks.md 4.9, 4.13, 4.14), label `foraging_loop_functions`: deliveries at home, the
//! swarm's energy account, the metrics TO, T88%, R2S, energy per time unit and the fixed-time yield, and the stop
//! condition "all targets delivered".
//!
//! Configuration: `<loop_functions label="foraging_loop_functions"><foraging .../></loop_functions>` with
//! `home_y_max` (m, default -2.0: home is the strip y <= home_y_max), `fixed_time_s` (default 300), `ef` (2000),
//! `es` (1), `et` (2), `er` (0) and `respawn` (default false: a delivered target leaves the arena; true: it is put
//! back where it first lay, and the run ends only at the time cap).
//!
//! **Delivery.** A target dropped in home is delivered: it leaves the arena (or respawns) and the swarm's cost
//! drops by Ef. "In home" holds when the robot's centre or the point where the target falls (just ahead of the
//! robot) lies in the strip: a robot senses home with its ground sensors, 3 cm ahead of its centre, so its centre
//! may still be outside when it drops at the border. A target dropped elsewhere stays where it fell.
//!
//! **Phases from LEDs.** The world cannot see a robot's supervisors, so the phase of docs/tasks.md 4.13 is read
//! from the LED the robot's profile shows (robot-agent's `foraging` profile): green = search phase, blue = rest phase on
//! its way home, white = real rest. Each tick every live robot costs Et when it carries a target, else Es in the
//! search phase, else Er. R2S counts white robots as resting and green ones as searching.
//!
//! Everything per tick is arithmetic on counters: nothing allocates after the first tick.

use serde_json::json;
use swarm_contract::messages::{ActuatorCommand, Rgb};

use crate::arena::{Arena, GripperEvent};
use crate::entities::{TargetId, TargetState};
use crate::error::WorldError;
use crate::geometry::Vec2;
use crate::loop_functions::argos_foraging::ArgosForaging;
use crate::loop_functions::{LoopFunctions, LoopFunctionsParams};

/// The label under which the configuration selects these loop functions.
pub const LABEL: &str = "foraging_loop_functions";
/// LED of a robot in the search phase.
pub const SEARCH_LED: Rgb = Rgb { r: 0, g: 255, b: 0 };
/// LED of a robot in the real rest.
pub const REST_LED: Rgb = Rgb {
    r: 255,
    g: 255,
    b: 255,
};
/// Share of the targets whose delivery time is T88% (docs/tasks.md 4.14).
pub const T88_SHARE: f64 = 0.88;

/// The `<foraging>` parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForagingParams {
    /// Home is the strip y <= this, in metres.
    pub home_y_max: f32,
    /// The window of the fixed-time yield, in simulated seconds.
    pub fixed_time_s: f64,
    /// Credit per delivered target.
    pub ef: f64,
    /// Cost per search-phase tick.
    pub es: f64,
    /// Cost per tick while carrying.
    pub et: f64,
    /// Cost per rest-phase tick.
    pub er: f64,
    /// Whether delivered targets return to where they first lay.
    pub respawn: bool,
}

impl Default for ForagingParams {
    /// The thesis' values (docs/tasks.md 4.13) and the recommended home strip.
    fn default() -> Self {
        Self {
            home_y_max: -2.0,
            fixed_time_s: 300.0,
            ef: 2000.0,
            es: 1.0,
            et: 2.0,
            er: 0.0,
            respawn: false,
        }
    }
}

impl ForagingParams {
    /// Reads the attributes of child `<foraging>`; other children must be in `extra_children`.
    pub fn parse(
        params: &LoopFunctionsParams,
        extra_children: &[&str],
    ) -> Result<Self, WorldError> {
        let invalid = |message: String| WorldError::Invalid {
            location: params.location.clone(),
            message,
        };
        let known: Vec<&str> = std::iter::once("foraging")
            .chain(extra_children.iter().copied())
            .collect();
        params.check_children(&known)?;
        let mut p = Self::default();
        for (key, value) in &params.attributes {
            let Some((child, attr)) = key.split_once('.') else {
                continue;
            };
            // Other children are the caller's (checked above).
            if child != "foraging" {
                continue;
            }
            let number = || {
                value
                    .trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        invalid(format!(
                            "<foraging {attr}=\"{value}\">: expected a finite number"
                        ))
                    })
            };
            match attr {
                "home_y_max" => p.home_y_max = number()? as f32,
                "fixed_time_s" => {
                    p.fixed_time_s = number()?;
                    if p.fixed_time_s < 0.0 {
                        return Err(invalid(format!(
                            "<foraging fixed_time_s=\"{value}\">: must be >= 0"
                        )));
                    }
                }
                "ef" => p.ef = number()?,
                "es" => p.es = number()?,
                "et" => p.et = number()?,
                "er" => p.er = number()?,
                "respawn" => {
                    p.respawn = match value.trim() {
                        "true" => true,
                        "false" => false,
                        _ => {
                            return Err(invalid(format!(
                                "<foraging respawn=\"{value}\">: expected true or false"
                            )));
                        }
                    }
                }
                _ => {
                    return Err(invalid(format!(
                        "<foraging> has no attribute '{attr}' (known: home_y_max, fixed_time_s, ef, es, et, er, \
                         respawn)"
                    )));
                }
            }
        }
        Ok(p)
    }
}

/// The foraging bookkeeping of one run.
#[derive(Debug, Clone)]
pub struct Foraging {
    params: ForagingParams,
    /// Where each target first lay (captured on the first tick; the respawn points).
    sources: Vec<Vec2>,
    delivered: u64,
    delivered_in_fixed_time: u64,
    t88_tick: Option<u64>,
    last_delivery_tick: Option<u64>,
    cost: f64,
    searching_ticks: u64,
    resting_ticks: u64,
    resting_share_sum: f64,
    ticks: u64,
}

impl Foraging {
    /// Bookkeeping with `params`.
    pub fn new(params: ForagingParams) -> Self {
        Self {
            params,
            sources: Vec::new(),
            delivered: 0,
            delivered_in_fixed_time: 0,
            t88_tick: None,
            last_delivery_tick: None,
            cost: 0.0,
            searching_ticks: 0,
            resting_ticks: 0,
            resting_share_sum: 0.0,
            ticks: 0,
        }
    }

    /// The factory registered under [`LABEL`]. `<foraging items=...>` selects ARGoS' foot-bot foraging example instead ([`ArgosForaging`]).
    pub fn factory(params: &LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError> {
        if ArgosForaging::applies_to(params) {
            return ArgosForaging::factory(params);
        }
        Ok(Box::new(Self::new(ForagingParams::parse(params, &[])?)))
    }

    /// The parameters in use.
    pub fn params(&self) -> &ForagingParams {
        &self.params
    }

    /// Targets delivered so far.
    pub fn delivered(&self) -> u64 {
        self.delivered
    }

    /// The swarm's net energy cost so far.
    pub fn cost(&self) -> f64 {
        self.cost
    }

    fn targets(&self) -> u64 {
        self.sources.len() as u64
    }

    /// Number of deliveries that is T88%: ⌈0.88·Nt⌉.
    pub fn t88_count(targets: u64) -> u64 {
        (T88_SHARE * targets as f64).ceil() as u64
    }

    fn deliver(&mut self, arena: &mut Arena, target: TargetId) {
        match self.sources.get(target.index()) {
            Some(&home) if self.params.respawn => arena.place_target(target, home),
            _ => arena.remove_target(target),
        }
        self.delivered += 1;
        self.cost -= self.params.ef;
        let tick = arena.tick;
        if tick as f64 <= self.params.fixed_time_s * f64::from(arena.ticks_per_second) {
            self.delivered_in_fixed_time += 1;
        }
        if self.t88_tick.is_none() && self.delivered >= Self::t88_count(self.targets()) {
            self.t88_tick = Some(tick);
        }
        self.last_delivery_tick = Some(tick);
    }

    fn seconds(&self, tick: Option<u64>, arena: &Arena) -> serde_json::Value {
        tick.map_or(serde_json::Value::Null, |t| {
            json!(t as f64 / f64::from(arena.ticks_per_second))
        })
    }

    fn all_delivered(&self) -> bool {
        !self.params.respawn && !self.sources.is_empty() && self.delivered >= self.targets()
    }
}

impl LoopFunctions for Foraging {
    fn pre_step(&mut self, arena: &mut Arena) {
        if arena.tick == 1 && self.sources.is_empty() {
            self.sources = arena.targets.iter().map(|t| t.placed.position).collect();
        }
    }

    fn post_step(&mut self, arena: &mut Arena, _: &[ActuatorCommand], _: &[bool]) {
        self.ticks = arena.tick;
        // Taken out and put back (no allocation) so that deliveries may change the arena while we walk them.
        let events = std::mem::take(&mut arena.gripper_events);
        for &event in &events {
            if let GripperEvent::Dropped {
                robot,
                target,
                position,
            } = event
                && (arena.robots[robot.index()].position.y <= self.params.home_y_max
                    || position.y <= self.params.home_y_max)
                && arena.targets[target.index()].state == TargetState::InArena
            {
                self.deliver(arena, target);
            }
        }
        arena.gripper_events = events;
        let (mut live, mut searching, mut resting) = (0u64, 0u64, 0u64);
        for r in arena.robots.iter().filter(|r| r.alive) {
            live += 1;
            if r.carrying.is_some() {
                self.cost += self.params.et;
            } else if r.led == SEARCH_LED {
                self.cost += self.params.es;
            } else {
                self.cost += self.params.er;
            }
            if r.led == SEARCH_LED {
                searching += 1;
            } else if r.led == REST_LED {
                resting += 1;
            }
        }
        self.searching_ticks += searching;
        self.resting_ticks += resting;
        if live > 0 {
            self.resting_share_sum += resting as f64 / live as f64;
        }
    }

    fn is_finished(&self, _arena: &Arena) -> bool {
        self.all_delivered()
    }

    fn metrics(&self, arena: &Arena) -> serde_json::Value {
        let finished = self.all_delivered();
        let ticks = self.ticks.max(1);
        json!({
            "ticks": self.ticks,
            "targets": self.targets(),
            "delivered": self.delivered,
            "all_delivered": finished,
            "censored": !finished,
            "TO_s": if finished { self.seconds(self.last_delivery_tick, arena) } else { serde_json::Value::Null },
            "T88_s": self.seconds(self.t88_tick, arena),
            "fixed_time_s": self.params.fixed_time_s,
            "delivered_in_fixed_time": self.delivered_in_fixed_time,
            "energy": self.cost,
            "energy_per_tick": self.cost / ticks as f64,
            "rho_rest": self.resting_share_sum / ticks as f64,
            "search_to_rest": if self.resting_ticks > 0 {
                json!(self.searching_ticks as f64 / self.resting_ticks as f64)
            } else {
                serde_json::Value::Null
            },
            "respawn": self.params.respawn,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use swarm_contract::messages::GripperAction;

    use super::*;
    use crate::devices::Devices;
    use crate::geometry::{Placed, Shape};
    use crate::{World, WorldBuilder};

    const RETURN_LED: Rgb = Rgb { r: 0, g: 0, b: 255 };
    const RED: Rgb = Rgb { r: 255, g: 0, b: 0 };

    /// A 10 x 10 m arena with robots at `robots` (facing +x) and a target 6 cm ahead of each position in
    /// `targets`, so that the gripper reaches it.
    fn world(params: ForagingParams, robots: &[Vec2], targets: &[Vec2]) -> World {
        let mut b = WorldBuilder::new(Vec2::splat(-5.0), Vec2::splat(5.0), 20, 1);
        for (i, &p) in robots.iter().enumerate() {
            b.robot(&format!("ep{i}"), "fc", p, 0.0, Devices::ALL);
        }
        for (i, &p) in targets.iter().enumerate() {
            let placed = Placed::new(Shape::Disc { radius: 0.02 }, p + Vec2::new(0.06, 0.0), 0.0);
            b.target(&format!("food{i}"), placed, 0.05, RED, 0.06);
        }
        b.loop_functions(Box::new(Foraging::new(params)));
        b.build()
    }

    fn command(led: Rgb, gripper: GripperAction) -> ActuatorCommand {
        let mut c = ActuatorCommand::idle(0, 0);
        c.led = led;
        c.gripper = gripper;
        c
    }

    fn step(w: &mut World, commands: &[ActuatorCommand]) {
        w.act_and_step(commands, &vec![true; commands.len()]);
    }

    #[test]
    fn delivery_in_home_credits_ef_and_ends_the_run_with_to_and_t88() {
        let home = Vec2::new(0.0, -3.0);
        let mut w = world(ForagingParams::default(), &[home], &[home]);
        step(&mut w, &[command(SEARCH_LED, GripperAction::Pick)]);
        assert!(!w.is_finished());
        step(&mut w, &[command(SEARCH_LED, GripperAction::Drop)]);
        assert!(w.is_finished());
        let m = w.metrics();
        // Tick 1 carrying: +Et = 2; tick 2 the drop delivers: -Ef, then a search tick: +Es = 1.
        assert_eq!(m["energy"], json!(2.0 - 2000.0 + 1.0));
        assert_eq!(m["energy_per_tick"], json!((2.0 - 2000.0 + 1.0) / 2.0));
        assert_eq!(m["delivered"], json!(1));
        assert_eq!(m["TO_s"], json!(0.1));
        assert_eq!(m["T88_s"], json!(0.1));
        assert_eq!(m["delivered_in_fixed_time"], json!(1));
        assert_eq!(m["censored"], json!(false));
        assert_eq!(w.arena.targets[0].state, TargetState::Removed);
    }

    #[test]
    fn a_drop_outside_home_is_no_delivery() {
        let field = Vec2::new(0.0, 1.0);
        let mut w = world(ForagingParams::default(), &[field], &[field]);
        step(&mut w, &[command(SEARCH_LED, GripperAction::Pick)]);
        step(&mut w, &[command(SEARCH_LED, GripperAction::Drop)]);
        let m = w.metrics();
        assert_eq!(m["delivered"], json!(0));
        assert_eq!(m["TO_s"], serde_json::Value::Null);
        assert_eq!(m["censored"], json!(true));
        assert_eq!(w.arena.targets[0].state, TargetState::InArena);
        assert!(!w.is_finished());
    }

    #[test]
    fn t88_needs_the_ceiling_of_0_88_nt_deliveries() {
        assert_eq!(Foraging::t88_count(40), 36);
        assert_eq!(Foraging::t88_count(10), 9);
        assert_eq!(Foraging::t88_count(80), 71);
        assert_eq!(Foraging::t88_count(1), 1);
    }

    #[test]
    fn t88_is_reached_before_to_with_two_targets() {
        // ceil(0.88 * 2) = 2: T88% is the second delivery, as TO is.
        let a = Vec2::new(-1.0, -3.0);
        let b = Vec2::new(1.0, -3.0);
        let mut w = world(ForagingParams::default(), &[a, b], &[a, b]);
        let idle = command(SEARCH_LED, GripperAction::Hold);
        step(
            &mut w,
            &[
                command(SEARCH_LED, GripperAction::Pick),
                command(SEARCH_LED, GripperAction::Pick),
            ],
        );
        step(&mut w, &[command(SEARCH_LED, GripperAction::Drop), idle]);
        assert_eq!(w.metrics()["T88_s"], serde_json::Value::Null);
        step(&mut w, &[idle, command(SEARCH_LED, GripperAction::Drop)]);
        let m = w.metrics();
        assert_eq!(m["T88_s"], json!(0.15));
        assert_eq!(m["TO_s"], json!(0.15));
    }

    #[test]
    fn resting_ratio_and_search_to_rest_come_from_the_leds() {
        let params = ForagingParams {
            er: 0.5,
            ..ForagingParams::default()
        };
        let spots: Vec<Vec2> = (0..4).map(|i| Vec2::new(i as f32 - 2.0, 0.0)).collect();
        let mut w = world(params, &spots, &[]);
        let leds = [SEARCH_LED, SEARCH_LED, REST_LED, RETURN_LED];
        let commands: Vec<ActuatorCommand> = leds
            .iter()
            .map(|&l| command(l, GripperAction::Hold))
            .collect();
        for _ in 0..10 {
            step(&mut w, &commands);
        }
        let m = w.metrics();
        assert_eq!(m["rho_rest"], json!(0.25));
        assert_eq!(m["search_to_rest"], json!(2.0));
        // Per tick: two searching robots at Es = 1, two others at Er = 0.5.
        assert_eq!(m["energy"], json!(30.0));
    }

    #[test]
    fn respawn_puts_a_delivered_target_back_where_it_first_lay() {
        let home = Vec2::new(0.0, -3.0);
        let params = ForagingParams {
            respawn: true,
            ..ForagingParams::default()
        };
        let mut w = world(params, &[home], &[home]);
        let first = w.arena.targets[0].placed.position;
        step(&mut w, &[command(SEARCH_LED, GripperAction::Pick)]);
        step(&mut w, &[command(RETURN_LED, GripperAction::Drop)]);
        assert_eq!(w.metrics()["delivered"], json!(1));
        assert_eq!(w.arena.targets[0].state, TargetState::InArena);
        assert_eq!(w.arena.targets[0].placed.position, first);
        assert!(!w.is_finished());
    }

    fn params(pairs: &[(&str, &str)]) -> LoopFunctionsParams {
        LoopFunctionsParams {
            label: LABEL.to_owned(),
            location: "f.argos:30:3".to_owned(),
            attributes: pairs
                .iter()
                .map(|&(k, v)| (k.to_owned(), v.to_owned()))
                .collect::<BTreeMap<_, _>>(),
            ..LoopFunctionsParams::default()
        }
    }

    #[test]
    fn a_misspelt_child_is_refused_and_a_callers_child_is_not() {
        let err = ForagingParams::parse(&params(&[("foragin.ef", "1")]), &[])
            .expect_err("refused")
            .to_string();
        assert!(
            err.contains("has no child <foragin> (known: <foraging>)"),
            "{err}"
        );
        assert!(
            ForagingParams::parse(&params(&[("trails.food_channel", "0")]), &["trails"]).is_ok()
        );
    }

    #[test]
    fn configuration_values_are_read_from_the_foraging_child() {
        let p = ForagingParams::parse(
            &params(&[
                ("label", LABEL),
                ("foraging.home_y_max", "-2.5"),
                ("foraging.er", "0.5"),
                ("foraging.respawn", "true"),
            ]),
            &[],
        )
        .unwrap();
        assert_eq!(p.home_y_max, -2.5);
        assert_eq!(p.er, 0.5);
        assert!(p.respawn);
        assert_eq!(p.ef, 2000.0);
    }

    #[test]
    fn unknown_attribute_is_reported_at_the_element() {
        let err = ForagingParams::parse(&params(&[("foraging.output", "run.csv")]), &[])
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "f.argos:30:3: <foraging> has no attribute 'output' (known: home_y_max, fixed_time_s, ef, es, et, er, \
             respawn)"
        );
    }

    #[test]
    fn malformed_number_names_attribute_and_value() {
        let err = ForagingParams::parse(&params(&[("foraging.ef", "lots")]), &[])
            .unwrap_err()
            .to_string();
        assert_eq!(
            err,
            "f.argos:30:3: <foraging ef=\"lots\">: expected a finite number"
        );
    }
}
