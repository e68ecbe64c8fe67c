//! What `synth` writes and prints: the supervisors' XML, the compiled set and generated module, the summary.

use std::path::Path;

use anyhow::Result;

use supervisor_gen::automaton::{Automaton, EventTable};
use supervisor_gen::codegen::generate_rust;
use supervisor_gen::dot;
use supervisor_gen::pipeline::Synthesis;
use supervisor_gen::reduce::{Reduction, ReductionOutcome};
use supervisor_gen::report::SkippedOutput;
use supervisor_gen::xml_write::write_xml;

use crate::{SynthArgs, origin, write, write_with};

/// The XML files `synth` writes, relative to the output directory.
pub(crate) struct XmlFiles {
    /// One per supervisor, the one compiled: `<S>.xml`.
    pub(crate) supervisors: Vec<String>,
    /// One per reduction computed (with `--reduce`): `<S>.reduced.xml`.
    pub(crate) reduced: Vec<String>,
    /// One per plant observer (with `--reduce`): `observer_<plant>.xml`.
    pub(crate) observers: Vec<String>,
}

/// The supervisors (reduced where a reduction is used), every reduction and the observers, each with its file.
pub(crate) fn supervisors_xml<'a>(
    synthesis: &'a Synthesis,
    reduction: Option<&'a Reduction>,
) -> (XmlFiles, Vec<(String, &'a Automaton)>) {
    let mut models = Vec::new();
    let mut named = |automata: Vec<&'a Automaton>, prefix: &str, suffix: &str| -> Vec<String> {
        automata
            .into_iter()
            .map(|a| {
                let file = format!("{prefix}{}{suffix}.xml", dot::file_stem(a.name()));
                models.push((file.clone(), a));
                file
            })
            .collect()
    };
    let files = match reduction {
        None => XmlFiles {
            supervisors: named(
                synthesis
                    .supervisors
                    .iter()
                    .map(|s| &s.supervisor)
                    .collect(),
                "",
                "",
            ),
            reduced: Vec::new(),
            observers: Vec::new(),
        },
        Some(r) => XmlFiles {
            supervisors: named(
                r.supervisors.iter().map(|s| s.supervisor()).collect(),
                "",
                "",
            ),
            reduced: named(
                r.supervisors
                    .iter()
                    .filter_map(|s| s.reduced.as_ref())
                    .collect(),
                "",
                ".reduced",
            ),
            observers: named(r.observers.iter().collect(), "observer_", ""),
        },
    };
    (files, models)
}

/// Writes `supervisors.ptsct` and `supervisors.rs` of the set (the reduced one with `--reduce`), or notes in
/// `skipped` why they were not; returns the bytes written and the set's MemCons.
pub(crate) fn write_compiled(
    args: &SynthArgs,
    synthesis: &Synthesis,
    reduction: Option<&Reduction>,
    skipped: &mut Vec<SkippedOutput>,
) -> Result<(usize, usize)> {
    let compiled = match reduction {
        Some(r) => r.compile(&synthesis.normalised.events),
        None => synthesis.compile(),
    };
    match compiled {
        Ok(set) => {
            let bytes = set.to_bytes();
            write(&args.out.join("supervisors.ptsct"), &bytes)?;
            let origin = origin(&args.project, synthesis.architecture, args.reduce);
            write(
                &args.out.join("supervisors.rs"),
                generate_rust(&set, &origin),
            )?;
            Ok((bytes.len(), set.mem_cons()))
        }
        Err(err) => {
            for output in ["supervisors.ptsct", "supervisors.rs"] {
                skipped.push(SkippedOutput {
                    output: output.to_owned(),
                    reason: format!("V15: {err}"),
                });
            }
            Ok((
                0,
                reduction.map_or(synthesis.mem_cons, |r| r.mem_cons_after),
            ))
        }
    }
}

/// Writes each automaton to its file in `out`.
pub(crate) fn write_models(
    out: &Path,
    models: &[(String, &Automaton)],
    events: &EventTable,
) -> Result<()> {
    for (file, a) in models {
        write_with(&out.join(file), |w| write_xml(a, events, w))?;
    }
    Ok(())
}

pub(crate) fn print_summary(
    synthesis: &Synthesis,
    reduction: Option<&Reduction>,
    mem_cons: usize,
    out: &Path,
) {
    for s in &synthesis.supervisors {
        println!(
            "{}: {} states, {} transitions ({} controllable), {} events; {} state(s) of K removed",
            s.name,
            s.stats.states,
            s.stats.transitions,
            s.stats.controllable_transitions,
            s.stats.events,
            s.removed.len()
        );
    }
    if let Some(nc) = &synthesis.non_conflict {
        if nc.nonblocking {
            println!("non-conflict: the supervisors are nonblocking together");
        } else {
            println!(
                "warning: the supervisors conflict: {} blocking product state(s), e.g. {}",
                nc.blocking_count,
                nc.blocking_states.join(", ")
            );
        }
    }
    if let Some(v) = &synthesis.local_modular_validation {
        if v.passed() {
            println!(
                "local-modular validation: the local supervisors equal the monolithic supervisor"
            );
        } else {
            println!(
                "warning: local-modular validation failed: see report.json (architecture_checks)"
            );
        }
    }
    match reduction {
        Some(r) => {
            print_reduction(r);
            println!(
                "MemCons {mem_cons} bytes ({} unreduced); outputs in {}",
                r.mem_cons_before,
                out.display()
            );
        }
        None => println!("MemCons {mem_cons} bytes; outputs in {}", out.display()),
    }
}

/// One line per supervisor of a reduction, its observers and its warnings.
fn print_reduction(reduction: &Reduction) {
    for s in &reduction.supervisors {
        let Some(reduced) = &s.reduced else {
            println!("reduction: {} not reduced (see the warning)", s.name);
            continue;
        };
        let what = match &s.outcome {
            ReductionOutcome::Reduced => "reduced",
            ReductionOutcome::NoGain => "kept, its reduction is no smaller",
            ReductionOutcome::ObserversCostMore => {
                "kept, the plant observers its reduction needs cost more"
            }
            ReductionOutcome::Skipped { .. } => "kept",
        };
        println!(
            "reduction: {} {what}: {} -> {} states, {} -> {} transitions",
            s.name,
            s.original.state_count(),
            reduced.state_count(),
            s.original.transition_count(),
            reduced.transition_count(),
        );
    }
    if !reduction.observers.is_empty() {
        let names: Vec<&str> = reduction.observers.iter().map(Automaton::name).collect();
        println!(
            "reduction: plant observers run with the reduced supervisors: {}",
            names.join(", ")
        );
    }
    println!(
        "reduction: each reduction checked against the unreduced closed loop (language, marking, P, T, timers)"
    );
    for w in reduction.warnings() {
        eprintln!("warning: {w}");
    }
}
