//! Supervisor reduction: random projects against a brute-force walk of the closed loops (independent of the
//! product code and of the library's own check), and textbook models whose reduced sizes were derived by hand.

use std::cell::Cell;
use std::collections::HashMap;
use std::path::PathBuf;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use supervisor_gen::architecture::Architecture;
use supervisor_gen::automaton::{Automaton, EventId, EventTable, ModelKind, Project, StateId};
use supervisor_gen::build::{BuildRequest, synthesise};
use supervisor_gen::compiled::prob_to_q16;
use supervisor_gen::families::{foraging_like, mutex, transfer_line};
use supervisor_gen::pipeline::{Synthesis, SynthesisOptions, synthesize};
use supervisor_gen::reduce::{
    ReduceLimits, Reduction, ReductionOutcome, check_reduction, check_set, reduce_synthesis,
};

/// One member of a set being simulated: its current state and its timer stamps (docs/ptsct.md section 3).
#[derive(Clone)]
struct Runner<'a> {
    a: &'a Automaton,
    state: StateId,
    entered: usize,
    fired: HashMap<EventId, usize>,
}

impl<'a> Runner<'a> {
    fn new(a: &'a Automaton) -> Self {
        Self {
            a,
            state: a.initial(),
            entered: 0,
            fired: HashMap::new(),
        }
    }

    fn owns(&self, e: EventId) -> bool {
        self.a.has_event(e)
    }

    fn defines(&self, e: EventId) -> bool {
        self.a.transition(self.state, e).is_some()
    }

    /// (P in Q0.16, T) of `e` here.
    fn label(&self, e: EventId) -> (u16, u32) {
        let t = self.a.transition(self.state, e).expect("defined");
        (prob_to_q16(t.prob), t.lower_bound)
    }

    /// The first tick at which `e` satisfies its lower bound here.
    fn ready_at(&self, e: EventId) -> usize {
        let since = self
            .fired
            .get(&e)
            .map_or(self.entered, |&f| f.max(self.entered));
        since + self.label(e).1 as usize
    }

    /// Moves on `e` at tick `tick` as the player does: a new state restarts every counter, a self-loop its own.
    fn fire(&mut self, e: EventId, tick: usize) {
        if !self.owns(e) {
            return;
        }
        let target = self.a.transition(self.state, e).expect("defined").target;
        if target == self.state {
            self.fired.insert(e, tick);
        } else {
            self.state = target;
            self.entered = tick;
            self.fired.clear();
        }
    }
}

/// What a set of automata running together offers at tick `next`: for every event all owners allow, the product
/// of the owners' P (Q0.16), and the first tick from `next` on at which the owners with a lower bound above 0
/// allow it (`None` if there are none); and whether every member is marked.
fn offer(
    ev: &EventTable,
    set: &[Runner<'_>],
    next: usize,
) -> (Vec<(EventId, f64, Option<usize>)>, bool) {
    let mut out = Vec::new();
    for e in ev.ids() {
        let owners: Vec<&Runner<'_>> = set.iter().filter(|r| r.owns(e)).collect();
        if owners.is_empty() || !owners.iter().all(|r| r.defines(e)) {
            continue;
        }
        if !ev.is_controllable(e) {
            out.push((e, 1.0, None));
            continue;
        }
        // Observers add factors 1.0 exactly; the other factors come in the same order in both sets.
        let weight = owners.iter().fold(1.0, |w, r| {
            w * f64::from(r.label(e).0) / f64::from(u16::MAX)
        });
        let ready = owners
            .iter()
            .filter(|r| r.label(e).1 > 0)
            .map(|r| r.ready_at(e).max(next))
            .max();
        out.push((e, weight, ready));
    }
    let marked = set.iter().all(|r| r.a.is_marked(r.state));
    (out, marked)
}

fn runners<'a>(set: &[&'a Automaton]) -> Vec<Runner<'a>> {
    set.iter().map(|x| Runner::new(x)).collect()
}

/// The tick of the `i`-th event (from 0) of a string: the gaps alternate between 1 and 2 ticks, so that both an
/// immediate and a delayed next event are tried.
fn tick_of(i: usize) -> usize {
    i + i / 2 + 1
}

/// Walks every string of up to `depth` events that the two sets generate, at the ticks of [`tick_of`], and compares what
/// they offer after each one (events, weights, ticks of timed events, and marking if `marking`). By direct
/// simulation of the members, without the library's product or check. Returns the number of strings compared.
fn walk_sets(
    ev: &EventTable,
    (a, b): (&[&Automaton], &[&Automaton]),
    marking: bool,
    depth: usize,
) -> Result<usize, String> {
    let mut stack = vec![(runners(a), runners(b), Vec::<String>::new())];
    let mut compared = 0;
    while let Some((ra, rb, string)) = stack.pop() {
        compared += 1;
        let tick = tick_of(string.len());
        let (mut oa, mut ob) = (offer(ev, &ra, tick), offer(ev, &rb, tick));
        if !marking {
            (oa.1, ob.1) = (false, false);
        }
        if oa != ob {
            return Err(format!("after {string:?}: {oa:?} against {ob:?}"));
        }
        if string.len() == depth {
            continue;
        }
        for &(e, _, _) in &oa.0 {
            let (mut na, mut nb) = (ra.clone(), rb.clone());
            na.iter_mut().for_each(|r| r.fire(e, tick));
            nb.iter_mut().for_each(|r| r.fire(e, tick));
            let mut s = string.clone();
            s.push(ev.name(e).to_owned());
            stack.push((na, nb, s));
        }
    }
    Ok(compared)
}

/// Every reduction of `synthesis` against its original in closed loop with its plant, and the compiled set of
/// `reduction` against the unreduced set as the player runs them (no plant, no marking), both by [`walk_sets`].
fn assert_equivalent(
    synthesis: &Synthesis,
    reduction: &Reduction,
    depth: usize,
) -> Result<(), String> {
    let ev = &synthesis.normalised.events;
    for (s, r) in synthesis.supervisors.iter().zip(&reduction.supervisors) {
        let Some(reduced) = &r.reduced else { continue };
        if reduced.state_count() > s.supervisor.state_count() {
            return Err(format!("{} grew", s.name));
        }
        check_reduction(ev, &s.plant, &s.supervisor, reduced).map_err(|m| m.to_string())?;
        walk_sets(
            ev,
            (&[&s.plant, &s.supervisor], &[&s.plant, reduced]),
            true,
            depth,
        )?;
    }
    let before = synthesis.final_supervisors();
    let after = reduction.final_automata();
    let before: Vec<&Automaton> = before.iter().collect();
    let after: Vec<&Automaton> = after.iter().collect();
    // The player has no marking: marked languages are compared above, in closed loop with each plant.
    walk_sets(ev, (&before, &after), false, depth)?;
    if reduction.mem_cons_after > reduction.mem_cons_before {
        return Err("the set grew".into());
    }
    Ok(())
}

/// Events of the random projects: a, b, c controllable; u, v, w uncontrollable.
const EVENTS: [(&str, bool); 6] = [
    ("a", true),
    ("b", true),
    ("c", true),
    ("u", false),
    ("v", false),
    ("w", false),
];

/// Whether each event has a transition, and its target, weight in quarters, and lower bound.
type Row = Vec<(bool, usize, u32, u32)>;

/// A random model of 2 or 3 states over `events` (indices into [`EVENTS`]) with its initial state marked: each
/// state has each event with probability about 2/3, to a random state, with a weight of 1-3 quarters and a lower
/// bound of 0 (usually), 1 or 2. A specification self-loops an uncontrollable event it does not otherwise take
/// (docs/ptsct.md 8.7), so fewer specifications are impossible.
fn arb_model(
    name: &'static str,
    kind: ModelKind,
    events: &'static [u16],
) -> impl Strategy<Value = Automaton> {
    let row = proptest::collection::vec(
        (
            prop::bool::weighted(0.67),
            0..3usize,
            1u32..4,
            prop::sample::select(vec![0u32, 0, 0, 1, 2]),
        ),
        events.len(),
    );
    (
        2..=3usize,
        proptest::collection::vec(any::<bool>(), 3),
        proptest::collection::vec(row, 3),
    )
        .prop_map(move |(n, marked, rows): (usize, Vec<bool>, Vec<Row>)| {
            let mut a = Automaton::new(name, kind);
            for (i, &m) in marked.iter().take(n).enumerate() {
                a.add_state(format!("{}{i}", name.to_lowercase()), m || i == 0)
                    .expect("state");
            }
            for (x, row) in rows.iter().take(n).enumerate() {
                for (&e, &(has, to, w, lb)) in events.iter().zip(row) {
                    let controllable = EVENTS[usize::from(e)].1;
                    let (to, lb) = match (has, controllable, kind) {
                        (true, _, _) => (to % n, if controllable { lb } else { 0 }),
                        (false, false, ModelKind::Spec) => (x, 0),
                        (false, _, _) => continue,
                    };
                    a.add_transition(
                        StateId(x as u32),
                        EventId(e),
                        StateId(to as u32),
                        f64::from(w) / 4.0,
                        lb,
                    )
                    .expect("deterministic");
                }
            }
            for &e in events {
                a.add_event(EventId(e));
            }
            a
        })
}

/// Three plants (a/u, b/v, c/w) and two specifications relating them, and the architecture.
fn arb_project() -> impl Strategy<Value = (Project, bool)> {
    (
        arb_model("G1", ModelKind::Plant, &[0, 3]),
        arb_model("G2", ModelKind::Plant, &[1, 4]),
        arb_model("G3", ModelKind::Plant, &[2, 5]),
        arb_model("E1", ModelKind::Spec, &[0, 1, 3, 4]),
        arb_model("E2", ModelKind::Spec, &[1, 2, 5]),
        any::<bool>(),
    )
        .prop_map(|(g1, g2, g3, e1, e2, monolithic)| {
            let mut events = EventTable::new();
            for (name, controllable) in EVENTS {
                events.intern(name, controllable).expect("fresh");
            }
            let project = Project {
                events,
                plants: vec![g1, g2, g3],
                specs: vec![e1, e2],
            };
            (project, monolithic)
        })
}

#[test]
fn reduced_supervisors_generate_what_the_unreduced_ones_generate() {
    let mut runner = TestRunner::new(Config {
        failure_persistence: None,
        ..Config::with_cases(250)
    });
    let (merged, used) = (Cell::new(0usize), Cell::new(0usize));
    let result = runner.run(&arb_project(), |(project, monolithic)| {
        let architecture = if monolithic {
            Architecture::Monolithic
        } else {
            Architecture::LocalModular
        };
        let options = SynthesisOptions {
            validate: false,
            ..SynthesisOptions::default()
        };
        // Impossible specifications have nothing to reduce.
        let Ok(synthesis) = synthesize(&project, architecture, options) else {
            return Ok(());
        };
        let reduction = reduce_synthesis(&synthesis, ReduceLimits::default())
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        for (s, r) in synthesis.supervisors.iter().zip(&reduction.supervisors) {
            let smaller = r
                .reduced
                .as_ref()
                .is_some_and(|x| x.state_count() < s.supervisor.state_count());
            merged.set(merged.get() + usize::from(smaller));
            used.set(used.get() + usize::from(r.outcome == ReductionOutcome::Reduced));
        }
        assert_equivalent(&synthesis, &reduction, 6).map_err(TestCaseError::fail)
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    // The property is not vacuous: many random supervisors lose states, and some reductions are run.
    assert!(
        merged.get() >= 25,
        "only {} reductions merged states",
        merged.get()
    );
    assert!(used.get() >= 10, "only {} reductions were used", used.get());
}

/// The synthesis and reduction of `project`, checked by [`assert_equivalent`] up to `depth` events.
fn reduced(project: &Project, architecture: Architecture, depth: usize) -> (Synthesis, Reduction) {
    let synthesis =
        synthesize(project, architecture, SynthesisOptions::default()).expect("synthesises");
    let reduction = reduce_synthesis(&synthesis, ReduceLimits::default()).expect("reduces");
    assert_equivalent(&synthesis, &reduction, depth).expect("equivalent");
    (synthesis, reduction)
}

fn sizes(reduction: &Reduction) -> Vec<(usize, usize)> {
    reduction
        .supervisors
        .iter()
        .map(|s| {
            (
                s.original.state_count(),
                s.reduced.as_ref().map_or(0, Automaton::state_count),
            )
        })
        .collect()
}

/// The small factory (two machines, a one-slot buffer): the 6-state supervisor reduces to 2 states, the buffer's
/// empty and full, as in Su and Wonham. By hand: in buffer order, ((I,I),e) takes ((W,I),e), ((I,W),e), ((W,W),e)
/// (start1 is enabled or impossible in each, start2 disabled or impossible), and the full states ((I,I),f),
/// ((I,W),f) form the other cell; only ((I,I),e) and ((I,I),f) are paired with the plant's marked state, and
/// only the first is marked, so the two cells cannot merge.
#[test]
fn small_factory_reduces_to_the_two_buffer_states() {
    for architecture in [Architecture::LocalModular, Architecture::Monolithic] {
        let (_, reduction) = reduced(&transfer_line(2, 1), architecture, 8);
        assert_eq!(sizes(&reduction), [(6, 2)], "{architecture}");
        // Alone it needs both machines as observers (44 bytes) to save 25: the unreduced set is kept.
        assert_eq!(
            reduction.supervisors[0].outcome,
            ReductionOutcome::ObserversCostMore
        );
        assert_eq!(reduction.mem_cons_after, reduction.mem_cons_before);
        assert!(reduction.observers.is_empty());
    }
}

/// The fixture factory has `start2` timed (T = 2) in the full buffer state ((I,I),f). Entering it by `finish1`
/// from ((W,I),e) or by `finish2` from ((I,W),f) must restart the counter, so neither may share its cell; by hand
/// the greedy merge then gives {((I,I),e), ((W,I),e)}, {((I,I),f), ((W,W),e)}, {((I,W),e)}, {((I,W),f)}: 4 states.
#[test]
fn a_timed_event_keeps_the_fixture_factory_at_four_states() {
    let fixture = |name: &str| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/factory")
            .join(name)
    };
    let synthesised = synthesise(&BuildRequest {
        plants: vec![fixture("machine1.xml"), fixture("machine2.xml")],
        specs: vec![fixture("buffer.xml")],
        architecture: Architecture::LocalModular,
        raw_weights: false,
        thesis_literal_probabilities: false,
        keep_targets: false,
    })
    .expect("synthesises");
    let synthesis = synthesised.synthesis;
    let reduction = reduce_synthesis(&synthesis, ReduceLimits::default()).expect("reduces");
    assert_equivalent(&synthesis, &reduction, 7).expect("equivalent");
    assert_eq!(sizes(&reduction), [(6, 4)]);
    let cells: Vec<&str> = {
        let r = reduction.supervisors[0].reduced.as_ref().expect("reduced");
        r.states().map(|x| r.state_name(x)).collect()
    };
    assert_eq!(
        cells,
        [
            "((idle,idle),empty)",
            "((idle,idle),full)",
            "((idle,working),empty)",
            "((idle,working),full)"
        ]
    );
}

/// n users of one resource: the n + 1 states (free, busy_i) reduce to 2, free and busy, because busy_i and busy_j
/// differ only in release events the plant rules out (user j is idle while i holds the resource).
#[test]
fn mutual_exclusion_of_four_users_reduces_from_five_states_to_two() {
    let (_, reduction) = reduced(&mutex(4), Architecture::LocalModular, 6);
    assert_eq!(sizes(&reduction), [(5, 2)]);
}

/// Transfer lines with buffers of capacity k: each local supervisor reduces to its buffer's k + 1 levels; the
/// interior machines are enforced by the neighbouring supervisors, so the set shrinks.
#[test]
fn transfer_line_supervisors_reduce_to_their_buffer_levels() {
    let (synthesis, reduction) = reduced(&transfer_line(3, 3), Architecture::LocalModular, 6);
    assert_eq!(sizes(&reduction), [(14, 4), (14, 4)]);
    assert_eq!(
        (reduction.mem_cons_before, reduction.mem_cons_after),
        (338, 244)
    );
    let observers: Vec<&str> = reduction.observers.iter().map(Automaton::name).collect();
    assert_eq!(observers, ["M1", "M2", "M3"]);
    // Without the observers the player would take `finish1` from a sensor while machine 1 is idle.
    let ev = &synthesis.normalised.events;
    let before = synthesis.final_supervisors();
    let before: Vec<&Automaton> = before.iter().collect();
    let bare: Vec<&Automaton> = reduction
        .supervisors
        .iter()
        .map(|s| s.supervisor())
        .collect();
    let err = walk_sets(ev, (&before, &bare), false, 3).expect_err("observers are needed");
    // The library's set check, which reduce_synthesis ran on the set with its observers, sees it too.
    let bare_set: Vec<Automaton> = bare.iter().map(|&a| a.clone()).collect();
    let mismatch = check_set(ev, &synthesis.final_supervisors(), &bare_set).expect_err("refused");
    assert_eq!(
        mismatch.to_string(),
        "initially, `finish1` is possible with the reduced supervisor only"
    );
    assert!(err.starts_with("after []: ([(EventId(0), 1.0, None)], false) against ([(EventId(0), 1.0, None), (EventId(1)"), "{err}");
    assert_eq!(ev.name(EventId(1)), "finish1");
}

/// The foraging-sized family has weights and a timed transition in every specification; every reduction is at
/// most as large as its supervisor, and the set shrinks.
#[test]
fn foraging_like_reductions_keep_weights_and_timers() {
    let (_, reduction) = reduced(&foraging_like(), Architecture::LocalModular, 3);
    assert!(
        sizes(&reduction)
            .iter()
            .all(|&(before, after)| after <= before)
    );
    assert!(reduction.mem_cons_after < reduction.mem_cons_before);
}

/// A supervisor over the state limit is kept unreduced, with the reason.
#[test]
fn supervisors_over_the_limit_are_skipped_with_a_warning() {
    let synthesis = synthesize(
        &transfer_line(2, 2),
        Architecture::Monolithic,
        SynthesisOptions::default(),
    )
    .expect("synthesises");
    let limits = ReduceLimits {
        max_states: 5,
        ..ReduceLimits::default()
    };
    let reduction = reduce_synthesis(&synthesis, limits).expect("reduces what it can");
    assert!(matches!(
        reduction.supervisors[0].outcome,
        ReductionOutcome::Skipped { .. }
    ));
    assert!(reduction.supervisors[0].reduced.is_none());
    assert_eq!(reduction.mem_cons_after, reduction.mem_cons_before);
    let warnings = reduction.warnings();
    assert_eq!(warnings.len(), 1);
    assert!(
        warnings[0].contains("10 states, more than the 5"),
        "{}",
        warnings[0]
    );
}
