//! `<floor>` of the arena: its colour from the loop functions, an image, or rectangular regions.

use super::Ctx;
use super::arena::color;
use crate::config::model::{Element, Floor, FloorRegion, FloorSource};
use crate::config::suggest::did_you_mean;
use crate::messages::Rgb;

/// Default floor resolution when `pixels_per_meter` is absent.
const PIXELS_PER_METER: f64 = 50.0;

const FLOOR_SOURCES: &[&str] = &["loop_functions", "image", "regions"];

/// Parses `<floor>`: its id, its source and what that source needs.
pub(super) fn parse_floor(ctx: &mut Ctx, el: &Element) -> Option<Floor> {
    ctx.unknown_attributes(el, &["id", "source", "pixels_per_meter", "path", "color"]);
    let id: Option<String> = ctx.required(el, "id");
    let source: Option<String> = ctx.required(el, "source");
    let pixels_per_meter: f64 = ctx.attr(el, "pixels_per_meter").unwrap_or(PIXELS_PER_METER);
    let ppm_ok = pixels_per_meter > 0.0 || {
        let at = el
            .attributes
            .get("pixels_per_meter")
            .map_or(el.location, |a| a.location);
        ctx.error(
            at,
            format!("'pixels_per_meter' in <floor> must be greater than 0, got {pixels_per_meter}"),
            None,
        );
        false
    };
    let source = match source.as_deref()? {
        "regions" => regions(ctx, el)?,
        other => {
            for child in &el.children {
                ctx.error(
                    child.location,
                    format!(
                        "<{}> is not allowed in a <floor source=\"{other}\">",
                        child.name
                    ),
                    (child.name == "region")
                        .then(|| "use source=\"regions\" to paint regions".to_string()),
                );
            }
            match other {
                "loop_functions" => FloorSource::LoopFunctions,
                "image" => FloorSource::Image {
                    path: ctx.required(el, "path")?,
                },
                _ => {
                    let at = el
                        .attributes
                        .get("source")
                        .map_or(el.location, |a| a.location);
                    let hint = did_you_mean(other, FLOOR_SOURCES.iter().copied());
                    ctx.error(at, format!("unknown floor source '{other}' (expected loop_functions, image or regions)"), hint);
                    return None;
                }
            }
        }
    };
    ppm_ok.then_some(())?;
    Some(Floor {
        id: id?,
        source,
        pixels_per_meter,
        location: el.location,
    })
}

/// `<floor source="regions" color>` with `<region min max color>` children.
fn regions(ctx: &mut Ctx, el: &Element) -> Option<FloorSource> {
    let background = color(
        ctx,
        el,
        Some(Rgb {
            r: 255,
            g: 255,
            b: 255,
        }),
    );
    let mut regions = Vec::new();
    let (children, mut ok) = ctx.children_named(el, "region");
    for child in children {
        ctx.unknown_attributes(child, &["min", "max", "color"]);
        let min = ctx.required(child, "min");
        let max = ctx.required(child, "max");
        let color = color(ctx, child, None);
        let (Some(min), Some(max), Some(color)) = (min, max, color) else {
            ok = false;
            continue;
        };
        let (min, max): (crate::config::model::Vec2, crate::config::model::Vec2) = (min, max);
        if min.x > max.x || min.y > max.y {
            ctx.error(
                child.location,
                format!("<region> min '{min}' exceeds max '{max}'"),
                None,
            );
            ok = false;
            continue;
        }
        regions.push(FloorRegion {
            min,
            max,
            color,
            location: child.location,
        });
    }
    ok.then_some(())?;
    Some(FloorSource::Regions {
        background: background?,
        regions,
    })
}
