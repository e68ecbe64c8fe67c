//! The judge: follows the box tick by tick (its path, its lifts and lowerings), takes the team's report, decides
//! when the task is over and how well it went.
//!
//! The task is over at the first tick after which the box is on the ground (not lifted) and either the team has
//! reported an `Outcome`, or the box has been carried (lifted at least once) and no robot's gripper has held
//! anything for [`SILENT_TICKS`] ticks (a team that put the box down reports in the same tick; one that never
//! reports does not hold the run open).
//! The box is delivered when it was put down that way and the team reported nothing else than `Delivered`; the
//! task succeeds when the box is delivered within the position and heading tolerances of the goal.

use swarm_navigation::vec2::wrap;
use swarm_navigation::wire::transport::Ending;

use super::records::{Pose, Records};

/// Ticks after the last grip opened that the judge waits for the team's report.
pub(super) const SILENT_TICKS: u64 = 20;

/// The goal pose and how close counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Goal {
    /// The box's end pose.
    pub pose: Pose,
    /// Position tolerance (m).
    pub tolerance: f32,
    /// Heading tolerance (rad).
    pub angle_tolerance: f32,
}

/// How the task ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct End {
    /// The tick it ended.
    pub tick: u64,
    /// Distance from the box's centre to the goal (m).
    pub position_error: f32,
    /// Heading error (degrees, in [0, 180]).
    pub angle_error_deg: f32,
    /// Delivered within both tolerances.
    pub success: bool,
}

/// What the box did in one tick, as the world sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Seen {
    /// The tick.
    pub tick: u64,
    /// Whether it is a whole second (a `pose` row while the box is lifted).
    pub whole_second: bool,
    /// The box's pose after the tick.
    pub pose: Pose,
    /// Whether it is lifted.
    pub lifted: bool,
    /// Whether no robot's gripper holds anything.
    pub grips_open: bool,
}

/// The judge's account of the run so far.
#[derive(Debug, Clone, Default)]
pub(super) struct Judge {
    last: Option<Pose>,
    lifted: bool,
    carried: bool,
    /// Since when no gripper holds anything, after the box was carried.
    open_since: Option<u64>,
    /// Metres the box's centre moved.
    pub path_m: f64,
    /// Ticks the box was lifted.
    pub lifted_ticks: u64,
    /// The team's report, the first one.
    pub outcome: Option<Ending>,
    /// How the task ended, once it has.
    pub end: Option<End>,
}

/// The name of an ending in the records and metrics.
pub(super) fn ending_name(ending: Ending) -> &'static str {
    match ending {
        Ending::Delivered => "delivered",
        Ending::TeammateLost => "teammate_lost",
        Ending::Dropped => "dropped",
        Ending::NoPath => "no_path",
    }
}

impl Judge {
    /// Takes in one tick; writes its events to `records`. Nothing changes once the task is over.
    pub fn step(&mut self, seen: Seen, goal: &Goal, records: &mut Records) {
        if self.end.is_some() {
            return;
        }
        let pose = seen.pose;
        if let Some(last) = self.last {
            self.path_m += f64::from((pose.centre - last.centre).length());
        }
        self.last = Some(pose);
        if seen.lifted != self.lifted {
            self.lifted = seen.lifted;
            self.carried |= seen.lifted;
            let event = if seen.lifted { "lifted" } else { "lowered" };
            records.row(seen.tick, event, pose, "");
        }
        if seen.lifted {
            self.lifted_ticks += 1;
            if seen.whole_second {
                records.row(seen.tick, "pose", pose, "");
            }
            return;
        }
        self.open_since = match (self.carried && seen.grips_open, self.open_since) {
            (false, _) => None,
            (true, None) => Some(seen.tick),
            (true, since) => since,
        };
        let silent = self
            .open_since
            .is_some_and(|since| seen.tick >= since + SILENT_TICKS);
        if self.outcome.is_none() && !silent {
            return;
        }
        let position_error = (pose.centre - goal.pose.centre).length();
        let angle_error = wrap(pose.angle - goal.pose.angle).abs();
        let delivered = matches!(self.outcome, None | Some(Ending::Delivered));
        let end = End {
            tick: seen.tick,
            position_error,
            angle_error_deg: angle_error.to_degrees(),
            success: delivered
                && position_error <= goal.tolerance
                && angle_error <= goal.angle_tolerance,
        };
        records.row(
            seen.tick,
            "final",
            pose,
            &format!(
                "position_error_m={} angle_error_deg={}",
                end.position_error, end.angle_error_deg
            ),
        );
        self.end = Some(end);
    }

    /// Takes the team's report at `tick`, with the box at `pose`: the first one counts, and none once the task
    /// is over.
    pub fn report(&mut self, tick: u64, ending: Ending, pose: Pose, records: &mut Records) {
        if self.outcome.is_some() || self.end.is_some() {
            return;
        }
        self.outcome = Some(ending);
        records.row(tick, "outcome", pose, ending_name(ending));
    }
}
