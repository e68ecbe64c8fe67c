//! Fault latencies of a real run: `swarm run` with N robot processes (default the 100-robot density experiment),
//! robots killed one after the other with `swarm ctl kill`, each restarted at once (`on-failure`, no backoff).
//!
//! Reports the median over the kills of the detection latency (the launcher's SIGKILL to the world marking the
//! robot dead, as the launcher measures it: `detection_ms` in `summary.json`) and the restart latency (SIGKILL to
//! the world taking the replacement back, i.e. the tick of its first command: `rejoin_ms`), plus the world's tick
//! time for scale. `cargo bench -p swarm-cli --bench faults`; `FAULTS_CONFIG`, `FAULTS_KILLS` (default 10)
//! and `FAULTS_DEADLINE_MS` (default 200) change the setup. The launcher builds the world and agent programs in
//! the bench's profile on its first run.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};

const SWARM: &str = env!("CARGO_BIN_EXE_swarm");
const DEFAULT_CONFIG: &str = "configs/obstacle_avoidance/density_N100.argos";
/// How long one kill may take to come back before the benchmark gives up.
const REJOIN_TIMEOUT: Duration = Duration::from_secs(30);
/// How often `swarm ctl list` is asked whether the killed robot is back.
const POLL: Duration = Duration::from_millis(20);

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn ctl(out: &Path, request: &[&str]) -> Result<String> {
    let output = Command::new(SWARM)
        .arg("ctl")
        .arg(out)
        .args(request)
        .output()
        .context("running swarm ctl")?;
    if !output.status.success() {
        bail!(
            "swarm ctl {request:?}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

fn main() -> Result<()> {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .context("the swarm program's crate sits in runtime/ of the workspace")?
        .to_path_buf();
    let config: PathBuf = workspace.join(env_or("FAULTS_CONFIG", DEFAULT_CONFIG.to_owned()));
    let kills: u32 = env_or("FAULTS_KILLS", 10);
    let deadline: u64 = env_or("FAULTS_DEADLINE_MS", 200);
    let out = tempfile::tempdir()?;
    let mut child = Command::new(SWARM)
        .arg("run")
        .arg(&config)
        .args([
            "--no-progress",
            "--ticks",
            "100000000",
            "--tick-deadline-ms",
        ])
        .arg(deadline.to_string())
        .args([
            "--fault",
            "restart policy=on-failure max_restarts=1000 backoff=0",
            "--out",
        ])
        .arg(out.path())
        .env("RUST_LOG", "info")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .context("starting swarm run")?;
    let mut stderr = BufReader::new(child.stderr.take().context("stderr is piped")?);
    let mut line = String::new();
    while stderr.read_line(&mut line)? > 0 && !line.contains("first tick completed") {
        line.clear();
    }
    // Keep draining the launcher's log so it never blocks on a full pipe.
    let drain = std::thread::spawn(move || {
        let mut rest = String::new();
        while stderr.read_line(&mut rest).unwrap_or(0) > 0 {
            rest.clear();
        }
    });
    let list = ctl(out.path(), &["list"])?;
    let robots = list.lines().filter(|l| l.starts_with("robot ")).count() as u32;
    for i in 0..kills {
        let robot = (i * 37 + 11) % robots.max(1);
        ctl(out.path(), &["kill", &robot.to_string()])?;
        let start = Instant::now();
        let back = "restarts 1";
        loop {
            let list = ctl(out.path(), &["list"])?;
            let line = list
                .lines()
                .find(|l| l.starts_with(&format!("robot {robot} ")))
                .unwrap_or_default();
            if line.contains(" running ") && line.ends_with(back) {
                break;
            }
            if start.elapsed() > REJOIN_TIMEOUT {
                bail!("robot {robot} did not come back: {line}");
            }
            std::thread::sleep(POLL);
        }
    }
    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(child.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    )?;
    let status = child.wait()?;
    let _ = drain.join();
    if !status.success() {
        bail!("swarm run ended with {status}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("summary.json"))?)?;
    let faults = summary["faults"].as_array().context("faults listed")?;
    let field = |name: &str| -> Vec<f64> {
        faults
            .iter()
            .filter(|f| f["what"] == "ctl-kill")
            .filter_map(|f| f[name].as_f64())
            .collect()
    };
    let mut detection = field("detection_ms");
    let mut rejoin = field("rejoin_ms");
    println!(
        "faults N={robots} kills={} ({}): detection median {:.1} ms (min {:.1}, max {:.1}), restart median {:.1} ms \
         (min {:.1}, max {:.1}); tick p50 {} us, p99 {} us",
        detection.len(),
        config.display(),
        median(&mut detection),
        detection.first().copied().unwrap_or(f64::NAN),
        detection.last().copied().unwrap_or(f64::NAN),
        median(&mut rejoin),
        rejoin.first().copied().unwrap_or(f64::NAN),
        rejoin.last().copied().unwrap_or(f64::NAN),
        summary["tick_micros_p50"],
        summary["tick_micros_p99"],
    );
    Ok(())
}
