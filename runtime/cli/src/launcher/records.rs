//! The run's records once its world has ended: cut back to whole ticks when the world died, then left in the
//! format the run was asked for.
//!
//! After the world process died (or was killed because the run failed), `trajectory.csv`, `events.csv` and
//! `messages.csv` are cut back to the last tick the trajectory holds completely (a half-written line or tick is
//! dropped). The world's recorder thread flushes a tick's events and messages before its poses, so this only ever
//! removes what a kill in the middle of writing left behind. It never touches the records of a run whose world
//! finished normally.
//!
//! Then, unless the run keeps CSV (`swarm run --records csv`), the CSV files become Parquet files
//! ([`swarm_records::finish_run_records`]).

use std::path::Path;

use swarm_contract::protocol::launcher_to_world::Records;
use swarm_contract::run_dir::{self, EVENTS_FILE, MESSAGES_FILE, TRAJECTORY_FILE};

/// Cuts the records in `run_dir` back to the last complete tick of `robots` robots; returns that tick (`None`
/// when the trajectory is missing or holds no complete tick).
pub fn trim_to_complete_ticks(run_dir: &Path, robots: u32) -> std::io::Result<Option<u64>> {
    let trajectory = run_dir.join(TRAJECTORY_FILE);
    let Ok(text) = std::fs::read_to_string(&trajectory) else {
        return Ok(None);
    };
    let complete = complete_lines(&text);
    let mut lines: Vec<&str> = complete.lines().collect();
    let tick_of = |line: &str| line.split(',').next().and_then(|t| t.parse::<u64>().ok());
    let last_tick = lines.iter().skip(1).filter_map(|l| tick_of(l)).next_back();
    let Some(mut last) = last_tick else {
        return Ok(None);
    };
    let rows_of_last = lines.iter().filter(|l| tick_of(l) == Some(last)).count();
    if rows_of_last < robots as usize {
        lines.retain(|l| tick_of(l) != Some(last));
        match last.checked_sub(1) {
            Some(previous) => last = previous,
            None => return Ok(None),
        }
    }
    let kept = lines.join("\n") + "\n";
    if kept != text {
        run_dir::write_atomically(&trajectory, kept.as_bytes())?;
    }
    for name in [EVENTS_FILE, MESSAGES_FILE] {
        let path = run_dir.join(name);
        if let Ok(text) = std::fs::read_to_string(&path) {
            let mut kept: Vec<&str> = complete_lines(&text).lines().collect();
            kept.retain(|l| tick_of(l).is_none_or(|t| t <= last));
            let kept = kept.join("\n") + "\n";
            if kept != text {
                run_dir::write_atomically(&path, kept.as_bytes())?;
            }
        }
    }
    Ok(Some(last))
}

/// Leaves the records of the ended run in `run_dir` as `records` asks. A conversion that fails leaves the CSV files
/// whole and is reported as a warning: the run's records are complete either way.
pub fn finish(run_dir: &Path, records: Records) {
    if records != Records::Parquet {
        return;
    }
    match swarm_records::finish_run_records(run_dir) {
        Ok(report) => {
            for file in &report.files {
                tracing::debug!("records: {file}");
            }
        }
        Err(e) => {
            tracing::warn!("the records stay CSV files, their conversion to Parquet failed: {e}")
        }
    }
}

/// The text up to its last newline.
fn complete_lines(text: &str) -> &str {
    text.rfind('\n').map_or("", |end| &text[..=end])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_half_written_tick_is_cut_from_every_record() {
        let dir = tempfile::tempdir().expect("temp dir");
        let header = "tick,robot,robot_id,x,y,heading,led_r,led_g,led_b,alive\n";
        std::fs::write(
            dir.path().join("trajectory.csv"),
            format!("{header}0,0,a,0,0,0,0,0,0,1\n0,1,b,0,0,0,0,0,0,1\n1,0,a,0,0,0,0,0,0,1\n1,1,b,0,0,0,0,0,0,1\n2,0,a,0,0,0,0,0,0,1\n2,1,b,0,0"),
        )
        .expect("written");
        std::fs::write(
            dir.path().join("events.csv"),
            "tick,robot,robot_id,event\n1,0,a,Go\n2,1,b,Go\n2,0,a,sa",
        )
        .expect("written");
        std::fs::write(
            dir.path().join("messages.csv"),
            "tick,from,to,address,bytes,outcome,reason\n1,0,1,one,8,delivered,\n2,1,0,one,8,deliv",
        )
        .expect("written");
        assert_eq!(
            trim_to_complete_ticks(dir.path(), 2).expect("trimmed"),
            Some(1)
        );
        let trajectory = std::fs::read_to_string(dir.path().join("trajectory.csv")).expect("read");
        assert_eq!(trajectory.lines().count(), 5);
        assert!(trajectory.ends_with("1,1,b,0,0,0,0,0,0,1\n"));
        let events = std::fs::read_to_string(dir.path().join("events.csv")).expect("read");
        assert_eq!(events, "tick,robot,robot_id,event\n1,0,a,Go\n");
        let messages = std::fs::read_to_string(dir.path().join("messages.csv")).expect("read");
        assert_eq!(
            messages,
            "tick,from,to,address,bytes,outcome,reason\n1,0,1,one,8,delivered,\n"
        );
    }
}
