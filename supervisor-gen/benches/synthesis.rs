//! Synthesis benchmarks on scalable model families:
//! - transfer lines (n machines, n-1 buffers of capacity c): K = G ∥ E throughput and SupC time up to ~10^6 states,
//!   minimisation and the whole monolithic pipeline below that;
//! - n-robot mutual exclusion: the 2^n-state plant product (2^20 ≈ 10^6 states) and monolithic synthesis;
//! - a foraging-sized local-modular project (8 plants, 7 specifications) with the monolithic validation.
//!
//! Model sizes are printed to stderr once per family so results can be read as states per second.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use supervisor_gen::architecture::Architecture;
use supervisor_gen::automaton::{Automaton, EventTable, ModelKind, Project, StateId};
use supervisor_gen::minimise::minimise;
use supervisor_gen::pipeline::{SynthesisOptions, synthesize};
use supervisor_gen::product::{product, product_with_tuples};
use supervisor_gen::supc::supc;

/// Machine i: idle (marked) -start_i-> working -finish_i-> idle.
fn machine(ev: &mut EventTable, i: usize) -> Automaton {
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
fn buffer(ev: &mut EventTable, i: usize, cap: usize) -> Automaton {
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

fn transfer_line(n: usize, cap: usize) -> Project {
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
fn mutex(n: usize) -> Project {
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
fn foraging_like() -> Project {
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

/// K = Gmon ∥ Emon of a project, with g(x) for SupC.
fn target(p: &Project) -> (Automaton, Automaton, Vec<StateId>) {
    let plants: Vec<&Automaton> = p.plants.iter().collect();
    let specs: Vec<&Automaton> = p.specs.iter().collect();
    let g = product("G", ModelKind::Plant, &p.events, &plants);
    let e = product("E", ModelKind::Spec, &p.events, &specs);
    let k = product_with_tuples("K", ModelKind::Supervisor, &p.events, &[&g, &e]);
    let g_of = k.tuples.chunks_exact(2).map(|t| StateId(t[0])).collect();
    (k.automaton, g, g_of)
}

fn bench_transfer_line(c: &mut Criterion) {
    let mut group = c.benchmark_group("transfer_line");
    group.sample_size(10);
    for &(n, cap) in &[(5, 2), (6, 3), (6, 6)] {
        let p = transfer_line(n, cap);
        let (k, g, g_of) = target(&p);
        let s = supc(&k, &g, &g_of, &p.events);
        eprintln!(
            "transfer_line n={n} cap={cap}: G {} states, K {} states / {} transitions, SupC {} states, {} rounds",
            g.state_count(),
            k.state_count(),
            k.transition_count(),
            s.supervisor.state_count(),
            s.rounds
        );
        let label = format!("n{n}_cap{cap}");
        group.throughput(Throughput::Elements(k.state_count() as u64));
        group.bench_function(BenchmarkId::new("product_K", &label), |b| {
            b.iter(|| black_box(target(black_box(&p))).0.state_count())
        });
        group.bench_function(BenchmarkId::new("supc", &label), |b| {
            b.iter(|| {
                black_box(supc(&k, &g, &g_of, &p.events))
                    .supervisor
                    .state_count()
            })
        });
        // Minimisation and the whole pipeline are measured below 10^6 states to keep the suite short.
        if k.state_count() < 500_000 {
            group.bench_function(BenchmarkId::new("minimise", &label), |b| {
                b.iter(|| black_box(minimise(&s.supervisor)).state_count())
            });
            group.bench_function(BenchmarkId::new("synthesize_monolithic", &label), |b| {
                b.iter(|| {
                    black_box(synthesize(
                        &p,
                        Architecture::Monolithic,
                        SynthesisOptions::default(),
                    ))
                    .map(|s| s.mem_cons)
                })
            });
        }
    }
    group.finish();
}

fn bench_mutex(c: &mut Criterion) {
    let mut group = c.benchmark_group("mutex");
    group.sample_size(10);
    for &n in &[10usize, 16, 20] {
        let p = mutex(n);
        let plants: Vec<&Automaton> = p.plants.iter().collect();
        let states = 1u64 << n;
        eprintln!("mutex n={n}: plant product {states} states");
        group.throughput(Throughput::Elements(states));
        group.bench_function(BenchmarkId::new("plant_product", n), |b| {
            b.iter(|| black_box(product("G", ModelKind::Plant, &p.events, &plants)).state_count())
        });
        if n <= 16 {
            group.bench_function(BenchmarkId::new("monolithic_synthesis", n), |b| {
                b.iter(|| {
                    black_box(synthesize(
                        &p,
                        Architecture::Monolithic,
                        SynthesisOptions::default(),
                    ))
                    .map(|s| s.mem_cons)
                })
            });
        }
    }
    group.finish();
}

fn bench_foraging(c: &mut Criterion) {
    let p = foraging_like();
    let s = synthesize(&p, Architecture::LocalModular, SynthesisOptions::default())
        .expect("synthesisable");
    let mono = s.monolithic_reference.as_ref().expect("validated");
    eprintln!(
        "foraging-like: 8 plants, 7 specs; local supervisors {:?} states; monolithic K {} states; validation passed: {}; MemCons {} B",
        s.supervisors
            .iter()
            .map(|x| x.stats.states)
            .collect::<Vec<_>>(),
        mono.target.state_count(),
        s.local_modular_validation
            .as_ref()
            .is_some_and(|v| v.passed()),
        s.mem_cons
    );
    let mut group = c.benchmark_group("foraging_like_8_plants_7_specs");
    group.sample_size(10);
    group.bench_function("local_modular_with_validation", |b| {
        b.iter(|| {
            black_box(synthesize(
                &p,
                Architecture::LocalModular,
                SynthesisOptions::default(),
            ))
            .map(|s| s.mem_cons)
        })
    });
    let no_validation = SynthesisOptions {
        validate: false,
        ..SynthesisOptions::default()
    };
    group.bench_function("local_modular_without_validation", |b| {
        b.iter(|| {
            black_box(synthesize(&p, Architecture::LocalModular, no_validation)).map(|s| s.mem_cons)
        })
    });
    group.finish();
}

criterion_group!(benches, bench_transfer_line, bench_mutex, bench_foraging);
criterion_main!(benches);
