//! Synthesis benchmarks on scalable model families:
//! - transfer lines (n machines, n-1 buffers of capacity c): K = G ∥ E throughput and SupC time up to ~10^6 states,
//!   minimisation and the whole monolithic pipeline below that;
//! - n-robot mutual exclusion: the 2^n-state plant product (2^20 ≈ 10^6 states) and monolithic synthesis;
//! - a foraging-sized local-modular project (8 plants, 7 specifications) with the monolithic validation;
//! - every task's model set under `configs/` (a folder with `G*.xml` plants and `E*.xml` specifications), loaded,
//!   validated and synthesised local-modular as robots do.
//!
//! Model sizes are printed to stderr once per family so results can be read as states per second.

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use supervisor_gen::architecture::Architecture;
use supervisor_gen::automaton::{Automaton, ModelKind, Project, StateId};
use supervisor_gen::build::{BuildRequest, synthesise};
use supervisor_gen::families::{foraging_like, mutex, transfer_line};
use supervisor_gen::minimise::minimise;
use supervisor_gen::pipeline::{SynthesisOptions, synthesize};
use supervisor_gen::product::{product, product_with_tuples};
use supervisor_gen::supc::supc;

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
        mono.target_stats.states,
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

/// Every folder under `dir` (itself included) that holds `G*.xml` plants and `E*.xml` specifications, sorted.
fn model_sets(dir: &Path, sets: &mut Vec<(PathBuf, Vec<PathBuf>, Vec<PathBuf>)>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    let named = |prefix: &str| -> Vec<PathBuf> {
        paths
            .iter()
            .filter(|p| {
                let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
                name.starts_with(prefix) && name.ends_with(".xml")
            })
            .cloned()
            .collect()
    };
    let (plants, specs) = (named("G"), named("E"));
    if !plants.is_empty() && !specs.is_empty() {
        sets.push((dir.to_path_buf(), plants, specs));
    }
    for sub in paths.iter().filter(|p| p.is_dir()) {
        model_sets(sub, sets);
    }
}

fn bench_task_models(c: &mut Criterion) {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    let mut sets = Vec::new();
    for task in std::fs::read_dir(&configs).expect("configs/ is readable") {
        let models = task.expect("a configs/ entry").path().join("models");
        model_sets(&models, &mut sets);
    }
    sets.sort();
    let mut group = c.benchmark_group("task_models");
    group.sample_size(20);
    for (dir, plants, specs) in sets {
        let name = dir
            .strip_prefix(&configs)
            .unwrap_or(&dir)
            .display()
            .to_string();
        let request = BuildRequest {
            plants,
            specs,
            architecture: Architecture::LocalModular,
            raw_weights: false,
            thesis_literal_probabilities: false,
            keep_targets: false,
        };
        let states: Vec<usize> = synthesise(&request)
            .expect("every task's models synthesise")
            .synthesis
            .supervisors
            .iter()
            .map(|s| s.stats.states)
            .collect();
        eprintln!("{name}: local supervisors of {states:?} states");
        group.bench_function(BenchmarkId::new("load_validate_synthesise", &name), |b| {
            b.iter(|| {
                black_box(synthesise(&request))
                    .map(|s| s.synthesis.mem_cons)
                    .ok()
            })
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    bench_transfer_line,
    bench_mutex,
    bench_foraging,
    bench_task_models
);
criterion_main!(benches);
