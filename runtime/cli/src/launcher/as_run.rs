//! The configuration as a run used it (`config.argos` in the run folder): the experiment's own text with every
//! relative path made absolute and every command-line override written in, so that `swarm run <run
//! folder>/config.argos` from anywhere runs the same experiment again.
//!
//! Only values change: comments, layout and everything else stay as written (the edits go through the grid's
//! [`Document`], which replaces attribute values in place). What is written in:
//!
//! - the seed that ran (`<experiment random_seed>`, also when it came from the clock);
//! - `--ticks` as `<experiment length>` (seconds: ticks / ticks_per_second, which gives back the same ticks);
//! - `--robots` as the quantity of the one e-puck `<distribute>`;
//! - each `--limit NAME=VALUE` as `<framework><system NAME="VALUE">`;
//! - each `--fault` text as a child of `<faults>`;
//! - the paths of `supervisors` params, `<floor path>` and the `<hosts>` files, made absolute.
//!
//! Where robots ran (`--hosts`, `--listen`, `--keys`) and whether ticks were paced (`--real-time`) do not change
//! what a lockstep run computes, so they are not written.

use std::path::Path;

use swarm_contract::config::faults::fault_text_as_xml;

use crate::experiment::address::Address;
use crate::experiment::document::{Document, DocumentError};

/// Attributes holding one path each, relative to the configuration's folder.
const PATH_ATTRIBUTES: &[&str] = &[
    "arena/floor@path",
    "framework/hosts@zenoh_config",
    "framework/hosts@password_file",
    "framework/hosts@credentials_file",
    "framework/hosts@tls_certificate",
    "framework/hosts@tls_private_key",
    "framework/hosts@tls_root_ca",
    "framework/hosts@keys",
];
/// Attributes holding a comma-separated list of paths.
const PATH_LIST_ATTRIBUTES: &[&str] = &["controllers/*/params@supervisors"];

/// What the run changed from the configuration file.
#[derive(Debug, Clone, Default)]
pub struct Overrides<'a> {
    /// The run seed.
    pub seed: u64,
    /// `--ticks`, with the experiment's ticks per second.
    pub ticks: Option<(u64, u32)>,
    /// The e-puck `<distribute>` quantity `--robots` gave.
    pub epuck_quantity: Option<u32>,
    /// `--limit` texts (`NAME=VALUE`, already checked).
    pub limits: &'a [String],
    /// `--fault` texts (already checked).
    pub faults: &'a [String],
}

/// Why the configuration could not be rewritten.
#[derive(Debug, thiserror::Error)]
pub enum AsRunError {
    /// The text is not one the editor can index.
    #[error("rewriting the configuration as run: {0}")]
    Document(#[from] DocumentError),
    /// An override cannot be written as XML.
    #[error("rewriting the configuration as run: {0}")]
    Override(String),
}

fn address(text: &str) -> Address {
    // The addresses here are constants of this module; a parse failure is a bug caught by its tests.
    Address::parse(text).unwrap_or_else(|e| unreachable!("address {text}: {e}"))
}

/// `text` (the file at `config`) as the run used it.
pub fn configuration_as_run(
    text: &str,
    config: &Path,
    overrides: &Overrides<'_>,
) -> Result<String, AsRunError> {
    let base = config.parent().unwrap_or_else(|| Path::new(""));
    let document = Document::parse(text)?;
    let mut edits = Vec::new();
    let absolute = |written: &str| base.join(written.trim()).display().to_string();
    for path in PATH_ATTRIBUTES.iter().chain(PATH_LIST_ATTRIBUTES) {
        let address = address(path);
        let list = PATH_LIST_ATTRIBUTES.contains(path);
        let values = document.values(&address);
        let Ok(found) = document.edits(&address, "") else {
            continue;
        };
        for (edit, value) in found.into_iter().zip(values) {
            let Some(value) = value else { continue };
            let resolved = if list {
                value
                    .split(',')
                    .filter(|p| !p.trim().is_empty())
                    .map(absolute)
                    .collect::<Vec<_>>()
                    .join(",")
            } else {
                absolute(&value)
            };
            edits.push(edit.with_value(resolved));
        }
    }
    let experiment = |attribute: &str| address(&format!("framework/experiment@{attribute}"));
    edits.extend(document.edits(&experiment("random_seed"), &overrides.seed.to_string())?);
    if let Some((ticks, ticks_per_second)) = overrides.ticks {
        let seconds = ticks as f64 / f64::from(ticks_per_second.max(1));
        edits.extend(document.edits(&experiment("length"), &seconds.to_string())?);
    }
    if let Some(quantity) = overrides.epuck_quantity {
        edits.extend(document.edits(&address("robots"), &quantity.to_string())?);
    }
    let mut missing_limits = Vec::new();
    for limit in overrides.limits {
        let (name, value) = limit
            .split_once('=')
            .ok_or_else(|| AsRunError::Override(format!("--limit {limit} is not NAME=VALUE")))?;
        let system = address(&format!("framework/system@{}", name.trim()));
        match document.edits(&system, value.trim()) {
            Ok(found) => edits.extend(found),
            Err(_) => missing_limits.push((name.trim().to_owned(), value.trim().to_owned())),
        }
    }
    let mut text = document.apply(&edits);
    if !missing_limits.is_empty() {
        let attributes: String = missing_limits
            .iter()
            .map(|(n, v)| format!(" {n}=\"{}\"", quick_xml::escape::escape(v.as_str())))
            .collect();
        text =
            Document::parse(&text)?.with_child(&["framework"], &format!("<system{attributes}/>"));
    }
    for fault in overrides.faults {
        let xml = fault_text_as_xml(fault).map_err(AsRunError::Override)?;
        text = Document::parse(&text)?.with_child(&["faults"], &xml);
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use swarm_contract::config::Experiment;

    const TEXT: &str = r#"<?xml version="1.0"?>
<argos-configuration>
  <!-- kept as written -->
  <framework>
    <experiment length="10" ticks_per_second="10" random_seed="1"/>
  </framework>
  <controllers>
    <epuck_ptsct_controller id="oa" library="agent">
      <actuators><epuck_wheels implementation="default"/></actuators>
      <sensors><epuck_proximity implementation="default"/></sensors>
      <params profile="obstacle_avoidance" supervisors="models/a.xml, models/b.xml"/>
    </epuck_ptsct_controller>
  </controllers>
  <arena size="2,2,1" center="0,0,0.5">
    <distribute>
      <position method="uniform" min="-1,-1,0" max="1,1,0"/>
      <orientation method="uniform" min="0,0,0" max="360,0,0"/>
      <entity quantity="4" max_trials="100"><e-puck id="ep"><controller config="oa"/></e-puck></entity>
    </distribute>
  </arena>
  <physics_engines><dynamics2d id="dyn2d"/></physics_engines>
  <media/>
</argos-configuration>
"#;

    #[test]
    fn overrides_and_absolute_paths_are_written_in_and_the_rest_is_kept() {
        let faults = ["kill robots=3 tick=50".to_owned()];
        let limits = ["tick_deadline_ms=300".to_owned()];
        let overrides = Overrides {
            seed: 77,
            ticks: Some((25, 10)),
            epuck_quantity: Some(6),
            limits: &limits,
            faults: &faults,
        };
        let text =
            configuration_as_run(TEXT, Path::new("/exp/oa.argos"), &overrides).expect("rewritten");
        assert!(text.contains("<!-- kept as written -->"), "{text}");
        assert!(
            text.contains(r#"supervisors="/exp/models/a.xml,/exp/models/b.xml""#),
            "{text}"
        );
        assert!(text.contains(r#"<kill robots="3" tick="50"/>"#), "{text}");
        assert!(
            text.contains(r#"<system tick_deadline_ms="300"/>"#),
            "{text}"
        );
        let (experiment, _) = Experiment::parse("/elsewhere/config.argos", &text)
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(experiment.framework.random_seed, Some(77));
        assert_eq!(experiment.framework.max_ticks(), Some(25));
        assert_eq!(experiment.arena.robots().len(), 6);
        assert_eq!(experiment.faults.faults.len(), 1);
        assert_eq!(experiment.framework.limits.tick_deadline().as_millis(), 300);
    }

    #[test]
    fn a_run_without_overrides_only_fixes_its_seed_and_paths() {
        let text = configuration_as_run(
            TEXT,
            Path::new("/exp/oa.argos"),
            &Overrides {
                seed: 1,
                ..Overrides::default()
            },
        )
        .expect("rewritten");
        let expected = TEXT.replace(
            "supervisors=\"models/a.xml, models/b.xml\"",
            "supervisors=\"/exp/models/a.xml,/exp/models/b.xml\"",
        );
        assert_eq!(text, expected);
    }
}
