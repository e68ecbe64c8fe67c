//! The `supervisor-gen` binary on the small factory example (two machines, one buffer): produced files, report
//! contents and exit codes (0 valid, 1 invalid or impossible, 2 usage or I/O).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use supervisor_gen::compiled::SupervisorSet;
use supervisor_gen::xml_read::read_model;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_supervisor-gen"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn graphviz_on_path() -> bool {
    Command::new("dot")
        .arg("-V")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// `synth` on the factory with the given mode and extra flags, into `out`.
fn synth_factory(out: &Path, mode: &str, extra: &[&str]) -> Output {
    let (m1, m2, buffer) = (
        fixture("factory/machine1.xml"),
        fixture("factory/machine2.xml"),
        fixture("factory/buffer.xml"),
    );
    let mut args = vec![
        "synth",
        "--plant",
        path(&m1),
        path(&m2),
        "--spec",
        path(&buffer),
        "--mode",
        mode,
    ];
    args.extend(["--out", path(out)]);
    args.extend(extra);
    run(&args)
}

#[test]
fn synth_local_modular_writes_xml_compiled_set_rust_and_report() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let o = synth_factory(&out, "local-modular", &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let xml = std::fs::read_to_string(out.join("S_buffer.xml")).expect("supervisor XML written");
    let sup = read_model("S_buffer.xml", &xml, None).expect("readable");
    assert_eq!(sup.kind.map(|k| k.value), Some("supervisor".to_owned()));
    assert_eq!((sup.states.len(), sup.transitions.len()), (6, 8));

    let bytes = std::fs::read(out.join("supervisors.ptsct")).expect("compiled set written");
    let set = SupervisorSet::from_bytes(&bytes).expect("compiled set parses");
    assert_eq!(set.supervisors.len(), 1);
    let rust = std::fs::read_to_string(out.join("supervisors.rs")).expect("generated Rust written");
    assert!(rust.contains("start1") && rust.contains("finish2"));

    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("report.json")).expect("report written"),
    )
    .expect("JSON");
    let s = &report["supervisors"][0];
    assert_eq!(s["name"], "S_buffer");
    assert_eq!(
        (s["states"].as_u64(), s["transitions"].as_u64()),
        (Some(6), Some(8))
    );
    assert_eq!(s["controllable_transitions"], 3);
    assert_eq!(
        s["events"],
        serde_json::json!(["start1", "finish1", "start2", "finish2"])
    );
    // Machine 1 finishing onto a full buffer cannot be prevented: both such states of K are bad.
    let bad: Vec<&str> = s["removed_bad"]
        .as_array()
        .expect("list")
        .iter()
        .map(|b| b["state"].as_str().unwrap_or(""))
        .collect();
    assert_eq!(bad, ["((working,idle),full)", "((working,working),full)"]);
    // MemCons = (s + 3t) + 2(s + 2 t_c) + e + (e + 2) N = (6 + 24) + 2(6 + 6) + 4 + 6 = 64.
    assert_eq!(report["mem_cons"]["formula_bytes"], 64);
    assert_eq!(set.mem_cons(), 64);
    assert_eq!(report["mem_cons"]["bytes_written"], bytes.len());
    let checks = &report["architecture_checks"];
    assert_eq!(checks["non_conflict"]["nonblocking"], true);
    assert_eq!(checks["local_modular_validation"]["passed"], true);
    assert!(report["warnings"].as_array().is_some_and(Vec::is_empty));
}

#[test]
fn synth_monolithic_with_draw_writes_every_stage_and_images_only_with_graphviz() {
    let dir = tempfile::tempdir().expect("temp dir");
    let o = synth_factory(dir.path(), "monolithic", &["--draw"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(dir.path().join("S_mon.xml").is_file());
    let drawings = dir.path().join("drawings");
    for stem in [
        "inputs/machine1",
        "inputs/buffer",
        "stages/S_mon_1_G",
        "stages/S_mon_2_E",
        "stages/S_mon_3_K",
        "stages/S_mon_4_supc",
        "S_mon",
    ] {
        assert!(drawings.join(format!("{stem}.dot")).is_file(), "{stem}.dot");
        assert_eq!(
            drawings.join(format!("{stem}.svg")).is_file(),
            graphviz_on_path(),
            "{stem}.svg"
        );
        assert_eq!(
            drawings.join(format!("{stem}.png")).is_file(),
            graphviz_on_path(),
            "{stem}.png"
        );
    }
    let k = std::fs::read_to_string(drawings.join("stages/S_mon_3_K.dot")).expect("K drawn");
    assert!(
        k.contains("fillcolor=\"#ff9999\""),
        "bad states of K are drawn red"
    );
}

#[test]
fn synth_accepts_a_nadzoru_plant() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (m1, m2, buffer) = (
        fixture("nadzoru/machine.xml"),
        fixture("factory/machine2.xml"),
        fixture("factory/buffer.xml"),
    );
    let o = run(&[
        "synth",
        "--plant",
        path(&m1),
        path(&m2),
        "--spec",
        path(&buffer),
        "--out",
        path(dir.path()),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(dir.path().join("S_buffer.xml").is_file());
}

#[test]
fn synth_invalid_input_exits_1_with_located_errors_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let (bad, buffer) = (
        fixture("invalid/v8_nondeterministic.xml"),
        fixture("factory/buffer.xml"),
    );
    let o = run(&[
        "synth",
        "--plant",
        path(&bad),
        "--spec",
        path(&buffer),
        "--out",
        path(&out),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let expected = format!(
        "{}:15:5: error[V8]: state `idle` has two transitions on event `go` (first at line 13)",
        bad.display()
    );
    assert!(stderr(&o).contains(&expected), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn synth_impossible_specification_exits_1_naming_the_spec() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (m1, spec) = (
        fixture("factory/machine1.xml"),
        fixture("factory/impossible.xml"),
    );
    let o = run(&[
        "synth",
        "--plant",
        path(&m1),
        "--spec",
        path(&spec),
        "--out",
        path(dir.path()),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains(
            "no nonblocking controllable supervisor exists for specification `impossible`"
        ),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("report.json").exists());
}

#[test]
fn check_exits_0_on_valid_and_1_on_invalid_models() {
    let valid = run(&["check", path(&fixture("example_10_3.xml"))]);
    assert_eq!(valid.status.code(), Some(0), "{}", stderr(&valid));
    assert!(
        stderr(&valid).contains("warning[W5]"),
        "warnings are printed"
    );
    let invalid = run(&[
        "check",
        path(&fixture("invalid/v3_no_marked.xml")),
        path(&fixture("invalid/v7_unused_event.xml")),
    ]);
    assert_eq!(invalid.status.code(), Some(1));
    let err = stderr(&invalid);
    assert!(
        err.contains("error[V3]") && err.contains("error[V7]"),
        "all errors at once: {err}"
    );
}

#[test]
fn usage_and_io_problems_exit_2() {
    let usage = run(&["synth", "--plant", path(&fixture("factory/machine1.xml"))]);
    assert_eq!(usage.status.code(), Some(2));
    let dir = tempfile::tempdir().expect("temp dir");
    let missing = dir.path().join("missing.xml");
    let io = run(&[
        "synth",
        "--plant",
        path(&missing),
        "--spec",
        path(&fixture("factory/buffer.xml")),
        "--out",
        path(dir.path()),
    ]);
    assert_eq!(io.status.code(), Some(2));
    assert!(stderr(&io).contains("cannot read"), "{}", stderr(&io));
}

#[test]
fn draw_writes_one_drawing_per_model() {
    let dir = tempfile::tempdir().expect("temp dir");
    let o = run(&[
        "draw",
        path(&fixture("example_10_3.xml")),
        "--out",
        path(dir.path()),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let dot = std::fs::read_to_string(dir.path().join("example.dot")).expect("drawn");
    // Input weights are shown normalised per state: 1 and 3 at q2 become 0.25 and 0.75.
    assert!(
        dot.contains("label=\"b [P=0.25]\"") && dot.contains("label=\"c [P=0.75]\""),
        "{dot}"
    );
}

#[test]
fn codegen_writes_the_rust_module() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("sup.rs");
    let (m1, m2, buffer) = (
        fixture("factory/machine1.xml"),
        fixture("factory/machine2.xml"),
        fixture("factory/buffer.xml"),
    );
    let o = run(&[
        "codegen",
        "--plant",
        path(&m1),
        path(&m2),
        "--spec",
        path(&buffer),
        "--out",
        path(&file),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rust = std::fs::read_to_string(&file).expect("written");
    assert!(rust.contains("start2"));
}

#[test]
fn weights_are_normalised_unless_raw_weights_is_given() {
    let (m1, m2, pref) = (
        fixture("factory/machine1.xml"),
        fixture("factory/machine2.xml"),
        fixture("factory/preference.xml"),
    );
    let start2_at_initial = |extra: &[&str]| {
        let dir = tempfile::tempdir().expect("temp dir");
        let mut args = vec![
            "synth",
            "--plant",
            path(&m1),
            path(&m2),
            "--spec",
            path(&pref),
            "--out",
            path(dir.path()),
        ];
        args.extend(extra);
        let o = run(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let xml = std::fs::read_to_string(dir.path().join("S_preference.xml")).expect("written");
        let line = xml
            .lines()
            .find(|l| l.contains(r#"src="((idle,idle),any)""#) && l.contains(r#"event="start2""#))
            .map(str::trim)
            .map(str::to_owned);
        line.expect("start2 is enabled initially")
    };
    assert!(start2_at_initial(&[]).contains(r#"prob="0.75""#));
    assert!(start2_at_initial(&["--raw-weights"]).contains(r#"prob="0.375""#));
}

#[test]
fn without_graphviz_only_dot_is_written_and_the_absence_is_logged_once() {
    let dir = tempfile::tempdir().expect("temp dir");
    let empty_path = tempfile::tempdir().expect("temp dir");
    let (m1, m2, buffer) = (
        fixture("factory/machine1.xml"),
        fixture("factory/machine2.xml"),
        fixture("factory/buffer.xml"),
    );
    let o = Command::new(env!("CARGO_BIN_EXE_supervisor-gen"))
        .args([
            "synth",
            "--plant",
            path(&m1),
            path(&m2),
            "--spec",
            path(&buffer),
            "--out",
            path(dir.path()),
            "--draw",
        ])
        .env("PATH", empty_path.path())
        .output()
        .expect("the binary runs");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        stderr(&o).matches("Graphviz `dot` is not on PATH").count(),
        1,
        "{}",
        stderr(&o)
    );
    let drawings = dir.path().join("drawings");
    assert!(drawings.join("stages/S_buffer_3_K.dot").is_file());
    assert!(drawings.join("S_buffer.dot").is_file());
    let images = std::fs::read_dir(&drawings)
        .expect("drawings dir")
        .filter_map(Result::ok)
        .filter(|e| e.path().extension().is_some_and(|x| x != "dot"))
        .count();
    assert_eq!(images, 0);
}

#[test]
fn modular_mode_checks_non_conflict_without_local_modular_validation() {
    let dir = tempfile::tempdir().expect("temp dir");
    let o = synth_factory(dir.path(), "modular", &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("report.json")).expect("report"),
    )
    .expect("JSON");
    assert_eq!(report["architecture"], "modular");
    assert_eq!(
        report["architecture_checks"]["non_conflict"]["nonblocking"],
        true
    );
    assert!(report["architecture_checks"]["local_modular_validation"].is_null());
}

#[test]
fn check_takes_nadzoru_files_with_a_role() {
    let o = run(&["check", "--plant", path(&fixture("nadzoru/machine.xml"))]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        String::from_utf8_lossy(&o.stdout).trim(),
        "1 model(s) valid"
    );
}

#[test]
fn image_formats_are_configurable() {
    let dir = tempfile::tempdir().expect("temp dir");
    let o = run(&[
        "draw",
        path(&fixture("example_10_3.xml")),
        "--out",
        path(dir.path()),
        "--image-format",
        "pdf,png",
        "--dpi",
        "50",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(dir.path().join("example.dot").is_file());
    assert_eq!(dir.path().join("example.pdf").is_file(), graphviz_on_path());
    assert_eq!(dir.path().join("example.png").is_file(), graphviz_on_path());
    assert!(!dir.path().join("example.svg").exists());
}

#[test]
fn report_lists_validation_warnings_with_their_locations() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (m1, m2, spec) = (
        fixture("factory/machine1.xml"),
        fixture("factory/machine2.xml"),
        fixture("example_10_3.xml"),
    );
    // The worked example's events a, b, c, u belong to no plant: W5 for `u`, W6 for both machines.
    let o = run(&[
        "synth",
        "--plant",
        path(&m1),
        path(&m2),
        "--spec",
        path(&spec),
        "--out",
        path(dir.path()),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("report.json")).expect("report"),
    )
    .expect("JSON");
    let warnings = report["warnings"].as_array().expect("list");
    let codes: Vec<&str> = warnings.iter().filter_map(|w| w["code"].as_str()).collect();
    assert_eq!(codes, ["W5", "W6", "W6"]);
    assert_eq!(
        (warnings[0]["line"].as_u64(), warnings[0]["column"].as_u64()),
        (Some(13), Some(5))
    );
    assert_eq!(warnings[0]["severity"], "warning");
}

#[test]
fn a_device_or_a_deeply_nested_file_is_refused_with_its_name_not_read_forever_or_overflowed() {
    let zero = run(&["check", "/dev/zero"]);
    assert_eq!(zero.status.code(), Some(2));
    assert!(
        stderr(&zero).contains("/dev/zero") && stderr(&zero).contains("not a regular file"),
        "{}",
        stderr(&zero)
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let deep = dir.path().join("deep.xml");
    let depth = 1_000_000;
    std::fs::write(
        &deep,
        format!("{}{}", "<a>".repeat(depth), "</a>".repeat(depth)),
    )
    .expect("write");
    let o = run(&["check", path(&deep)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("nests deeper than 256 elements"),
        "{}",
        stderr(&o)
    );
}

/// Writes a plant that may always do `event` and a specification that is a cycle of `states` states over it, only
/// the first marked (no two of its states can be merged); returns their paths.
fn write_cycle(dir: &Path, event: &str, states: usize) -> (PathBuf, PathBuf) {
    let plant = dir.join(format!("clock_{event}.xml"));
    std::fs::write(
        &plant,
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<automata name="clock_{event}" type="plant">
  <states><state name="on" i="1" m="1"/></states>
  <events><event name="{event}" con="1"/></events>
  <transitions><transition src="on" dst="on" event="{event}"/></transitions>
</automata>
"#
        ),
    )
    .expect("writes the plant");
    let mut spec = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<automata name=\"cycle_{event}\" type=\"spec\">\n  <states>\n"
    );
    spec.push_str("    <state name=\"s0\" i=\"1\" m=\"1\"/>\n");
    for k in 1..states {
        spec.push_str(&format!("    <state name=\"s{k}\"/>\n"));
    }
    spec.push_str(&format!(
        "  </states>\n  <events><event name=\"{event}\" con=\"1\"/></events>\n  <transitions>\n"
    ));
    for k in 0..states {
        spec.push_str(&format!(
            "    <transition src=\"s{k}\" dst=\"s{}\" event=\"{event}\"/>\n",
            (k + 1) % states
        ));
    }
    spec.push_str("  </transitions>\n</automata>\n");
    let spec_path = dir.join(format!("cycle_{event}.xml"));
    std::fs::write(&spec_path, spec).expect("writes the specification");
    (plant, spec_path)
}

#[test]
fn a_supervisor_too_large_to_compile_still_gives_its_xml_report_and_drawings_and_exit_0() {
    let dir = tempfile::tempdir().expect("temp dir");
    // Two independent cycles of 300 and 250 states: the monolithic supervisor is their product, 75,000 states,
    // more than the compiled format's 65,535.
    let (plant_a, spec_a) = write_cycle(dir.path(), "a", 300);
    let (plant_b, spec_b) = write_cycle(dir.path(), "b", 250);
    let out = dir.path().join("out");
    let o = run(&[
        "synth",
        "--plant",
        path(&plant_a),
        path(&plant_b),
        "--spec",
        path(&spec_a),
        path(&spec_b),
        "--mode",
        "monolithic",
        "--draw",
        "--out",
        path(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let warnings = stderr(&o);
    assert!(
        warnings.contains("warning: supervisors.ptsct not written: V15:")
            && warnings.contains("65535"),
        "{warnings}"
    );
    assert!(!out.join("supervisors.ptsct").exists());
    assert!(!out.join("supervisors.rs").exists());
    let xml =
        std::fs::read_to_string(out.join("S_mon.xml")).expect("the supervisor's XML is written");
    let supervisor = read_model("S_mon.xml", &xml, None).expect("readable");
    assert_eq!(supervisor.states.len(), 75_000);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("report"))
            .expect("JSON");
    let skipped: Vec<&str> = report["skipped"]
        .as_array()
        .expect("skipped")
        .iter()
        .filter_map(|s| s["output"].as_str())
        .collect();
    assert!(skipped.contains(&"supervisors.ptsct") && skipped.contains(&"supervisors.rs"));
    // The 75,000-state automata are too large to draw; the inputs are drawn (the 300-state cycle without images).
    assert!(skipped.contains(&"drawings/S_mon.dot"), "{skipped:?}");
    assert!(out.join("drawings/inputs/clock_a.dot").is_file());
    assert!(out.join("drawings/inputs/cycle_a.dot").is_file());
    assert!(!out.join("drawings/S_mon.dot").exists());
}
