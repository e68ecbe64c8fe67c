//! `<distribute>` blocks of the arena: how many entities of a kind, placed where and turned how.

use super::Ctx;
use super::arena::{ENTITIES, entity};
use crate::config::model::{Distribute, Element, Euler, OrientationMethod, PositionMethod, Vec3};
use crate::config::suggest::did_you_mean;

const DISTRIBUTE_CHILDREN: &[&str] = &["position", "orientation", "entity"];

/// Parses `<distribute>`: exactly one `<position>`, `<orientation>` and `<entity>`.
pub(super) fn distribute(ctx: &mut Ctx, el: &Element) -> Option<Distribute> {
    ctx.unknown_attributes(el, &[]);
    let mut parts: [Option<&Element>; 3] = [None, None, None];
    for child in &el.children {
        match DISTRIBUTE_CHILDREN.iter().position(|n| *n == child.name) {
            Some(i) => match parts[i] {
                Some(first) => ctx.duplicate(child, &el.name, first.location),
                None => parts[i] = Some(child),
            },
            None => ctx.unknown_element(child, &el.name, DISTRIBUTE_CHILDREN),
        }
    }
    for (part, name) in parts.iter().zip(DISTRIBUTE_CHILDREN) {
        if part.is_none() {
            ctx.error(el.location, format!("<distribute> has no <{name}>"), None);
        }
    }
    let [position_el, orientation_el, entity_el] = parts;
    let position = position_el.and_then(|p| position_method(ctx, p));
    let orientation = orientation_el.and_then(|o| orientation_method(ctx, o));
    let entity_el = entity_el?;
    ctx.unknown_attributes(entity_el, &["quantity", "max_trials", "base_num"]);
    let quantity: Option<u32> = ctx.required(entity_el, "quantity");
    let max_trials: Option<u32> = ctx.required(entity_el, "max_trials");
    let base_num: u32 = ctx.attr(entity_el, "base_num").unwrap_or(0);
    let template = match entity_el.children.as_slice() {
        [one] if ENTITIES.contains(&one.name.as_str()) => entity(ctx, one, false).1,
        [one] => {
            let hint = did_you_mean(&one.name, ENTITIES.iter().copied());
            ctx.error(
                one.location,
                format!("<{}> cannot be distributed", one.name),
                hint,
            );
            None
        }
        children => {
            ctx.error(
                entity_el.location,
                format!(
                    "<entity> must contain exactly one entity template, found {}",
                    children.len()
                ),
                None,
            );
            None
        }
    };
    let (position, quantity) = (position?, quantity?);
    if let PositionMethod::Grid { layout, .. } = &position {
        let cells = layout.iter().map(|&n| u64::from(n)).product::<u64>();
        if u64::from(quantity) > cells {
            let at = entity_el
                .attributes
                .get("quantity")
                .map_or(entity_el.location, |a| a.location);
            ctx.error(
                at,
                format!(
                    "quantity {quantity} exceeds the grid layout's {}x{}x{} = {cells} cells",
                    layout[0], layout[1], layout[2]
                ),
                None,
            );
            return None;
        }
    }
    Some(Distribute {
        position,
        orientation: orientation?,
        quantity,
        max_trials: max_trials?,
        base_num,
        template: template?,
        location: el.location,
        position_location: position_el.map_or(el.location, |p| p.location),
        orientation_location: orientation_el.map_or(el.location, |o| o.location),
        entity_location: entity_el.location,
    })
}

const POSITION_METHODS: &[&str] = &["uniform", "gaussian", "constant", "grid"];
const ORIENTATION_METHODS: &[&str] = &["uniform", "gaussian", "constant"];

/// The `method` attribute, checked against `methods`.
fn method<'a>(ctx: &mut Ctx, el: &'a Element, methods: &[&str]) -> Option<&'a str> {
    let Some(attribute) = el.attributes.get("method") else {
        ctx.error(
            el.location,
            format!("<{}> is missing the attribute 'method'", el.name),
            None,
        );
        return None;
    };
    let method = attribute.value.trim();
    if methods.contains(&method) {
        return Some(method);
    }
    let hint = if method == "grid" {
        Some("grid places positions only".to_string())
    } else {
        did_you_mean(method, methods.iter().copied())
    };
    ctx.error(
        attribute.location,
        format!(
            "unknown {} method '{method}' (expected {})",
            el.name,
            methods.join(", ")
        ),
        hint,
    );
    None
}

fn position_method(ctx: &mut Ctx, el: &Element) -> Option<PositionMethod> {
    let method = method(ctx, el, POSITION_METHODS)?;
    let generator = match method {
        "uniform" => {
            ctx.unknown_attributes(el, &["method", "min", "max"]);
            let (min, max) = (ctx.required(el, "min"), ctx.required(el, "max"));
            let (min, max): (Vec3, Vec3) = (min?, max?);
            uniform_bounds(
                ctx,
                el,
                [min.x, min.y, min.z],
                [max.x, max.y, max.z],
                &min.to_string(),
                &max.to_string(),
            )?;
            PositionMethod::Uniform { min, max }
        }
        "gaussian" => {
            ctx.unknown_attributes(el, &["method", "mean", "std_dev"]);
            let (mean, std_dev) = (ctx.required(el, "mean"), ctx.required(el, "std_dev"));
            let (mean, std_dev): (Vec3, Vec3) = (mean?, std_dev?);
            non_negative_std_dev(ctx, el, [std_dev.x, std_dev.y, std_dev.z])?;
            PositionMethod::Gaussian { mean, std_dev }
        }
        "constant" => {
            ctx.unknown_attributes(el, &["method", "values"]);
            PositionMethod::Constant {
                values: ctx.required(el, "values")?,
            }
        }
        _ => {
            ctx.unknown_attributes(el, &["method", "center", "distances", "layout"]);
            let center = ctx.required(el, "center");
            let distances = ctx.required(el, "distances");
            let layout: Option<[u32; 3]> = ctx.required(el, "layout");
            let layout = layout.filter(|l| {
                let ok = l.iter().all(|&n| n >= 1);
                if !ok {
                    let at = el
                        .attributes
                        .get("layout")
                        .map_or(el.location, |a| a.location);
                    ctx.error(
                        at,
                        format!(
                            "grid 'layout' needs at least 1 cell along each axis, got {},{},{}",
                            l[0], l[1], l[2]
                        ),
                        None,
                    );
                }
                ok
            });
            PositionMethod::Grid {
                center: center?,
                distances: distances?,
                layout: layout?,
            }
        }
    };
    Some(generator)
}

fn orientation_method(ctx: &mut Ctx, el: &Element) -> Option<OrientationMethod> {
    let method = method(ctx, el, ORIENTATION_METHODS)?;
    let generator = match method {
        "uniform" => {
            ctx.unknown_attributes(el, &["method", "min", "max"]);
            let (min, max) = (ctx.required(el, "min"), ctx.required(el, "max"));
            let (min, max): (Euler, Euler) = (min?, max?);
            let text = |e: Euler| format!("{},{},{}", e.z_deg, e.y_deg, e.x_deg);
            uniform_bounds(
                ctx,
                el,
                [min.z_deg, min.y_deg, min.x_deg],
                [max.z_deg, max.y_deg, max.x_deg],
                &text(min),
                &text(max),
            )?;
            OrientationMethod::Uniform { min, max }
        }
        "gaussian" => {
            ctx.unknown_attributes(el, &["method", "mean", "std_dev"]);
            let (mean, std_dev) = (ctx.required(el, "mean"), ctx.required(el, "std_dev"));
            let (mean, std_dev): (Euler, Euler) = (mean?, std_dev?);
            non_negative_std_dev(ctx, el, [std_dev.z_deg, std_dev.y_deg, std_dev.x_deg])?;
            OrientationMethod::Gaussian { mean, std_dev }
        }
        _ => {
            ctx.unknown_attributes(el, &["method", "values"]);
            OrientationMethod::Constant {
                values: ctx.required(el, "values")?,
            }
        }
    };
    Some(generator)
}

/// `uniform` needs min <= max in every component (a component with min = max is constant).
fn uniform_bounds(
    ctx: &mut Ctx,
    el: &Element,
    min: [f64; 3],
    max: [f64; 3],
    min_text: &str,
    max_text: &str,
) -> Option<()> {
    let axes = if el.name == "orientation" {
        ["z", "y", "x"]
    } else {
        ["x", "y", "z"]
    };
    let bad: Vec<&str> = (0..3)
        .filter(|&i| min[i] > max[i])
        .map(|i| axes[i])
        .collect();
    if bad.is_empty() {
        return Some(());
    }
    let at = el.attributes.get("min").map_or(el.location, |a| a.location);
    ctx.error(
        at,
        format!(
            "uniform {} min '{min_text}' exceeds max '{max_text}' in {}",
            el.name,
            bad.join(", ")
        ),
        None,
    );
    None
}

fn non_negative_std_dev(ctx: &mut Ctx, el: &Element, std_dev: [f64; 3]) -> Option<()> {
    if std_dev.iter().all(|&s| s >= 0.0) {
        return Some(());
    }
    let at = el
        .attributes
        .get("std_dev")
        .map_or(el.location, |a| a.location);
    ctx.error(
        at,
        format!("gaussian {} 'std_dev' must not be negative", el.name),
        None,
    );
    None
}
