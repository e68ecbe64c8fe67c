//! The batch folder, and what makes a run count as finished.
//!
//! ```text
//! <batch>/grid.toml                      the grid as last run
//! <batch>/configs/<configuration>.argos  derived configurations
//! <batch>/runs/<configuration>/seed-<s>/          finished runs (a complete run directory plus run.json)
//! <batch>/runs/<configuration>/seed-<s>.partial/  a run in progress, or one a killed batch left behind
//! ```
//!
//! A run is written under its `.partial` name and renamed when complete, so a killed batch never leaves a
//! partial run under a finished name; a finished run whose configuration text or ticks no longer match the grid
//! is stale and is run again. The run's marker records the SHA-256 of the derived configuration text it ran
//! (the run folder's own `config.argos` is the configuration as run, with absolute paths and the seed written in,
//! so it is not compared). This module never deletes anything outside the batch folder.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::plan::Configuration;
use swarm_contract::run_dir::RUN_MARKER;

/// What the batch folder says about one run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RunState {
    /// Finished for this configuration text, seed and ticks.
    Finished,
    /// Not run yet (or only partially).
    Missing,
    /// Finished, but for different inputs (the grid or the base configuration changed): run again.
    Stale(String),
}

#[derive(Debug, Serialize, Deserialize, PartialEq)]
struct RunMarker {
    configuration: String,
    seed: u64,
    ticks: Option<u64>,
    /// SHA-256 (hex) of the derived configuration text the run was started with.
    configuration_sha256: String,
}

/// SHA-256 of `text`, in hex.
fn sha256(text: &str) -> String {
    ring::digest::digest(&ring::digest::SHA256, text.as_bytes())
        .as_ref()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// A batch folder.
#[derive(Debug, Clone)]
pub struct BatchDir {
    root: PathBuf,
}

impl BatchDir {
    /// Creates (or reopens) the batch folder.
    pub fn create(root: &Path) -> std::io::Result<BatchDir> {
        std::fs::create_dir_all(root.join("configs"))?;
        std::fs::create_dir_all(root.join("runs"))?;
        Ok(BatchDir {
            root: root.to_path_buf(),
        })
    }

    /// The batch folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Where a configuration's derived `.argos` lives.
    pub fn config_path(&self, id: &str) -> PathBuf {
        self.root.join("configs").join(format!("{id}.argos"))
    }

    /// Writes a configuration's derived `.argos` (left untouched when it already holds the same text).
    pub fn write_config(&self, configuration: &Configuration) -> std::io::Result<PathBuf> {
        let path = self.config_path(&configuration.id);
        if std::fs::read_to_string(&path).ok().as_deref() != Some(configuration.text.as_str()) {
            std::fs::write(&path, &configuration.text)?;
        }
        Ok(path)
    }

    /// The finished run directory of a configuration and seed.
    pub fn run_dir(&self, id: &str, seed: u64) -> PathBuf {
        self.root.join("runs").join(id).join(format!("seed-{seed}"))
    }

    /// The directory a run is written to until it is complete.
    pub fn partial_dir(&self, id: &str, seed: u64) -> PathBuf {
        self.root
            .join("runs")
            .join(id)
            .join(format!("seed-{seed}.partial"))
    }

    /// Whether a run is finished for exactly these inputs.
    pub fn state(&self, configuration: &Configuration, seed: u64, ticks: Option<u64>) -> RunState {
        let dir = self.run_dir(&configuration.id, seed);
        if !dir.is_dir() {
            return RunState::Missing;
        }
        let marker = std::fs::read_to_string(dir.join(RUN_MARKER))
            .ok()
            .and_then(|text| serde_json::from_str::<RunMarker>(&text).ok());
        let expected = RunMarker {
            configuration: configuration.id.clone(),
            seed,
            ticks,
            configuration_sha256: sha256(&configuration.text),
        };
        match marker {
            Some(marker) if marker == expected => RunState::Finished,
            Some(marker) if marker.configuration_sha256 != expected.configuration_sha256 => {
                RunState::Stale("its configuration differs from the grid's".into())
            }
            _ => RunState::Stale(format!(
                "{RUN_MARKER} does not record this run's configuration, seed and ticks"
            )),
        }
    }

    /// Removes a run's partial directory (left by an interrupted or killed batch) and, for a stale run, its old
    /// finished directory, so the run starts afresh.
    pub fn clear(&self, id: &str, seed: u64) -> std::io::Result<()> {
        for dir in [self.partial_dir(id, seed), self.run_dir(id, seed)] {
            if dir.exists() {
                std::fs::remove_dir_all(&dir)?;
            }
        }
        Ok(())
    }

    /// Marks a completed run and moves it to its finished name (one rename: a killed batch leaves either the
    /// partial directory or the finished one).
    pub fn complete(
        &self,
        configuration: &Configuration,
        seed: u64,
        ticks: Option<u64>,
    ) -> std::io::Result<PathBuf> {
        let id = configuration.id.as_str();
        let partial = self.partial_dir(id, seed);
        let marker = RunMarker {
            configuration: id.to_owned(),
            seed,
            ticks,
            configuration_sha256: sha256(&configuration.text),
        };
        let text = serde_json::to_string_pretty(&marker).map_err(std::io::Error::other)?;
        swarm_contract::run_dir::write_atomically(
            &partial.join(RUN_MARKER),
            (text + "\n").as_bytes(),
        )?;
        let finished = self.run_dir(id, seed);
        std::fs::rename(&partial, &finished)?;
        Ok(finished)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn configuration(text: &str) -> Configuration {
        Configuration {
            id: "Nr-4".into(),
            levels: vec![0],
            robots: 4,
            text: text.into(),
        }
    }

    fn finish_run(batch: &BatchDir, text: &str, seed: u64, ticks: Option<u64>) {
        let partial = batch.partial_dir("Nr-4", seed);
        std::fs::create_dir_all(&partial).expect("partial dir");
        batch
            .complete(&configuration(text), seed, ticks)
            .expect("rename");
    }

    #[test]
    fn partial_run_is_not_finished_until_completed() {
        let dir = tempfile::tempdir().expect("temp dir");
        let batch = BatchDir::create(dir.path()).expect("batch");
        let c = configuration("<a/>");
        std::fs::create_dir_all(batch.partial_dir("Nr-4", 1)).expect("partial dir");
        assert_eq!(batch.state(&c, 1, Some(20)), RunState::Missing);
        finish_run(&batch, "<a/>", 1, Some(20));
        assert_eq!(batch.state(&c, 1, Some(20)), RunState::Finished);
        assert!(!batch.partial_dir("Nr-4", 1).exists());
    }

    #[test]
    fn finished_run_of_other_inputs_is_stale() {
        let dir = tempfile::tempdir().expect("temp dir");
        let batch = BatchDir::create(dir.path()).expect("batch");
        finish_run(&batch, "<a/>", 1, Some(20));
        assert!(matches!(
            batch.state(&configuration("<a/>"), 1, Some(40)),
            RunState::Stale(_)
        ));
        assert!(matches!(
            batch.state(&configuration("<b/>"), 1, Some(20)),
            RunState::Stale(_)
        ));
        batch.clear("Nr-4", 1).expect("clear");
        assert_eq!(
            batch.state(&configuration("<a/>"), 1, Some(20)),
            RunState::Missing
        );
    }
}
