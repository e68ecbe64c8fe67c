//! Addressed messages between robots and coordinators, end to end with real processes: the world decides every
//! message's fate by the `<messages>` medium, records it in `messages.csv`, and delivers what passes to the
//! recipient's agent in the next tick. The shipped example `configs/messages/talk.argos` has a robot of each kind
//! of trouble (see its header); `configs/messages/coordinator.argos` has four robots reporting to a coordinator
//! that the schedule kills and restarts. Across hosts:
//! `hosts::messages_between_robots_on_two_hosts_have_the_fates_they_have_on_one`.

use std::collections::BTreeMap;
use std::path::Path;

use swarm_system_tests::{LiveSwarm, assert_same_records, run_to_completion, swarm_ctl};

const TALK: &str = "configs/messages/talk.argos";
const COORDINATOR: &str = "configs/messages/coordinator.argos";
/// The coordinator's participant index in `COORDINATOR`: after the four robots.
const CENTRAL: u32 = 4;

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
    run_to_completion(TALK, out, extra);
}

/// The rows of `messages.csv` (of a live run: the lines written so far, up to the last whole one).
fn messages(out: &Path) -> Vec<Row> {
    let text = swarm_system_tests::run_text(out, "messages.csv");
    let whole = text.rfind('\n').map_or("", |end| &text[..end]);
    let mut lines = whole.lines();
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
    let text = swarm_system_tests::run_text(out, "trajectory.csv");
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
    // summary.json counts what messages.csv lists.
    let summary: serde_json::Value =
        serde_json::from_str(&text(out.path(), "summary.json")).expect("summary.json");
    assert_eq!(summary["messages"]["delivered"], delivered);
    assert_eq!(summary["messages"]["dropped"]["forged_sender"], 40);
    assert_eq!(summary["messages"]["dropped"]["lost"], lost);
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

fn text(out: &Path, file: &str) -> String {
    swarm_system_tests::run_text(out, file)
}

#[test]
fn a_coordinator_answers_robots_and_the_run_goes_on_while_it_is_killed_and_restarted() {
    let runs: Vec<tempfile::TempDir> = (0..2)
        .map(|_| tempfile::tempdir().expect("a temporary directory"))
        .collect();
    for out in &runs {
        run_to_completion(COORDINATOR, out.path(), &[]);
    }
    let out = runs[0].path();
    let summary: serde_json::Value =
        serde_json::from_str(&text(out, "summary.json")).expect("summary.json");
    assert_eq!(summary["robots"], 4);
    assert_eq!(
        summary["alive_final"], 4,
        "robots taking part; the coordinator is not one"
    );
    assert_eq!(summary["coordinators"][0]["id"], "central");
    assert_eq!(summary["coordinators"][0]["index"], CENTRAL);
    let fault = &summary["faults"][0];
    assert_eq!(
        (&fault["robot"], &fault["restarted"], &fault["rejoin_tick"]),
        (&CENTRAL.into(), &true.into(), &22.into()),
        "{fault}"
    );
    let events = text(out, "events.csv");
    assert!(events.contains("20,4,central,fault:kill\n"), "{events}");
    assert!(events.contains("22,4,central,fault:up\n"), "{events}");
    let trajectory = text(out, "trajectory.csv");
    assert!(
        trajectory
            .lines()
            .skip(1)
            .all(|l| l.split(',').nth(1) != Some("4")),
        "a coordinator has no body, so no trajectory"
    );
    let rows = messages(out);
    for tick in 1..=50u64 {
        let reports: Vec<&Row> = rows
            .iter()
            .filter(|r| r.tick == tick && r.to == Some(CENTRAL))
            .collect();
        let down = (20..=21).contains(&tick);
        assert_eq!(reports.len(), 4, "tick {tick}");
        assert!(
            reports.iter().all(|r| if down {
                r.reason == "recipient_down"
            } else {
                r.outcome == "delivered"
            }),
            "tick {tick}: {reports:?}"
        );
        // It answers in the tick after a report reached it: not while it is down, nor in its first tick back.
        let answers = rows
            .iter()
            .filter(|r| r.tick == tick && r.from == CENTRAL && r.outcome == "delivered")
            .count();
        let answering = tick >= 2 && !(20..=22).contains(&tick);
        assert_eq!(answers, if answering { 4 } else { 0 }, "tick {tick}");
    }
    assert_same_records(
        runs[0].path(),
        runs[1].path(),
        &["messages.csv", "events.csv"],
    );
}

#[test]
fn swarm_ctl_freezes_thaws_and_kills_a_coordinator_like_a_robot() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let mut run = LiveSwarm::run(COORDINATOR, out.path(), &["--tick-deadline-ms", "100"]);
    // The schedule's kill at tick 20 and the restart come first.
    run.wait_for("robot 4 takes part again from tick 22");
    let list = swarm_ctl(out.path(), &["list"]);
    assert!(
        list.lines()
            .any(|l| l.starts_with("robot 4 central pid ") && l.contains(" running ")),
        "{list}"
    );
    assert_eq!(swarm_ctl(out.path(), &["freeze", "4"]), "robot 4 frozen\n");
    assert_eq!(swarm_ctl(out.path(), &["thaw", "4"]), "robot 4 thawed\n");
    assert_eq!(swarm_ctl(out.path(), &["kill", "4"]), "robot 4 killed\n");
    let back = run.wait_for("robot 4 takes part again from tick");
    let back: u64 = back
        .trim_end()
        .rsplit(' ')
        .next()
        .and_then(|t| t.parse().ok())
        .expect("a tick");
    // The run writes messages.csv tick by tick: wait until the coordinator has answered after its return.
    let answered_again = |rows: &[Row]| {
        rows.iter()
            .any(|r| r.from == CENTRAL && r.outcome == "delivered" && r.tick > back)
    };
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    while !answered_again(&messages(out.path())) {
        assert!(
            std::time::Instant::now() < deadline,
            "the coordinator never answered after its return at tick {back}"
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    run.interrupt();
    let summary: serde_json::Value =
        serde_json::from_str(&text(out.path(), "summary.json")).expect("summary.json");
    let faults: Vec<(String, u64, bool)> = summary["faults"]
        .as_array()
        .expect("faults")
        .iter()
        .map(|f| {
            (
                f["what"].as_str().unwrap_or_default().to_owned(),
                f["robot"].as_u64().unwrap_or(u64::MAX),
                f["restarted"].as_bool().unwrap_or(false),
            )
        })
        .collect();
    for what in ["ctl-freeze", "ctl-thaw", "ctl-kill"] {
        assert!(
            faults.iter().any(|(w, robot, _)| w == what && *robot == 4),
            "{what} of the coordinator in {faults:?}"
        );
    }
    assert!(
        faults
            .iter()
            .any(|(w, _, restarted)| w == "ctl-kill" && *restarted),
        "{faults:?}"
    );
    assert!(
        messages(out.path())
            .iter()
            .any(|r| r.to == Some(CENTRAL) && r.reason == "recipient_down" && r.tick > 22),
        "reports are dropped while the coordinator is away"
    );
}
