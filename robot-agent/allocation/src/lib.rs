//! Multi-robot task allocation for exploration with task allocation (paper A, docs/allocation.md): the model of
//! which teams can do which tasks ([`team`]), the fast genetic allocator ([`fga`]) that assigns the available
//! robots to the discovered tasks on every event, and its NSGA-II baseline ([`nsga2`]), which share their
//! genetic operators ([`operators`]). Pure functions of their inputs and a seeded random stream.

pub mod fga;
#[cfg(test)]
mod fixtures;
pub mod instances;
pub mod model;
pub mod nsga2;
pub mod operators;
pub mod taguchi;
pub mod team;

pub use model::{Kind, Problem, Robot, Task, Weights};
