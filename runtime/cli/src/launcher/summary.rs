//! The launcher's part of `summary.json`: what the run did as the launcher saw it, and where the run came from.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use swarm_contract::run_dir;

use super::fault_log::FaultRecord;
use super::{LaunchError, RunReport, io};

/// Adds the launcher's fields to the world's `summary.json` (or writes it if the world wrote none, e.g. because
/// it died: `world_died` then says why). Returns why the world stopped the run before its end (its disk
/// budget, `stopped_early`), if it did.
pub(super) fn complete_summary(
    out_dir: &Path,
    report: &RunReport,
    provenance: &Provenance,
    world_died: Option<&str>,
) -> Result<Option<String>, LaunchError> {
    let path = out_dir.join(run_dir::SUMMARY_FILE);
    let mut summary = std::fs::read_to_string(&path)
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .filter(serde_json::Value::is_object)
        .unwrap_or_else(|| serde_json::json!({}));
    let deaths: Vec<serde_json::Value> = report
        .deaths
        .iter()
        .map(|d| serde_json::json!({"robot": d.robot, "after_tick": d.after_tick, "status": d.status}))
        .collect();
    if let Some(object) = summary.as_object_mut() {
        object.insert("seed".into(), report.seed.into());
        object.insert("robots".into(), report.robots.into());
        object.insert("ticks".into(), report.ticks.into());
        object.insert("wall_seconds".into(), report.wall_seconds.into());
        object.insert(
            "time_to_first_tick_seconds".into(),
            report.time_to_first_tick_seconds.into(),
        );
        object.insert("interrupted".into(), report.interrupted.into());
        object.insert("deaths".into(), deaths.into());
        object.insert(
            "processes".into(),
            serde_json::json!({"world": report.world_pid, "agents": report.agent_pids}),
        );
        let faults: Vec<serde_json::Value> =
            report.faults.iter().map(FaultRecord::to_json).collect();
        object.insert("faults".into(), faults.into());
        object
            .entry("alive_final")
            .or_insert(report.alive_final.into());
        if let Some(reason) = world_died {
            object.insert("world_died".into(), reason.into());
        }
        object.extend(provenance.to_json());
    }
    let text = serde_json::to_string_pretty(&summary).unwrap_or_default() + "\n";
    run_dir::write_atomically(&path, text.as_bytes())
        .map_err(io(format!("writing {}", path.display())))?;
    Ok(summary["stopped_early"].as_str().map(str::to_owned))
}

/// Where a run came from: what was run, by which program, when, from which configuration.
pub(super) struct Provenance {
    /// The program's arguments, the program first.
    pub(super) command_line: Vec<String>,
    /// When the run started.
    pub(super) started_at: SystemTime,
    /// The configuration file, absolute.
    pub(super) config: PathBuf,
}

impl Provenance {
    /// The fields `summary.json` gets: `command_line`, `version`, `git_commit` (null when the program was not
    /// built from a git checkout), `started_at` (RFC 3339, UTC) and `config` (absolute path).
    fn to_json(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut fields = serde_json::Map::new();
        fields.insert("command_line".into(), self.command_line.clone().into());
        fields.insert("version".into(), env!("CARGO_PKG_VERSION").into());
        fields.insert(
            "git_commit".into(),
            option_env!("SWARM_GIT_COMMIT").map_or(serde_json::Value::Null, Into::into),
        );
        fields.insert(
            "started_at".into(),
            humantime::format_rfc3339_seconds(self.started_at)
                .to_string()
                .into(),
        );
        fields.insert("config".into(), self.config.display().to_string().into());
        fields
    }
}
