//! Scalable model families for benchmarks and tests of synthesis at size: transfer lines, mutual exclusion among n
//! users, and a foraging-sized local-modular project. Each is a [`Project`] built in memory.

use crate::automaton::{Automaton, EventTable, ModelKind, Project, StateId};

/// Machine i: idle (marked) -start_i-> working -finish_i-> idle.
pub fn machine(ev: &mut EventTable, i: usize) -> Automaton {
    let start = ev.intern(&format!("start{i}"), true).expect("fresh event");
    let finish = ev
        .intern(&format!("finish{i}"), false)
        .expect("fresh event");
    let mut m = Automaton::new(format!("M{i}"), ModelKind::Plant);
    let idle = m.add_state("I", true).expect("state");
    let work = m.add_state("W", false).expect("state");
    m.add_transition(idle, start, work, 1.0, 0)
        .expect("transition");
    m.add_transition(work, finish, idle, 1.0, 0)
        .expect("transition");
    m
}

/// Buffer between machines i and i+1 with `cap` slots: finish_i fills, start_{i+1} takes; overflow is forbidden.
pub fn buffer(ev: &mut EventTable, i: usize, cap: usize) -> Automaton {
    let fill = ev.intern(&format!("finish{i}"), false).expect("event");
    let take = ev.intern(&format!("start{}", i + 1), true).expect("event");
    let mut b = Automaton::new(format!("B{i}"), ModelKind::Spec);
    let slots: Vec<StateId> = (0..=cap)
        .map(|k| b.add_state(format!("{k}"), k == 0).expect("state"))
        .collect();
    for k in 0..cap {
        b.add_transition(slots[k], fill, slots[k + 1], 1.0, 0)
            .expect("transition");
        b.add_transition(slots[k + 1], take, slots[k], 1.0, 0)
            .expect("transition");
    }
    b
}

/// A transfer line: machines 1..=n (plants) and the n - 1 buffers of capacity `cap` between them
/// (specifications); its closed loop has up to 2^n (cap + 1)^(n - 1) states.
pub fn transfer_line(n: usize, cap: usize) -> Project {
    let mut ev = EventTable::new();
    let plants = (1..=n).map(|i| machine(&mut ev, i)).collect();
    let specs = (1..n).map(|i| buffer(&mut ev, i, cap)).collect();
    Project {
        events: ev,
        plants,
        specs,
    }
}

/// n users competing for one resource: user i idle -acquire_i-> using -release_i-> idle; spec: one at a time.
pub fn mutex(n: usize) -> Project {
    let mut ev = EventTable::new();
    let mut plants = Vec::new();
    let mut spec = Automaton::new("mutex", ModelKind::Spec);
    let free = spec.add_state("free", true).expect("state");
    for i in 0..n {
        let acq = ev.intern(&format!("acquire{i}"), true).expect("event");
        let rel = ev.intern(&format!("release{i}"), false).expect("event");
        let mut u = Automaton::new(format!("U{i}"), ModelKind::Plant);
        let idle = u.add_state("idle", true).expect("state");
        let using = u.add_state("using", false).expect("state");
        u.add_transition(idle, acq, using, 1.0, 0)
            .expect("transition");
        u.add_transition(using, rel, idle, 1.0, 0)
            .expect("transition");
        plants.push(u);
        let busy = spec.add_state(format!("busy{i}"), false).expect("state");
        spec.add_transition(free, acq, busy, 1.0, 0)
            .expect("transition");
        spec.add_transition(busy, rel, free, 1.0, 0)
            .expect("transition");
    }
    Project {
        events: ev,
        plants,
        specs: vec![spec],
    }
}

/// A foraging-sized project: 8 two-state actuator/sensor plants and 7 specifications chaining them, each with
/// weights, a timed transition and uncontrollable self-loops as in the thesis' conventions (8.7).
pub fn foraging_like() -> Project {
    let mut ev = EventTable::new();
    let mut plants = Vec::new();
    for k in 0..8 {
        let on = ev.intern(&format!("on{k}"), true).expect("event");
        let off = ev.intern(&format!("off{k}"), true).expect("event");
        let sense = ev.intern(&format!("sense{k}"), false).expect("event");
        let mut p = Automaton::new(format!("P{k}"), ModelKind::Plant);
        let s_off = p.add_state("off", true).expect("state");
        let s_on = p.add_state("on", false).expect("state");
        p.add_transition(s_off, on, s_on, 1.0, 0)
            .expect("transition");
        p.add_transition(s_on, off, s_off, 1.0, 0)
            .expect("transition");
        p.add_transition(s_on, sense, s_on, 1.0, 0)
            .expect("transition");
        p.add_transition(s_off, sense, s_off, 1.0, 0)
            .expect("transition");
        plants.push(p);
    }
    let mut specs = Vec::new();
    for j in 0..7 {
        let sense = ev.lookup(&format!("sense{j}")).expect("declared");
        let on = ev.lookup(&format!("on{}", j + 1)).expect("declared");
        let off = ev.lookup(&format!("off{}", j + 1)).expect("declared");
        let mut e = Automaton::new(format!("E{j}"), ModelKind::Spec);
        let wait = e.add_state("wait", true).expect("state");
        let armed = e.add_state("armed", false).expect("state");
        e.add_transition(wait, sense, armed, 1.0, 0)
            .expect("transition");
        e.add_transition(wait, off, wait, 3.0, 0)
            .expect("transition");
        e.add_transition(armed, on, wait, 1.0, 2)
            .expect("transition");
        e.add_transition(armed, sense, armed, 1.0, 0)
            .expect("transition");
        e.add_transition(armed, off, armed, 1.0, 0)
            .expect("transition");
        specs.push(e);
    }
    Project {
        events: ev,
        plants,
        specs,
    }
}
