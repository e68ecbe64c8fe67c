//! `swarm bench`: the whole system and the bare transport, measured the same way every time.
//!
//! Whole system: ARGoS' obstacle-avoidance density (`density_N<N>.argos`: 50 e-pucks per 16 m², N/10 boxes and
//! N/10 cylinders) with one agent process per robot, through the same launcher as `swarm run`, repeated; per N the
//! medians of the whole run's wall time (what a user times: start-up and shut-down included), the time to the first
//! tick and after the last one, robot-steps per second and p50/p99 tick time while ticking (the world's own
//! figures from summary.json), each agent's peak RSS, and the CPU time the agents use per robot-step and the world
//! per tick.
//! Bare: the lockstep round trip with no world work and no player ([`bare`]), next to the same-hour floor of a
//! minimal futex-broadcast lockstep ([`floor`]). Real time: one paced run (e.g. 2,000 agents at 10 ticks/s) and
//! whether every tick kept its slot.
//! ARGoS side by side (`--argos <prefix>`, [`argos`]): per N the same experiment run by ARGoS headless with its own
//! e-puck obstacle-avoidance example controller, alternating with ours, both timed as whole runs, start to exit.

pub mod argos;
pub mod bare;
pub mod floor;
pub mod rss;
pub mod stats;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use serde::Serialize;

use crate::launcher::{self, LaunchError, RunOptions};
use argos::{ArgosError, ArgosFigures, ArgosInstall, Engine};
use bare::{BareError, BareOptions};
use rss::RssSampler;
use stats::median;
use swarm_contract::process::binaries::{
    AGENT_PROGRAM, Binaries, BinariesError, LOCKSTEP_AGENT_PROGRAM,
};
use swarm_contract::run_dir::SUMMARY_FILE;

/// What `swarm bench` measures.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Folder holding `density_N<N>.argos` for every size.
    pub configs_dir: PathBuf,
    /// Robot counts.
    pub sizes: Vec<u32>,
    /// Ticks per whole-system run (`None`: 200,000 / N clamped to 200..2,000).
    pub ticks: Option<u64>,
    /// Runs per size; figures are medians over them.
    pub repeat: usize,
    /// Folder for the run directories and `bench.json`.
    pub out: PathBuf,
    /// Measure the whole system.
    pub system: bool,
    /// Measure the bare lockstep.
    pub bare: bool,
    /// Robot count of the real-time check (`None`: skip it).
    pub real_time_robots: Option<u32>,
    /// Ticks of the real-time check.
    pub real_time_ticks: u64,
    /// Also run ARGoS on the same experiment, alternating with ours (`None`: ours only).
    pub argos: Option<ArgosInstall>,
}

/// The seed of every whole-system run, ours and ARGoS'.
pub const SEED: u32 = 1;

/// Whole-system figures for one robot count (medians over the runs).
#[derive(Debug, Clone, Serialize)]
pub struct SystemFigures {
    /// Robots (= agent processes).
    pub robots: u32,
    /// Runs measured.
    pub runs: usize,
    /// Ticks per run.
    pub ticks: u64,
    /// Robot-steps per second while ticking (the world's figure).
    pub robot_steps_per_second: f64,
    /// Every run's robot-steps per second, in run order.
    pub robot_steps_per_second_runs: Vec<f64>,
    /// Median tick time in microseconds.
    pub tick_p50_us: f64,
    /// 99th-percentile tick time in microseconds.
    pub tick_p99_us: f64,
    /// Seconds from starting the world to the end of the first tick.
    pub first_tick_seconds: f64,
    /// Median over the runs of the whole run's wall time, start-up and shut-down included: what a user times.
    pub wall_seconds: f64,
    /// Median over the runs of the seconds from the end of the last tick to the end of the run (records
    /// flushed, every process gone).
    pub after_last_tick_seconds: f64,
    /// Median over agents of their peak RSS, in KiB.
    pub agent_peak_rss_kib_median: f64,
    /// Largest agent peak RSS, in KiB.
    pub agent_peak_rss_kib_max: f64,
    /// Median over the runs of the agents' CPU time per robot-step while ticking, in microseconds (from the
    /// scheduler's accounts; see `swarm-world`'s summary).
    pub cpu_agents_us_per_robot_step: f64,
    /// Median over the runs of the world process's CPU time per tick (every thread), in microseconds.
    pub cpu_world_us_per_tick: f64,
    /// ARGoS on the same experiment, run in alternation with ours (with `--argos`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub argos: Option<ArgosFigures>,
}

/// Bare lockstep figures for one robot count.
#[derive(Debug, Clone, Serialize)]
pub struct BareFigures {
    /// Agent processes.
    pub robots: u32,
    /// Robot-steps per second (median over windows).
    pub robot_steps_per_second: f64,
    /// Median tick time in microseconds.
    pub tick_p50_us: f64,
    /// 99th-percentile tick time in microseconds.
    pub tick_p99_us: f64,
    /// Seconds from spawning the agents to the end of the first tick.
    pub first_tick_seconds: f64,
    /// CPU time of the world and every agent per robot-step over the windows, in microseconds.
    pub cpu_us_per_robot_step: f64,
    /// Robot-steps per second of the minimal futex-broadcast lockstep, measured right after ([`floor`]).
    pub floor_robot_steps_per_second: f64,
    /// The floor's CPU time per robot-step, in microseconds.
    pub floor_cpu_us_per_robot_step: f64,
}

/// The real-time check.
#[derive(Debug, Clone, Serialize)]
pub struct RealTimeFigures {
    /// Robots.
    pub robots: u32,
    /// Ticks run.
    pub ticks: u64,
    /// What the world recorded: tick period, late ticks, largest lag, whether it kept up.
    pub pacing: serde_json::Value,
    /// Seconds from starting the world to the end of the first tick.
    pub first_tick_seconds: f64,
}

/// Everything one `swarm bench` measured.
#[derive(Debug, Clone, Default, Serialize)]
pub struct BenchReport {
    /// Whole-system figures by size.
    pub system: Vec<SystemFigures>,
    /// Bare lockstep figures by size.
    pub bare: Vec<BareFigures>,
    /// The real-time check, if run.
    pub real_time: Option<RealTimeFigures>,
}

/// Why a benchmark failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A run failed.
    #[error("benchmark run of {config}")]
    Run {
        /// The configuration.
        config: PathBuf,
        /// Why.
        #[source]
        source: Box<LaunchError>,
    },
    /// The bare lockstep failed.
    #[error("bare lockstep with {robots} agents")]
    Bare {
        /// Agents.
        robots: u32,
        /// Why.
        #[source]
        source: BareError,
    },
    /// The floor could not be measured.
    #[error("lockstep floor with {robots} processes")]
    Floor {
        /// Processes.
        robots: u32,
        /// Why.
        #[source]
        source: floor::FloorError,
    },
    /// A program is missing.
    #[error(transparent)]
    Binaries(#[from] BinariesError),
    /// A run's summary.json is missing or lacks a figure.
    #[error("{path}: {what}")]
    Summary {
        /// The summary file.
        path: PathBuf,
        /// What is wrong.
        what: String,
    },
    /// Writing the report failed.
    #[error("writing {path}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// ARGoS could not be run beside ours.
    #[error("ARGoS side by side with {robots} robots")]
    Argos {
        /// Robots.
        robots: u32,
        /// Why.
        #[source]
        source: ArgosError,
    },
    /// Ctrl-C.
    #[error("interrupted")]
    Interrupted,
}

/// Runs the benchmarks; `on_result` sees each figure as soon as it is measured. Writes `bench.json` into
/// `options.out`.
pub fn run(
    options: &BenchOptions,
    stop: &Arc<AtomicBool>,
    mut on_result: impl FnMut(&BenchReport),
) -> Result<BenchReport, BenchError> {
    let mut report = BenchReport::default();
    if options.system {
        for &robots in &options.sizes {
            let figures = system(options, robots, stop)?;
            report.system.push(figures);
            on_result(&report);
        }
    }
    if options.bare {
        let agent = Binaries::locate_program(LOCKSTEP_AGENT_PROGRAM)?;
        for &robots in &options.sizes {
            check_stop(stop)?;
            let ticks = (200_000 / robots as usize).clamp(200, 5000);
            let bare_options = BareOptions {
                robots,
                ticks,
                windows: 5,
                world_spin: None,
                agent_spin: None,
            };
            let measured = bare::run(&agent, &bare_options)
                .map_err(|source| BenchError::Bare { robots, source })?;
            check_stop(stop)?;
            let floor = floor::run(robots, ticks, 5)
                .map_err(|source| BenchError::Floor { robots, source })?;
            report.bare.push(BareFigures {
                robots,
                robot_steps_per_second: measured.robot_steps_per_second,
                tick_p50_us: measured.tick_p50.as_secs_f64() * 1e6,
                tick_p99_us: measured.tick_p99.as_secs_f64() * 1e6,
                first_tick_seconds: measured.first_tick.as_secs_f64(),
                cpu_us_per_robot_step: measured.cpu_per_robot_step.as_secs_f64() * 1e6,
                floor_robot_steps_per_second: floor.robot_steps_per_second,
                floor_cpu_us_per_robot_step: floor.cpu_per_robot_step.as_secs_f64() * 1e6,
            });
            on_result(&report);
        }
    }
    if let Some(robots) = options.real_time_robots {
        report.real_time = Some(real_time(options, robots, stop)?);
        on_result(&report);
    }
    let path = options.out.join("bench.json");
    let json = serde_json::to_string_pretty(&report).unwrap_or_default();
    swarm_contract::run_dir::write_atomically(&path, json.as_bytes())
        .map_err(|source| BenchError::Write { path, source })?;
    Ok(report)
}

fn check_stop(stop: &AtomicBool) -> Result<(), BenchError> {
    if stop.load(Ordering::Relaxed) {
        Err(BenchError::Interrupted)
    } else {
        Ok(())
    }
}

fn density_config(options: &BenchOptions, robots: u32) -> PathBuf {
    options.configs_dir.join(format!("density_N{robots}.argos"))
}

/// What one launcher run gave.
struct Measured {
    /// Its summary.json.
    summary: serde_json::Value,
    /// The agents' peak RSS in KiB.
    peaks: Vec<f64>,
    /// Wall time of the launcher's call, configuration read to the last process gone, in seconds.
    elapsed_seconds: f64,
}

/// One launcher run without progress bar.
fn measured_run(
    config: &Path,
    out: PathBuf,
    ticks: u64,
    real_time: bool,
    stop: &Arc<AtomicBool>,
) -> Result<Measured, BenchError> {
    check_stop(stop)?;
    let _ = std::fs::remove_dir_all(&out);
    let run_options = RunOptions {
        config: config.to_path_buf(),
        ticks: Some(ticks),
        seed: Some(u64::from(SEED)),
        out: Some(out),
        overwrite: true,
        progress: false,
        real_time,
        ..RunOptions::default()
    };
    let sampler = RssSampler::start(AGENT_PROGRAM);
    let started = Instant::now();
    let result = launcher::run(&run_options, Arc::clone(stop));
    let elapsed_seconds = started.elapsed().as_secs_f64();
    let peaks = sampler.finish();
    let report = result.map_err(|source| BenchError::Run {
        config: config.to_path_buf(),
        source: Box::new(source),
    })?;
    if report.interrupted {
        return Err(BenchError::Interrupted);
    }
    let path = report.out_dir.join(SUMMARY_FILE);
    let summary = std::fs::read_to_string(&path)
        .ok()
        .and_then(|text| serde_json::from_str(&text).ok())
        .ok_or_else(|| BenchError::Summary {
            path: path.clone(),
            what: "missing or not JSON".into(),
        })?;
    Ok(Measured {
        summary,
        peaks: peaks.into_values().map(|kib| kib as f64).collect(),
        elapsed_seconds,
    })
}

fn figure(summary: &serde_json::Value, key: &str, path: &Path) -> Result<f64, BenchError> {
    summary
        .get(key)
        .and_then(serde_json::Value::as_f64)
        .ok_or_else(|| BenchError::Summary {
            path: path.to_path_buf(),
            what: format!("no number `{key}`"),
        })
}

/// Our runs' figures for one size, in run order.
#[derive(Debug, Default)]
struct Samples {
    rates: Vec<f64>,
    p50s: Vec<f64>,
    p99s: Vec<f64>,
    first_ticks: Vec<f64>,
    walls: Vec<f64>,
    afters: Vec<f64>,
    rss: Vec<f64>,
    agents_cpu: Vec<f64>,
    world_cpu: Vec<f64>,
    /// The launcher call's wall time (the figure compared with ARGoS').
    elapsed: Vec<f64>,
}

impl Samples {
    /// Adds one run; `path` names its summary.json in messages.
    fn push(&mut self, measured: Measured, path: &Path) -> Result<(), BenchError> {
        let summary = &measured.summary;
        self.rates
            .push(figure(summary, "robot_steps_per_second", path)?);
        self.p50s.push(figure(summary, "tick_micros_p50", path)?);
        self.p99s.push(figure(summary, "tick_micros_p99", path)?);
        let first_tick = figure(summary, "time_to_first_tick_seconds", path)?;
        let wall = figure(summary, "wall_seconds", path)?;
        let ticking = figure(summary, "ticking_seconds", path)?;
        self.first_ticks.push(first_tick);
        self.walls.push(wall);
        self.afters.push((wall - first_tick - ticking).max(0.0));
        self.agents_cpu
            .push(figure(summary, "cpu_agents_us_per_robot_step", path)?);
        self.world_cpu
            .push(figure(summary, "cpu_world_us_per_tick", path)?);
        self.rss.extend(measured.peaks);
        self.elapsed.push(measured.elapsed_seconds);
        Ok(())
    }

    /// The medians.
    fn figures(self, robots: u32, ticks: u64) -> SystemFigures {
        SystemFigures {
            robots,
            runs: self.rates.len(),
            ticks,
            robot_steps_per_second: median(&self.rates).unwrap_or(0.0),
            tick_p50_us: median(&self.p50s).unwrap_or(0.0),
            tick_p99_us: median(&self.p99s).unwrap_or(0.0),
            first_tick_seconds: median(&self.first_ticks).unwrap_or(0.0),
            wall_seconds: median(&self.walls).unwrap_or(0.0),
            after_last_tick_seconds: median(&self.afters).unwrap_or(0.0),
            agent_peak_rss_kib_median: median(&self.rss).unwrap_or(0.0),
            agent_peak_rss_kib_max: self.rss.iter().copied().fold(0.0, f64::max),
            cpu_agents_us_per_robot_step: median(&self.agents_cpu).unwrap_or(0.0),
            cpu_world_us_per_tick: median(&self.world_cpu).unwrap_or(0.0),
            robot_steps_per_second_runs: self.rates,
            argos: None,
        }
    }
}

fn system(
    options: &BenchOptions,
    robots: u32,
    stop: &Arc<AtomicBool>,
) -> Result<SystemFigures, BenchError> {
    let config = density_config(options, robots);
    let ticks = options
        .ticks
        .unwrap_or_else(|| (200_000 / u64::from(robots)).clamp(200, 2000));
    let argos_error = |source| BenchError::Argos { robots, source };
    let argos_config = options.out.join(format!("argos_N{robots}.argos"));
    if options.argos.is_some() {
        argos::write_config(&config, &argos_config, ticks, SEED).map_err(argos_error)?;
    }
    let mut samples = Samples::default();
    let mut argos_walls = Vec::new();
    for turn in argos::schedule(options.repeat, options.argos.is_some()) {
        check_stop(stop)?;
        match (turn.engine, &options.argos) {
            (Engine::Ours, _) => {
                let out = options
                    .out
                    .join(format!("system_N{robots}_{}", turn.repetition));
                let summary_path = out.join(SUMMARY_FILE);
                let measured = measured_run(&config, out, ticks, false, stop)?;
                samples.push(measured, &summary_path)?;
            }
            (Engine::Argos, Some(install)) => {
                let log = options
                    .out
                    .join(format!("argos_N{robots}_{}.log", turn.repetition));
                let result = install.run(&argos_config, &log);
                // Ctrl-C reaches ARGoS too: its failure is then the interruption.
                check_stop(stop)?;
                argos_walls.push(result.map_err(argos_error)?.as_secs_f64());
            }
            (Engine::Argos, None) => {}
        }
    }
    let ours_elapsed = samples.elapsed.clone();
    let mut figures = samples.figures(robots, ticks);
    if options.argos.is_some() {
        figures.argos = Some(ArgosFigures::new(argos_config, ours_elapsed, argos_walls));
    }
    Ok(figures)
}

fn real_time(
    options: &BenchOptions,
    robots: u32,
    stop: &Arc<AtomicBool>,
) -> Result<RealTimeFigures, BenchError> {
    let config = density_config(options, robots);
    let out = options.out.join(format!("real_time_N{robots}"));
    let summary_path = out.join(SUMMARY_FILE);
    let summary = measured_run(&config, out, options.real_time_ticks, true, stop)?.summary;
    Ok(RealTimeFigures {
        robots,
        ticks: figure(&summary, "ticks", &summary_path)? as u64,
        pacing: summary
            .get("real_time")
            .cloned()
            .unwrap_or(serde_json::Value::Null),
        first_tick_seconds: figure(&summary, "time_to_first_tick_seconds", &summary_path)?,
    })
}

/// The report as Markdown tables, for the terminal and BENCHMARKS.md.
pub fn markdown(report: &BenchReport) -> String {
    let mut text = String::new();
    if !report.system.is_empty() {
        text.push_str(
            "| N | runs x ticks | whole run | first tick | after the last tick | robot-steps/s (median) | tick p50 | tick p99 \
             | agent peak RSS (median / max) | agent CPU per robot-step | world CPU per tick |\n\
             |---|---|---|---|---|---|---|---|---|---|---|\n",
        );
        for f in &report.system {
            text.push_str(&format!(
                "| {} | {} x {} | {:.2} s | {:.2} s | {:.2} s | {:.0} | {:.0} µs | {:.0} µs | {:.1} / {:.1} MiB | {:.1} µs \
                 | {:.0} µs |\n",
                f.robots,
                f.runs,
                f.ticks,
                f.wall_seconds,
                f.first_tick_seconds,
                f.after_last_tick_seconds,
                f.robot_steps_per_second,
                f.tick_p50_us,
                f.tick_p99_us,
                f.agent_peak_rss_kib_median / 1024.0,
                f.agent_peak_rss_kib_max / 1024.0,
                f.cpu_agents_us_per_robot_step,
                f.cpu_world_us_per_tick,
            ));
        }
    }
    let compared: Vec<(&SystemFigures, &ArgosFigures)> = report
        .system
        .iter()
        .filter_map(|f| f.argos.as_ref().map(|a| (f, a)))
        .collect();
    if !compared.is_empty() {
        text.push_str(
            "\n| N (ours vs ARGoS, alternated) | runs x ticks | ours, start to exit | ARGoS, start to exit | ARGoS / ours |\n\
             |---|---|---|---|---|\n",
        );
        for (f, a) in compared {
            text.push_str(&format!(
                "| {} | {} x {} | {:.2} s | {:.2} s | {:.2} ({}) |\n",
                f.robots,
                a.runs,
                f.ticks,
                a.ours_wall_seconds,
                a.wall_seconds,
                a.argos_over_ours,
                a.verdict(),
            ));
        }
    }
    if !report.bare.is_empty() {
        text.push_str(
            "\n| N (bare lockstep) | robot-steps/s | tick p50 | tick p99 | first tick | CPU per robot-step \
             | floor (same hour) | floor CPU per robot-step | bare / floor |\n|---|---|---|---|---|---|---|---|---|\n",
        );
        for f in &report.bare {
            text.push_str(&format!(
                "| {} | {:.0} | {:.0} µs | {:.0} µs | {:.2} s | {:.1} µs | {:.0} | {:.1} µs | {:.2} |\n",
                f.robots,
                f.robot_steps_per_second,
                f.tick_p50_us,
                f.tick_p99_us,
                f.first_tick_seconds,
                f.cpu_us_per_robot_step,
                f.floor_robot_steps_per_second,
                f.floor_cpu_us_per_robot_step,
                f.robot_steps_per_second / f.floor_robot_steps_per_second.max(1.0),
            ));
        }
    }
    if let Some(rt) = &report.real_time {
        text.push_str(&format!(
            "\nreal time: {} robots, {} ticks, first tick after {:.1} s, pacing {}\n",
            rt.robots, rt.ticks, rt.first_tick_seconds, rt.pacing
        ));
    }
    text
}

/// Default ticks of the real-time check: 10 s of simulated time at 10 ticks/s.
pub const DEFAULT_REAL_TIME_TICKS: u64 = 100;
