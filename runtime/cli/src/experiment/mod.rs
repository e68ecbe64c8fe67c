//! `swarm experiment <grid.toml>`: a grid of configurations x seeds, run in parallel through the launcher,
//! resumable, summarised as the thesis does (each configuration by its median run).
//!
//! Order: read the [`grid`] -> derive and validate every configuration ([`plan`]) before any run starts -> open
//! the batch folder ([`store`]) and skip finished runs -> run the others, `jobs` at a time, each into a
//! `.partial` directory renamed when complete -> read every finished run's metrics and select medians
//! ([`results`]) -> write `results.csv`, the figures ([`plots`]) and `report.md` ([`report`]).
//!
//! It never simulates anything itself: each run is [`crate::launcher::run`], i.e. one world process and one agent
//! process per robot, exactly as `swarm run`. It never counts a run that did not complete. One process at a time
//! writes into a batch folder (it holds the folder's lock).
//!
//! **Shards.** `--shard i/n` runs only the i-th of n shares of the grid's runs (run k of the configurations x
//! seeds order belongs to shard k mod n + 1) into its own folder, so n machines or jobs can share a grid.
//! `--merge <shard folder>...` runs nothing: it reads the finished runs of the shard folders (each checked against
//! the grid like any finished run) and writes one `results.csv`, the figures and `report.md` for the whole grid.

pub mod address;
pub mod document;
pub mod grid;
pub mod plan;
pub mod plots;
pub mod report;
pub mod results;
pub mod store;

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};

use indicatif::{ProgressBar, ProgressStyle};

use crate::launcher::{self, RunOptions};
use grid::Grid;
use plan::Configuration;
use results::RunResult;
use store::{BatchDir, RunState};
use swarm_contract::config::ConfigErrors;

/// Memory a run's world process is assumed to need when `--jobs` is left to the machine. Measured: the world of a
/// 10-robot obstacle-avoidance run peaks at ~155 MB resident (debug build, shared memory included).
const MEMORY_PER_WORLD: u64 = 192 << 20;
/// Memory an agent process is assumed to need: measured ~10 MB resident; the figure leaves room.
const MEMORY_PER_AGENT: u64 = 16 << 20;

/// What `swarm experiment` was asked to do.
#[derive(Debug, Clone, Default)]
pub struct ExperimentOptions {
    /// The grid file.
    pub grid: PathBuf,
    /// Batch folder, overriding the grid's `out`.
    pub out: Option<PathBuf>,
    /// Runs at once (default: [`default_jobs`]).
    pub jobs: Option<usize>,
    /// Show a progress bar.
    pub progress: bool,
    /// Run only this share of the grid: `(i, n)`, the i-th of n (1-based).
    pub shard: Option<Shard>,
    /// Run nothing; summarise the finished runs of these batch folders (shards of the same grid).
    pub merge: Vec<PathBuf>,
}

/// One of n shares of a grid's runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which share, from 1.
    pub index: usize,
    /// How many shares.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;

    /// Parses `i/n` with 1 <= i <= n.
    fn from_str(text: &str) -> Result<Shard, String> {
        let parsed = text
            .split_once('/')
            .and_then(|(i, n)| Some((i.trim().parse().ok()?, n.trim().parse().ok()?)));
        match parsed {
            Some((index, count)) if index >= 1 && index <= count => Ok(Shard { index, count }),
            _ => Err(format!(
                "'{text}' is not a shard i/n with 1 <= i <= n (e.g. 2/4)"
            )),
        }
    }
}

impl Shard {
    /// Whether run number `k` (in configurations x seeds order, from 0) belongs to this shard.
    fn owns(self, k: usize) -> bool {
        k % self.count == self.index - 1
    }

    /// The folder name of this shard inside the grid's batch folder.
    fn folder(self) -> String {
        format!("shard-{}-of-{}", self.index, self.count)
    }
}

/// What a batch did.
#[derive(Debug, Clone, PartialEq)]
pub struct BatchReport {
    /// The batch folder.
    pub dir: PathBuf,
    /// Configurations in the grid.
    pub configurations: usize,
    /// Runs the grid asks for.
    pub runs_planned: usize,
    /// Runs found finished from earlier invocations (not recomputed).
    pub runs_reused: usize,
    /// Runs completed by this invocation.
    pub runs_completed: usize,
    /// Runs that failed, with the reason.
    pub failures: Vec<String>,
    /// Whether the batch was stopped early (Ctrl-C); rerunning continues it.
    pub interrupted: bool,
    /// Runs at once.
    pub jobs: usize,
    /// Why figures are missing, if they are.
    pub plots_missing: Option<String>,
}

/// Why a batch could not run.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// The grid, or a configuration derived from it, is invalid.
    #[error("{0}")]
    Grid(#[from] ConfigErrors),
    /// A file operation on the batch folder failed.
    #[error("{what}: {source}")]
    Io {
        /// What the runner was doing.
        what: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A finished run's summary is unreadable.
    #[error(transparent)]
    Summary(#[from] results::SummaryError),
    /// Another process writes into the batch folder.
    #[error(transparent)]
    Locked(#[from] swarm_contract::run_dir::RunDirError),
    /// A folder to merge is not a batch folder.
    #[error("{0} is not a batch folder of `swarm experiment` (it has no runs/ folder)")]
    NotABatch(PathBuf),
}

fn io(what: impl Into<String>) -> impl FnOnce(std::io::Error) -> ExperimentError {
    let what = what.into();
    move |source| ExperimentError::Io { what, source }
}

/// Runs at once when `--jobs` is not given: one per core (a lockstep run alternates a serial world phase with a
/// parallel agent phase, so it rarely keeps every core busy alone, and a second run fills the gaps), but no more
/// than available memory holds with one world and `max_robots` agents per run.
pub fn default_jobs(max_robots: u32) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let per_run = MEMORY_PER_WORLD + u64::from(max_robots) * MEMORY_PER_AGENT;
    let by_memory = available_memory().map_or(cores, |bytes| (bytes / per_run.max(1)) as usize);
    cores.min(by_memory).max(1)
}

/// `MemAvailable` from `/proc/meminfo`, in bytes.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// One run to do.
#[derive(Debug, Clone, Copy)]
struct Task {
    configuration: usize,
    seed: u64,
}

/// What a worker reports about a task.
enum Outcome {
    Completed,
    Interrupted,
    Failed(String),
}

/// Runs (or continues) a batch; `stop` set (e.g. by Ctrl-C) stops the runs in progress cleanly, discards them,
/// and still writes the results of every finished run.
pub fn run(
    options: &ExperimentOptions,
    stop: Arc<AtomicBool>,
) -> Result<BatchReport, ExperimentError> {
    let grid = Grid::load(&options.grid)?;
    let configurations = plan::configurations(&grid)?;
    let root = match (&options.out, options.shard) {
        (Some(out), _) => out.clone(),
        (None, Some(shard)) => grid.out.join(shard.folder()),
        (None, None) => grid.out.clone(),
    };
    // Held until the batch is summarised.
    let _lock = swarm_contract::run_dir::lock_folder(&root)?;
    if !options.merge.is_empty() {
        return merge(options, &grid, &configurations, root);
    }
    let batch = BatchDir::create(&root).map_err(io(format!("creating {}", root.display())))?;
    std::fs::write(root.join("grid.toml"), &grid.text).map_err(io("copying the grid"))?;
    for configuration in &configurations {
        batch.write_config(configuration).map_err(io(format!(
            "writing the configuration {}",
            configuration.id
        )))?;
    }

    let mut tasks = VecDeque::new();
    let mut reused = 0;
    let mut runs_planned = 0;
    let mut k = 0;
    for (index, configuration) in configurations.iter().enumerate() {
        for &seed in &grid.seeds {
            k += 1;
            if options.shard.is_some_and(|shard| !shard.owns(k - 1)) {
                continue;
            }
            runs_planned += 1;
            match batch.state(configuration, seed, grid.ticks) {
                RunState::Finished => reused += 1,
                state => {
                    if let RunState::Stale(reason) = state {
                        tracing::warn!(configuration = %configuration.id, seed, "running again: {reason}");
                    }
                    batch
                        .clear(&configuration.id, seed)
                        .map_err(io(format!("clearing {}/seed-{seed}", configuration.id)))?;
                    tasks.push_back(Task {
                        configuration: index,
                        seed,
                    });
                }
            }
        }
    }
    let max_robots = configurations.iter().map(|c| c.robots).max().unwrap_or(0);
    let jobs = options
        .jobs
        .unwrap_or_else(|| default_jobs(max_robots))
        .max(1);
    tracing::info!(
        configurations = configurations.len(),
        runs = runs_planned,
        reused,
        to_run = tasks.len(),
        jobs,
        batch = %root.display(),
        "experiment"
    );

    let progress = progress_bar(options.progress, runs_planned as u64, reused as u64);
    let (completed, failures) = execute(
        &grid,
        &batch,
        &configurations,
        tasks,
        jobs,
        &stop,
        &progress,
    );
    progress.finish_and_clear();
    let interrupted = stop.load(Ordering::Relaxed);

    let (plots_missing, _) = summarise(
        &grid,
        std::slice::from_ref(&batch),
        &root,
        &configurations,
        runs_planned,
    )?;
    Ok(BatchReport {
        dir: root,
        configurations: configurations.len(),
        runs_planned,
        runs_reused: reused,
        runs_completed: completed,
        failures,
        interrupted,
        jobs,
        plots_missing,
    })
}

fn progress_bar(visible: bool, total: u64, done: u64) -> ProgressBar {
    if !visible {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total);
    if let Ok(style) =
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] run {pos}/{len} eta {eta} {msg}")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_position(done);
    bar
}

/// Runs `tasks` on `jobs` threads; prints `finished <configuration>/seed-<s>` on standard output as each run
/// completes. Returns the number completed and the failures.
fn execute(
    grid: &Grid,
    batch: &BatchDir,
    configurations: &[Configuration],
    tasks: VecDeque<Task>,
    jobs: usize,
    stop: &Arc<AtomicBool>,
    progress: &ProgressBar,
) -> (usize, Vec<String>) {
    let queue = Mutex::new(tasks);
    let (sender, receiver) = mpsc::channel::<(Task, Outcome)>();
    let mut completed = 0;
    let mut failures = Vec::new();
    std::thread::scope(|scope| {
        for _ in 0..jobs {
            let sender = sender.clone();
            let queue = &queue;
            scope.spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    let next = queue.lock().ok().and_then(|mut q| q.pop_front());
                    let Some(task) = next else { break };
                    let outcome = run_one(
                        grid,
                        batch,
                        &configurations[task.configuration],
                        task.seed,
                        stop,
                    );
                    if sender.send((task, outcome)).is_err() {
                        break;
                    }
                }
            });
        }
        drop(sender);
        for (task, outcome) in receiver {
            let id = &configurations[task.configuration].id;
            match outcome {
                Outcome::Completed => {
                    completed += 1;
                    progress.inc(1);
                    progress.suspend(|| println!("finished {id}/seed-{}", task.seed));
                }
                Outcome::Interrupted => {
                    tracing::info!(configuration = %id, seed = task.seed, "run stopped; it will run again");
                }
                Outcome::Failed(reason) => {
                    progress.suspend(|| tracing::error!(configuration = %id, seed = task.seed, "run failed: {reason}"));
                    failures.push(format!("{id}/seed-{}: {reason}", task.seed));
                }
            }
        }
    });
    (completed, failures)
}

/// One run into its partial directory, renamed when complete.
fn run_one(
    grid: &Grid,
    batch: &BatchDir,
    configuration: &Configuration,
    seed: u64,
    stop: &Arc<AtomicBool>,
) -> Outcome {
    let partial = batch.partial_dir(&configuration.id, seed);
    let options = RunOptions {
        config: batch.config_path(&configuration.id),
        robots: None,
        ticks: grid.ticks,
        seed: Some(seed),
        out: Some(partial.clone()),
        overwrite: true,
        progress: false,
        ..RunOptions::default()
    };
    match launcher::run(&options, Arc::clone(stop)) {
        Ok(report) if report.interrupted => Outcome::Interrupted,
        Ok(_) => match batch.complete(configuration, seed, grid.ticks) {
            Ok(_) => Outcome::Completed,
            Err(e) => Outcome::Failed(format!("completing {}: {e}", partial.display())),
        },
        // A run stopped while it started up fails rather than reporting an interruption; it is not a failure.
        Err(_) if stop.load(Ordering::Relaxed) => Outcome::Interrupted,
        Err(e) => Outcome::Failed(format!("{e} (its records are in {})", partial.display())),
    }
}

/// `--merge`: summarises the finished runs of the shard folders into `root`.
fn merge(
    options: &ExperimentOptions,
    grid: &Grid,
    configurations: &[Configuration],
    root: PathBuf,
) -> Result<BatchReport, ExperimentError> {
    let mut sources = Vec::new();
    for dir in &options.merge {
        if !dir.join("runs").is_dir() {
            return Err(ExperimentError::NotABatch(dir.clone()));
        }
        sources.push(BatchDir::create(dir).map_err(io(format!("opening {}", dir.display())))?);
    }
    std::fs::write(root.join("grid.toml"), &grid.text).map_err(io("copying the grid"))?;
    let runs_planned = configurations.len() * grid.seeds.len();
    let (plots_missing, found) = summarise(grid, &sources, &root, configurations, runs_planned)?;
    Ok(BatchReport {
        dir: root,
        configurations: configurations.len(),
        runs_planned,
        runs_reused: found,
        runs_completed: 0,
        failures: Vec::new(),
        interrupted: false,
        jobs: 0,
        plots_missing,
    })
}

/// The (configuration, seed) runs finished in `batch` for this grid.
fn finished_runs(
    grid: &Grid,
    batch: &BatchDir,
    configurations: &[Configuration],
) -> Vec<(usize, u64)> {
    let mut finished = Vec::new();
    for (index, configuration) in configurations.iter().enumerate() {
        for &seed in &grid.seeds {
            if batch.state(configuration, seed, grid.ticks) == RunState::Finished {
                finished.push((index, seed));
            }
        }
    }
    finished
}

/// Reads every run finished in one of `sources` (the first that holds it) and writes `results.csv`, the figures
/// and `report.md` into `root`; returns why figures are missing, if they are, and how many runs it read.
fn summarise(
    grid: &Grid,
    sources: &[BatchDir],
    root: &Path,
    configurations: &[Configuration],
    runs_planned: usize,
) -> Result<(Option<String>, usize), ExperimentError> {
    let mut runs: Vec<RunResult> = Vec::new();
    for source in sources {
        for (index, seed) in finished_runs(grid, source, configurations) {
            if runs
                .iter()
                .any(|r| r.configuration == index && r.seed == seed)
            {
                continue;
            }
            let dir = source.run_dir(&configurations[index].id, seed);
            runs.push(RunResult::read(&dir, index, seed)?);
        }
    }
    runs.sort_by_key(|r| {
        (
            r.configuration,
            grid.seeds.iter().position(|&s| s == r.seed),
        )
    });
    let metrics = results::metric_names(&runs);
    if !runs.is_empty() && !metrics.contains(&grid.median_metric) {
        return Err(ExperimentError::Grid(ConfigErrors {
            errors: vec![grid.diagnostic(
                grid.median_metric_location,
                format!(
                    "median_metric '{}' is not among the runs' metrics: {}",
                    grid.median_metric,
                    metrics.join(", ")
                ),
            )],
        }));
    }
    let selected = results::select_medians(configurations.len(), &runs, &grid.median_metric);
    write(
        root,
        "results.csv",
        &results::csv(grid, configurations, &runs, &selected),
    )?;
    let (figures, plots_missing) =
        match plots::draw(root, grid, configurations, &runs, &selected, &metrics) {
            Ok(figures) => (figures, None),
            Err(e) => {
                tracing::warn!("figures not drawn: {e}");
                (Vec::new(), Some(e.to_string()))
            }
        };
    let facts = report::ReportFacts {
        runs_planned,
        runs_finished: runs.len(),
        plots_missing: plots_missing.clone(),
    };
    let text = report::markdown(
        grid,
        configurations,
        &runs,
        &selected,
        &metrics,
        &figures,
        &facts,
    );
    write(root, "report.md", &text)?;
    Ok((plots_missing, runs.len()))
}

fn write(root: &Path, name: &str, text: &str) -> Result<(), ExperimentError> {
    let path = root.join(name);
    swarm_contract::run_dir::write_atomically(&path, text.as_bytes())
        .map_err(io(format!("writing {}", path.display())))
}
