//! Multi-robot task allocation for exploration with task allocation (paper A, docs/allocation.md): the model of
//! which teams can do which tasks ([`team`]) and the fast genetic allocator ([`fga`]) that assigns the available
//! robots to the discovered tasks on every event. Pure functions of their inputs and a seeded random stream.

pub mod fga;
pub mod model;
pub mod team;

pub use model::{Kind, Problem, Robot, Task, Weights};
