//! The experiment configuration: the `.argos` format (ARGoS' XML) read into a typed, located model.
//!
//! - [`model`]: the types the launcher and the world build from; every item knows its line and column.
//! - [`diagnostic`]: located errors and warnings, `file:line:column: message (hint)`.
//! - `xml` reads the text into a located element tree, `parse` interprets it section by section and `registry`
//!   maps device names to kinds.
//!
//! `docs/configuration.md` lists every supported element and attribute, our extensions, and the controller params
//! the agent's profiles read. This module never depends on the world or the robot agent, and never panics on user
//! input: every problem becomes a [`Diagnostic`].

pub mod diagnostic;
pub mod faults;
pub mod hosts;
pub mod input;
pub mod model;
mod parse;
mod registry;
mod robot_count;
pub mod suggest;
mod values;
mod xml;

use std::path::Path;

pub use diagnostic::{ConfigErrors, Diagnostic};
pub use model::*;

impl Experiment {
    /// Reads and checks an experiment file. On success returns the experiment and its warnings (harmless
    /// unsupported elements and attributes, a seed left to the clock, ...); on failure every error found, each
    /// located `file:line:column`.
    pub fn load(path: impl AsRef<Path>) -> Result<(Experiment, Vec<Diagnostic>), ConfigErrors> {
        parse::load(path.as_ref())
    }

    /// Parses configuration text as if it had been read from `path` (used for messages and relative paths).
    pub fn parse(
        path: impl AsRef<Path>,
        text: &str,
    ) -> Result<(Experiment, Vec<Diagnostic>), ConfigErrors> {
        parse::parse_str(path.as_ref(), text)
    }
}

/// The sections that complete a test experiment after its `<framework>` (and any section under test): one
/// controller `oa`, a small empty arena, the physics engine and no media.
#[cfg(test)]
pub(crate) const TEST_SECTIONS: &str = "<controllers><test_controller id=\"oa\" library=\"agent\"><actuators/>\
    <sensors/><params/></test_controller></controllers>\n<arena size=\"1,1,1\" center=\"0,0,0.5\"/>\n\
    <physics_engines><dynamics2d id=\"d\"/></physics_engines>\n<media/>";
