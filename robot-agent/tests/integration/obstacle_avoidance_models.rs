//! The shipped obstacle-avoidance models synthesise local-modular, pass the local-modular validation
//! (docs/ptsct.md 6.6) and bind to their profiles.

use std::path::{Path, PathBuf};

use robot_agent::params::Params;
use robot_agent::profiles::bind_profile;
use swarm_contract::supervisor_gen::architecture::Architecture;
use swarm_contract::supervisor_gen::load::{Input, load};
use swarm_contract::supervisor_gen::pipeline::{Synthesis, SynthesisOptions, synthesize};
use swarm_contract::supervisor_gen::validate::ValidateOptions;

fn models(variant: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../configs/obstacle_avoidance/models")
        .join(variant)
}

fn synthesise(variant: &str, files: &[&str]) -> Synthesis {
    let inputs: Vec<Input> = files
        .iter()
        .map(|f| Input::new(models(variant).join(f), None))
        .collect();
    let validation = load(&inputs, ValidateOptions::default()).unwrap();
    let errors: Vec<String> = validation
        .diagnostics
        .iter()
        .map(ToString::to_string)
        .collect();
    assert!(errors.is_empty(), "{errors:#?}");
    let project =
        swarm_contract::supervisor_gen::convert::to_project(&validation.models.unwrap()).unwrap();
    synthesize(
        &project,
        Architecture::LocalModular,
        SynthesisOptions::default(),
    )
    .unwrap()
}

#[test]
fn ptsct_models_are_local_modular_equivalent_to_the_monolithic_supervisor() {
    let s = synthesise(
        "ptsct",
        &["G_prox.xml", "G_motor.xml", "E_walk.xml", "E_avoid.xml"],
    );
    assert_eq!(s.supervisors.len(), 2);
    for sup in &s.supervisors {
        assert!(
            sup.removed.is_empty(),
            "{} lost states: {:?}",
            sup.name,
            sup.removed
        );
    }
    let check = s.local_modular_validation.as_ref().unwrap();
    assert!(check.passed(), "{check:?}");
}

#[test]
fn ptsct_walk_supervisor_keeps_weights_9_1_1_and_the_5_tick_go_bound() {
    let s = synthesise(
        "ptsct",
        &["G_prox.xml", "G_motor.xml", "E_walk.xml", "E_avoid.xml"],
    );
    let set = s.compile().unwrap();
    let id = |name: &str| set.events.iter().position(|e| e.name == name).unwrap() as u8;
    let walk = set
        .supervisors
        .iter()
        .find(|x| x.name.contains("E_walk"))
        .unwrap();
    let go = id("Go");
    let bounds: Vec<u16> = walk
        .states
        .iter()
        .flat_map(|st| st.transitions.iter())
        .filter(|t| t.event == go)
        .map(|t| t.lower_bound)
        .collect();
    let mut sorted = bounds.clone();
    sorted.sort();
    assert_eq!(sorted, [0, 5]);
    let fwd = walk
        .states
        .iter()
        .find(|st| st.transitions.iter().any(|t| t.event == id("turn-left")))
        .unwrap();
    let p = |e: u8| {
        fwd.transitions
            .iter()
            .find(|t| t.event == e)
            .unwrap()
            .probability()
    };
    assert!((p(go) / p(id("turn-left")) - 9.0).abs() < 1e-3);
    assert!((p(id("turn-left")) - p(id("turn-right"))).abs() < 1e-4);
}

#[test]
fn sct_models_with_timer_generator_are_local_modular_equivalent() {
    let s = synthesise(
        "sct",
        &[
            "G_prox.xml",
            "G_motor.xml",
            "G_timer1.xml",
            "E_walk.xml",
            "E_avoid.xml",
        ],
    );
    assert_eq!(s.supervisors.len(), 2);
    let check = s.local_modular_validation.as_ref().unwrap();
    assert!(check.passed(), "{check:?}");
    let set = s.compile().unwrap();
    for sup in &set.supervisors {
        for st in &sup.states {
            assert!(
                st.transitions.iter().all(|t| t.lower_bound == 0),
                "plain SCT has no lower bounds"
            );
        }
    }
}

#[test]
fn each_variant_binds_to_its_profile_and_not_to_the_other() {
    let pt = synthesise(
        "ptsct",
        &["G_prox.xml", "G_motor.xml", "E_walk.xml", "E_avoid.xml"],
    )
    .compile()
    .unwrap();
    let sct = synthesise(
        "sct",
        &[
            "G_prox.xml",
            "G_motor.xml",
            "G_timer1.xml",
            "E_walk.xml",
            "E_avoid.xml",
        ],
    )
    .compile()
    .unwrap();
    let p = Params::default();
    assert!(bind_profile("obstacle_avoidance", &p, &pt.events).is_ok());
    assert!(bind_profile("obstacle_avoidance_sct", &p, &sct.events).is_ok());
    let err = bind_profile("obstacle_avoidance_sct", &p, &pt.events)
        .err()
        .unwrap()
        .to_string();
    assert_eq!(
        err,
        "profile `obstacle_avoidance_sct` does not fit the supervisors\n  callbacks for events the supervisors do \
         not have: `start_timer_1`, `timer_1_lw_5`, `inc_timer_1`, `timer_1_eq_5`, `end_timer_1`"
    );
}

#[test]
fn ptsct_supervisors_have_two_states_each_and_memcons_107_bytes() {
    let s = synthesise(
        "ptsct",
        &["G_prox.xml", "G_motor.xml", "E_walk.xml", "E_avoid.xml"],
    );
    for sup in &s.supervisors {
        assert_eq!(
            (sup.stats.states, sup.stats.transitions),
            (2, 6),
            "{}",
            sup.name
        );
    }
    // s = 4, t = 12, t_c = 10, e = 5, N = 2: (4 + 36) + 2 (4 + 20) + 5 + 7 * 2 (docs/ptsct.md section 9).
    assert_eq!(s.compile().unwrap().mem_cons(), 107);
}

#[test]
fn sct_walk_supervisor_grows_to_six_states_and_memcons_189_bytes() {
    let s = synthesise(
        "sct",
        &[
            "G_prox.xml",
            "G_motor.xml",
            "G_timer1.xml",
            "E_walk.xml",
            "E_avoid.xml",
        ],
    );
    let sizes: Vec<(&str, usize, usize)> = s
        .supervisors
        .iter()
        .map(|x| (x.name.as_str(), x.stats.states, x.stats.transitions))
        .collect();
    assert_eq!(sizes, [("S_E_walk", 6, 15), ("S_E_avoid", 2, 6)]);
    // s = 8, t = 21, t_c = 17, e = 10, N = 2: (8 + 63) + 2 (8 + 34) + 10 + 12 * 2.
    assert_eq!(s.compile().unwrap().mem_cons(), 189);
}

#[test]
fn compiled_file_written_by_the_toolchain_loads_as_the_same_set_as_the_model_folder() {
    let m = |f: &str| models("ptsct").join(f);
    let built = swarm_contract::supervisor_gen::build::build(
        &swarm_contract::supervisor_gen::build::BuildRequest {
            plants: vec![m("G_prox.xml"), m("G_motor.xml")],
            specs: vec![m("E_walk.xml"), m("E_avoid.xml")],
            architecture: Architecture::LocalModular,
            raw_weights: false,
            thesis_literal_probabilities: false,
            keep_targets: false,
        },
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let compiled = dir.path().join("supervisors.ptsct");
    built.set.write(&compiled).unwrap();
    let from_file = robot_agent::supervisors::load(&[compiled]).unwrap();
    let from_models = robot_agent::supervisors::load(&[
        m("G_prox.xml"),
        m("G_motor.xml"),
        m("E_walk.xml"),
        m("E_avoid.xml"),
    ])
    .unwrap();
    assert_eq!(from_file, from_models);
}
