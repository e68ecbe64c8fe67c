//! supervisor-gen: the offline ptSCT toolchain.
//!
//! Reads plant and specification automata (the thesis XML format, or Nadzoru2 FSA files), validates them with
//! located errors, synthesises supervisors (monolithic, modular, local-modular), checks and minimises them, draws
//! them, reports their memory and compiles them into the byte layout the robot agents execute.
//! `docs/ptsct.md` is the normative specification; section numbers in doc comments refer to it.
//!
//! This crate depends on nothing else of the workspace.

#![warn(missing_docs)]

pub mod architecture;
pub mod automaton;
pub mod build;
pub mod codegen;
pub mod compiled;
pub mod convert;
pub mod diagnostics;
pub mod dot;
pub mod families;
pub mod load;
pub mod minimise;
mod nadzoru;
pub mod normalise;
pub mod pipeline;
pub mod product;
pub mod progress;
pub mod reduce;
pub mod report;
pub mod source;
pub mod supc;
pub mod trim;
pub mod validate;
pub mod xml_read;
mod xml_tree;
pub mod xml_write;
