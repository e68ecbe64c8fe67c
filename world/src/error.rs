//! The world's typed errors. Every error that comes from a configuration names the place in the file
//! (`path:line:column`) and says what is wrong and, where it helps, what to do.

use std::path::PathBuf;

/// Everything that can go wrong while building, running or recording a world.
#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    /// `<distribute>` could not place every entity without collisions.
    #[error(
        "{location}: <distribute> placed only {placed} of {quantity} '{base}' entities: entity '{id}' still collided \
         after {max_trials} trials (enlarge the area, reduce the quantity or raise max_trials)"
    )]
    Placement {
        /// Where the `<distribute>` is.
        location: String,
        /// The base id of the distributed entities.
        base: String,
        /// The id of the entity that could not be placed.
        id: String,
        /// How many entities were placed before the failure.
        placed: usize,
        /// How many were asked for.
        quantity: usize,
        /// The configured retry limit.
        max_trials: u32,
    },
    /// A grid `<distribute>` put an entity on an occupied lattice point.
    #[error(
        "{location}: grid position ({x}, {y}) of '{id}' collides with an entity placed earlier ({placed} of {quantity} \
         placed; move the lattice or widen its spacing)"
    )]
    GridCollision {
        /// Where the `<distribute>` is.
        location: String,
        /// The entity that collided.
        id: String,
        /// Lattice point x.
        x: f32,
        /// Lattice point y.
        y: f32,
        /// How many entities were placed before the failure.
        placed: usize,
        /// How many were asked for.
        quantity: usize,
    },
    /// A grid `<distribute>` cannot hold the requested quantity.
    #[error(
        "{location}: grid layout {layout} has room for {room} entities but quantity is {quantity}"
    )]
    GridTooSmall {
        /// Where the `<distribute>` is.
        location: String,
        /// The layout as written.
        layout: String,
        /// Lattice size.
        room: usize,
        /// Requested quantity.
        quantity: usize,
    },
    /// A value in the configuration cannot be simulated.
    #[error("{location}: {message}")]
    Invalid {
        /// Where the value is.
        location: String,
        /// What is wrong with it.
        message: String,
    },
    /// The loop functions label is not registered.
    #[error("{location}: unknown loop functions '{label}' (registered: {known})")]
    UnknownLoopFunctions {
        /// Where `<loop_functions>` is.
        location: String,
        /// The label as written.
        label: String,
        /// The registered labels.
        known: String,
    },
    /// Writing a record file failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// Rendering a snapshot failed.
    #[error("cannot render snapshot {path}: {message}")]
    Render {
        /// The file.
        path: PathBuf,
        /// The cause.
        message: String,
    },
}
