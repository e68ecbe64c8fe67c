use super::*;
use crate::automaton::ModelKind;

include!("../../tests/common/section9_example.rs");

/// The arrays of the worked example, as printed in section 9.
const WORKED_DELTA: [u8; 21] = [
    0x02, 0x00, 0x00, 0x01, 0x01, 0x00, 0x02, //
    0x02, 0x00, 0x00, 0x01, 0x03, 0x00, 0x00, //
    0x02, 0x01, 0x00, 0x00, 0x02, 0x00, 0x01,
];
const WORKED_P: [u8; 13] = [
    0x02, 0xCC, 0xCC, 0x33, 0x33, 0x01, 0xFF, 0xFF, 0x02, 0x40, 0x00, 0xBF, 0xFF,
];
const WORKED_T: [u8; 13] = [
    0x02, 0x00, 0x02, 0x00, 0x00, 0x01, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x00,
];
const WORKED_CTRL: [u8; 4] = [0x01, 0x01, 0x01, 0x00];
const WORKED_MEMBER: [u8; 4] = [0x01, 0x01, 0x01, 0x01];
const WORKED_CURRENT: [u8; 2] = [0x00, 0x00];

fn worked_payload() -> Vec<u8> {
    [
        &WORKED_DELTA[..],
        &WORKED_P,
        &WORKED_T,
        &WORKED_CTRL,
        &WORKED_MEMBER,
        &WORKED_CURRENT,
    ]
    .concat()
}

#[test]
fn worked_example_of_section_9_gives_the_thesis_bytes_and_memcons_57() {
    let (ev, g) = section9_example();
    let set = SupervisorSet::from_supervisors(&ev, std::slice::from_ref(&g)).unwrap();
    let bytes = set.to_bytes();
    let payload = worked_payload();
    assert_eq!(payload.len(), 21 + 13 + 13 + 4 + 4 + 2);
    assert!(bytes.ends_with(&payload), "payload differs: {bytes:02X?}");
    assert_eq!(set.mem_cons(), 57);
    assert_eq!(mem_cons_of(&ev, &[&g]), 57);
    // Header: magic, version, counts, 4 one-letter event names, one supervisor entry.
    assert_eq!(bytes.len() - 57, 10 + 4 * 3 + (2 + 7 + 2));
    assert_eq!(&bytes[..4], b"PTSC");
    assert_eq!(SupervisorSet::from_bytes(&bytes).unwrap(), set);
}

#[test]
fn initial_state_is_renumbered_to_zero() {
    let (ev, mut g) = section9_example();
    g.set_initial(StateId(2)).unwrap();
    let set = SupervisorSet::from_supervisors(&ev, &[g]).unwrap();
    let s = &set.supervisors[0];
    // Old q2 (b -> q0, c -> q1) is now state 0; old q0 is 1, old q1 is 2.
    let t: Vec<_> = s.states[0]
        .transitions
        .iter()
        .map(|t| (t.event, t.target))
        .collect();
    assert_eq!(t, vec![(1, 1), (2, 2)]);
}

#[test]
fn uncontrollable_transitions_are_stored_after_controllable_ones() {
    let mut ev = EventTable::new();
    let u = ev.intern("u", false).unwrap();
    let a = ev.intern("a", true).unwrap();
    let mut g = Automaton::new("s", ModelKind::Supervisor);
    let q = g.add_state("q", true).unwrap();
    g.add_transition(q, u, q, 1.0, 0).unwrap();
    g.add_transition(q, a, q, 1.0, 3).unwrap();
    let set = SupervisorSet::from_supervisors(&ev, &[g]).unwrap();
    let events: Vec<_> = set.supervisors[0].states[0]
        .transitions
        .iter()
        .map(|t| t.event)
        .collect();
    assert_eq!(events, vec![a.0 as u8, u.0 as u8]);
    assert_eq!(SupervisorSet::from_bytes(&set.to_bytes()).unwrap(), set);
}

#[test]
fn v15_lower_bound_over_65535_is_a_codegen_error() {
    let (ev, mut g) = section9_example();
    g.transitions_mut(StateId(0))[0].lower_bound = 70_000;
    assert!(matches!(
        SupervisorSet::from_supervisors(&ev, &[g]),
        Err(CodegenError::LowerBoundTooLarge { bound: 70_000, .. })
    ));
}

#[test]
fn v15_more_than_256_events_is_a_codegen_error() {
    let mut ev = EventTable::new();
    for i in 0..257 {
        ev.intern(&format!("e{i}"), true).unwrap();
    }
    let g = Automaton::identity("s", ModelKind::Supervisor);
    assert!(matches!(
        SupervisorSet::from_supervisors(&ev, &[g]),
        Err(CodegenError::TooManyEvents { count: 257 })
    ));
}

#[test]
fn v15_more_than_255_transitions_in_a_state_is_a_codegen_error() {
    let mut ev = EventTable::new();
    let mut g = Automaton::new("s", ModelKind::Supervisor);
    let q = g.add_state("q", true).unwrap();
    for i in 0..256 {
        let e = ev.intern(&format!("e{i}"), true).unwrap();
        g.add_transition(q, e, q, 1.0, 0).unwrap();
    }
    assert!(matches!(
        SupervisorSet::from_supervisors(&ev, &[g]),
        Err(CodegenError::TooManyTransitions { count: 256, .. })
    ));
}

#[test]
fn raw_weight_above_one_cannot_be_encoded() {
    let (ev, mut g) = section9_example();
    g.transitions_mut(StateId(2))[1].prob = 3.0;
    assert!(matches!(
        SupervisorSet::from_supervisors(&ev, &[g]),
        Err(CodegenError::ProbabilityOutOfRange { .. })
    ));
}

fn worked_bytes() -> Vec<u8> {
    let (ev, g) = section9_example();
    SupervisorSet::from_supervisors(&ev, &[g])
        .unwrap()
        .to_bytes()
}

fn problem(bytes: &[u8]) -> (usize, FormatProblem) {
    match SupervisorSet::from_bytes(bytes) {
        Err(CompiledFormatError::Malformed {
            offset, problem, ..
        }) => (offset, problem),
        other => panic!("expected a format error, got {other:?}"),
    }
}

#[test]
fn every_truncation_is_reported_as_truncated() {
    let bytes = worked_bytes();
    for len in 0..bytes.len() {
        let (offset, p) = problem(&bytes[..len]);
        assert!(matches!(p, FormatProblem::Truncated(_)), "len {len}: {p:?}");
        assert!(offset <= len);
    }
}

#[test]
fn corrupt_fields_are_named() {
    let good = worked_bytes();
    let payload = good.len() - 57;
    let mut b = good.clone();
    b[0] = b'X';
    assert_eq!(problem(&b), (0, FormatProblem::BadMagic));
    let mut b = good.clone();
    b[5] = 2;
    assert_eq!(problem(&b).1, FormatProblem::UnsupportedVersion(2));
    let mut b = good.clone();
    b[payload + 1] = 9; // first event id of q0
    assert!(matches!(
        problem(&b).1,
        FormatProblem::EventOutOfRange { event: 9, .. }
    ));
    let mut b = good.clone();
    b[payload + 3] = 7; // first target of q0
    assert!(matches!(
        problem(&b).1,
        FormatProblem::TargetOutOfRange { target: 7, .. }
    ));
    let mut b = good.clone();
    b[payload + 1] = 1; // q0: b, b -> not strictly ascending
    assert!(matches!(
        problem(&b).1,
        FormatProblem::BadTransitionOrder { .. }
    ));
    let mut b = good.clone();
    b[payload + 47 + 3] = 2; // controllability flag of u
    assert_eq!(
        problem(&b),
        (
            payload + 50,
            FormatProblem::BadFlag("controllability table", 2)
        )
    );
    let mut b = good.clone();
    b[payload + 51] = 0; // a is no longer in the alphabet
    assert!(matches!(
        problem(&b).1,
        FormatProblem::EventNotInAlphabet { event: 0, .. }
    ));
    let mut b = good.clone();
    b[payload + 56] = 1;
    assert!(matches!(
        problem(&b).1,
        FormatProblem::NonInitialCurrentState { .. }
    ));
    let mut b = good.clone();
    b.push(0);
    assert_eq!(problem(&b).1, FormatProblem::TrailingBytes(1));
}

#[test]
fn read_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.ptsc");
    std::fs::write(&path, b"PTSC\x00").unwrap();
    let msg = SupervisorSet::read(&path).unwrap_err().to_string();
    assert!(msg.contains("bad.ptsc") && msg.contains("byte 4"), "{msg}");
    let ok = dir.path().join("ok.ptsc");
    let (ev, g) = section9_example();
    let set = SupervisorSet::from_supervisors(&ev, &[g]).unwrap();
    set.write(&ok).unwrap();
    assert_eq!(SupervisorSet::read(&ok).unwrap(), set);
}
