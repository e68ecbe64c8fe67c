//! Shared helpers for the system tests in `tests/tests/`: build the real programs once, run `swarm` as a user
//! would, and check that a run leaves no process and no shared-memory file behind.
//!
//! Runs are recognised by their iceoryx2 run name, which the launcher derives from its own process id
//! (`sw<pid in hex>-...`): every shared-memory file is `/dev/shm/iox2_<run>_*` and every child's command line
//! carries `--run <run>`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// The folder holding `swarm`, `swarm-world` and `robot-agent`, brought up to date once per test binary with the
/// cargo that runs the tests. `--workspace --tests` selects the same packages and features as
/// `cargo test --workspace`, which has already built these programs, so under the README's test command this is
/// a no-op; run alone (`cargo test -p swarm-system-tests`) it builds what is missing.
pub fn bin_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let status = Command::new(cargo)
            .args(["build", "--quiet", "--workspace", "--tests"])
            .current_dir(workspace_root())
            .status()
            .expect("cargo must be runnable from the tests");
        assert!(status.success(), "building the programs failed");
        let exe = std::env::current_exe().expect("the test binary knows its path");
        // target/<profile>/deps/<test binary>
        exe.parent()
            .and_then(Path::parent)
            .expect("test binaries live in target/<profile>/deps")
            .to_path_buf()
    })
}

/// The workspace root (the parent of this crate).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace")
        .to_path_buf()
}

/// A file of the workspace, e.g. `configs/obstacle_avoidance/thesis_example.argos`.
pub fn workspace_file(relative: &str) -> PathBuf {
    workspace_root().join(relative)
}

/// The outcome of one `swarm` invocation.
pub struct SwarmOutcome {
    /// Exit status, standard output and standard error.
    pub output: Output,
    /// The launcher's process id (its run names start with `sw<pid in hex>-`).
    pub pid: u32,
}

impl SwarmOutcome {
    /// Standard error as text.
    pub fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.output.stderr).into_owned()
    }

    /// Standard output as text.
    pub fn stdout(&self) -> String {
        String::from_utf8_lossy(&self.output.stdout).into_owned()
    }

    /// The run-name prefix of every run this launcher started.
    pub fn run_prefix(&self) -> String {
        format!("sw{:x}-", self.pid)
    }
}

/// Runs `swarm <args>` to completion with the test-built programs.
pub fn swarm(args: &[&str]) -> SwarmOutcome {
    let dir = bin_dir();
    let child = Command::new(dir.join("swarm"))
        .args(args)
        .env("SWARM_BIN_DIR", dir)
        .env("RUST_LOG", "info")
        .current_dir(workspace_root())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("swarm starts");
    let pid = child.id();
    let output = child.wait_with_output().expect("swarm runs to its end");
    SwarmOutcome { output, pid }
}

/// Shared-memory files left by runs whose name starts with `run_prefix`.
pub fn shm_leftovers(run_prefix: &str) -> Vec<PathBuf> {
    let prefix = format!("iox2_{run_prefix}");
    std::fs::read_dir("/dev/shm")
        .map(|entries| {
            entries
                .flatten()
                .filter(|e| e.file_name().to_string_lossy().starts_with(&prefix))
                .map(|e| e.path())
                .collect()
        })
        .unwrap_or_default()
}

/// Processes still running whose command line names a run starting with `run_prefix`.
pub fn process_leftovers(run_prefix: &str) -> Vec<u32> {
    let needle = format!("--run\0{run_prefix}");
    std::fs::read_dir("/proc")
        .map(|entries| {
            entries
                .flatten()
                .filter_map(|e| e.file_name().to_string_lossy().parse::<u32>().ok())
                .filter(|pid| {
                    std::fs::read(format!("/proc/{pid}/cmdline"))
                        .map(|cmd| String::from_utf8_lossy(&cmd).contains(&needle))
                        .unwrap_or(false)
                })
                .collect()
        })
        .unwrap_or_default()
}

/// Asserts that the runs of `outcome` left no process and no shared-memory file.
pub fn assert_clean(outcome: &SwarmOutcome) {
    let prefix = outcome.run_prefix();
    assert_eq!(
        process_leftovers(&prefix),
        Vec::<u32>::new(),
        "processes outlived the run"
    );
    assert_eq!(
        shm_leftovers(&prefix),
        Vec::<PathBuf>::new(),
        "shared memory outlived the run"
    );
}

/// Kills every process still running for runs starting with `run_prefix` and removes their shared-memory files
/// and iceoryx2 root folders: the cleanup after a test killed a launcher on purpose (SIGKILL leaves them behind).
pub fn wipe_runs(run_prefix: &str) {
    for pid in process_leftovers(run_prefix) {
        if let Ok(pid) = i32::try_from(pid) {
            let _ = nix::sys::signal::kill(
                nix::unistd::Pid::from_raw(pid),
                nix::sys::signal::Signal::SIGKILL,
            );
        }
    }
    let roots = std::fs::read_dir(std::env::temp_dir())
        .map(|entries| entries.flatten().map(|e| e.path()).collect::<Vec<_>>())
        .unwrap_or_default();
    for root in roots {
        let Some(name) = root
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(|n| n.strip_prefix("iceoryx2-"))
            .filter(|n| n.starts_with(run_prefix))
        else {
            continue;
        };
        if let Ok(spec) = swarm_runtime::transport::RunSpec::new(name, &root) {
            let _ = spec.cleanup();
        }
    }
    for file in shm_leftovers(run_prefix) {
        let _ = std::fs::remove_file(file);
    }
}
