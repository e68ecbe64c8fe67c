//! Resume points: the last supervisor snapshot the world recorded for a robot, handed to its restarted agent.
//!
//! The world writes `resume/robot-<r>.json` in the run directory when it marks robot r dead (before it tells the
//! launcher), from the last command it recorded; the launcher passes the file to the replacement agent
//! (`robot-agent --resume <file>`), which restores its player from it at its first live tick. A robot that
//! never answered has no snapshot (`count` 0): its replacement starts from the initial states.

use std::path::{Path, PathBuf};

use serde_json::json;

use crate::messages::{FiredStamp, MAX_FIRED_STAMPS, MAX_SUPERVISORS, SupervisorSnapshot};
use crate::run_dir::RESUME_DIR;

/// Why a resume point could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum ResumeError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a resume point.
    #[error("{path}: not a resume point: {reason}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
}

/// The last recorded state of one robot's supervisors.
#[derive(Debug, Clone, PartialEq)]
pub struct ResumePoint {
    /// Robot index.
    pub robot: u32,
    /// Tick of the command the snapshot came with (0: the robot never answered).
    pub tick: u64,
    /// The supervisors' states and timers after that tick.
    pub snapshot: SupervisorSnapshot,
}

impl ResumePoint {
    /// Path of robot `robot`'s resume point in `run_dir`.
    pub fn path(run_dir: &Path, robot: u32) -> PathBuf {
        run_dir.join(RESUME_DIR).join(format!("robot-{robot}.json"))
    }

    /// Writes the point into `run_dir` (creating `resume/`); returns the file.
    pub fn write(&self, run_dir: &Path) -> Result<PathBuf, ResumeError> {
        let path = Self::path(run_dir, self.robot);
        let io = |source| ResumeError::Io {
            path: path.clone(),
            source,
        };
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(io)?;
        }
        let s = &self.snapshot;
        let count = usize::from(s.count).min(MAX_SUPERVISORS);
        let fired: Vec<[u64; 3]> = s.fired[..usize::from(s.fired_len).min(MAX_FIRED_STAMPS)]
            .iter()
            .map(|f| [u64::from(f.supervisor), u64::from(f.event), f.tick])
            .collect();
        let value = json!({
            "robot": self.robot,
            "tick": self.tick,
            "states": &s.states[..count],
            "entered": &s.entered[..count],
            "fired": fired,
        });
        // Written whole then renamed, so a reader never sees half a file.
        crate::run_dir::write_atomically(&path, value.to_string().as_bytes()).map_err(io)?;
        Ok(path)
    }

    /// Reads a resume point.
    pub fn read(path: &Path) -> Result<ResumePoint, ResumeError> {
        let invalid = |reason: String| ResumeError::Invalid {
            path: path.to_path_buf(),
            reason,
        };
        let text = std::fs::read_to_string(path).map_err(|source| ResumeError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| invalid(e.to_string()))?;
        let number = |v: &serde_json::Value, what: &str| {
            v.as_u64()
                .ok_or_else(|| invalid(format!("'{what}' is not a non-negative integer")))
        };
        let list = |name: &str| {
            value[name]
                .as_array()
                .ok_or_else(|| invalid(format!("'{name}' is not a list")))
        };
        let robot = u32::try_from(number(&value["robot"], "robot")?)
            .map_err(|_| invalid("'robot' is too large".into()))?;
        let tick = number(&value["tick"], "tick")?;
        let states = list("states")?;
        let entered = list("entered")?;
        let fired = list("fired")?;
        if states.len() > MAX_SUPERVISORS || entered.len() != states.len() {
            return Err(invalid(format!(
                "{} states and {} entry ticks (at most {MAX_SUPERVISORS}, one each)",
                states.len(),
                entered.len()
            )));
        }
        if fired.len() > MAX_FIRED_STAMPS {
            return Err(invalid(format!(
                "{} timer stamps, at most {MAX_FIRED_STAMPS}",
                fired.len()
            )));
        }
        let mut snapshot = SupervisorSnapshot {
            count: states.len() as u8,
            fired_len: fired.len() as u8,
            ..SupervisorSnapshot::default()
        };
        for (i, (state, entry)) in states.iter().zip(entered).enumerate() {
            snapshot.states[i] = u16::try_from(number(state, "states")?)
                .map_err(|_| invalid(format!("state {state} is too large")))?;
            snapshot.entered[i] = number(entry, "entered")?;
        }
        for (i, stamp) in fired.iter().enumerate() {
            let parts = stamp
                .as_array()
                .filter(|p| p.len() == 3)
                .ok_or_else(|| invalid("a timer stamp is not [supervisor, event, tick]".into()))?;
            let small = |v: &serde_json::Value, what: &str| {
                number(v, what).and_then(|n| {
                    u8::try_from(n).map_err(|_| invalid(format!("{what} {n} is too large")))
                })
            };
            snapshot.fired[i] = FiredStamp {
                supervisor: small(&parts[0], "supervisor")?,
                event: small(&parts[1], "event")?,
                tick: number(&parts[2], "tick")?,
            };
        }
        Ok(ResumePoint {
            robot,
            tick,
            snapshot,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_resume_point_reads_back_as_written() {
        let dir = tempfile::tempdir().expect("temp dir");
        let mut snapshot = SupervisorSnapshot {
            count: 2,
            fired_len: 1,
            ..SupervisorSnapshot::default()
        };
        snapshot.states[..2].copy_from_slice(&[3, 1]);
        snapshot.entered[..2].copy_from_slice(&[40, 12]);
        snapshot.fired[0] = FiredStamp {
            supervisor: 1,
            event: 4,
            tick: 41,
        };
        let point = ResumePoint {
            robot: 7,
            tick: 42,
            snapshot,
        };
        let path = point.write(dir.path()).expect("written");
        assert_eq!(path, dir.path().join("resume/robot-7.json"));
        assert_eq!(ResumePoint::read(&path).expect("read"), point);
    }

    #[test]
    fn a_damaged_resume_point_names_the_file_and_the_problem() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("bad.json");
        std::fs::write(
            &path,
            r#"{"robot":1,"tick":3,"states":[1],"entered":[],"fired":[]}"#,
        )
        .expect("written");
        let err = ResumePoint::read(&path).unwrap_err().to_string();
        assert!(
            err.contains("bad.json: not a resume point: 1 states and 0 entry ticks"),
            "{err}"
        );
    }
}
