//! `supervisor-gen synth --reduce` on the factory fixtures: the written supervisors, reductions, compiled set,
//! drawings and report.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use supervisor_gen::compiled::SupervisorSet;
use supervisor_gen::xml_read::read_model;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/factory")
        .join(name)
}

fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// `synth` on the two machines with the buffer and the preference specification, into `out`.
fn synth(out: &Path, extra: &[&str]) -> Output {
    let files: Vec<PathBuf> = [
        "machine1.xml",
        "machine2.xml",
        "buffer.xml",
        "preference.xml",
    ]
    .iter()
    .map(|f| fixture(f))
    .collect();
    let mut args = vec!["synth", "--plant", path(&files[0]), path(&files[1])];
    args.extend([
        "--spec",
        path(&files[2]),
        path(&files[3]),
        "--out",
        path(out),
    ]);
    args.extend(extra);
    Command::new(env!("CARGO_BIN_EXE_supervisor-gen"))
        .args(&args)
        .output()
        .expect("the binary runs")
}

fn states_of(file: &Path) -> usize {
    let xml = std::fs::read_to_string(file).expect("written");
    read_model(&file.display().to_string(), &xml, None)
        .expect("reads back")
        .states
        .len()
}

fn report(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("report written"))
        .expect("JSON")
}

/// S_preference (4 states) only weighs start1 against start2; in closed loop with the machines all its states are
/// consistent, so it reduces to 1 state, and S_buffer, kept unreduced, still enforces both machines: no observer
/// is needed and MemCons drops from 122 to 93 bytes. S_buffer's own reduction (6 to 4 states, its timed start2
/// keeps the rest apart) would need both machines observed and is not used.
#[test]
fn synth_reduce_writes_the_reduced_set_its_reductions_drawings_and_report() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let o = synth(&out, &["--reduce", "--draw", "--image-format", "svg"]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        stdout.contains("reduction: S_preference reduced: 4 -> 1 states, 8 -> 4 transitions"),
        "{stdout}"
    );
    assert!(
        stdout.contains(
            "reduction: S_buffer kept, the plant observers its reduction needs cost more"
        ),
        "{stdout}"
    );
    assert!(
        stdout.contains("MemCons 93 bytes (122 unreduced)"),
        "{stdout}"
    );

    // The supervisors run: S_buffer unreduced, S_preference reduced; every reduction is written too.
    assert_eq!(states_of(&out.join("S_buffer.xml")), 6);
    assert_eq!(states_of(&out.join("S_preference.xml")), 1);
    assert_eq!(states_of(&out.join("S_buffer.reduced.xml")), 4);
    assert_eq!(states_of(&out.join("S_preference.reduced.xml")), 1);
    assert!(!out.join("observer_machine1.xml").exists());

    let set =
        SupervisorSet::from_bytes(&std::fs::read(out.join("supervisors.ptsct")).expect("compiled"))
            .expect("parses");
    let sizes: Vec<(&str, usize)> = set
        .supervisors
        .iter()
        .map(|s| (s.name.as_str(), s.states.len()))
        .collect();
    assert_eq!(sizes, [("S_buffer", 6), ("S_preference", 1)]);
    assert_eq!(set.mem_cons(), 93);

    let drawings = out.join("drawings");
    for stem in [
        "S_preference",
        "stages/S_preference_5_minimised",
        "stages/S_preference_6_reduced",
    ] {
        assert!(drawings.join(format!("{stem}.dot")).is_file(), "{stem}.dot");
    }

    let r = report(&out);
    assert_eq!(r["mem_cons"]["formula_bytes"], 93);
    assert_eq!(
        (
            r["reduction"]["mem_cons_before"].as_u64(),
            r["reduction"]["mem_cons_after"].as_u64()
        ),
        (Some(122), Some(93))
    );
    assert_eq!(r["reduction"]["observers"], serde_json::json!([]));
    let pref = &r["supervisors"][1];
    assert_eq!(pref["states"], 1);
    let red = &pref["reduction"];
    assert_eq!(red["outcome"], "reduced");
    assert_eq!(
        red["before"],
        serde_json::json!({"states": 4, "transitions": 8, "controllable_transitions": 4, "mem_cons": 58})
    );
    assert_eq!(
        red["after"],
        serde_json::json!({"states": 1, "transitions": 4, "controllable_transitions": 2, "mem_cons": 29})
    );
    assert_eq!(red["reduced_file"], "S_preference.reduced.xml");
    let buffer = &r["supervisors"][0]["reduction"];
    assert_eq!(buffer["outcome"], "observers cost more");
    assert_eq!(
        (
            buffer["before"]["states"].as_u64(),
            buffer["after"]["states"].as_u64()
        ),
        (Some(6), Some(4))
    );
}

#[test]
fn without_reduce_the_report_has_no_reduction_and_nothing_reduced_is_written() {
    let dir = tempfile::tempdir().expect("temp dir");
    let o = synth(dir.path(), &[]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!String::from_utf8_lossy(&o.stdout).contains("reduction"));
    let r = report(dir.path());
    assert!(r.get("reduction").is_none());
    assert!(r["supervisors"][1].get("reduction").is_none());
    assert_eq!(states_of(&dir.path().join("S_preference.xml")), 4);
    assert!(!dir.path().join("S_preference.reduced.xml").exists());
}
