//! Addressed messages between robots, end to end with real processes: the world decides every message's fate by
//! the `<messages>` medium, records it in `messages.csv`, and delivers what passes to the recipient's agent in the
//! next tick. The shipped example `configs/messages/talk.argos` has a robot of each kind of trouble (see its
//! header). Across hosts: `hosts::messages_between_robots_on_two_hosts_have_the_fates_they_have_on_one`.

use std::collections::BTreeMap;
use std::path::Path;

use swarm_system_tests::{assert_clean, swarm, workspace_file};

const TALK: &str = "configs/messages/talk.argos";

/// One row of `messages.csv`.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Row {
    tick: u64,
    from: u32,
    to: Option<u32>,
    outcome: String,
    reason: String,
}

fn run(out: &Path, extra: &[&str]) {
    let config = workspace_file(TALK).display().to_string();
    let out = out.display().to_string();
    let mut args = vec!["run", &config, "--out", &out, "--no-progress"];
    args.extend_from_slice(extra);
    let outcome = swarm(&args);
    assert!(
        outcome.output.status.success(),
        "swarm run {config} failed:\n{}",
        outcome.stderr()
    );
    assert_clean(&outcome);
}

fn messages(out: &Path) -> Vec<Row> {
    let text = std::fs::read_to_string(out.join("messages.csv")).expect("messages.csv");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("tick,from,to,address,bytes,outcome,reason")
    );
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            assert_eq!(f.len(), 7, "{line}");
            Row {
                tick: f[0].parse().expect("tick"),
                from: f[1].parse().expect("from"),
                to: (!f[2].is_empty()).then(|| f[2].parse().expect("to")),
                outcome: f[5].to_owned(),
                reason: f[6].to_owned(),
            }
        })
        .collect()
}

/// What each robot's agent read per tick: `led_r` of `trajectory.csv` (the probe shows its inbox's size there).
fn read_per_tick(out: &Path) -> BTreeMap<(u64, u32), u32> {
    let text = std::fs::read_to_string(out.join("trajectory.csv")).expect("trajectory.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let (tick, robot, led) = (col("tick"), col("robot"), col("led_r"));
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            (
                (
                    f[tick].parse().expect("tick"),
                    f[robot].parse().expect("robot"),
                ),
                f[led].parse().expect("led_r"),
            )
        })
        .collect()
}

#[test]
fn messages_are_delivered_or_dropped_for_a_reason_and_each_robot_reads_what_was_delivered() {
    let out = tempfile::tempdir().expect("a temporary directory");
    run(out.path(), &[]);
    let rows = messages(out.path());
    let count = |reason: &str| rows.iter().filter(|r| r.reason == reason).count();
    // talker (0) broadcasts to everyone: loner (2) is beyond the medium's 1 m range.
    assert!(
        rows.iter()
            .filter(|r| r.from == 0 && r.to == Some(2))
            .all(|r| r.reason == "out_of_range")
    );
    // echoer (1) sends 3 messages a tick where the medium allows 2, and echoes what it reads.
    assert!(
        count("over_tick_limit") >= 200,
        "{}",
        count("over_tick_limit")
    );
    // forger (3) claims to be robot 1: every one of its messages is refused, none delivered.
    assert_eq!(count("forged_sender"), 40);
    assert!(
        rows.iter()
            .filter(|r| r.from == 3)
            .all(|r| r.reason == "forged_sender")
    );
    // chatter (4) sends 200-byte messages where the medium allows 64.
    assert_eq!(count("too_long"), 40);
    // loner's ranged broadcast finds nobody within 0.5 m.
    assert_eq!(count("nobody_in_range"), 100);
    // A fifth of what could arrive is lost.
    let lost = count("lost");
    let delivered = count("");
    assert!(
        lost * 10 > (lost + delivered) && lost * 10 < 3 * (lost + delivered),
        "{lost} lost, {delivered} delivered"
    );
    // Every message delivered after tick k is what its recipient's agent read in tick k + 1: nothing more, nothing
    // less, and nothing to a robot that was not addressed.
    let mut delivered_to: BTreeMap<(u64, u32), u32> = BTreeMap::new();
    for row in rows.iter().filter(|r| r.outcome == "delivered") {
        *delivered_to
            .entry((row.tick + 1, row.to.expect("a recipient")))
            .or_default() += 1;
    }
    for ((tick, robot), read) in read_per_tick(out.path()) {
        if tick == 0 || tick > 200 {
            continue;
        }
        let expected = delivered_to.get(&(tick, robot)).copied().unwrap_or(0);
        assert_eq!(read, expected, "robot {robot} in tick {tick}");
    }
}

#[test]
fn the_same_seed_gives_the_same_messages_and_another_seed_other_losses() {
    let runs: Vec<tempfile::TempDir> = (0..3)
        .map(|_| tempfile::tempdir().expect("a temporary directory"))
        .collect();
    run(runs[0].path(), &["--ticks", "60"]);
    run(runs[1].path(), &["--ticks", "60"]);
    run(runs[2].path(), &["--ticks", "60", "--seed", "6"]);
    let [a, b, c] = [0, 1, 2].map(|i| messages(runs[i].path()));
    assert!(!a.is_empty());
    assert_eq!(a, b, "two runs with the same seed");
    assert_ne!(a, c, "the loss draws of another seed");
}
