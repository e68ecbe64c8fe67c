//! Where a robot's supervisor set comes from: a compiled file, a folder of XML models synthesised at startup, or
//! the models built into this binary.
//!
//! Models go through supervisor-gen's library exactly as `supervisor-gen synth` would take them: read, validate
//! (every located diagnostic reported at once), local-modular synthesis, minimisation, compilation; and, when the
//! controller asks for it (`reduce_supervisors="true"`), supervisor reduction as `supervisor-gen synth --reduce`
//! does it: every reduction checked against the unreduced closed loop, used only where the set shrinks, with the
//! plant observers the reduced supervisors need. This module runs only at startup; it never touches the tick loop.

use std::fmt;
use std::path::{Path, PathBuf};

use swarm_contract::supervisor_gen::architecture::Architecture;
use swarm_contract::supervisor_gen::compiled::{CodegenError, CompiledFormatError, SupervisorSet};
use swarm_contract::supervisor_gen::convert::{ConvertError, to_project};
use swarm_contract::supervisor_gen::diagnostics::{Diagnostic, has_errors};
use swarm_contract::supervisor_gen::pipeline::{SynthesisError, SynthesisOptions, synthesize};
use swarm_contract::supervisor_gen::reduce::{ReduceError, ReduceLimits, reduce_synthesis};
use swarm_contract::supervisor_gen::validate::{ValidateOptions, validate};
use swarm_contract::supervisor_gen::xml_read::read_model;
use thiserror::Error;
use tracing::{info, warn};

/// One model file: the name diagnostics use, and its text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModelText<'a> {
    /// File name as shown in diagnostics.
    pub file: &'a str,
    /// XML text.
    pub text: &'a str,
}

/// The ptSCT obstacle-avoidance models (configs/obstacle_avoidance/models/ptsct), built into the binary for the
/// thesis' `epuck_obstacle_avoidance_sct_prob_controller`.
pub const OBSTACLE_AVOIDANCE_PTSCT: &[ModelText<'static>] = &[
    ModelText {
        file: "builtin:obstacle_avoidance/ptsct/G_prox.xml",
        text: include_str!("../../configs/obstacle_avoidance/models/ptsct/G_prox.xml"),
    },
    ModelText {
        file: "builtin:obstacle_avoidance/ptsct/G_motor.xml",
        text: include_str!("../../configs/obstacle_avoidance/models/ptsct/G_motor.xml"),
    },
    ModelText {
        file: "builtin:obstacle_avoidance/ptsct/E_walk.xml",
        text: include_str!("../../configs/obstacle_avoidance/models/ptsct/E_walk.xml"),
    },
    ModelText {
        file: "builtin:obstacle_avoidance/ptsct/E_avoid.xml",
        text: include_str!("../../configs/obstacle_avoidance/models/ptsct/E_avoid.xml"),
    },
];

/// The located diagnostics of models that failed validation, one per line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostics(pub Vec<Diagnostic>);

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{d}")?;
        }
        Ok(())
    }
}

/// Why no supervisor set could be loaded.
#[derive(Debug, Error)]
pub enum SupervisorError {
    /// A model file or folder could not be read.
    #[error("cannot read {}: {problem}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The OS error.
        problem: std::io::Error,
    },
    /// No supervisor file was named.
    #[error("no supervisor files given")]
    NoFiles,
    /// XML models and compiled files were mixed.
    #[error(
        "give either XML model files (or one folder of them) or one compiled supervisor file, not a mix"
    )]
    Mixed,
    /// A folder of models holds no `.xml` file.
    #[error("{}: no .xml model files in this folder", path.display())]
    NoModels {
        /// The folder.
        path: PathBuf,
    },
    /// The models have errors.
    #[error("the supervisor models have errors:\n{0}")]
    Invalid(Diagnostics),
    /// Validated models could not become a project.
    #[error(transparent)]
    Convert(#[from] ConvertError),
    /// Synthesis found no supervisor.
    #[error(transparent)]
    Synthesis(#[from] SynthesisError),
    /// The supervisors exceed the compiled layout's limits.
    #[error(transparent)]
    Codegen(#[from] CodegenError),
    /// A reduced supervisor failed its equivalence check (it is never used).
    #[error(transparent)]
    Reduction(#[from] ReduceError),
    /// A compiled supervisor file is unreadable or malformed.
    #[error(transparent)]
    Compiled(#[from] CompiledFormatError),
}

/// Loads a supervisor set from `files`: XML model files, or one folder of them (synthesised local-modular), or
/// one compiled supervisor-set file.
pub fn load(files: &[PathBuf]) -> Result<SupervisorSet, SupervisorError> {
    load_with(files, false)
}

/// Like [`load`]; with `reduce`, supervisors synthesised from models are reduced. A compiled file is loaded as it
/// was written (reduced or not when it was compiled, e.g. by the launcher's `--check --write-supervisors`).
pub fn load_with(files: &[PathBuf], reduce: bool) -> Result<SupervisorSet, SupervisorError> {
    let is_xml = |p: &Path| p.extension().is_some_and(|x| x == "xml");
    let models: Vec<PathBuf> = match files {
        [] => return Err(SupervisorError::NoFiles),
        [one] if one.is_dir() => models_in(one)?,
        [one] if !is_xml(one) => return Ok(SupervisorSet::read(one)?),
        many if many.iter().all(|p| is_xml(p)) => many.to_vec(),
        _ => return Err(SupervisorError::Mixed),
    };
    let mut texts = Vec::with_capacity(models.len());
    for file in &models {
        let io = |problem| SupervisorError::Io {
            path: file.clone(),
            problem,
        };
        // The same limits as `supervisor-gen`: a device or FIFO named as a model must not hang the agent.
        let bytes = swarm_contract::supervisor_gen::load::read_limited(file).map_err(io)?;
        let text = String::from_utf8(bytes).map_err(|e| {
            io(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "not valid UTF-8 at byte {} (model files must be UTF-8)",
                    e.utf8_error().valid_up_to()
                ),
            ))
        })?;
        texts.push((file.display().to_string(), text));
    }
    let models: Vec<ModelText<'_>> = texts
        .iter()
        .map(|(file, text)| ModelText { file, text })
        .collect();
    synthesise_with(&models, reduce)
}

/// The `.xml` files of folder `dir`, sorted by name.
fn models_in(dir: &Path) -> Result<Vec<PathBuf>, SupervisorError> {
    let io = |problem| SupervisorError::Io {
        path: dir.to_owned(),
        problem,
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(io)?
        .map(|entry| entry.map(|e| e.path()))
        .collect::<Result<_, _>>()
        .map_err(io)?;
    files.retain(|p| p.extension().is_some_and(|x| x == "xml"));
    files.sort();
    if files.is_empty() {
        return Err(SupervisorError::NoModels {
            path: dir.to_owned(),
        });
    }
    Ok(files)
}

/// Validates `models` and synthesises their local-modular supervisor set.
pub fn synthesise(models: &[ModelText<'_>]) -> Result<SupervisorSet, SupervisorError> {
    synthesise_with(models, false)
}

/// Like [`synthesise`]; with `reduce`, the set is reduced (see the module documentation).
pub fn synthesise_with(
    models: &[ModelText<'_>],
    reduce: bool,
) -> Result<SupervisorSet, SupervisorError> {
    let mut problems = Vec::new();
    let mut sources = Vec::with_capacity(models.len());
    for m in models {
        match read_model(m.file, m.text, None) {
            Ok(source) => sources.push(source),
            Err(mut found) => problems.append(&mut found),
        }
    }
    let validation = validate(&sources, ValidateOptions::default());
    problems.extend(validation.diagnostics);
    let checked = match validation.models {
        Some(checked) if !has_errors(&problems) => checked,
        _ => {
            problems.retain(Diagnostic::is_error);
            return Err(SupervisorError::Invalid(Diagnostics(problems)));
        }
    };
    for w in &problems {
        warn!("{w}");
    }
    let project = to_project(&checked)?;
    let options = SynthesisOptions {
        validate: false,
        ..SynthesisOptions::default()
    };
    let synthesis = synthesize(&project, Architecture::LocalModular, options)?;
    if !reduce {
        return Ok(synthesis.compile()?);
    }
    let reduction = reduce_synthesis(&synthesis, ReduceLimits::default())?;
    for w in reduction.warnings() {
        warn!("{w}");
    }
    info!(
        mem_cons_before = reduction.mem_cons_before,
        mem_cons_after = reduction.mem_cons_after,
        observers = reduction.observers.len(),
        "supervisors reduced"
    );
    Ok(reduction.compile(&synthesis.normalised.events)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_obstacle_avoidance_models_give_two_local_supervisors() {
        let set = synthesise(OBSTACLE_AVOIDANCE_PTSCT).unwrap();
        assert_eq!(set.supervisors.len(), 2);
        let mut names: Vec<(&str, bool)> = set
            .events
            .iter()
            .map(|e| (e.name.as_str(), e.controllable))
            .collect();
        names.sort();
        assert_eq!(
            names,
            [
                ("Go", true),
                ("saw-obs", false),
                ("turn-inv-obs", true),
                ("turn-left", true),
                ("turn-right", true),
            ]
        );
    }

    #[test]
    fn reduced_synchronisation_supervisors_are_smaller_and_bind_the_same_events() {
        let models = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../configs/synchronisation/models/ptsct");
        let plain = load(std::slice::from_ref(&models)).unwrap();
        let reduced = load_with(&[models], true).unwrap();
        assert_eq!((plain.mem_cons(), reduced.mem_cons()), (140, 137));
        assert_eq!(reduced.events, plain.events);
        let states = |set: &SupervisorSet| -> Vec<(String, usize)> {
            set.supervisors
                .iter()
                .map(|s| (s.name.clone(), s.states.len()))
                .collect()
        };
        assert_eq!(
            states(&reduced),
            [
                ("S_E1".to_owned(), 5),
                ("S_E2a".to_owned(), 2),
                ("S_E2b".to_owned(), 2)
            ]
        );
        // Nothing pays for the obstacle-avoidance models: the reduced set is the set.
        let builtin = synthesise_with(OBSTACLE_AVOIDANCE_PTSCT, true).unwrap();
        assert_eq!(builtin, synthesise(OBSTACLE_AVOIDANCE_PTSCT).unwrap());
    }

    #[test]
    fn invalid_model_reports_file_line_and_column() {
        let broken = ModelText {
            file: "E_bad.xml",
            text: "<automata name=\"E_bad\" type=\"spec\">\n  <states><state name=\"a\" i=\"1\" m=\"1\"/></states>\n  \
                   <events><event name=\"x\" con=\"1\"/></events>\n  \
                   <transitions><transition src=\"a\" dst=\"nowhere\" event=\"x\"/></transitions>\n</automata>\n",
        };
        let err = synthesise(&[broken]).unwrap_err().to_string();
        assert!(
            err.starts_with("the supervisor models have errors:\nE_bad.xml:4:"),
            "{err}"
        );
        assert!(err.contains("nowhere"), "{err}");
    }

    #[test]
    fn xml_models_and_a_compiled_file_cannot_be_mixed() {
        let files = [PathBuf::from("G.xml"), PathBuf::from("set.sup")];
        assert!(matches!(load(&files), Err(SupervisorError::Mixed)));
    }

    #[test]
    fn folder_without_models_is_rejected() {
        let dir = tempfile::tempdir().unwrap();
        let err = load(&[dir.path().to_owned()]).unwrap_err();
        assert!(matches!(err, SupervisorError::NoModels { .. }));
    }

    #[test]
    fn missing_compiled_file_names_the_path() {
        let err = load(&[PathBuf::from("/nonexistent/oa.sup")])
            .unwrap_err()
            .to_string();
        assert!(err.contains("/nonexistent/oa.sup"), "{err}");
    }

    #[test]
    fn a_device_named_as_a_model_or_compiled_set_is_refused_before_it_is_read() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let model = dir.path().join("zero.xml");
        std::os::unix::fs::symlink("/dev/zero", &model).expect("a symbolic link");
        for files in [vec![model], vec![PathBuf::from("/dev/zero")]] {
            let err = load(&files).unwrap_err().to_string();
            assert!(err.contains("not a regular file"), "{err}");
        }
    }
}
