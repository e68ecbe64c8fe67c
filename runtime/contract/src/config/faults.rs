//! The fault schedule of a run: the `<faults>` extension section of a `.argos` file and `swarm run --fault`.
//!
//! ```xml
//! <faults dead_bodies="inert">              <!-- or "removed": a dead robot's body leaves the arena -->
//!   <kill robots="3,7" tick="50"/>            <!-- or time="5.0" (seconds) -->
//!   <kill fraction="0.1" time="2.0"/>         <!-- a seeded random 10% of the live robots -->
//!   <chaos every="1.5" count="2" stop="9"/>   <!-- every 1.5 s from t = 1.5 s: kill 2 random live robots -->
//!   <freeze robots="4" tick="30"/>  <thaw robots="4" tick="60"/>
//!   <kill_world tick="400"/>
//!   <restart controller="oa" policy="on-failure" max_restarts="3" restart_window="30" backoff="0.1"/>
//! </faults>
//! ```
//!
//! `--fault` takes the same element as words: `--fault "kill robots=3 tick=50"`. This module only reads and checks
//! the schedule (every error located, never a panic); the launcher and the world execute it
//! ([`crate::fault_plan`]). docs/faults.md explains the semantics.

use std::path::PathBuf;

use super::diagnostic::{ConfigErrors, Diagnostic};
use super::model::{Attribute, Element, Experiment, Location};
use super::parse::Ctx;
use super::values::Value;
use crate::transport::MAX_ROBOTS;

/// Name of the extension section.
pub const SECTION: &str = "faults";
/// Child elements of `<faults>`.
const ELEMENTS: &[&str] = &["kill", "chaos", "freeze", "thaw", "kill_world", "restart"];
/// Default `max_restarts` of a `<restart>` rule.
pub const DEFAULT_MAX_RESTARTS: u32 = 3;
/// Default `restart_window` in seconds.
pub const DEFAULT_RESTART_WINDOW: f64 = 60.0;
/// Default `backoff` in seconds.
pub const DEFAULT_BACKOFF: f64 = 0.1;

/// What becomes of a dead robot's body (`<faults dead_bodies>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DeadBodies {
    /// It stays where it died as an inert obstacle with its LEDs off (the default).
    #[default]
    Inert,
    /// It leaves the arena: no collisions, nothing senses it; it comes back where it was if the robot restarts.
    Removed,
}

/// What a scheduled fault does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FaultKind {
    /// SIGKILL the robots' agents.
    Kill,
    /// SIGSTOP the robots' agents.
    Freeze,
    /// SIGCONT the robots' agents.
    Thaw,
    /// SIGKILL the world process.
    KillWorld,
}

impl FaultKind {
    /// The name used in records (`events.csv`, `summary.json`) and on the world's report lines.
    pub fn name(self) -> &'static str {
        match self {
            FaultKind::Kill => "kill",
            FaultKind::Freeze => "freeze",
            FaultKind::Thaw => "thaw",
            FaultKind::KillWorld => "kill-world",
        }
    }

    /// The kind named `name` (see [`FaultKind::name`]).
    pub fn from_name(name: &str) -> Option<FaultKind> {
        [
            FaultKind::Kill,
            FaultKind::Freeze,
            FaultKind::Thaw,
            FaultKind::KillWorld,
        ]
        .into_iter()
        .find(|k| k.name() == name)
    }
}

/// A moment of the run: a tick, or simulated seconds (converted with the experiment's `ticks_per_second`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum At {
    /// A tick; 0 is start-up, before the first tick.
    Tick(u64),
    /// Simulated seconds since the start.
    Seconds(f64),
}

impl At {
    /// The tick of this moment: seconds round to the nearest tick.
    pub fn tick(self, ticks_per_second: u32) -> u64 {
        match self {
            At::Tick(t) => t,
            At::Seconds(s) => (s * f64::from(ticks_per_second)).round() as u64,
        }
    }
}

/// Which robots a fault hits.
#[derive(Debug, Clone, PartialEq)]
pub enum Targets {
    /// These robot indices (0..N).
    Robots(Vec<u32>),
    /// A seeded random fraction of the robots alive at the time (rounded, at least one).
    Fraction(f64),
    /// A seeded random number of the robots alive at the time.
    Count(u32),
    /// The world process.
    World,
}

/// Where an item of the schedule was written, for located errors.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Origin {
    /// The configuration file, or `--fault #n` for the n-th command-line fault.
    pub path: PathBuf,
    /// Line and column.
    pub location: Location,
}

impl Origin {
    /// A located error at this item.
    pub fn error(&self, message: impl Into<String>) -> Diagnostic {
        Diagnostic::new(self.path.clone(), self.location, message)
    }
}

/// One entry of the schedule.
#[derive(Debug, Clone, PartialEq)]
pub struct ScheduledFault {
    /// What it does.
    pub kind: FaultKind,
    /// When it first happens.
    pub at: At,
    /// Repeat period (`<chaos>`), if any.
    pub every: Option<At>,
    /// Last moment a repeated fault may happen (inclusive), if any.
    pub until: Option<At>,
    /// Whom it hits.
    pub targets: Targets,
    /// Where it was written.
    pub origin: Origin,
}

/// What the launcher does when a robot's agent ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RestartPolicy {
    /// Never restart (the default).
    Never,
    /// Restart an agent that was killed or failed (non-zero exit, signal, missed deadlines).
    OnFailure,
    /// Restart an agent whenever it ends before the run does.
    Always,
}

/// A `<restart>` rule: the policy of some robots.
#[derive(Debug, Clone, PartialEq)]
pub struct RestartRule {
    /// The policy.
    pub policy: RestartPolicy,
    /// Most restarts of one robot within `restart_window`.
    pub max_restarts: u32,
    /// Sliding window for `max_restarts`, in simulated seconds.
    pub restart_window: f64,
    /// Delay before the first restart in seconds; doubles with every further restart inside the window.
    pub backoff: f64,
    /// Robots of this controller id, if given.
    pub controller: Option<String>,
    /// These robot indices, if given (neither: every robot).
    pub robots: Option<Vec<u32>>,
    /// Where it was written.
    pub origin: Origin,
}

/// The faults and restart rules of a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FaultSchedule {
    /// Scheduled faults in the order written (configuration first, then `--fault`).
    pub faults: Vec<ScheduledFault>,
    /// Restart rules; for each robot the last matching rule applies.
    pub restarts: Vec<RestartRule>,
    /// What becomes of dead robots' bodies.
    pub dead_bodies: DeadBodies,
}

impl FaultSchedule {
    /// The schedule of one run: the experiment's `<faults>` (read with the rest of the configuration) and the
    /// `--fault` texts, with robot indices checked against `robots` (the run's count, after `--robots`) and
    /// controller ids against the experiment's. Every error is located.
    pub fn for_run(
        experiment: &Experiment,
        cli: &[String],
        robots: u32,
    ) -> Result<FaultSchedule, ConfigErrors> {
        let mut errors = Vec::new();
        let mut schedule = experiment.faults.clone();
        for (i, text) in cli.iter().enumerate() {
            let path = PathBuf::from(format!("--fault #{}", i + 1));
            let mut ctx = Ctx::new(&path);
            match element_from_words(text) {
                Ok(el) => read_child(&mut ctx, &el, &mut schedule),
                Err((column, message)) => ctx.error(Location { line: 1, column }, message, None),
            }
            errors.extend(ctx.into_errors());
        }
        let controllers: Vec<&str> = experiment
            .controllers
            .iter()
            .map(|c| c.id.as_str())
            .collect();
        errors.extend(schedule.check(robots, &controllers));
        if errors.is_empty() {
            Ok(schedule)
        } else {
            Err(ConfigErrors { errors })
        }
    }

    /// Errors for robot indices beyond `robots` and unknown controller ids.
    fn check(&self, robots: u32, controllers: &[&str]) -> Vec<Diagnostic> {
        let mut errors = Vec::new();
        let mut check_robots = |list: &[u32], origin: &Origin| {
            if let Some(bad) = list.iter().find(|&&r| r >= robots) {
                errors.push(origin.error(format!(
                    "robot {bad} does not exist: the run has {robots} robots (0..{robots})"
                )));
            }
        };
        for fault in &self.faults {
            if let Targets::Robots(list) = &fault.targets {
                check_robots(list, &fault.origin);
            }
        }
        for rule in &self.restarts {
            if let Some(list) = &rule.robots {
                check_robots(list, &rule.origin);
            }
        }
        for rule in &self.restarts {
            if let Some(id) = &rule.controller
                && !controllers.contains(&id.as_str())
            {
                errors.push(rule.origin.error(format!(
                    "unknown controller '{id}' in <restart> (controllers: {})",
                    controllers.join(", ")
                )));
            }
        }
        errors
    }

    /// The restart rule of `robot` (running `controller`): the last rule naming it, its controller, or all.
    pub fn restart_rule(&self, robot: u32, controller: &str) -> Option<&RestartRule> {
        self.restarts
            .iter()
            .rev()
            .find(|rule| match (&rule.robots, &rule.controller) {
                (Some(list), _) => list.contains(&robot),
                (None, Some(id)) => id == controller,
                (None, None) => true,
            })
    }

    /// Whether the schedule has no fault and no restart rule (`dead_bodies` alone changes nothing).
    pub fn is_empty(&self) -> bool {
        self.faults.is_empty() && self.restarts.is_empty()
    }
}

/// Reads a `<faults>` section during the normal configuration load, so its errors come with all the others.
pub(crate) fn read_section(ctx: &mut Ctx, el: &Element) -> FaultSchedule {
    ctx.unknown_attributes(el, &["dead_bodies"]);
    let mut schedule = FaultSchedule {
        dead_bodies: dead_bodies(ctx, el),
        ..FaultSchedule::default()
    };
    for child in &el.children {
        read_child(ctx, child, &mut schedule);
    }
    schedule
}

fn read_child(ctx: &mut Ctx, el: &Element, schedule: &mut FaultSchedule) {
    let origin = Origin {
        path: ctx.path().to_path_buf(),
        location: el.location,
    };
    let kind = match el.name.as_str() {
        "kill" | "chaos" => FaultKind::Kill,
        "freeze" => FaultKind::Freeze,
        "thaw" => FaultKind::Thaw,
        "kill_world" => FaultKind::KillWorld,
        "restart" => {
            if let Some(rule) = restart_rule(ctx, el, origin) {
                schedule.restarts.push(rule);
            }
            return;
        }
        _ => {
            ctx.unknown_element(el, SECTION, ELEMENTS);
            return;
        }
    };
    let fault = match el.name.as_str() {
        "chaos" => chaos(ctx, el, origin),
        "kill_world" => {
            ctx.unknown_attributes(el, &["tick", "time"]);
            at(ctx, el).map(|at| ScheduledFault {
                kind,
                at,
                every: None,
                until: None,
                targets: Targets::World,
                origin,
            })
        }
        _ => {
            let allowed: &[&str] = if kind == FaultKind::Kill {
                &["robots", "fraction", "count", "tick", "time"]
            } else {
                &["robots", "tick", "time"]
            };
            ctx.unknown_attributes(el, allowed);
            let targets = targets(ctx, el, kind == FaultKind::Kill);
            let at = at(ctx, el);
            match (targets, at) {
                (Some(targets), Some(at)) => Some(ScheduledFault {
                    kind,
                    at,
                    every: None,
                    until: None,
                    targets,
                    origin,
                }),
                _ => None,
            }
        }
    };
    schedule.faults.extend(fault);
}

/// `tick="N"` or `time="seconds"`, exactly one.
fn at(ctx: &mut Ctx, el: &Element) -> Option<At> {
    match (
        el.attributes.contains_key("tick"),
        el.attributes.contains_key("time"),
    ) {
        (true, true) => {
            ctx.error(
                el.location,
                format!("<{}> gives both 'tick' and 'time'; give one", el.name),
                None,
            );
            None
        }
        (true, false) => ctx.attr::<u64>(el, "tick").map(At::Tick),
        (false, true) => {
            let seconds: f64 = ctx.attr(el, "time")?;
            ctx.in_range(el, "time", seconds, 0.0, None)
                .then_some(At::Seconds(seconds))
        }
        (false, false) => {
            ctx.error(
                el.location,
                format!("<{}> needs 'tick' (a tick) or 'time' (seconds)", el.name),
                None,
            );
            None
        }
    }
}

/// `robots`, or (kills only) `fraction` or `count`: exactly one.
fn targets(ctx: &mut Ctx, el: &Element, random_allowed: bool) -> Option<Targets> {
    let given: Vec<&str> = ["robots", "fraction", "count"]
        .into_iter()
        .filter(|a| el.attributes.contains_key(*a))
        .collect();
    match given.as_slice() {
        ["robots"] => robot_list(ctx, el, "robots").map(Targets::Robots),
        ["fraction"] if random_allowed => {
            let fraction: f64 = ctx.attr(el, "fraction")?;
            (ctx.in_range(el, "fraction", fraction, 0.0, Some(1.0)) && fraction > 0.0)
                .then_some(Targets::Fraction(fraction))
                .or_else(|| {
                    if fraction == 0.0 {
                        ctx.error(
                            el.location,
                            format!("'fraction' in <{}> must be greater than 0", el.name),
                            None,
                        );
                    }
                    None
                })
        }
        ["count"] if random_allowed => positive_count(ctx, el, "count").map(Targets::Count),
        [] => {
            let what = if random_allowed {
                "'robots', 'fraction' or 'count'"
            } else {
                "'robots'"
            };
            ctx.error(el.location, format!("<{}> needs {what}", el.name), None);
            None
        }
        [_] => {
            ctx.error(
                el.location,
                format!(
                    "<{}> needs 'robots': random targets ('fraction', 'count') are for <kill>",
                    el.name
                ),
                None,
            );
            None
        }
        _ => {
            ctx.error(
                el.location,
                format!(
                    "<{}> takes one of 'robots', 'fraction' and 'count', not {}",
                    el.name,
                    given.join(" and ")
                ),
                None,
            );
            None
        }
    }
}

fn positive_count(ctx: &mut Ctx, el: &Element, name: &str) -> Option<u32> {
    let count: u32 = ctx.attr(el, name)?;
    if count == 0 {
        let at = el.attributes.get(name).map_or(el.location, |a| a.location);
        ctx.error(
            at,
            format!("'{name}' in <{}> must be at least 1", el.name),
            None,
        );
        return None;
    }
    Some(count)
}

/// `<chaos every count start stop>`: every `every` seconds from `start` (default `every`) to `stop`, kill
/// `count` random live robots.
fn chaos(ctx: &mut Ctx, el: &Element, origin: Origin) -> Option<ScheduledFault> {
    ctx.unknown_attributes(el, &["every", "count", "start", "stop"]);
    let every = ctx.positive(el, "every");
    let count = if el.attributes.contains_key("count") {
        positive_count(ctx, el, "count")
    } else {
        Some(1)
    };
    let start = match ctx.attr::<f64>(el, "start") {
        Some(s) if ctx.in_range(el, "start", s, 0.0, None) => Some(s),
        Some(_) => return None,
        None => every,
    };
    let stop = match ctx.attr::<f64>(el, "stop") {
        Some(s) if ctx.in_range(el, "stop", s, 0.0, None) => Some(At::Seconds(s)),
        Some(_) => return None,
        None => None,
    };
    Some(ScheduledFault {
        kind: FaultKind::Kill,
        at: At::Seconds(start?),
        every: Some(At::Seconds(every?)),
        until: stop,
        targets: Targets::Count(count?),
        origin,
    })
}

fn dead_bodies(ctx: &mut Ctx, el: &Element) -> DeadBodies {
    match ctx.attr::<String>(el, "dead_bodies").as_deref() {
        None | Some("inert") => DeadBodies::Inert,
        Some("removed") => DeadBodies::Removed,
        Some(other) => {
            let at = el
                .attributes
                .get("dead_bodies")
                .map_or(el.location, |a| a.location);
            ctx.error(
                at,
                format!("invalid 'dead_bodies' in <faults>: '{other}' is not inert or removed"),
                None,
            );
            DeadBodies::Inert
        }
    }
}

fn restart_rule(ctx: &mut Ctx, el: &Element, origin: Origin) -> Option<RestartRule> {
    ctx.unknown_attributes(
        el,
        &[
            "policy",
            "max_restarts",
            "restart_window",
            "backoff",
            "controller",
            "robots",
        ],
    );
    let policy = match ctx.required::<String>(el, "policy")?.as_str() {
        "never" => RestartPolicy::Never,
        "on-failure" => RestartPolicy::OnFailure,
        "always" => RestartPolicy::Always,
        other => {
            let at = el
                .attributes
                .get("policy")
                .map_or(el.location, |a| a.location);
            ctx.error(
                at,
                format!(
                    "invalid 'policy' in <restart>: '{other}' is not never, on-failure or always"
                ),
                None,
            );
            return None;
        }
    };
    let max_restarts = ctx
        .attr::<u32>(el, "max_restarts")
        .unwrap_or(DEFAULT_MAX_RESTARTS);
    let restart_window = match ctx.attr::<f64>(el, "restart_window") {
        Some(w) if !ctx.in_range(el, "restart_window", w, 0.0, None) => return None,
        Some(w) => w,
        None => DEFAULT_RESTART_WINDOW,
    };
    let backoff = match ctx.attr::<f64>(el, "backoff") {
        Some(b) if !ctx.in_range(el, "backoff", b, 0.0, None) => return None,
        Some(b) => b,
        None => DEFAULT_BACKOFF,
    };
    let robots = if el.attributes.contains_key("robots") {
        Some(robot_list(ctx, el, "robots")?)
    } else {
        None
    };
    Some(RestartRule {
        policy,
        max_restarts,
        restart_window,
        backoff,
        controller: ctx.attr(el, "controller"),
        robots,
        origin,
    })
}

/// A robot list: indices and inclusive ranges, comma-separated (`"3"`, `"0,4,9"`, `"10-19"`).
fn robot_list(ctx: &mut Ctx, el: &Element, name: &str) -> Option<Vec<u32>> {
    let text: String = ctx.attr(el, name)?;
    match parse_robot_list(&text) {
        Ok(list) => Some(list),
        Err(reason) => {
            let at = el.attributes.get(name).map_or(el.location, |a| a.location);
            ctx.error(
                at,
                format!("invalid '{name}' in <{}>: {reason}", el.name),
                None,
            );
            None
        }
    }
}

/// Parses `"0,4,10-12"` into sorted, distinct robot indices.
pub fn parse_robot_list(text: &str) -> Result<Vec<u32>, String> {
    let mut robots = Vec::new();
    for part in text.split(',').map(str::trim) {
        let (low, high) = match part.split_once('-') {
            Some((a, b)) => (a.trim(), b.trim()),
            None => (part, part),
        };
        let low = u32::parse_value(low)
            .map_err(|_| format!("'{part}' is not a robot index or a range a-b"))?;
        let high = u32::parse_value(high)
            .map_err(|_| format!("'{part}' is not a robot index or a range a-b"))?;
        if high < low {
            return Err(format!("the range '{part}' is empty"));
        }
        // Checked before the range is expanded, so a huge range is an error, not gigabytes of indices.
        if high >= MAX_ROBOTS {
            return Err(format!(
                "robot {high} is beyond the most robots a run can have ({MAX_ROBOTS})"
            ));
        }
        robots.extend(low..=high);
    }
    robots.sort_unstable();
    robots.dedup();
    Ok(robots)
}

/// A `--fault` text as the `<faults>` child it stands for: `kill robots=3 tick=50` is `<kill robots="3"
/// tick="50"/>`. Check the text with [`FaultSchedule::for_run`] first; this only rewrites it.
pub fn fault_text_as_xml(text: &str) -> Result<String, String> {
    let el = element_from_words(text).map_err(|(_, message)| message)?;
    let mut xml = format!("<{}", el.name);
    for (name, attribute) in &el.attributes {
        let value = quick_xml::escape::escape(attribute.value.as_str());
        xml.push_str(&format!(" {name}=\"{value}\""));
    }
    xml.push_str("/>");
    Ok(xml)
}

/// Turns `--fault` words (`kill robots=3 tick=50`) into an element located at their columns.
fn element_from_words(text: &str) -> Result<Element, (u32, String)> {
    let mut words = text
        .char_indices()
        .filter(|&(i, c)| {
            !c.is_whitespace() && (i == 0 || text[..i].ends_with(char::is_whitespace))
        })
        .map(|(i, _)| {
            let word = text[i..].split_whitespace().next().unwrap_or_default();
            (text[..i].chars().count() as u32 + 1, word)
        });
    let Some((column, name)) = words.next() else {
        return Err((
            1,
            "an empty --fault; write e.g. \"kill robots=3 tick=50\"".into(),
        ));
    };
    let mut el = Element {
        name: name.to_owned(),
        location: Location { line: 1, column },
        ..Element::default()
    };
    for (column, word) in words {
        let Some((key, value)) = word.split_once('=') else {
            return Err((column, format!("'{word}' is not NAME=VALUE")));
        };
        el.attributes.insert(
            key.to_owned(),
            Attribute {
                value: value.to_owned(),
                location: Location { line: 1, column },
            },
        );
    }
    Ok(el)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sections after `<faults>` that make the experiment complete (one controller, `oa`).
    /// An experiment whose `<faults>` section starts on line 3.
    fn experiment(faults: &str) -> Result<Experiment, ConfigErrors> {
        let text = format!(
            "<argos-configuration>\n<framework><experiment length=\"10\" ticks_per_second=\"10\"/></framework>\n\
             {faults}\n{}\n</argos-configuration>\n",
            crate::config::TEST_SECTIONS
        );
        Experiment::parse("x.argos", &text).map(|(experiment, _)| experiment)
    }

    fn load(faults: &str, cli: &[&str]) -> Result<FaultSchedule, ConfigErrors> {
        let cli: Vec<String> = cli.iter().map(|s| s.to_string()).collect();
        FaultSchedule::for_run(&experiment(faults)?, &cli, 40)
    }

    #[test]
    fn every_fault_element_reads_into_the_schedule() {
        let schedule = load(
            r#"<faults>
                 <kill robots="3,7-8" tick="50"/>
                 <kill fraction="0.1" time="2.5"/>
                 <chaos every="1.5" count="2" stop="9"/>
                 <freeze robots="4" tick="30"/><thaw robots="4" tick="60"/>
                 <kill_world tick="400"/>
                 <restart controller="oa" policy="on-failure" max_restarts="2" backoff="0.5"/>
               </faults>"#,
            &[],
        )
        .expect("valid schedule");
        assert_eq!(schedule.faults.len(), 6);
        assert_eq!(schedule.faults[0].targets, Targets::Robots(vec![3, 7, 8]));
        assert_eq!(schedule.faults[0].at, At::Tick(50));
        assert_eq!(schedule.faults[1].at.tick(10), 25);
        assert_eq!(schedule.faults[2].every, Some(At::Seconds(1.5)));
        assert_eq!(schedule.faults[2].at, At::Seconds(1.5));
        assert_eq!(schedule.faults[2].targets, Targets::Count(2));
        assert_eq!(schedule.faults[5].kind, FaultKind::KillWorld);
        let rule = schedule.restart_rule(12, "oa").expect("rule for oa");
        assert_eq!(
            (rule.policy, rule.max_restarts, rule.backoff),
            (RestartPolicy::OnFailure, 2, 0.5)
        );
        assert!(schedule.restart_rule(12, "other").is_none());
    }

    #[test]
    fn command_line_faults_read_like_elements() {
        let schedule = load("", &["kill robots=5 tick=20", "restart policy=always"]).unwrap();
        assert_eq!(schedule.faults[0].targets, Targets::Robots(vec![5]));
        assert_eq!(schedule.restarts[0].policy, RestartPolicy::Always);
    }

    #[test]
    fn errors_in_the_section_are_located_with_the_rest_of_the_configuration() {
        let err = experiment(
            "<faults>\n  <kill robots=\"3\"/>\n  <kill robots=\"99\" tick=\"1\"/>\n  <explode tick=\"1\"/>\n</faults>",
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains(":4:3: <kill> needs 'tick' (a tick) or 'time' (seconds)"),
            "{err}"
        );
        assert!(
            err.contains(":6:3: unknown element <explode> in <faults>"),
            "{err}"
        );
    }

    #[test]
    fn a_run_checks_robot_indices_and_command_line_faults_with_their_locations() {
        let err = load(
            "<faults>\n  <kill robots=\"3\" tick=\"2\"/>\n  <kill robots=\"99\" tick=\"1\"/>\n</faults>",
            &["freeze robots=2 tick=x"],
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains(":5:3: robot 99 does not exist: the run has 40 robots"),
            "{err}"
        );
        assert!(
            err.contains("--fault #1:1:17: invalid 'tick' in <freeze>"),
            "{err}"
        );
    }

    #[test]
    fn freeze_takes_no_random_targets_and_restart_needs_a_known_policy() {
        let err = load(
            r#"<faults><freeze fraction="0.5" tick="3"/><restart policy="sometimes"/></faults>"#,
            &[],
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains(":3:9: <freeze> needs 'robots': random targets"),
            "{err}"
        );
        assert!(
            err.contains("'sometimes' is not never, on-failure or always"),
            "{err}"
        );
    }

    #[test]
    fn robot_lists_accept_indices_and_ranges() {
        assert_eq!(parse_robot_list("4, 0,2-3").unwrap(), vec![0, 2, 3, 4]);
        assert!(parse_robot_list("5-2").is_err());
        assert!(parse_robot_list("a").is_err());
    }

    #[test]
    fn a_huge_range_is_refused_before_it_is_expanded() {
        let err = parse_robot_list("0-4294967295").expect_err("beyond any run");
        assert!(
            err.contains("beyond the most robots a run can have"),
            "{err}"
        );
        let err = load("", &["kill robots=0-4294967295 tick=1"])
            .unwrap_err()
            .to_string();
        assert!(err.contains("--fault #1:1:"), "{err}");
    }

    #[test]
    fn dead_bodies_default_to_inert_and_read_removed() {
        assert_eq!(
            load("<faults/>", &[]).unwrap().dead_bodies,
            DeadBodies::Inert
        );
        let schedule = load("<faults dead_bodies=\"removed\"/>", &[]).unwrap();
        assert_eq!(schedule.dead_bodies, DeadBodies::Removed);
        let err = load("<faults dead_bodies=\"gone\"/>", &[])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(":3:9:") && err.contains("'gone' is not inert or removed"),
            "{err}"
        );
    }
}
