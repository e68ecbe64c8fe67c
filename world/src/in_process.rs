//! A trivial in-process controller for tests and benches: ARGoS' e-puck obstacle-avoidance rule.
//!
//! Drive straight at full speed; when a front sensor (0, 1, 6, 7) reads more than 0.1 (about 4 cm, the
//! recommended theta_obs), pivot away from the side with the higher readings. Real robots run supervisors in
//! their own processes; this exists so the world can be exercised and measured alone.

use swarm_contract::messages::{ActuatorCommand, SensorFrame};

use swarm_contract::bodies::EPUCK;

/// Front-sensor reading above which the robot turns (docs/tasks.md 3, theta_obs).
pub const OBSTACLE_THRESHOLD: f32 = 0.1;

/// The obstacle-avoidance rule: sets the wheels from the proximity readings.
pub fn avoid_obstacles(frame: &SensorFrame, command: &mut ActuatorCommand) {
    let p = &frame.proximity;
    let left = p[0].max(p[1]);
    let right = p[7].max(p[6]);
    let v = EPUCK.max_wheel_speed_cm_s;
    command.wheels = if left.max(right) <= OBSTACLE_THRESHOLD {
        [v, v]
    } else if left >= right {
        [v, -v]
    } else {
        [-v, v]
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turns_away_from_the_side_with_the_higher_front_reading() {
        let mut frame = SensorFrame::empty(0);
        let mut cmd = ActuatorCommand::idle(0, 1);
        avoid_obstacles(&frame, &mut cmd);
        assert_eq!(cmd.wheels, [12.8, 12.8]);
        frame.proximity[0] = 0.5;
        avoid_obstacles(&frame, &mut cmd);
        assert_eq!(
            cmd.wheels,
            [12.8, -12.8],
            "obstacle on the left: turn right"
        );
        frame.proximity[0] = 0.0;
        frame.proximity[7] = 0.5;
        avoid_obstacles(&frame, &mut cmd);
        assert_eq!(
            cmd.wheels,
            [-12.8, 12.8],
            "obstacle on the right: turn left"
        );
    }
}
