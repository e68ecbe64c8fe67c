//! `<coordinators>` (our extension): processes of a run that are not robots, each running a controller of
//! `<controllers>` in lockstep with the world (docs/messages.md, "Coordinators").

use super::Ctx;
use super::arena::controller_ref;
use crate::config::model::{Coordinator, Element};

/// Parses `<coordinators>`: `<coordinator id>` children, each with one `<controller config>`.
pub(super) fn coordinators(ctx: &mut Ctx, el: &Element) -> Vec<Coordinator> {
    ctx.unknown_attributes(el, &[]);
    let (children, _) = ctx.children_named(el, "coordinator");
    let mut coordinators: Vec<Coordinator> = Vec::new();
    for child in children {
        ctx.unknown_attributes(child, &["id"]);
        for other in child.children.iter().filter(|c| c.name != "controller") {
            ctx.unknown_element(other, &child.name, &["controller"]);
        }
        let id: Option<String> = ctx.required(child, "id");
        let controller = controller_ref(ctx, child);
        let (Some(id), Some(controller)) = (id, controller) else {
            continue;
        };
        if let Some(first) = coordinators.iter().find(|c| c.id == id) {
            ctx.error(
                child.location,
                format!(
                    "duplicate coordinator id '{id}' (first at {})",
                    first.location
                ),
                None,
            );
            continue;
        }
        coordinators.push(Coordinator {
            id,
            controller,
            location: child.location,
        });
    }
    coordinators
}
