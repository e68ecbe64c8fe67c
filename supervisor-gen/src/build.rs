//! Models to a compiled supervisor set in one call: load, validate, convert, synthesise, compile.
//!
//! This is what the command line's `synth` and `codegen` do before writing files, and what a launcher calls to
//! compile supervisors from XML models at start-up. It writes nothing and prints nothing: diagnostics come back in
//! the result or in [`BuildError::Invalid`].

use std::fmt;
use std::path::PathBuf;

use crate::architecture::Architecture;
use crate::automaton::ModelKind;
use crate::compiled::{CodegenError, SupervisorSet};
use crate::convert::{ConvertError, to_project};
use crate::diagnostics::Diagnostic;
use crate::load::{Input, LoadError, load};
use crate::pipeline::{Synthesis, SynthesisError, SynthesisOptions, synthesize};
use crate::validate::ValidateOptions;

/// What to build and how.
#[derive(Debug, Clone)]
pub struct BuildRequest {
    /// Plant model files (thesis XML or Nadzoru2).
    pub plants: Vec<PathBuf>,
    /// Specification model files.
    pub specs: Vec<PathBuf>,
    /// Supervisor architecture.
    pub architecture: Architecture,
    /// Keep specification weights as written (`--raw-weights`).
    pub raw_weights: bool,
    /// Keep plant probability factors (`--thesis-literal-probabilities`).
    pub thesis_literal_probabilities: bool,
    /// Keep each K = G ∥ E in the synthesis ([`SynthesisOptions::keep_targets`]), for drawings.
    pub keep_targets: bool,
}

/// A successful build.
#[derive(Debug, Clone)]
pub struct Built {
    /// Every intermediate result of synthesis, for reports and drawings.
    pub synthesis: Synthesis,
    /// The compiled set the runtime executes.
    pub set: SupervisorSet,
    /// Validation warnings (never errors).
    pub warnings: Vec<Diagnostic>,
}

/// Why no supervisor set was built.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// A model file could not be read.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// Validation found errors; holds every diagnostic (errors and warnings), sorted by file and position.
    #[error("{}", Listing(.0))]
    Invalid(Vec<Diagnostic>),
    /// Validated models were refused by the core model.
    #[error(transparent)]
    Convert(#[from] ConvertError),
    /// No supervisor exists (impossible specification) or synthesis could not run.
    #[error(transparent)]
    Synthesis(#[from] SynthesisError),
    /// The supervisors exceed the limits of the compiled format.
    #[error(transparent)]
    Codegen(#[from] CodegenError),
}

/// Renders diagnostics one per line.
struct Listing<'a>(&'a [Diagnostic]);

impl fmt::Display for Listing<'_> {
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

/// A synthesised project before it is compiled: everything but the compiled set, which can be too large for the
/// compact format while the synthesis itself succeeded.
#[derive(Debug)]
pub struct Synthesised {
    /// Every intermediate result of synthesis, for reports, drawings and the supervisors' XML.
    pub synthesis: Synthesis,
    /// Validation warnings (never errors).
    pub warnings: Vec<Diagnostic>,
}

/// Loads, validates, synthesises and compiles.
pub fn build(request: &BuildRequest) -> Result<Built, BuildError> {
    let Synthesised {
        synthesis,
        warnings,
    } = synthesise(request)?;
    let set = synthesis.compile()?;
    Ok(Built {
        synthesis,
        set,
        warnings,
    })
}

/// Loads, validates and synthesises, without compiling.
pub fn synthesise(request: &BuildRequest) -> Result<Synthesised, BuildError> {
    let plants = request
        .plants
        .iter()
        .map(|p| Input::new(p, Some(ModelKind::Plant)));
    let specs = request
        .specs
        .iter()
        .map(|p| Input::new(p, Some(ModelKind::Spec)));
    let inputs: Vec<Input> = plants.chain(specs).collect();
    let validation = load(
        &inputs,
        ValidateOptions {
            thesis_literal_probabilities: request.thesis_literal_probabilities,
            raw_weights: request.raw_weights,
        },
    )?;
    let Some(models) = validation.models else {
        return Err(BuildError::Invalid(validation.diagnostics));
    };
    let project = to_project(&models)?;
    let synthesis = synthesize(
        &project,
        request.architecture,
        SynthesisOptions {
            raw_weights: request.raw_weights,
            thesis_literal_probabilities: request.thesis_literal_probabilities,
            keep_targets: request.keep_targets,
            ..SynthesisOptions::default()
        },
    )?;
    Ok(Synthesised {
        synthesis,
        warnings: validation.diagnostics,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture(name: &str) -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures")
            .join(name)
    }

    fn request(plants: &[&str], specs: &[&str]) -> BuildRequest {
        BuildRequest {
            plants: plants.iter().map(|p| fixture(p)).collect(),
            specs: specs.iter().map(|s| fixture(s)).collect(),
            architecture: Architecture::LocalModular,
            raw_weights: false,
            thesis_literal_probabilities: false,
            keep_targets: false,
        }
    }

    #[test]
    fn factory_builds_one_local_supervisor_of_64_bytes() {
        let built = build(&request(
            &["factory/machine1.xml", "factory/machine2.xml"],
            &["factory/buffer.xml"],
        ))
        .expect("builds");
        assert_eq!(built.set.supervisors.len(), 1);
        assert_eq!(built.set.mem_cons(), 64);
        assert!(built.warnings.is_empty());
    }

    #[test]
    fn invalid_models_return_every_diagnostic() {
        let err = build(&request(
            &[
                "invalid/v8_nondeterministic.xml",
                "invalid/v3_no_marked.xml",
            ],
            &["factory/buffer.xml"],
        ))
        .expect_err("invalid");
        let BuildError::Invalid(diagnostics) = &err else {
            panic!("expected Invalid, got {err}");
        };
        let codes: Vec<String> = diagnostics.iter().map(|d| d.code.to_string()).collect();
        assert!(
            codes.contains(&"V8".into()) && codes.contains(&"V3".into()),
            "{codes:?}"
        );
        assert_eq!(err.to_string().lines().count(), diagnostics.len());
    }

    #[test]
    fn impossible_specification_names_the_spec() {
        let err = build(&request(
            &["factory/machine1.xml"],
            &["factory/impossible.xml"],
        ))
        .expect_err("impossible");
        assert!(
            matches!(&err, BuildError::Synthesis(SynthesisError::EmptySupervisor { spec, .. }) if spec == "impossible"),
            "{err}"
        );
    }
}
