//! The run's fault log: every fault the launcher applied or saw, when the world took it into account, and the
//! restarts that followed. It becomes the `faults` list of `summary.json`.

use serde_json::{Value, json};

/// A replacement agent started after a fault.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RestartRecord {
    /// Which restart of the robot within its window.
    pub attempt: u32,
    /// Process id of the replacement agent.
    pub pid: u32,
    /// First tick the replacement took part in, once the world reported it.
    pub rejoin_tick: Option<u64>,
}

/// One fault of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct FaultRecord {
    /// What happened: `kill`, `freeze`, `thaw`, `kill-world` (scheduled), `ctl-kill`, `ctl-freeze`, `ctl-thaw`,
    /// `ctl-kill-host` (`swarm ctl`), `exit` (an agent ended by itself or by someone else's signal), `deadline`
    /// (the world saw a robot miss a tick's deadline), `host-lost` (the robot's host was lost).
    pub what: String,
    /// The robot, or `None` for the world.
    pub robot: Option<u32>,
    /// The tick the schedule set, for scheduled faults.
    pub scheduled_tick: Option<u64>,
    /// The first tick the world ran without the robot (or, for a thaw, with it again).
    pub detection_tick: Option<u64>,
    /// How the process ended, when it did.
    pub status: Option<String>,
    /// The restart that followed, if any.
    pub restart: Option<RestartRecord>,
    /// Milliseconds from the launcher's kill (or its first sight of the exit) to the world marking the robot
    /// dead, for deaths outside the schedule.
    pub detection_ms: Option<f64>,
    /// Milliseconds from that moment to the world taking the replacement back, for restarts outside the
    /// schedule.
    pub rejoin_ms: Option<f64>,
}

impl FaultRecord {
    /// A record of `what` for `robot`, nothing else known yet.
    pub fn new(what: &str, robot: Option<u32>) -> FaultRecord {
        FaultRecord {
            what: what.to_owned(),
            robot,
            scheduled_tick: None,
            detection_tick: None,
            status: None,
            restart: None,
            detection_ms: None,
            rejoin_ms: None,
        }
    }

    /// The record as it appears in `summary.json`.
    pub fn to_json(&self) -> Value {
        json!({
            "what": self.what,
            "robot": self.robot,
            "scheduled_tick": self.scheduled_tick,
            "detection_tick": self.detection_tick,
            "status": self.status,
            "restarted": self.restart.is_some(),
            "restart_attempt": self.restart.as_ref().map(|r| r.attempt),
            "restart_pid": self.restart.as_ref().map(|r| r.pid),
            "rejoin_tick": self.restart.as_ref().and_then(|r| r.rejoin_tick),
            "detection_ms": self.detection_ms,
            "rejoin_ms": self.rejoin_ms,
        })
    }
}
