//! Multi-robot navigation as pure functions, for the navigation task (`configs/navigation/`,
//! `docs/navigation.md`).
//!
//! - [`apf`]: the forces of adaptive artificial potential fields for many robots (AMR-APF), the force-to-velocity
//!   law, and the two baselines that share its code path (DAPF and Khatib's classic field). A planner is a pure
//!   function of its robot's state and the coordinator's snapshot, so it is deterministic and unit-testable.
//! - [`planning`]: single-robot path planning (paper D): the GSA planner, the Theta* reference optimum and a
//!   path follower.
//! - [`wire`]: the byte layout of the messages between the task server (the world's loop functions), the robots'
//!   planners and the coordinator.
//! - [`vec2`]: the plane vector both use.

pub mod apf;
pub mod planning;
pub mod vec2;
pub mod wire;

pub use vec2::V2;
