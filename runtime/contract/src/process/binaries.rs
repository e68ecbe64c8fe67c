//! Finding the world and agent programs a run starts.
//!
//! They are separate packages (`swarm-world-process`, `robot-agent`) because the launcher must not depend on
//! them, so `cargo run --bin swarm` alone would not build them. The launcher therefore looks next to its own executable
//! and, when it was started by cargo (`CARGO` is set and it lives in a `target/<profile>` folder), first asks the
//! same cargo to build them with the same profile, so a fresh checkout runs with one command and a stale sibling
//! binary never meets a newer launcher. `SWARM_BIN_DIR` names another folder and skips the build.

use std::path::{Path, PathBuf};
use std::process::Command;

/// File name of the world program.
pub const WORLD_PROGRAM: &str = "swarm-world";
/// File name of the robot agent program.
pub const AGENT_PROGRAM: &str = "robot-agent";
/// File name of the bare lockstep agent (no player), used by `swarm bench`.
pub const LOCKSTEP_AGENT_PROGRAM: &str = "swarm-lockstep-agent";

/// Why the programs of a run could not be found.
#[derive(Debug, thiserror::Error)]
pub enum BinariesError {
    /// The launcher's own path is unknown.
    #[error("cannot locate the swarm executable: {0}")]
    OwnPath(#[source] std::io::Error),
    /// Building the sibling programs with cargo failed.
    #[error("`{command}` failed ({status}); fix the build error above")]
    Build {
        /// The command that was run.
        command: String,
        /// Its exit status.
        status: String,
    },
    /// Cargo could not be started.
    #[error("cannot run cargo ({cargo}): {source}")]
    Cargo {
        /// The cargo executable.
        cargo: String,
        /// Why it failed.
        #[source]
        source: std::io::Error,
    },
    /// A program is missing.
    #[error(
        "{program} not found at {path}; build it with `cargo build --release --workspace` or set SWARM_BIN_DIR"
    )]
    Missing {
        /// The program's name.
        program: &'static str,
        /// Where it was looked for.
        path: PathBuf,
    },
}

/// The programs of a run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Binaries {
    /// The world program.
    pub world: PathBuf,
    /// The robot agent program.
    pub agent: PathBuf,
}

impl Binaries {
    /// Finds (and, under cargo, builds) the world and agent programs.
    pub fn locate() -> Result<Binaries, BinariesError> {
        let dir = program_dir()?;
        Ok(Binaries {
            world: find(&dir, WORLD_PROGRAM)?,
            agent: find(&dir, AGENT_PROGRAM)?,
        })
    }

    /// Finds (and, under cargo, builds) one more program of the workspace that lives beside the world and agent
    /// programs, e.g. [`LOCKSTEP_AGENT_PROGRAM`].
    pub fn locate_program(program: &'static str) -> Result<PathBuf, BinariesError> {
        find(&program_dir()?, program)
    }
}

/// The folder of the run's programs: `SWARM_BIN_DIR`, or the launcher's own folder (built first under cargo).
fn program_dir() -> Result<PathBuf, BinariesError> {
    if let Some(dir) = std::env::var_os("SWARM_BIN_DIR") {
        return Ok(PathBuf::from(dir));
    }
    let own = std::env::current_exe().map_err(BinariesError::OwnPath)?;
    let dir = own.parent().map(Path::to_path_buf).unwrap_or_default();
    if let Some(cargo) = std::env::var_os("CARGO") {
        build_with_cargo(&cargo.to_string_lossy(), &dir)?;
    }
    Ok(dir)
}

fn find(dir: &Path, program: &'static str) -> Result<PathBuf, BinariesError> {
    let path = dir.join(program);
    if path.is_file() {
        Ok(path)
    } else {
        Err(BinariesError::Missing { program, path })
    }
}

/// Removes from `command` the environment variables cargo sets for the program it runs (`cargo run`, `cargo
/// test`): the package under test's name, version, manifest and the like. Build scripts that watch them (ring's
/// does) would see them changed and rebuild the TLS stack and everything above it, so a cargo started from a
/// program cargo ran gets the environment the outer cargo was started with.
pub fn without_cargo_package_env(command: &mut Command) -> &mut Command {
    for (name, _) in std::env::vars_os() {
        if name.to_str().is_some_and(set_by_cargo_for_programs) {
            command.env_remove(name);
        }
    }
    command
}

/// Whether cargo sets the environment variable `name` for the programs it runs (and for build scripts).
fn set_by_cargo_for_programs(name: &str) -> bool {
    const EXACT: [&str; 9] = [
        "CARGO_MANIFEST_DIR",
        "CARGO_MANIFEST_PATH",
        "CARGO_MANIFEST_LINKS",
        "CARGO_CRATE_NAME",
        "CARGO_BIN_NAME",
        "CARGO_PRIMARY_PACKAGE",
        "CARGO_TARGET_TMPDIR",
        "CARGO_RUSTC_CURRENT_DIR",
        "OUT_DIR",
    ];
    EXACT.contains(&name) || name.starts_with("CARGO_PKG_") || name.starts_with("CARGO_BIN_EXE_")
}

/// Builds the sibling packages with the profile of the target folder `dir` (`.../target/<profile>`).
fn build_with_cargo(cargo: &str, dir: &Path) -> Result<(), BinariesError> {
    let Some(profile) = dir.file_name().and_then(|p| p.to_str()) else {
        return Ok(());
    };
    let in_target = dir
        .parent()
        .and_then(Path::file_name)
        .is_some_and(|t| t.to_string_lossy().starts_with("target"));
    if !in_target {
        return Ok(());
    }
    let mut command = Command::new(cargo);
    without_cargo_package_env(&mut command);
    // The whole workspace's programs: `cargo run --bin swarm` in the workspace resolves features over every
    // member too, so this build finds every dependency fresh and compiles only the missing programs, with
    // cargo's own progress on the terminal.
    command.args(["build", "--workspace", "--bins"]);
    match profile {
        "debug" => {}
        "release" => {
            command.arg("--release");
        }
        other => {
            command.args(["--profile", other]);
        }
    }
    let shown = format!("{command:?}");
    tracing::info!(command = %shown, "building the programs of a run");
    let status = command.status().map_err(|source| BinariesError::Cargo {
        cargo: cargo.to_owned(),
        source,
    })?;
    if status.success() {
        Ok(())
    } else {
        Err(BinariesError::Build {
            command: shown,
            status: status.to_string(),
        })
    }
}
