//! Drawing a synthesis: the inputs, every stage of every supervisor (G, E, K, SupC, minimised, reduced) and the
//! final supervisors, as DOT and the images asked for; an automaton too large to draw is noted, not an error.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{Context, Result};

use supervisor_gen::automaton::{Automaton, EventTable, StateId};
use supervisor_gen::dot::{self, Images, ProbLabels, StateMark};
use supervisor_gen::pipeline::{SupervisorSynthesis, Synthesis};
use supervisor_gen::reduce::{Reduction, SupervisorReduction};
use supervisor_gen::report::SkippedOutput;
use supervisor_gen::supc::RemovalReason;

/// Draws the project's inputs (once, into `inputs/`), every intermediate stage of every supervisor (into
/// `stages/`) and the final supervisors (at the top, apart from the rest).
pub(crate) fn draw_synthesis(
    drawer: &mut Drawer<'_>,
    synthesis: &Synthesis,
    reduction: Option<&Reduction>,
) -> Result<()> {
    let project = &synthesis.normalised;
    for a in project.plants.iter().chain(&project.specs) {
        let stem = format!("inputs/{}", dot::file_stem(a.name()));
        drawer.draw(&stem, a, &HashMap::new(), ProbLabels::Stored)?;
    }
    for (i, s) in synthesis.supervisors.iter().enumerate() {
        draw_stages(drawer, s, reduction.map(|r| &r.supervisors[i]))?;
    }
    if let Some(s) = &synthesis.monolithic_reference {
        draw_stages(drawer, s, None)?;
    }
    for o in reduction.iter().flat_map(|r| &r.observers) {
        let stem = format!("observer_{}", dot::file_stem(o.name()));
        drawer.draw(&stem, o, &HashMap::new(), ProbLabels::Stored)?;
    }
    Ok(())
}

/// G, E, K (with the removed states marked), SupC before minimisation, with a reduction the minimised supervisor
/// and its reduction (`_5_minimised`, `_6_reduced`), and the final supervisor (the one compiled).
fn draw_stages(
    drawer: &mut Drawer<'_>,
    s: &SupervisorSynthesis,
    reduction: Option<&SupervisorReduction>,
) -> Result<()> {
    let stem = dot::file_stem(&s.name);
    let removed: HashMap<StateId, StateMark> = s
        .removed
        .iter()
        .map(|r| match r.reason {
            RemovalReason::Bad { .. } => (r.state, StateMark::Bad),
            _ => (r.state, StateMark::Removed),
        })
        .collect();
    let none = HashMap::new();
    // K is kept only when drawing (`keep_targets`).
    let target = s.target.as_ref().map(|k| ("3_K", k, &removed));
    let inputs = [("1_G", &s.plant, &none), ("2_E", &s.spec, &none)];
    let supc = ("4_supc", &s.unminimised, &none);
    let minimised = reduction.map(|_| ("5_minimised", &s.supervisor, &none));
    let reduced = reduction
        .and_then(|r| r.reduced.as_ref())
        .map(|a| ("6_reduced", a, &none));
    let stages = inputs
        .into_iter()
        .chain(target)
        .chain([supc])
        .chain(minimised)
        .chain(reduced);
    for (stage, automaton, marks) in stages {
        drawer.draw(
            &format!("stages/{stem}_{stage}"),
            automaton,
            marks,
            ProbLabels::Stored,
        )?;
    }
    let last = reduction.map_or(&s.supervisor, SupervisorReduction::supervisor);
    drawer.draw(&stem, last, &none, ProbLabels::Stored)?;
    Ok(())
}

/// Writes drawings of automata over one event table into one directory, and notes the drawings it leaves out.
pub(crate) struct Drawer<'a> {
    pub(crate) dir: &'a Path,
    pub(crate) events: &'a EventTable,
    pub(crate) images: Images,
    /// Drawings (or their images) not written because the automaton is too large, relative to `dir`.
    pub(crate) skipped: Vec<SkippedOutput>,
}

impl Drawer<'_> {
    /// Writes one drawing; returns the number of files written. An automaton of more than
    /// [`dot::MAX_DOT_STATES`] states is not drawn, and one of more than [`dot::MAX_IMAGE_STATES`] gets its DOT
    /// file but no images: both are noted in `skipped`.
    pub(crate) fn draw(
        &mut self,
        stem: &str,
        a: &Automaton,
        marks: &HashMap<StateId, StateMark>,
        probs: ProbLabels,
    ) -> Result<usize> {
        let states = a.state_count();
        if states > dot::MAX_DOT_STATES {
            self.skipped.push(SkippedOutput {
                output: format!("{stem}.dot"),
                reason: format!(
                    "{states} states, more than the {} drawn at all",
                    dot::MAX_DOT_STATES
                ),
            });
            return Ok(0);
        }
        let text = dot::to_dot(a, self.events, marks, probs);
        let no_images = Images {
            formats: Vec::new(),
            dpi: None,
        };
        let images = if states > dot::MAX_IMAGE_STATES && !self.images.formats.is_empty() {
            self.skipped.push(SkippedOutput {
                output: format!("{stem} images"),
                reason: format!(
                    "{states} states, more than the {} Graphviz is asked to lay out; the DOT file is written",
                    dot::MAX_IMAGE_STATES
                ),
            });
            &no_images
        } else {
            &self.images
        };
        let written = dot::write_drawing(self.dir, stem, &text, images)
            .with_context(|| format!("cannot write drawing {stem} in {}", self.dir.display()))?;
        Ok(written.len())
    }
}
