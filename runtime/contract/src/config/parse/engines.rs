//! `<physics_engines>` (one `dynamics2d`) and `<media>` (`led`, `range_and_bearing`, our `pheromone` and
//! `messages`).

use super::Ctx;
use crate::config::model::{
    Element, Location, Media, Medium, MessagesMedium, PheromoneChannel, PheromoneField,
    PhysicsEngine,
};
use crate::mail::{MAIL_PAYLOAD_BYTES, MAILBOX_CAPACITY};
use crate::messages::PHEROMONE_CHANNELS;

const ENGINES: &[&str] = &["dynamics2d"];
/// ARGoS engines we recognise but do not implement (the world is 2-D and has one engine).
const UNSUPPORTED_ENGINES: &[&str] = &["dynamics3d", "pointmass3d", "physx", "dynamics2d_multi"];

/// Parses `<physics_engines>`: exactly one `<dynamics2d>`.
pub(super) fn physics_engines(ctx: &mut Ctx, el: &Element) -> Option<PhysicsEngine> {
    ctx.unknown_attributes(el, &[]);
    let mut engine: Option<PhysicsEngine> = None;
    for child in &el.children {
        match child.name.as_str() {
            "dynamics2d" => {
                if let Some(first) = &engine {
                    ctx.error(
                        child.location,
                        format!("a second physics engine (first at {}): the world runs one dynamics2d engine over the whole arena", first.location),
                        None,
                    );
                    continue;
                }
                engine = dynamics2d(ctx, child);
            }
            name if UNSUPPORTED_ENGINES.contains(&name) => ctx.error(
                child.location,
                format!("physics engine <{name}> is not supported: the world is 2-D"),
                Some("use <dynamics2d id=\"dyn2d\"/>".to_string()),
            ),
            _ => ctx.unknown_element(child, &el.name, ENGINES),
        }
    }
    if engine.is_none() && !el.children.iter().any(|c| c.name == "dynamics2d") {
        ctx.error(
            el.location,
            "<physics_engines> declares no engine",
            Some("add <dynamics2d id=\"dyn2d\"/>".to_string()),
        );
    }
    engine
}

fn dynamics2d(ctx: &mut Ctx, el: &Element) -> Option<PhysicsEngine> {
    ctx.unknown_attributes(el, &["id", "iterations"]);
    for child in &el.children {
        match child.name.as_str() {
            "boundaries" => ctx.warn(
                child.location,
                "<boundaries> is ignored: the engine covers the whole arena",
                None,
            ),
            _ => ctx.unknown_element(child, &el.name, &["boundaries"]),
        }
    }
    let id: String = ctx.required(el, "id")?;
    let iterations: u32 = ctx.attr(el, "iterations").unwrap_or(10);
    if !ctx.in_range(el, "iterations", f64::from(iterations), 1.0, None) {
        return None;
    }
    Some(PhysicsEngine {
        id,
        iterations,
        location: el.location,
    })
}

const MEDIA: &[&str] = &["led", "range_and_bearing", "pheromone", "messages"];
/// ARGoS media we recognise but do not implement.
const UNSUPPORTED_MEDIA: &[&str] = &["directional_led", "simple_radio", "tag", "radio"];

/// Parses `<media>`; at most one medium of each kind, ids unique across kinds.
pub(super) fn media(ctx: &mut Ctx, el: &Element) -> Media {
    ctx.unknown_attributes(el, &[]);
    let mut media = Media::default();
    let mut ids: Vec<(String, Location)> = Vec::new();
    for child in &el.children {
        let id = match child.name.as_str() {
            "led" | "range_and_bearing" => {
                let is_led = child.name == "led";
                let slot_taken = if is_led {
                    &media.leds
                } else {
                    &media.range_and_bearing
                }
                .as_ref()
                .map(|m| m.location);
                if let Some(first) = slot_taken {
                    ctx.error(
                        child.location,
                        format!(
                            "a second <{}> medium (first at {first}): only one is supported",
                            child.name
                        ),
                        None,
                    );
                    continue;
                }
                let Some(medium) = medium(ctx, child) else {
                    continue;
                };
                let id = medium.id.clone();
                if is_led {
                    media.leds = Some(medium);
                } else {
                    media.range_and_bearing = Some(medium);
                }
                id
            }
            "pheromone" => {
                if let Some(first) = &media.pheromone {
                    ctx.error(
                        child.location,
                        format!(
                            "a second <pheromone> field (first at {}): only one is supported",
                            first.location
                        ),
                        None,
                    );
                    continue;
                }
                let Some(field) = pheromone(ctx, child) else {
                    continue;
                };
                let id = field.id.clone();
                media.pheromone = Some(field);
                id
            }
            "messages" => {
                if let Some(first) = &media.messages {
                    ctx.error(
                        child.location,
                        format!(
                            "a second <messages> medium (first at {}): only one is supported",
                            first.location
                        ),
                        None,
                    );
                    continue;
                }
                let Some(medium) = messages(ctx, child) else {
                    continue;
                };
                let id = medium.id.clone();
                media.messages = Some(medium);
                id
            }
            name if UNSUPPORTED_MEDIA.contains(&name) => {
                ctx.error(
                    child.location,
                    format!("medium <{name}> is not supported"),
                    Some(
                        "supported media: led, range_and_bearing, pheromone, messages".to_string(),
                    ),
                );
                continue;
            }
            _ => {
                ctx.unknown_element(child, &el.name, MEDIA);
                continue;
            }
        };
        if let Some((_, first)) = ids.iter().find(|(known, _)| *known == id) {
            ctx.error(
                child.location,
                format!("duplicate medium id '{id}' (first at {first})"),
                None,
            );
        }
        ids.push((id, child.location));
    }
    media
}

fn medium(ctx: &mut Ctx, el: &Element) -> Option<Medium> {
    ctx.unknown_attributes(el, &["id", "grid_size", "index"]);
    for child in &el.children {
        ctx.unknown_element(child, &el.name, &[]);
    }
    let id: String = ctx.required(el, "id")?;
    let grid_size: Option<[u32; 3]> = ctx.attr(el, "grid_size");
    Some(Medium {
        id,
        grid_size,
        location: el.location,
    })
}

/// Default of `<messages max_per_tick>`.
const DEFAULT_MESSAGES_PER_TICK: u32 = 8;

/// `<messages id range loss max_payload max_per_tick>`.
fn messages(ctx: &mut Ctx, el: &Element) -> Option<MessagesMedium> {
    ctx.unknown_attributes(el, &["id", "range", "loss", "max_payload", "max_per_tick"]);
    for child in &el.children {
        ctx.unknown_element(child, &el.name, &[]);
    }
    let id: Option<String> = ctx.required(el, "id");
    let range = if el.attributes.contains_key("range") {
        Some(ctx.positive(el, "range")?)
    } else {
        None
    };
    let loss: f64 = ctx.attr(el, "loss").unwrap_or(0.0);
    let max_payload: u32 = ctx
        .attr(el, "max_payload")
        .unwrap_or(MAIL_PAYLOAD_BYTES as u32);
    let max_per_tick: u32 = ctx
        .attr(el, "max_per_tick")
        .unwrap_or(DEFAULT_MESSAGES_PER_TICK);
    let loss_ok = ctx.in_range(el, "loss", loss, 0.0, Some(1.0));
    let payload_ok = ctx.in_range(
        el,
        "max_payload",
        f64::from(max_payload),
        1.0,
        Some(MAIL_PAYLOAD_BYTES as f64),
    );
    let per_tick_ok = ctx.in_range(
        el,
        "max_per_tick",
        f64::from(max_per_tick),
        1.0,
        Some(MAILBOX_CAPACITY as f64),
    );
    (loss_ok && payload_ok && per_tick_ok).then_some(())?;
    Some(MessagesMedium {
        id: id?,
        range,
        loss,
        max_payload,
        max_per_tick,
        location: el.location,
    })
}

/// `<pheromone id cell_size>` with 1..=PHEROMONE_CHANNELS `<channel name evaporation diffusion>` children.
fn pheromone(ctx: &mut Ctx, el: &Element) -> Option<PheromoneField> {
    ctx.unknown_attributes(el, &["id", "cell_size"]);
    let id: Option<String> = ctx.required(el, "id");
    let cell_size = ctx.positive(el, "cell_size");
    let mut channels: Vec<PheromoneChannel> = Vec::new();
    let (children, mut ok) = ctx.children_named(el, "channel");
    for child in children {
        let Some(channel) = channel(ctx, child) else {
            ok = false;
            continue;
        };
        if let Some(first) = channels.iter().find(|c| c.name == channel.name) {
            ctx.error(
                child.location,
                format!(
                    "duplicate pheromone channel '{}' (first at {})",
                    channel.name, first.location
                ),
                None,
            );
            ok = false;
            continue;
        }
        channels.push(channel);
    }
    if channels.is_empty() && ok {
        ctx.error(
            el.location,
            "<pheromone> declares no <channel>",
            Some("add e.g. <channel name=\"food\" evaporation=\"0.001\"/>".to_string()),
        );
        return None;
    }
    if channels.len() > PHEROMONE_CHANNELS {
        ctx.error(
            channels[PHEROMONE_CHANNELS].location,
            format!("<pheromone> declares {} channels; the sensor frame carries at most {PHEROMONE_CHANNELS}", channels.len()),
            None,
        );
        return None;
    }
    if !ok {
        return None;
    }
    Some(PheromoneField {
        id: id?,
        cell_size: cell_size?,
        channels,
        location: el.location,
    })
}

fn channel(ctx: &mut Ctx, el: &Element) -> Option<PheromoneChannel> {
    ctx.unknown_attributes(el, &["name", "evaporation", "diffusion"]);
    let name: Option<String> = ctx.required(el, "name");
    let evaporation: Option<f64> = ctx.required(el, "evaporation");
    let diffusion: f64 = ctx.attr(el, "diffusion").unwrap_or(0.0);
    let evaporation = evaporation.filter(|&e| ctx.in_range(el, "evaporation", e, 0.0, Some(1.0)));
    let diffusion_ok = ctx.in_range(el, "diffusion", diffusion, 0.0, Some(1.0));
    diffusion_ok.then_some(())?;
    Some(PheromoneChannel {
        name: name?,
        evaporation: evaporation?,
        diffusion,
        location: el.location,
    })
}
