//! The binary frame layout the page decodes (docs/viewer.md): little-endian `u32` robot count and `u32` frame
//! count, then per frame a `u32` tick and 16 bytes per robot (`f32` x, y, heading; `u8` red, green, blue; `u8`
//! flags). 16 bytes a robot keeps a 64-tick chunk of a 1,000-robot run at 1 MB.

use crate::trajectory::Pose;

/// Flag bit: the robot is in the run (its pose is not `NaN`).
pub const PRESENT: u8 = 1;
/// Flag bit: the robot is alive.
pub const ALIVE: u8 = 1 << 1;
/// Flag bit: a fault froze the robot.
pub const FROZEN: u8 = 1 << 2;
/// Flag bit: the robot holds something in its gripper.
pub const CARRYING: u8 = 1 << 3;

/// One robot of one frame.
pub struct FrameRobot {
    /// Its trajectory row.
    pub pose: Pose,
    /// Frozen by a fault.
    pub frozen: bool,
    /// Holding something.
    pub carrying: bool,
}

/// A body's opening: robot and frame counts.
pub fn header(robots: usize, frames: usize) -> Vec<u8> {
    let mut body = Vec::with_capacity(8 + frames * (4 + robots * 16));
    body.extend_from_slice(&(robots as u32).to_le_bytes());
    body.extend_from_slice(&(frames as u32).to_le_bytes());
    body
}

/// Appends the frame of `tick`.
pub fn push_frame(body: &mut Vec<u8>, tick: u64, robots: impl Iterator<Item = FrameRobot>) {
    body.extend_from_slice(&(tick as u32).to_le_bytes());
    for robot in robots {
        let pose = robot.pose;
        for value in [pose.x, pose.y, pose.heading] {
            body.extend_from_slice(&value.to_le_bytes());
        }
        body.extend_from_slice(&pose.led);
        let flags = [
            (!pose.x.is_nan(), PRESENT),
            (pose.alive, ALIVE),
            (robot.frozen, FROZEN),
            (robot.carrying, CARRYING),
        ]
        .into_iter()
        .filter(|&(on, _)| on)
        .fold(0, |flags, (_, bit)| flags | bit);
        body.push(flags);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_is_a_tick_and_sixteen_bytes_a_robot() {
        let mut body = header(2, 1);
        let pose = Pose {
            x: 1.0,
            y: -2.0,
            heading: 0.5,
            led: [1, 2, 3],
            alive: true,
        };
        push_frame(
            &mut body,
            7,
            [
                FrameRobot {
                    pose,
                    frozen: true,
                    carrying: false,
                },
                FrameRobot {
                    pose: Pose::ABSENT,
                    frozen: false,
                    carrying: false,
                },
            ]
            .into_iter(),
        );
        assert_eq!(body.len(), 8 + 4 + 2 * 16);
        assert_eq!(&body[0..8], &[2, 0, 0, 0, 1, 0, 0, 0]);
        assert_eq!(&body[8..12], &7u32.to_le_bytes());
        assert_eq!(&body[12..16], &1.0f32.to_le_bytes());
        assert_eq!(&body[24..28], &[1, 2, 3, PRESENT | ALIVE | FROZEN]);
        assert_eq!(body[28 + 15], 0, "an absent robot has no flags");
    }
}
