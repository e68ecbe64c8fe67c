//! Every timeout and size limit of a run, in one typed struct with documented defaults.
//!
//! A limit is set, from lowest to highest precedence, by its default, by the configuration's `<system>` attribute
//! of the same name (`<system tick_deadline_ms="300"/>`) and by `swarm run --limit NAME=VALUE` (repeatable;
//! `--tick-deadline-ms` and `--join-timeout-ms` are shorthands). The launcher passes its overrides on to the world
//! with the same flag, so both resolve the same values from the same configuration; hosts get theirs with their
//! share. `summary.json` records the values a run used under `limits`.
//!
//! Polling periods (how often a loop looks at its children or its queue) are not limits: they decide no outcome,
//! only how soon a loop notices one, and stay constants next to their loops.

use std::time::Duration;

use serde::Serialize;

use crate::transport::DEFAULT_TICK_DEADLINE;

/// The timeouts and size limits of one run; see the module documentation for how each is set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Limits {
    /// How long a tick waits for a missing command before it goes on without it (the robot holds still), in
    /// milliseconds. Default 500.
    pub tick_deadline_ms: u64,
    /// How long the world waits for every agent, or every host, to join before the first tick and for a restarted
    /// agent to rejoin, in milliseconds. Default 120,000.
    pub join_timeout_ms: u64,
    /// How long the launcher waits for the world to create the run's shared memory, in milliseconds. Default
    /// 60,000.
    pub world_ready_timeout_ms: u64,
    /// How long agents get to exit by themselves once their run ended, before they are killed, in milliseconds.
    /// Default 5,000.
    pub agent_exit_grace_ms: u64,
    /// How long the world waits for the launcher to carry out the faults due at a tick, in milliseconds. Default
    /// 30,000.
    pub fault_apply_timeout_ms: u64,
    /// How long a `swarm ctl` request waits for the launcher's answer, in milliseconds. Default 10,000.
    pub ctl_reply_timeout_ms: u64,
    /// Largest message the world accepts from a host, in bytes. Default 16 MiB.
    pub max_host_message_bytes: u64,
    /// How long a replacement agent keeps trying to join while the world frees the ports of the agent it
    /// replaces, in milliseconds. Default 10,000.
    pub agent_join_retry_ms: u64,
    /// How long a joining agent waits for the death notice of its robot's previous agent, and for a previous
    /// agent stopped in the middle of writing its command slot, in milliseconds. Default 30,000.
    pub agent_board_wait_ms: u64,
    /// Free space the run leaves on the disk of its run folder, in MiB: when less is free the run stops, with
    /// its records complete. Default 100.
    pub disk_reserve_mb: u64,
    /// Largest size of a run folder, in MiB: a run whose records grow past it stops, with its records complete.
    /// Default 1,048,576 (1 TiB).
    pub records_max_mb: u64,
}

/// Largest message the world accepts from a host by default.
pub const DEFAULT_MAX_HOST_MESSAGE_BYTES: u64 = 16 * 1024 * 1024;

impl Default for Limits {
    fn default() -> Self {
        Limits {
            tick_deadline_ms: DEFAULT_TICK_DEADLINE.as_millis() as u64,
            join_timeout_ms: 120_000,
            world_ready_timeout_ms: 60_000,
            agent_exit_grace_ms: 5_000,
            fault_apply_timeout_ms: 30_000,
            ctl_reply_timeout_ms: 10_000,
            max_host_message_bytes: DEFAULT_MAX_HOST_MESSAGE_BYTES,
            agent_join_retry_ms: 10_000,
            agent_board_wait_ms: 30_000,
            disk_reserve_mb: 100,
            records_max_mb: 1 << 20,
        }
    }
}

/// A limit that cannot be set as asked.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LimitError {
    /// No limit has this name.
    #[error("unknown limit '{name}' (the limits are {})", Limits::NAMES.join(", "))]
    Unknown {
        /// The name given.
        name: String,
    },
    /// The value is not a whole number above 0.
    #[error("limit {name}={value}: the value must be a whole number above 0")]
    Value {
        /// The limit.
        name: String,
        /// The value given.
        value: String,
    },
    /// Not of the form `NAME=VALUE`.
    #[error("'{0}' is not NAME=VALUE")]
    Form(String),
}

impl Limits {
    /// The names of the limits, as `<system>` attributes and `--limit` names.
    pub const NAMES: [&'static str; 11] = [
        "tick_deadline_ms",
        "join_timeout_ms",
        "world_ready_timeout_ms",
        "agent_exit_grace_ms",
        "fault_apply_timeout_ms",
        "ctl_reply_timeout_ms",
        "max_host_message_bytes",
        "agent_join_retry_ms",
        "agent_board_wait_ms",
        "disk_reserve_mb",
        "records_max_mb",
    ];

    fn field(&mut self, name: &str) -> Option<&mut u64> {
        Some(match name {
            "tick_deadline_ms" => &mut self.tick_deadline_ms,
            "join_timeout_ms" => &mut self.join_timeout_ms,
            "world_ready_timeout_ms" => &mut self.world_ready_timeout_ms,
            "agent_exit_grace_ms" => &mut self.agent_exit_grace_ms,
            "fault_apply_timeout_ms" => &mut self.fault_apply_timeout_ms,
            "ctl_reply_timeout_ms" => &mut self.ctl_reply_timeout_ms,
            "max_host_message_bytes" => &mut self.max_host_message_bytes,
            "agent_join_retry_ms" => &mut self.agent_join_retry_ms,
            "agent_board_wait_ms" => &mut self.agent_board_wait_ms,
            "disk_reserve_mb" => &mut self.disk_reserve_mb,
            "records_max_mb" => &mut self.records_max_mb,
            _ => return None,
        })
    }

    /// Sets limit `name` to `value` (a whole number above 0).
    pub fn set(&mut self, name: &str, value: &str) -> Result<(), LimitError> {
        let field = self.field(name).ok_or_else(|| LimitError::Unknown {
            name: name.to_owned(),
        })?;
        *field = value
            .trim()
            .parse::<u64>()
            .ok()
            .filter(|v| *v > 0)
            .ok_or_else(|| LimitError::Value {
                name: name.to_owned(),
                value: value.to_owned(),
            })?;
        Ok(())
    }

    /// Applies overrides of the form `NAME=VALUE` in order (`swarm run --limit`).
    pub fn apply(&mut self, overrides: &[String]) -> Result<(), LimitError> {
        for item in overrides {
            let (name, value) = item
                .split_once('=')
                .ok_or_else(|| LimitError::Form(item.clone()))?;
            self.set(name.trim(), value)?;
        }
        Ok(())
    }

    /// [`Limits::tick_deadline_ms`] as a duration.
    pub fn tick_deadline(&self) -> Duration {
        Duration::from_millis(self.tick_deadline_ms)
    }

    /// [`Limits::join_timeout_ms`] as a duration.
    pub fn join_timeout(&self) -> Duration {
        Duration::from_millis(self.join_timeout_ms)
    }

    /// [`Limits::world_ready_timeout_ms`] as a duration.
    pub fn world_ready_timeout(&self) -> Duration {
        Duration::from_millis(self.world_ready_timeout_ms)
    }

    /// [`Limits::agent_exit_grace_ms`] as a duration.
    pub fn agent_exit_grace(&self) -> Duration {
        Duration::from_millis(self.agent_exit_grace_ms)
    }

    /// [`Limits::fault_apply_timeout_ms`] as a duration.
    pub fn fault_apply_timeout(&self) -> Duration {
        Duration::from_millis(self.fault_apply_timeout_ms)
    }

    /// [`Limits::ctl_reply_timeout_ms`] as a duration.
    pub fn ctl_reply_timeout(&self) -> Duration {
        Duration::from_millis(self.ctl_reply_timeout_ms)
    }

    /// [`Limits::agent_join_retry_ms`] as a duration.
    pub fn agent_join_retry(&self) -> Duration {
        Duration::from_millis(self.agent_join_retry_ms)
    }

    /// [`Limits::agent_board_wait_ms`] as a duration.
    pub fn agent_board_wait(&self) -> Duration {
        Duration::from_millis(self.agent_board_wait_ms)
    }

    /// [`Limits::max_host_message_bytes`] as a size.
    pub fn max_host_message(&self) -> usize {
        usize::try_from(self.max_host_message_bytes).unwrap_or(usize::MAX)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_sets_its_own_limit_and_overrides_apply_in_order() {
        for name in Limits::NAMES {
            let mut limits = Limits::default();
            limits.set(name, "7").expect("known limit");
            assert_ne!(limits, Limits::default(), "{name}");
            let recorded = serde_json::to_value(limits).expect("serialisable");
            assert_eq!(recorded[name], 7, "{name} in {recorded}");
        }
        let mut limits = Limits::default();
        limits
            .apply(&["tick_deadline_ms=300".into(), "tick_deadline_ms=250".into()])
            .expect("valid overrides");
        assert_eq!(limits.tick_deadline(), Duration::from_millis(250));
    }

    #[test]
    fn unknown_names_zero_and_malformed_values_are_refused() {
        let mut limits = Limits::default();
        assert!(matches!(
            limits.set("tick_deadline", "5"),
            Err(LimitError::Unknown { .. })
        ));
        assert!(matches!(
            limits.set("join_timeout_ms", "0"),
            Err(LimitError::Value { .. })
        ));
        assert!(matches!(
            limits.apply(&["join_timeout_ms".into()]),
            Err(LimitError::Form(_))
        ));
        assert_eq!(limits, Limits::default());
    }
}
