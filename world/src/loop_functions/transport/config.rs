//! The `<transport>` element: what to carry where, how closely, and the global planner's parameters.

use swarm_navigation::V2;
use swarm_navigation::planning::tree::{Tree, TreeParams};
use swarm_navigation::vec2::wrap;

use crate::error::WorldError;
use crate::loop_functions::LoopFunctionsParams;
use crate::loop_functions::params::ParamReader;

/// Most samples a plan may draw (the tree planner's own limit).
const MAX_ITERATIONS: u64 = 1_000_000;

/// The task's settings, as read from the configuration.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Settings {
    /// Id of the box to carry.
    pub object: String,
    /// Where the box's centre must end.
    pub goal: V2,
    /// The box's heading there (rad, in [-pi, pi]).
    pub goal_angle: f32,
    /// Position tolerance at the goal (m).
    pub tolerance: f32,
    /// Heading tolerance at the goal (rad).
    pub angle_tolerance: f32,
    /// The global planner.
    pub tree: Tree,
    /// Its parameters.
    pub params: TreeParams,
    /// Room kept beyond the formation (m).
    pub margin: f32,
    /// Seconds between two `Object` letters.
    pub repeat_s: f64,
}

impl Settings {
    /// Reads `<transport>` from `params`; unknown attributes and out-of-range values are located errors.
    pub fn read(params: &LoopFunctionsParams) -> Result<Self, WorldError> {
        let r = ParamReader::new(
            params,
            "transport",
            &[
                "object",
                "goal",
                "tolerance",
                "angle_tolerance",
                "planner",
                "step",
                "failures",
                "iterations",
                "reach",
                "margin",
                "repeat",
            ],
        )?;
        let object = r.required("object")?.trim().to_owned();
        r.required("goal")?;
        let [x, y, angle] = r.numbers::<3>("goal")?.unwrap_or_default();
        let tree = match r.choice("planner", &["ort", "rrt"], "ort")? {
            "rrt" => Tree::Rrt,
            _ => Tree::Ort,
        };
        Ok(Settings {
            object,
            goal: V2::new(x as f32, y as f32),
            goal_angle: wrap((angle as f32).to_radians()),
            // Finite in f32 too: the robots refuse an `Object` with an infinite tolerance.
            tolerance: (r.positive("tolerance", 0.02)? as f32).min(f32::MAX),
            angle_tolerance: (r.positive("angle_tolerance", 3.0)? as f32)
                .min(f32::MAX)
                .to_radians(),
            tree,
            params: TreeParams {
                step: r.positive("step", 0.2)? as f32,
                failures: r.u64_between("failures", 5, 1, u64::from(u32::MAX))? as u32,
                iterations: r.u64_between("iterations", 20_000, 1, MAX_ITERATIONS)? as u32,
                reach: r.positive("reach", 1.0)? as f32,
            },
            margin: r.non_negative("margin", 0.1)? as f32,
            repeat_s: r.positive("repeat", 1.0)?,
        })
    }

    /// The planner's name in the records.
    pub fn planner_name(&self) -> &'static str {
        match self.tree {
            Tree::Ort => "ort",
            Tree::Rrt => "rrt",
        }
    }
}
