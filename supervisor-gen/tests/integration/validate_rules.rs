//! Every structural rule of docs/ptsct.md section 11 (and the document codes X1/X2) on a malformed fixture, with the
//! exact located message it must produce. Each test validates its files as one project and compares the complete
//! list of diagnostics, so an extra or missing report fails too.

use std::path::{Path, PathBuf};

use supervisor_gen::automaton::ModelKind;
use supervisor_gen::load::{Input, load};
use supervisor_gen::validate::ValidateOptions;

fn tests_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests")
}

/// Validates fixtures (paths under `tests/fixtures`) as one project; diagnostics are rendered with paths relative
/// to `tests/`.
fn diagnose(files: &[&str]) -> Vec<String> {
    let inputs: Vec<Input> = files
        .iter()
        .map(|f| Input::new(tests_dir().join("fixtures").join(f), None))
        .collect();
    run(&inputs, ValidateOptions::default(), &tests_dir())
}

fn run(inputs: &[Input], options: ValidateOptions, base: &Path) -> Vec<String> {
    let validation = load(inputs, options).expect("inputs are readable");
    if validation.diagnostics.iter().any(|d| d.is_error()) {
        assert!(
            validation.models.is_none(),
            "errors must withhold the models"
        );
    }
    let prefix = format!("{}/", base.display());
    validation
        .diagnostics
        .iter()
        .map(|d| d.to_string().replace(&prefix, ""))
        .collect()
}

const W5_DONE: &str = "uncontrollable event `done` appears in no plant: it can never make a state bad, and it is \
                       applied only when every owning supervisor allows it";

#[test]
fn v1_model_without_initial_state_is_rejected() {
    assert_eq!(
        diagnose(&["invalid/v1_no_initial.xml"]),
        [
            "fixtures/invalid/v1_no_initial.xml:2:1: error[V1]: model `v1_no_initial` has no initial state"
        ]
    );
}

#[test]
fn v2_second_initial_state_is_rejected_at_its_declaration() {
    assert_eq!(
        diagnose(&["invalid/v2_two_initial.xml"]),
        [
            "fixtures/invalid/v2_two_initial.xml:5:5: error[V2]: state `busy` is a second initial state (first at line 4)"
        ]
    );
}

#[test]
fn v3_model_without_marked_state_is_rejected() {
    assert_eq!(
        diagnose(&["invalid/v3_no_marked.xml"]),
        [
            "fixtures/invalid/v3_no_marked.xml:2:1: error[V3]: model `v3_no_marked` has no marked state"
        ]
    );
}

#[test]
fn v4_undeclared_event_points_at_the_event_attribute() {
    assert_eq!(
        diagnose(&["invalid/v4_undeclared_event.xml"]),
        [
            "fixtures/invalid/v4_undeclared_event.xml:14:39: error[V4]: transition uses event `stop`, which is not \
             declared in `<events>`"
        ]
    );
}

#[test]
fn v5_undeclared_state_points_at_the_dst_attribute() {
    assert_eq!(
        diagnose(&["invalid/v5_undeclared_state.xml"]),
        [
            "fixtures/invalid/v5_undeclared_state.xml:13:28: error[V5]: transition target `done` is not declared in `<states>`"
        ]
    );
}

#[test]
fn v6_state_used_by_no_transition_is_rejected() {
    assert_eq!(
        diagnose(&["invalid/v6_unused_state.xml"]),
        [
            "fixtures/invalid/v6_unused_state.xml:6:5: error[V6]: state `broken` is used by no transition"
        ]
    );
}

#[test]
fn v7_event_used_by_no_transition_is_rejected() {
    assert_eq!(
        diagnose(&["invalid/v7_unused_event.xml"]),
        [
            "fixtures/invalid/v7_unused_event.xml:10:5: error[V7]: event `repair` is used by no transition"
        ]
    );
}

#[test]
fn v8_two_transitions_on_one_event_name_the_first() {
    // `fast` is entered only by the rejected transition, so it is also reported unreachable.
    assert_eq!(
        diagnose(&["invalid/v8_nondeterministic.xml"]),
        [
            "fixtures/invalid/v8_nondeterministic.xml:6:5: warning[W2]: state `fast` is unreachable from the initial \
             state `idle`",
            "fixtures/invalid/v8_nondeterministic.xml:15:5: error[V8]: state `idle` has two transitions on event `go` \
             (first at line 13)",
        ]
    );
}

#[test]
fn v9_duplicate_state_and_event_names_are_both_reported() {
    assert_eq!(
        diagnose(&["invalid/v9_duplicate_names.xml"]),
        [
            "fixtures/invalid/v9_duplicate_names.xml:6:12: error[V9]: duplicate state name `busy` (first at line 5)",
            "fixtures/invalid/v9_duplicate_names.xml:11:12: error[V9]: duplicate event name `go` (first at line 9)",
        ]
    );
}

#[test]
fn v10_conflicting_controllability_points_at_the_later_declaration() {
    assert_eq!(
        diagnose(&["invalid/v10_machine.xml", "invalid/v10_rule.xml"]),
        [
            "fixtures/invalid/v10_rule.xml:9:5: error[V10]: event `done` is controllable here but uncontrollable in \
             fixtures/invalid/v10_machine.xml:9:5"
        ]
    );
}

#[test]
fn v11_negative_prob_and_fractional_time_are_rejected() {
    assert_eq!(
        diagnose(&["invalid/v11_bad_values.xml"]),
        [
            format!("fixtures/invalid/v11_bad_values.xml:9:5: warning[W5]: {W5_DONE}"),
            "fixtures/invalid/v11_bad_values.xml:12:50: error[V11]: `prob` is `-1`; expected a finite real number >= 0"
                .into(),
            "fixtures/invalid/v11_bad_values.xml:12:60: error[V11]: `time` is `1.5`; expected an integer number of \
             ticks >= 0"
                .into(),
        ]
    );
}

#[test]
fn v12_state_whose_controllable_weights_are_all_zero_is_rejected() {
    assert_eq!(
        diagnose(&["invalid/v12_zero_weights.xml"]),
        [
            "fixtures/invalid/v12_zero_weights.xml:4:5: error[V12]: all 2 outgoing controllable transitions of state \
             `idle` have weight 0"
                .to_string(),
            format!("fixtures/invalid/v12_zero_weights.xml:9:5: warning[W5]: {W5_DONE}"),
        ]
    );
}

#[test]
fn v13_missing_type_is_rejected() {
    assert_eq!(
        diagnose(&["invalid/v13_missing_type.xml"]),
        [
            "fixtures/invalid/v13_missing_type.xml:2:1: error[V13]: model `x` has no `type` (expected plant or spec)"
        ]
    );
}

#[test]
fn v13_unknown_type_points_at_the_type_attribute() {
    assert_eq!(
        diagnose(&["invalid/v13_unknown_type.xml"]),
        [
            "fixtures/invalid/v13_unknown_type.xml:2:35: error[V13]: unknown model type `controller` (expected plant, \
             spec, free-behaviour, specification or supervisor)"
        ]
    );
}

#[test]
fn v13_duplicate_model_name_points_at_the_second_name() {
    assert_eq!(
        diagnose(&["invalid/v13_duplicate_a.xml", "invalid/v13_duplicate_b.xml"]),
        [
            "fixtures/invalid/v13_duplicate_b.xml:2:11: error[V13]: duplicate model name `twin` (first in \
             fixtures/invalid/v13_duplicate_a.xml:2:11)"
        ]
    );
}

#[test]
fn v13_type_must_match_the_role_given_on_the_command_line() {
    let input = Input::new(
        tests_dir().join("fixtures/invalid/v13_duplicate_a.xml"),
        Some(ModelKind::Spec),
    );
    assert_eq!(
        run(&[input], ValidateOptions::default(), &tests_dir()),
        [
            "fixtures/invalid/v13_duplicate_a.xml:2:23: error[V13]: model `twin` declares type `plant` but was passed \
             as --spec"
        ]
    );
}

#[test]
fn v14_reserved_tick_event_is_rejected() {
    assert_eq!(
        diagnose(&["invalid/v14_tick.xml"]),
        [
            "fixtures/invalid/v14_tick.xml:10:12: error[V14]: event name `tick` is reserved for the global clock and must not be declared"
        ]
    );
}

#[test]
fn v15_lower_bound_over_65535_ticks_is_rejected() {
    assert_eq!(
        diagnose(&["invalid/v15_time_too_large.xml"]),
        [
            "fixtures/invalid/v15_time_too_large.xml:12:50: error[V15]: `time` is 70000 ticks; a compiled supervisor \
             stores at most 65535"
        ]
    );
}

#[test]
fn v15_more_than_255_transitions_per_state_and_256_events_are_rejected() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut xml = String::from(
        "<automata name=\"wide\" type=\"plant\">\n<states><state name=\"s\" i=\"1\" m=\"1\"/></states>\n<events>\n",
    );
    for e in 0..257 {
        xml.push_str(&format!("<event name=\"e{e}\" con=\"1\"/>\n"));
    }
    xml.push_str("</events>\n<transitions>\n");
    for e in 0..257 {
        xml.push_str(&format!(
            "<transition src=\"s\" dst=\"s\" event=\"e{e}\"/>\n"
        ));
    }
    xml.push_str("</transitions>\n</automata>\n");
    let path = dir.path().join("wide.xml");
    std::fs::write(&path, xml).expect("write fixture");
    assert_eq!(
        run(
            &[Input::new(&path, None)],
            ValidateOptions::default(),
            dir.path()
        ),
        [
            "wide.xml:2:9: error[V15]: state `s` has 257 outgoing transitions; a compiled supervisor allows at most 255",
            "wide.xml:260:1: error[V15]: event `e256` is event number 257 of the project; compiled supervisors \
             address at most 256",
        ]
    );
}

#[test]
fn w1_omitted_con_warns_and_means_uncontrollable() {
    assert_eq!(
        diagnose(&["invalid/w1_con_omitted.xml"]),
        [
            "fixtures/invalid/w1_con_omitted.xml:9:5: warning[W1]: event `done` has no `con` attribute; it is treated as uncontrollable"
        ]
    );
}

#[test]
fn w2_unreachable_state_warns_without_stopping() {
    let inputs = [Input::new(
        tests_dir().join("fixtures/invalid/w2_unreachable.xml"),
        None,
    )];
    let validation = load(&inputs, ValidateOptions::default()).expect("readable");
    assert!(
        validation.models.is_some(),
        "warnings never stop the pipeline"
    );
    assert_eq!(
        run(&inputs, ValidateOptions::default(), &tests_dir()),
        [
            "fixtures/invalid/w2_unreachable.xml:6:5: warning[W2]: state `lost` is unreachable from the initial state `idle`"
        ]
    );
}

#[test]
fn w3_prob_and_time_on_uncontrollable_transition_are_ignored_with_warnings() {
    assert_eq!(
        diagnose(&["invalid/w3_prob_on_uncontrollable.xml"]),
        [
            "fixtures/invalid/w3_prob_on_uncontrollable.xml:13:52: warning[W3]: `prob` on a transition of \
             uncontrollable event `done` is ignored",
            "fixtures/invalid/w3_prob_on_uncontrollable.xml:13:61: warning[W3]: `time` on a transition of \
             uncontrollable event `done` is ignored",
        ]
    );
}

#[test]
fn w4_prob_in_plant_warns_unless_thesis_literal_probabilities() {
    assert_eq!(
        diagnose(&["invalid/w4_prob_in_plant.xml"]),
        [
            "fixtures/invalid/w4_prob_in_plant.xml:12:50: warning[W4]: `prob` in a plant model is ignored \
             (probabilities belong in specifications)"
        ]
    );
    let literal = ValidateOptions {
        thesis_literal_probabilities: true,
        ..ValidateOptions::default()
    };
    let inputs = [Input::new(
        tests_dir().join("fixtures/invalid/w4_prob_in_plant.xml"),
        None,
    )];
    assert!(run(&inputs, literal, &tests_dir()).is_empty());
    let models = load(&inputs, literal)
        .expect("readable")
        .models
        .expect("valid");
    assert_eq!(models[0].transitions[0].weight, Some(0.5));
}

#[test]
fn w5_uncontrollable_event_in_no_plant_warns_at_its_declaration() {
    assert_eq!(
        diagnose(&["invalid/w5_spec_only_event.xml"]),
        [format!(
            "fixtures/invalid/w5_spec_only_event.xml:9:5: warning[W5]: {W5_DONE}"
        )]
    );
}

#[test]
fn w6_plant_sharing_no_event_with_a_specification_warns_at_its_root() {
    assert_eq!(
        diagnose(&["invalid/w6_plant.xml", "invalid/w6_spec.xml"]),
        [
            "fixtures/invalid/w6_plant.xml:2:1: warning[W6]: plant `lonely` shares no event with any specification: \
             its events belong to no local supervisor and are never enabled at runtime"
        ]
    );
}

#[test]
fn errors_in_several_files_are_all_reported_at_once() {
    let all = diagnose(&[
        "invalid/v1_no_initial.xml",
        "invalid/x1_truncated.xml",
        "invalid/v7_unused_event.xml",
    ]);
    let codes: Vec<&str> = all
        .iter()
        .map(|d| &d[d.find('[').unwrap_or(0)..])
        .map(|d| &d[1..3])
        .collect();
    assert_eq!(codes, ["V1", "V7", "X1"]);
}

#[test]
fn x1_mismatched_end_tag_is_located() {
    assert_eq!(
        diagnose(&["invalid/x1_unclosed_tag.xml"]),
        [
            "fixtures/invalid/x1_unclosed_tag.xml:14:1: error[X1]: malformed XML: ill-formed document: expected \
             `</events>`, but `</automata>` was found"
        ]
    );
}

#[test]
fn x1_element_never_closed_points_at_its_start_tag() {
    assert_eq!(
        diagnose(&["invalid/x1_truncated.xml"]),
        [
            "fixtures/invalid/x1_truncated.xml:11:3: error[X1]: element `<transitions>` is never closed"
        ]
    );
}

#[test]
fn x1_unquoted_attribute_value_points_at_the_value() {
    assert_eq!(
        diagnose(&["invalid/x1_bad_quoting.xml"]),
        [
            "fixtures/invalid/x1_bad_quoting.xml:4:17: error[X1]: malformed attribute in `<state>`: attribute value is not enclosed in quotes"
        ]
    );
}

#[test]
fn x2_wrong_root_element_is_rejected() {
    assert_eq!(
        diagnose(&["invalid/x2_wrong_root.xml"]),
        [
            "fixtures/invalid/x2_wrong_root.xml:2:1: error[X2]: root element is `<automaton>`; expected `<automata>` \
             (ptSCT model) or `<model type=\"FSA\">` (Nadzoru2)"
        ]
    );
}

#[test]
fn x2_missing_required_attribute_and_bad_flag_are_both_reported() {
    assert_eq!(
        diagnose(&["invalid/x2_missing_attribute.xml"]),
        [
            "fixtures/invalid/x2_missing_attribute.xml:9:24: error[X2]: attribute `con` is `maybe`; expected 1, 0, \
             true or false",
            "fixtures/invalid/x2_missing_attribute.xml:12:5: error[X2]: `<transition>` lacks the required attribute `dst`",
        ]
    );
}

#[test]
fn x2_unknown_attribute_and_element_are_rejected() {
    assert_eq!(
        diagnose(&["invalid/x2_unknown_names.xml"]),
        [
            "fixtures/invalid/x2_unknown_names.xml:4:24: error[X2]: unknown attribute `initial` on `<state>` \
             (expected `name`, `i`, `m`)",
            "fixtures/invalid/x2_unknown_names.xml:15:3: error[X2]: unknown element `<layout>` in `<automata>` \
             (expected `<states>`, `<events>` or `<transitions>`)",
        ]
    );
}

#[test]
fn nadzoru_fsa_imports_without_diagnostics() {
    let inputs = [Input::new(
        tests_dir().join("fixtures/nadzoru/machine.xml"),
        Some(ModelKind::Plant),
    )];
    assert!(run(&inputs, ValidateOptions::default(), &tests_dir()).is_empty());
}

#[test]
fn nadzoru_fsa_needs_a_role() {
    assert_eq!(
        diagnose(&["nadzoru/machine.xml"]),
        [
            "fixtures/nadzoru/machine.xml:2:1: error[V13]: Nadzoru2 model `machine` carries no type: pass it with --plant or --spec"
        ]
    );
}

#[test]
fn nadzoru_duplicate_and_unknown_ids_are_located() {
    let inputs = [Input::new(
        tests_dir().join("fixtures/nadzoru/bad_ids.xml"),
        Some(ModelKind::Plant),
    )];
    assert_eq!(
        run(&inputs, ValidateOptions::default(), &tests_dir()),
        [
            "fixtures/nadzoru/bad_ids.xml:5:12: error[V9]: duplicate state id `0` (first at line 4)",
            "fixtures/nadzoru/bad_ids.xml:7:28: error[V5]: transition target refers to state id `7`, which no state \
             declares",
            "fixtures/nadzoru/bad_ids.xml:8:39: error[V4]: transition event refers to event id `3`, which no event \
             declares",
        ]
    );
}

#[test]
fn worked_example_of_section_10_3_warns_only_about_u() {
    assert_eq!(
        diagnose(&["example_10_3.xml"]),
        [
            "fixtures/example_10_3.xml:13:5: warning[W5]: uncontrollable event `u` appears in no plant: it can never \
             make a state bad, and it is applied only when every owning supervisor allows it"
        ]
    );
}

#[test]
fn v15_raw_weight_above_1_cannot_be_stored() {
    let raw = ValidateOptions {
        raw_weights: true,
        ..ValidateOptions::default()
    };
    let inputs = [Input::new(
        tests_dir().join("fixtures/example_10_3.xml"),
        None,
    )];
    let diagnostics = run(&inputs, raw, &tests_dir());
    assert_eq!(
        diagnostics[1],
        "fixtures/example_10_3.xml:21:45: error[V15]: `prob` is 3; with --raw-weights weights are stored as \
         probabilities and must be at most 1"
    );
}

#[test]
fn x1_file_that_is_not_utf8_is_located() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("latin1.xml");
    std::fs::write(&path, b"<automata name=\"m\"\n  type=\"pl\xe4nt\"/>").expect("write fixture");
    assert_eq!(
        run(
            &[Input::new(&path, None)],
            ValidateOptions::default(),
            dir.path()
        ),
        ["latin1.xml:2:11: error[X1]: the file is not valid UTF-8 (model files must be UTF-8)"]
    );
}
