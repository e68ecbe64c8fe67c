//! Multi-host throughput: 2 hosts x 50 robots against 1 host x 100 robots (and the local run of 100 robots), and
//! 2 hosts x 50 with host authentication on (the default) against off (`--insecure-hosts`), in robot-steps per
//! second, as ratios measured in one run of this benchmark.
//!
//! Every configuration runs the obstacle-avoidance experiment with real processes: `swarm run` (world), `swarm
//! host` daemons on loopback and one agent process per robot, so all of them share this machine's cores. Each is
//! measured `ROUNDS` times; the median of the world's `robot_steps_per_second` (from `summary.json`, ticking time
//! only) is reported.
//!
//! `cargo bench -p swarm-cli --bench hosts` (optional argument: ticks per run, default 400).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

const CONFIG: &str = "configs/obstacle_avoidance/obstacle_avoidance.argos";
const ROUNDS: usize = 3;
const ROBOTS: u32 = 100;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .map(Path::to_path_buf)
        .unwrap_or_default()
}

fn swarm() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_swarm"))
}

fn free_endpoint() -> String {
    let port = std::net::TcpListener::bind(("127.0.0.1", 0))
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .unwrap_or(7447);
    format!("tcp/127.0.0.1:{port}")
}

/// A host daemon killed when dropped.
struct Daemon(Child);

impl Drop for Daemon {
    fn drop(&mut self) {
        if let Ok(pid) = i32::try_from(self.0.id()) {
            let _ = nix::sys::signal::kill(
                nix::unistd::Pid::from_raw(pid),
                nix::sys::signal::Signal::SIGTERM,
            );
        }
        let _ = self.0.wait();
    }
}

/// Host authentication of a run.
#[derive(Clone, Copy)]
enum Auth {
    /// Keys from this folder (the default of `swarm run --hosts`).
    On,
    /// `--insecure-hosts` / `swarm host --insecure`.
    Off,
}

/// One run; returns the world's robot-steps per second.
fn run(ticks: u64, hosts: u32, auth: Auth, keys: &Path) -> f64 {
    let out =
        std::env::temp_dir().join(format!("swarm-bench-hosts-{}-{hosts}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let endpoint = free_endpoint();
    let names: Vec<String> = (0..hosts).map(|i| format!("bench{i}")).collect();
    let (run_auth, host_auth): (Vec<String>, Vec<Vec<String>>) = match auth {
        Auth::On => {
            if !names.is_empty() {
                let status = Command::new(swarm())
                    .args(["host-key", "--dir"])
                    .arg(keys)
                    .args(&names)
                    .stdout(Stdio::null())
                    .status();
                assert!(status.is_ok_and(|s| s.success()), "swarm host-key failed");
            }
            (
                vec!["--keys".into(), keys.display().to_string()],
                names
                    .iter()
                    .map(|n| {
                        vec![
                            "--key".into(),
                            keys.join(format!("{n}.key")).display().to_string(),
                        ]
                    })
                    .collect(),
            )
        }
        Auth::Off => (
            vec!["--insecure-hosts".into()],
            names.iter().map(|_| vec!["--insecure".into()]).collect(),
        ),
    };
    let _daemons: Vec<Daemon> = names
        .iter()
        .zip(&host_auth)
        .map(|(name, auth)| {
            let child = Command::new(swarm())
                .args(["host", "--connect", &endpoint, "--name", name])
                .args(auth)
                .env("RUST_LOG", "warn")
                .current_dir(workspace())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("swarm host starts");
            Daemon(child)
        })
        .collect();
    let mut command = Command::new(swarm());
    command
        .args([
            "run",
            CONFIG,
            "--robots",
            &ROBOTS.to_string(),
            "--seed",
            "1",
            "--no-progress",
        ])
        .args(["--ticks", &ticks.to_string(), "--out"])
        .arg(&out)
        .env("RUST_LOG", "warn")
        .current_dir(workspace())
        .stdout(Stdio::null());
    if hosts > 0 {
        command.args(["--hosts", &names.join(","), "--listen", &endpoint]);
        command.args(&run_auth);
    }
    let status = command.status().expect("swarm run starts");
    assert!(status.success(), "swarm run with {hosts} hosts failed");
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    let summary: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    let _ = std::fs::remove_dir_all(&out);
    summary["robot_steps_per_second"].as_f64().unwrap_or(0.0)
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn main() {
    let ticks: u64 = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(400);
    let keys = std::env::temp_dir().join(format!("swarm-bench-keys-{}", std::process::id()));
    // Let the launcher build the world and agent programs once before measuring.
    run(5, 0, Auth::On, &keys);
    let mut local = Vec::new();
    let mut one = Vec::new();
    let mut two = Vec::new();
    let mut two_insecure = Vec::new();
    for _ in 0..ROUNDS {
        local.push(run(ticks, 0, Auth::On, &keys));
        one.push(run(ticks, 1, Auth::On, &keys));
        two.push(run(ticks, 2, Auth::On, &keys));
        two_insecure.push(run(ticks, 2, Auth::Off, &keys));
    }
    let _ = std::fs::remove_dir_all(&keys);
    let (local, one, two, two_insecure) = (
        median(local),
        median(one),
        median(two),
        median(two_insecure),
    );
    println!("hosts: {ROBOTS} robots, {ticks} ticks, median of {ROUNDS} rounds (robot-steps/s)");
    println!("  local, no zenoh      {local:>10.0}");
    println!("  1 host  x {ROBOTS:>3}       {one:>10.0}");
    println!("  2 hosts x {:>3}       {two:>10.0}", ROBOTS / 2);
    println!(
        "  2 hosts x {:>3}, insecure {two_insecure:>6.0}",
        ROBOTS / 2
    );
    println!(
        "  authentication on / off {:>7.0}%",
        100.0 * two / two_insecure
    );
    println!(
        "  ratio 2x{} / 1x{ROBOTS}    {:>9.0}%",
        ROBOTS / 2,
        100.0 * two / one
    );
    println!(
        "  ratio 2x{} / local    {:>9.0}%",
        ROBOTS / 2,
        100.0 * two / local
    );
}
