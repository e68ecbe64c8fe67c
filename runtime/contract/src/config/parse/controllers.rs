//! `<controllers>` (controller types with their sensors, actuators and params) and `<loop_functions>`.

use super::{Ctx, MediumRef};
use crate::config::model::{Controller, Device, DeviceRole, Element, Location, LoopFunctions};
use crate::config::registry::{self, Entry, MediumKind};
use crate::config::suggest::did_you_mean;

const CONTROLLER_CHILDREN: &[&str] = &["actuators", "sensors", "params"];
const COMMON_DEVICE_ATTRIBUTES: &[&str] = &[
    "implementation",
    "noise_level",
    "noise_std_dev",
    "medium",
    "show_rays",
];

/// Parses `<controllers>`; controllers with errors are left out (their errors are recorded).
pub(super) fn controllers(ctx: &mut Ctx, el: &Element) -> Vec<Controller> {
    ctx.unknown_attributes(el, &[]);
    let mut out: Vec<Controller> = Vec::new();
    for child in &el.children {
        let Some(controller) = controller(ctx, child) else {
            continue;
        };
        if let Some(first) = out.iter().find(|c| c.id == controller.id) {
            let at = child
                .attributes
                .get("id")
                .map_or(child.location, |a| a.location);
            ctx.error(
                at,
                format!(
                    "duplicate controller id '{}' (first at {})",
                    controller.id, first.location
                ),
                None,
            );
            continue;
        }
        out.push(controller);
    }
    out
}

fn controller(ctx: &mut Ctx, el: &Element) -> Option<Controller> {
    ctx.unknown_attributes(el, &["id", "library"]);
    let id: Option<String> = ctx.required(el, "id");
    let library: String = ctx.attr(el, "library").unwrap_or_default();
    let label = id.clone().unwrap_or_else(|| el.name.clone());
    let mut actuators: Option<(Vec<Device>, Location)> = None;
    let mut sensors: Option<(Vec<Device>, Location)> = None;
    let mut params: Option<&Element> = None;
    for child in &el.children {
        match child.name.as_str() {
            "actuators" | "sensors" => {
                let (role, slot) = if child.name == "actuators" {
                    (DeviceRole::Actuator, &mut actuators)
                } else {
                    (DeviceRole::Sensor, &mut sensors)
                };
                match slot {
                    Some((_, first)) => ctx.duplicate(child, &el.name, *first),
                    None => *slot = Some((devices(ctx, child, role, &label), child.location)),
                }
            }
            "params" => match params {
                Some(first) => ctx.duplicate(child, &el.name, first.location),
                None => params = Some(child),
            },
            _ => ctx.unknown_element(child, &el.name, CONTROLLER_CHILDREN),
        }
    }
    if let Some(params) = params {
        runtime_params(ctx, params);
    }
    let params = params.cloned().unwrap_or_else(|| Element {
        name: "params".to_string(),
        location: el.location,
        ..Element::default()
    });
    Some(Controller {
        tag: el.name.clone(),
        id: id?,
        library,
        actuators: actuators.map(|(d, _)| d).unwrap_or_default(),
        sensors: sensors.map(|(d, _)| d).unwrap_or_default(),
        params,
        location: el.location,
    })
}

/// Checks the params the runtime itself reads (`profile`, `supervisors`, `velocity`); the rest belongs to the
/// profile and is passed on unchecked.
fn runtime_params(ctx: &mut Ctx, params: &Element) {
    if let Some(profile) = params.attributes.get("profile")
        && profile.value.trim().is_empty()
    {
        ctx.error(
            profile.location,
            "'profile' in <params> is empty",
            Some("name an agent profile, e.g. obstacle_avoidance".to_string()),
        );
    }
    if let Some(list) = params.attributes.get("supervisors")
        && list.value.split(',').any(|p| p.trim().is_empty())
    {
        ctx.error(
            list.location,
            format!(
                "'supervisors' in <params> has an empty entry: '{}'",
                list.value
            ),
            Some("separate supervisor files with single commas".to_string()),
        );
    }
    if params.attributes.contains_key("velocity")
        && let Some(velocity) = ctx.attr::<f64>(params, "velocity")
    {
        ctx.in_range(params, "velocity", velocity, 0.0, None);
    }
}

/// The children of `<sensors>` or `<actuators>`.
fn devices(ctx: &mut Ctx, el: &Element, role: DeviceRole, controller: &str) -> Vec<Device> {
    ctx.unknown_attributes(el, &[]);
    let noun = registry::noun(role);
    let mut out: Vec<Device> = Vec::new();
    for child in &el.children {
        let Some(entry) = registry::lookup(role, &child.name) else {
            unknown_device(ctx, child, role, controller);
            continue;
        };
        if let Some(first) = out.iter().find(|d| d.name == child.name) {
            ctx.error(
                child.location,
                format!(
                    "duplicate {noun} '{}' in controller '{controller}' (first at {})",
                    child.name, first.location
                ),
                None,
            );
            continue;
        }
        if let Some(device) = device(ctx, child, entry, controller) {
            out.push(device);
        }
    }
    out
}

fn unknown_device(ctx: &mut Ctx, child: &Element, role: DeviceRole, controller: &str) {
    let noun = registry::noun(role);
    let other = match role {
        DeviceRole::Sensor => DeviceRole::Actuator,
        DeviceRole::Actuator => DeviceRole::Sensor,
    };
    if registry::lookup(other, &child.name).is_some() {
        ctx.error(
            child.location,
            format!(
                "'{}' is {} {}, not {} {noun}, in controller '{controller}'",
                child.name,
                article(other),
                registry::noun(other),
                article(role)
            ),
            Some(format!("declare it under <{}>", registry::section(other))),
        );
    } else {
        let hint = did_you_mean(&child.name, registry::names(role));
        ctx.error(
            child.location,
            format!(
                "unknown {noun} '{}' in controller '{controller}'",
                child.name
            ),
            hint,
        );
    }
}

fn article(role: DeviceRole) -> &'static str {
    match role {
        DeviceRole::Sensor => "a",
        DeviceRole::Actuator => "an",
    }
}

fn device(ctx: &mut Ctx, el: &Element, entry: &Entry, controller: &str) -> Option<Device> {
    let known: Vec<&str> = COMMON_DEVICE_ATTRIBUTES
        .iter()
        .chain(entry.attributes)
        .copied()
        .collect();
    ctx.unknown_attributes(el, &known);
    let user = format!(
        "{} '{}' in controller '{controller}'",
        registry::noun(entry.role),
        entry.name
    );
    let implementation = ctx
        .attr(el, "implementation")
        .unwrap_or_else(|| "default".to_string());
    let noise_level: f64 = ctx.attr(el, "noise_level").unwrap_or(0.0);
    let noise_std_dev: f64 = ctx.attr(el, "noise_std_dev").unwrap_or(0.0);
    let noise_ok = ctx.in_range(el, "noise_level", noise_level, 0.0, None)
        & ctx.in_range(el, "noise_std_dev", noise_std_dev, 0.0, None);
    if let Some(show_rays) = el.attributes.get("show_rays") {
        let _: Option<bool> = ctx.attr(el, "show_rays");
        ctx.warn(
            show_rays.location,
            "'show_rays' is ignored: there is no GUI to draw rays in",
            None,
        );
    }
    let attributes_ok = device_attributes(ctx, el);
    let medium: Option<String> = ctx.attr(el, "medium");
    match (entry.medium, &medium) {
        (Some(kind), Some(id)) => ctx.medium_refs.push(MediumRef {
            id: id.clone(),
            kind,
            location: el
                .attributes
                .get("medium")
                .map_or(el.location, |a| a.location),
            user: user.clone(),
        }),
        // ARGoS' range-and-bearing actuator names no medium: it emits into the one the sensor listens to.
        (Some(MediumKind::RangeAndBearing), None) if entry.role == DeviceRole::Actuator => {}
        (Some(kind), None) => ctx.error(
            el.location,
            format!("{user} needs a 'medium' naming a <{}> medium", kind.tag()),
            None,
        ),
        (None, Some(_)) => ctx.warn(
            el.attributes
                .get("medium")
                .map_or(el.location, |a| a.location),
            format!("'medium' is ignored: {user} uses no medium"),
            None,
        ),
        (None, None) => {}
    }
    (noise_ok && attributes_ok).then(|| Device {
        name: el.name.clone(),
        kind: entry.kind,
        role: entry.role,
        implementation,
        noise_level,
        noise_std_dev,
        medium: entry.medium.and(medium),
        body: entry.body,
        attributes: Element {
            children: Vec::new(),
            ..el.clone()
        },
        location: el.location,
    })
}

/// Checks the syntax and range of the device-specific attributes the registry lists.
fn device_attributes(ctx: &mut Ctx, el: &Element) -> bool {
    let mut ok = true;
    for name in el.attributes.keys() {
        ok &= match name.as_str() {
            "data_size" => ctx
                .attr::<u32>(el, name)
                .is_some_and(|v| ctx.in_range(el, name, f64::from(v), 1.0, Some(4.0))),
            "max_packets" => ctx.attr::<u32>(el, name).is_some(),
            "range" => ctx
                .attr::<f64>(el, name)
                .is_some_and(|v| ctx.in_range(el, name, v, 0.0, None)),
            "pickup_gap" => ctx
                .attr::<f64>(el, name)
                .is_some_and(|v| ctx.in_range(el, name, v, 0.0, None)),
            "loss_probability" => ctx
                .attr::<f64>(el, name)
                .is_some_and(|v| ctx.in_range(el, name, v, 0.0, Some(1.0))),
            "real_range_noise" | "argos_uniform_ring" => ctx.attr::<bool>(el, name).is_some(),
            _ => true,
        };
    }
    ok
}

/// Parses `<loop_functions label library>`; its whole subtree is kept for the loop functions.
pub(super) fn loop_functions(ctx: &mut Ctx, el: &Element) -> Option<LoopFunctions> {
    let label: String = ctx.required(el, "label")?;
    let library: String = ctx.attr(el, "library").unwrap_or_default();
    Some(LoopFunctions {
        label,
        library,
        params: el.clone(),
        location: el.location,
    })
}
