//! Single-robot path planning among disc obstacles (paper D, docs/planning.md): the map a planner works in, the
//! GSA planner, the any-angle grid search that serves as the reference optimum, a path follower, reproducible test maps, the tree planners (ORT and RRT) for a carried object's path, TangentBug with
//! its potential-field correction (the local planner of exploration and transport), and Multi-SRT exploration.

pub mod discovery;
pub mod follow;
pub mod gsa;
pub mod map;
pub mod scattered;
pub mod srt;
pub mod tangent_bug;
pub mod theta_star;
pub mod tree;

pub use map::{Bounds, Map};
