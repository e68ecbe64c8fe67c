//! The task's own records, `transport.csv`: one row per event, with the box's pose.

use std::fmt::Write as _;

use swarm_navigation::V2;
use swarm_navigation::vec2::wrap;

/// Where the box is: its centre and heading (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Pose {
    /// Its centre.
    pub centre: V2,
    /// Its heading (rad).
    pub angle: f32,
}

/// The rows written since the last drain.
#[derive(Debug, Clone)]
pub(super) struct Records {
    text: String,
}

impl Records {
    /// Nothing but the header.
    pub fn new() -> Records {
        Records {
            text: String::from("tick,event,x,y,angle_deg,detail\n"),
        }
    }

    /// A row: `event` at `tick` with the box at `pose` (heading in degrees, in [-180, 180]).
    pub fn row(&mut self, tick: u64, event: &str, pose: Pose, detail: &str) {
        let _ = writeln!(
            self.text,
            "{tick},{event},{},{},{},{detail}",
            pose.centre.x,
            pose.centre.y,
            wrap(pose.angle).to_degrees()
        );
    }

    /// Moves the rows written so far to the end of `out`.
    pub fn drain(&mut self, out: &mut Vec<u8>) {
        out.extend_from_slice(self.text.as_bytes());
        self.text.clear();
    }
}
