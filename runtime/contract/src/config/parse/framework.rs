//! `<framework>`: `<system threads pin_threads_to_cores realtime_priority>` and the run's [`Limits`],
//! `<experiment length ticks_per_second random_seed>` and `<hosts>` ([`crate::config::hosts`]).

use super::Ctx;
use crate::config::model::{Element, Framework, Location};
use crate::limits::Limits;

const CHILDREN: &[&str] = &["system", "experiment", "profiling", "hosts"];

/// Parses `<framework>`.
pub(super) fn framework(ctx: &mut Ctx, el: &Element) -> Option<Framework> {
    ctx.unknown_attributes(el, &[]);
    let mut threads = 0;
    let mut pin_agents = true;
    let mut realtime_priority = true;
    let mut limits = Limits::default();
    let mut hosts = None;
    let mut experiment: Option<(&Element, Location)> = None;
    let mut system_at: Option<Location> = None;
    for child in &el.children {
        match child.name.as_str() {
            "system" => {
                if let Some(first) = system_at {
                    ctx.duplicate(child, &el.name, first);
                }
                system_at = Some(child.location);
                let mut known = vec![
                    "threads",
                    "method",
                    "pin_threads_to_cores",
                    "realtime_priority",
                ];
                known.extend(Limits::NAMES);
                ctx.unknown_attributes(child, &known);
                for name in Limits::NAMES {
                    if let Some(attribute) = child.attributes.get(name)
                        && let Err(e) = limits.set(name, &attribute.value)
                    {
                        ctx.error(attribute.location, format!("in <system>: {e}"), None);
                    }
                }
                threads = ctx.attr(child, "threads").unwrap_or(0);
                pin_agents = ctx.attr(child, "pin_threads_to_cores").unwrap_or(true);
                realtime_priority = ctx.attr(child, "realtime_priority").unwrap_or(true);
            }
            "experiment" => match experiment {
                Some((_, first)) => ctx.duplicate(child, &el.name, first),
                None => experiment = Some((child, child.location)),
            },
            "profiling" => ctx.warn(
                child.location,
                "<profiling> is ignored: use `cargo bench` and the run log",
                None,
            ),
            "hosts" => {
                let (parsed, errors) = crate::config::hosts::parse(child, ctx.base_dir());
                for (at, message) in errors {
                    ctx.error(at, message, None);
                }
                hosts = parsed;
            }
            _ => ctx.unknown_element(child, &el.name, CHILDREN),
        }
    }
    let Some((exp, location)) = experiment else {
        ctx.error(el.location, "<framework> has no <experiment> element", None);
        return None;
    };
    ctx.unknown_attributes(
        exp,
        &[
            "length",
            "ticks_per_second",
            "random_seed",
            "real_time",
            "visualization",
        ],
    );
    let length_seconds: f64 = ctx.attr(exp, "length").unwrap_or(0.0);
    ctx.in_range(exp, "length", length_seconds, 0.0, None);
    let ticks_per_second: u32 = ctx.required(exp, "ticks_per_second")?;
    if ticks_per_second == 0 {
        let at = exp
            .attributes
            .get("ticks_per_second")
            .map_or(location, |a| a.location);
        ctx.error(
            at,
            "'ticks_per_second' in <experiment> must be greater than 0",
            None,
        );
        return None;
    }
    let random_seed = ctx
        .attr::<u64>(exp, "random_seed")
        .filter(|&seed| seed != 0);
    if random_seed.is_none() {
        ctx.warn(
            location,
            "no random_seed (absent or 0): the launcher draws one from the clock and prints it",
            None,
        );
    }
    Some(Framework {
        threads,
        pin_agents,
        realtime_priority,
        limits,
        hosts,
        length_seconds,
        ticks_per_second,
        random_seed,
        location,
    })
}
