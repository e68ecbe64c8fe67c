//! Foraging and pheromone foraging (docs/tasks.md 4 and 5): the shipped models pass the local-modular architecture
//! check, competing events keep their stated ratios at runtime, and a short foraging run through `swarm run`
//! delivers a target that shows up in `summary.json`.

use std::path::{Path, PathBuf};

use supervisor_gen::architecture::Architecture;
use supervisor_gen::build::{BuildRequest, Built, build};
use swarm_system_tests::{assert_clean, swarm, workspace_file};

fn models(task: &str, names: &[&str]) -> Vec<PathBuf> {
    names
        .iter()
        .map(|n| workspace_file(&format!("configs/{task}/models/{n}.xml")))
        .collect()
}

fn synthesise(task: &str, plants: &[&str]) -> Built {
    let specs = ["E1", "E2", "E3", "E4", "E5", "E6", "E7"];
    build(&BuildRequest {
        plants: models(task, plants),
        specs: models(task, &specs),
        architecture: Architecture::LocalModular,
        raw_weights: false,
        thesis_literal_probabilities: false,
        keep_targets: false,
    })
    .expect("the models synthesise")
}

const FORAGING_PLANTS: [&str; 8] = ["G1", "G2", "G3", "G4", "G5", "G6", "G7", "G8"];
const PHEROMONE_PLANTS: [&str; 9] = ["G1", "G2", "G3", "G4", "G5", "G6", "G7", "G8", "G9"];

fn assert_architecture_check_passes(built: &Built) {
    let s = &built.synthesis;
    assert_eq!(s.supervisors.len(), 7);
    for sup in &s.supervisors {
        assert!(
            sup.removed.is_empty(),
            "{} lost states to SupC: {:?}",
            sup.name,
            sup.removed
        );
    }
    let non_conflict = s.non_conflict.as_ref().expect("non-conflict was checked");
    assert!(non_conflict.nonblocking, "{non_conflict:?}");
    let check = s
        .local_modular_validation
        .as_ref()
        .expect("the local-modular validation ran");
    assert!(check.passed(), "{check:?}");
}

#[test]
fn foraging_local_modular_supervisors_equal_the_monolithic_supervisor() {
    assert_architecture_check_passes(&synthesise("foraging", &FORAGING_PLANTS));
}

#[test]
fn pheromone_foraging_local_modular_supervisors_equal_the_monolithic_supervisor() {
    assert_architecture_check_passes(&synthesise("pheromone_foraging", &PHEROMONE_PLANTS));
}

/// The supervisors (by name) whose alphabet holds `event`.
fn owners(built: &Built, event: &str) -> Vec<String> {
    let s = &built.synthesis;
    let id = s
        .normalised
        .events
        .lookup(event)
        .unwrap_or_else(|| panic!("event {event} exists"));
    s.final_supervisors()
        .iter()
        .filter(|a| a.has_event(id))
        .map(|a| a.name().to_owned())
        .collect()
}

/// docs/ptsct.md 5.2: the runtime weight of an event is the product of its owners' factors, so events that compete in
/// one choice (E5's walk 9/1/1, E2's 20/80 and 8/1/1, E4's rest-ended against rest-wait, E7's 20/80 rest
/// decision, the pheromone follow events' weight 6) keep the ratio the module states only when every other owner
/// scales them alike: they must have the same owners.
#[test]
fn competing_events_have_the_same_owners_so_the_stated_ratios_hold() {
    let groups: [&[&str]; 3] = [
        &["Go", "turn-left", "turn-right", "turn-inv-home"],
        &["rest-wait", "rest-ended"],
        &["start-search", "continue-rest"],
    ];
    for (task, plants, extra) in [
        ("foraging", &FORAGING_PLANTS[..], &[][..]),
        (
            "pheromone_foraging",
            &PHEROMONE_PLANTS[..],
            &["follow-food-trail", "follow-home-trail"][..],
        ),
    ] {
        let built = synthesise(task, plants);
        let motion: Vec<&str> = groups[0].iter().chain(extra).copied().collect();
        for group in [&motion[..], groups[1], groups[2]] {
            let first = owners(&built, group[0]);
            for event in &group[1..] {
                assert_eq!(
                    owners(&built, event),
                    first,
                    "{task}: {event} and {} compete but have different owners",
                    group[0]
                );
            }
        }
    }
}

fn summary(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json exists");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

#[test]
fn short_foraging_run_delivers_a_target_home() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let config = workspace_file("configs/foraging/quick.argos");
    let (config, out_arg) = (
        config.display().to_string(),
        out.path().display().to_string(),
    );
    let outcome = swarm(&["run", &config, "--out", &out_arg, "--no-progress"]);
    assert!(
        outcome.output.status.success(),
        "swarm run failed:\n{}",
        outcome.stderr()
    );
    assert_clean(&outcome);
    let metrics = &summary(out.path())["metrics"];
    assert_eq!(metrics["targets"], 10);
    let delivered = metrics["delivered"].as_u64().expect("delivered is a count");
    assert!(delivered >= 1, "no target delivered: {metrics}");
    assert_eq!(metrics["delivered_in_fixed_time"], delivered);
    // Each delivery credits Ef = 2000; five robots cost at most Et = 2 per tick over the 1200 ticks.
    let energy = metrics["energy"].as_f64().expect("energy is a number");
    assert!(
        energy <= 5.0 * 2.0 * 1200.0 - 2000.0 * delivered as f64,
        "{metrics}"
    );
}
