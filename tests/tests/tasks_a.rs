//! The aggregation, synchronisation and plain-SCT obstacle-avoidance experiments run from their shipped
//! configurations (shortened with `--robots`/`--ticks`) and put their task metrics into `summary.json`.

use std::path::Path;

use swarm_system_tests::{assert_clean, swarm};

/// Runs `config` shortened to `robots` robots and `ticks` ticks; returns the `metrics` of its `summary.json`.
fn run_task(config: &str, robots: u32, ticks: u64, out: &Path) -> serde_json::Value {
    let out_arg = out.display().to_string();
    let (robots, ticks) = (robots.to_string(), ticks.to_string());
    let outcome = swarm(&[
        "run",
        config,
        "--robots",
        &robots,
        "--ticks",
        &ticks,
        "--out",
        &out_arg,
        "--no-progress",
    ]);
    assert!(
        outcome.output.status.success(),
        "swarm run {config} failed:\n{}",
        outcome.stderr()
    );
    assert_clean(&outcome);
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json exists");
    let summary: serde_json::Value = serde_json::from_str(&text).expect("summary.json is JSON");
    assert_eq!(
        summary["ticks"],
        serde_json::json!(ticks.parse::<u64>().unwrap())
    );
    summary["metrics"].clone()
}

#[test]
fn aggregation_reports_clusters_over_time() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let m = run_task("configs/aggregation/aggregation.argos", 10, 100, out.path());
    assert_eq!(m["robots"], 10);
    let clusters = m["clusters"].as_u64().expect("clusters is a count");
    let largest = m["largest_cluster"]
        .as_u64()
        .expect("largest_cluster is a count");
    assert!((1..=10).contains(&clusters), "{m}");
    assert!((1..=10).contains(&largest), "{m}");
    assert!(
        largest * clusters >= 10,
        "the clusters hold all 10 robots: {m}"
    );
    let series = m["series"].as_array().expect("a series");
    assert_eq!(series.len(), 1, "one sample per 10 s at 10 ticks/s: {m}");
    assert_eq!(series[0]["tick"], 100);
}

#[test]
fn synchronisation_robots_flash_and_synchrony_is_measured() {
    let out = tempfile::tempdir().expect("a temporary directory");
    // Counters start in [1, 50] and advance at most once per two ticks: every robot reaches the top by tick 100.
    let m = run_task(
        "configs/synchronisation/synchronisation.argos",
        9,
        240,
        out.path(),
    );
    let flashes = m["flashes"].as_u64().expect("flashes is a count");
    assert!(flashes >= 9, "every robot flashed at least once: {m}");
    assert_eq!(m["window_ticks"], 5);
    let fraction = m["series"][0]["window_fraction"]
        .as_f64()
        .expect("the first sample has a window fraction");
    assert!(fraction > 0.0 && fraction <= 1.0, "{m}");
    assert!(m.get("time_to_synchrony_tick").is_some(), "{m}");
}

#[test]
fn obstacle_avoidance_sct_variant_reports_the_comparison_metrics() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let m = run_task(
        "configs/obstacle_avoidance/obstacle_avoidance_sct.argos",
        10,
        60,
        out.path(),
    );
    let forward = m["forward_fraction"].as_f64().expect("forward_fraction");
    assert!(forward > 0.0 && forward < 1.0, "{m}");
    assert!(m["collisions_per_robot_minute"].is_number(), "{m}");
}
