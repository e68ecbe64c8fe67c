//! Picking up where a robot left off: a restarted agent resumes its supervisors from the resume point the world
//! recorded, and an agent whose robot was out for a while (frozen, or marked dead after missing deadlines)
//! re-aligns its player's clock with the world's tick.
//!
//! While the world says the robot is not alive (`frame.alive == 0`) the agent does not step: it answers with its
//! held command so the tick is not stalled, and the world ignores it. At the first live frame of tick t after a
//! gap the player is restored at tick t − 1, from the resume point (restarted agent) or from its own snapshot
//! (an agent that was away), so its random stream is positioned by tick exactly as an uninterrupted player's.
//! Timers keep counting through the gap: a supervisor's clock is the world's. Native controllers keep their own
//! state and have nothing to restore.

use swarm_contract::messages::{SensorFrame, SupervisorSnapshot};
use swarm_contract::player::PlayerError;
use swarm_contract::protocol::resume::ResumePoint;
use tracing::info;

use crate::control::Control;

/// Decides, frame by frame, whether the controller steps, restoring its player after a gap.
#[derive(Debug, Default)]
pub struct Resumer {
    /// The resume point of a restarted agent, until its first live frame.
    pending: Option<ResumePoint>,
    /// The tick of the last frame the controller stepped on.
    last_stepped: Option<u64>,
}

impl Resumer {
    /// A resumer for an agent started fresh (`None`) or restarted from `point`.
    pub fn new(point: Option<ResumePoint>) -> Resumer {
        Resumer {
            pending: point,
            last_stepped: None,
        }
    }

    /// Whether `control` should step on `frame`; restores its player first when the frame follows a gap.
    #[unsafe(link_section = "swarm_hot")]
    pub fn before_step(
        &mut self,
        control: &mut Control,
        frame: &SensorFrame,
    ) -> Result<bool, PlayerError> {
        if frame.alive == 0 {
            return Ok(false);
        }
        let tick = frame.tick;
        let expected = self.last_stepped.map_or(1, |t| t + 1);
        let pending = self.pending.take();
        if (pending.is_some() || tick != expected)
            && let Control::Supervised { player, .. } = control
        {
            let (snapshot, from): (SupervisorSnapshot, String) = match &pending {
                Some(point) if point.snapshot.count > 0 => (
                    point.snapshot,
                    format!("the snapshot of tick {}", point.tick),
                ),
                Some(_) => (player.snapshot(), "its initial states".to_owned()),
                None => (player.snapshot(), "its own last snapshot".to_owned()),
            };
            player.restore(&snapshot, tick - 1)?;
            let count = usize::from(snapshot.count);
            info!(
                "resumed supervisors at tick {tick} from {from}: states {:?}, entered {:?}",
                &snapshot.states[..count],
                &snapshot.entered[..count]
            );
        }
        self.last_stepped = Some(tick);
        Ok(true)
    }
}
