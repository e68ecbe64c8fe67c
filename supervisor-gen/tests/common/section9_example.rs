// The generator of the worked example in section 9 (three states, four events), with normalised probabilities.
// Included by the compiled format's unit tests and by the code generator's integration tests, which bring
// `Automaton`, `EventTable` and `ModelKind` into scope first.

/// The section 9 worked example: its event table and its one automaton.
fn section9_example() -> (EventTable, Automaton) {
    let mut ev = EventTable::new();
    let a = ev.intern("a", true).unwrap();
    let b = ev.intern("b", true).unwrap();
    let c = ev.intern("c", true).unwrap();
    let u = ev.intern("u", false).unwrap();
    let mut g = Automaton::new("example", ModelKind::Supervisor);
    let q0 = g.add_state("q0", true).unwrap();
    let q1 = g.add_state("q1", false).unwrap();
    let q2 = g.add_state("q2", false).unwrap();
    g.add_transition(q0, a, q1, 0.8, 2).unwrap();
    g.add_transition(q0, b, q2, 0.2, 0).unwrap();
    g.add_transition(q1, a, q1, 1.0, 0).unwrap();
    g.add_transition(q1, u, q0, 1.0, 0).unwrap();
    g.add_transition(q2, b, q0, 0.25, 0).unwrap();
    g.add_transition(q2, c, q1, 0.75, 0).unwrap();
    (ev, g)
}
