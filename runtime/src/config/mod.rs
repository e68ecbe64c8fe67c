//! The experiment configuration: the `.argos` format (ARGoS' XML) read into a typed, located model.
//!
//! - [`model`]: the types the launcher and the world build from; every item knows its line and column.
//! - [`diagnostic`]: located errors and warnings, `file:line:column: message (hint)`.
//!
//! `docs/configuration.md` lists every supported element and attribute and our extensions. This module never
//! depends on the world or the robot agent, and never panics on user input.

pub mod diagnostic;
pub mod model;

pub use diagnostic::{ConfigErrors, Diagnostic};
pub use model::*;
