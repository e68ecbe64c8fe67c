//! Shared helpers for the system tests in `tests/tests/`: build the real programs once, run `swarm` as a user
//! would, and check that a run leaves no process and no shared-memory file behind.
//!
//! Runs are recognised by their iceoryx2 run name, which the launcher derives from its own process id
//! (`sw<pid in hex>-...`): every shared-memory file is `/dev/shm/iox2_<run>_*` and every child's command line
//! carries `--run <run>`.

#![warn(missing_docs)]

pub mod browser;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use swarm_contract::process::binaries::without_cargo_package_env;
use swarm_contract::transport::RUN_ROOTS_DIR;

/// The folder holding `swarm`, `swarm-world` and `robot-agent`, brought up to date once per test binary with the
/// cargo that runs the tests. It asks for exactly the build of the README's test command (`cargo test --workspace`,
/// without running anything), so under that command this is a no-op; run alone (`cargo test -p
/// swarm-system-tests`) it builds what is missing. (`cargo build --workspace --tests` would resolve dependency
/// features differently and build zenoh's TLS stack a second time.)
pub fn bin_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let mut command = Command::new(cargo);
        // Cargo gives a test process the variables of the package under test; the inner cargo gets the
        // environment the outer one was started with, or it would rebuild the TLS stack.
        without_cargo_package_env(&mut command);
        let status = command
            .args(["test", "--quiet", "--workspace", "--no-run"])
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

/// Runs `swarm <args>` to completion from the workspace root with the test-built programs.
pub fn swarm(args: &[&str]) -> SwarmOutcome {
    swarm_in(&workspace_root(), args)
}

/// Runs `swarm <args>` to completion from the folder `cwd` with the test-built programs.
pub fn swarm_in(cwd: &Path, args: &[&str]) -> SwarmOutcome {
    let dir = bin_dir();
    let child = Command::new(dir.join("swarm"))
        .args(args)
        .env("SWARM_BIN_DIR", dir)
        .env("RUST_LOG", "info")
        .current_dir(cwd)
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
    entries_starting_with(Path::new("/dev/shm"), &format!("iox2_{run_prefix}"))
}

/// Entries of `dir` whose file name starts with `prefix` (none if `dir` cannot be read).
fn entries_starting_with(dir: &Path, prefix: &str) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .flatten()
                .filter(|e| e.file_name().to_string_lossy().starts_with(prefix))
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

/// Asserts that the runs of `outcome` left no process, no shared-memory file and no iceoryx2 root directory.
pub fn assert_clean(outcome: &SwarmOutcome) {
    assert_prefix_clean(&outcome.run_prefix());
}

/// iceoryx2 root directories (`/dev/shm/iceoryx2-<run>`) left by runs whose name starts with `run_prefix`.
pub fn iceoryx_root_leftovers(run_prefix: &str) -> Vec<PathBuf> {
    entries_starting_with(Path::new(RUN_ROOTS_DIR), &format!("iceoryx2-{run_prefix}"))
}

/// Asserts that the runs of the launcher with process id `pid` left no process, no shared-memory file and no
/// iceoryx2 root directory, whatever was killed during them.
pub fn assert_nothing_left(pid: u32) {
    assert_prefix_clean(&format!("sw{pid:x}-"));
}

fn assert_prefix_clean(prefix: &str) {
    assert_eq!(
        process_leftovers(prefix),
        Vec::<u32>::new(),
        "processes outlived the run"
    );
    assert_eq!(
        shm_leftovers(prefix),
        Vec::<PathBuf>::new(),
        "shared memory outlived the run"
    );
    assert_eq!(
        iceoryx_root_leftovers(prefix),
        Vec::<PathBuf>::new(),
        "iceoryx2 files outlived the run"
    );
}

/// Starts `swarm <args>` from the workspace root with the test-built programs and returns it running, standard
/// error piped (for tests that talk to a live run).
pub fn spawn_swarm(args: &[&str]) -> std::process::Child {
    spawn_swarm_in(&workspace_root(), args)
}

/// Starts `swarm <args>` from the folder `cwd`, as [`spawn_swarm`] does.
pub fn spawn_swarm_in(cwd: &Path, args: &[&str]) -> std::process::Child {
    let dir = bin_dir();
    Command::new(dir.join("swarm"))
        .args(args)
        .env("SWARM_BIN_DIR", dir)
        .env("RUST_LOG", "info")
        .current_dir(cwd)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("swarm starts")
}

/// Runs `swarm ctl <out> <request>` against a live run and returns its standard output (it must succeed).
pub fn swarm_ctl(out: &Path, request: &[&str]) -> String {
    let output = Command::new(bin_dir().join("swarm"))
        .arg("ctl")
        .arg(out)
        .args(request)
        .output()
        .expect("swarm ctl runs");
    assert!(
        output.status.success(),
        "swarm ctl {request:?} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Removes the shared-memory files and iceoryx2 root directories of every run whose name starts with `run_prefix`
/// (for processes a test killed with SIGKILL, which cannot clean up themselves).
pub fn remove_run_leftovers(run_prefix: &str) {
    for path in shm_leftovers(run_prefix) {
        let _ = std::fs::remove_file(path);
    }
    for root in iceoryx_root_leftovers(run_prefix) {
        let _ = std::fs::remove_dir_all(root);
    }
}

/// A free TCP port on `ip` (bound once and released, for a zenoh endpoint).
pub fn free_port(ip: &str) -> u16 {
    std::net::TcpListener::bind((ip, 0))
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port")
}

/// The host keys of one test, made by `swarm host-key` in a temporary folder removed when dropped.
pub struct TestKeys {
    dir: tempfile::TempDir,
}

impl Default for TestKeys {
    fn default() -> Self {
        TestKeys::new()
    }
}

impl TestKeys {
    /// An empty key folder.
    pub fn new() -> TestKeys {
        TestKeys {
            dir: tempfile::tempdir().expect("a temporary directory"),
        }
    }

    /// The key folder (`swarm run --keys`).
    pub fn dir(&self) -> &Path {
        self.dir.path()
    }

    /// The key file of host `name`, created with `swarm host-key` if missing.
    pub fn key(&self, name: &str) -> PathBuf {
        let dir = self.dir().display().to_string();
        let outcome = swarm(&["host-key", name, "--dir", &dir]);
        assert!(
            outcome.output.status.success(),
            "swarm host-key {name} failed:\n{}",
            outcome.stderr()
        );
        self.dir().join(format!("{name}.key"))
    }

    /// `--keys <folder>` for `swarm run`.
    pub fn run_args(&self) -> Vec<String> {
        vec!["--keys".into(), self.dir().display().to_string()]
    }
}

/// A `swarm host` daemon started by a test (optionally inside a network namespace). Its log lines are collected
/// so the test can wait for events; dropping it kills it and removes whatever its runs left.
pub struct HostDaemon {
    child: std::process::Child,
    lines: std::sync::mpsc::Receiver<String>,
    seen: Vec<String>,
    /// The host name.
    pub name: String,
    logs: tempfile::TempDir,
}

impl HostDaemon {
    /// Starts `swarm host --connect <connect> --name <name> --key <its key in keys>`, inside `netns` when given.
    pub fn start(name: &str, connect: &str, netns: Option<&str>, keys: &TestKeys) -> HostDaemon {
        let key = keys.key(name);
        HostDaemon::start_with(
            name,
            connect,
            netns,
            &[std::ffi::OsStr::new("--key"), key.as_os_str()],
        )
    }

    /// Like [`HostDaemon::start`], with more `swarm host` flags (e.g. credentials).
    pub fn start_with(
        name: &str,
        connect: &str,
        netns: Option<&str>,
        flags: &[&std::ffi::OsStr],
    ) -> HostDaemon {
        let dir = bin_dir();
        let logs = tempfile::tempdir().expect("a temporary directory");
        let swarm = dir.join("swarm");
        let mut command = match netns {
            Some(ns) => {
                let mut c = Command::new("ip");
                c.args(["netns", "exec", ns]).arg(&swarm);
                c
            }
            None => Command::new(&swarm),
        };
        command
            .args(["host", "--connect", connect, "--name", name, "--logs"])
            .arg(logs.path())
            .args(flags)
            .env("SWARM_BIN_DIR", dir)
            .env("RUST_LOG", "info,zenoh=warn")
            .current_dir(workspace_root())
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped());
        let mut child = command.spawn().expect("swarm host starts");
        let lines = follow_lines(child.stderr.take());
        HostDaemon {
            child,
            lines,
            seen: Vec::new(),
            name: name.to_owned(),
            logs,
        }
    }

    /// The daemon's process id (`ip netns exec` execs it, so it is the daemon's own).
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Waits until a log line containing `needle` appears after the lines already consumed; false on timeout or
    /// when the daemon's output ends.
    pub fn wait_for(&mut self, needle: &str, timeout: std::time::Duration) -> bool {
        wait_for_line(&self.lines, &mut self.seen, needle, timeout)
    }

    /// Every log line read so far.
    pub fn log(&self) -> String {
        self.seen.join("\n")
    }

    /// The log of the agent this daemon started last for run-wide robot `robot` (empty when there is none).
    pub fn agent_log(&self, robot: u64) -> String {
        std::fs::read_to_string(self.logs.path().join(format!("robot-{robot}.log")))
            .unwrap_or_default()
    }

    /// Asks the daemon to stop (SIGTERM) and waits for it; true when it exited successfully.
    pub fn stop(&mut self) -> bool {
        let _ = nix::sys::signal::kill(
            nix::unistd::Pid::from_raw(self.child.id() as i32),
            nix::sys::signal::Signal::SIGTERM,
        );
        self.child.wait().map(|s| s.success()).unwrap_or(false)
    }

    /// Kills the daemon with SIGKILL (its agents die with it) and removes what its runs left.
    pub fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        remove_run_leftovers(&format!("sw{:x}-", self.child.id()));
    }
}

impl Drop for HostDaemon {
    fn drop(&mut self) {
        self.kill();
    }
}

/// Collects the lines of a child's output on a thread.
pub fn follow_lines(
    output: Option<impl std::io::Read + Send + 'static>,
) -> std::sync::mpsc::Receiver<String> {
    use std::io::BufRead;
    let (sender, receiver) = std::sync::mpsc::channel();
    if let Some(output) = output {
        std::thread::spawn(move || {
            for line in std::io::BufReader::new(output).lines() {
                let Ok(line) = line else { break };
                if sender.send(line).is_err() {
                    break;
                }
            }
        });
    }
    receiver
}

/// Waits for a line containing `needle` on `lines`, keeping every line read in `seen`; false on timeout or end.
pub fn wait_for_line(
    lines: &std::sync::mpsc::Receiver<String>,
    seen: &mut Vec<String>,
    needle: &str,
    timeout: std::time::Duration,
) -> bool {
    let deadline = std::time::Instant::now() + timeout;
    loop {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        match lines.recv_timeout(left) {
            Ok(line) => {
                let found = line.contains(needle);
                seen.push(line);
                if found {
                    return true;
                }
            }
            Err(_) => return false,
        }
    }
}

/// A Linux network namespace joined to the test's namespace by a veth pair: the world listens on `outer_ip`, a
/// host inside reaches it from `inner_ip`. Needs root and iproute2; dropping it deletes both.
pub struct Netns {
    /// Namespace name (for `ip netns exec`).
    pub name: String,
    /// The veth end outside the namespace.
    pub outer: String,
    /// Address of the outer end.
    pub outer_ip: String,
    /// Address of the inner end.
    pub inner_ip: String,
}

/// Whether this process runs with effective user id 0 (the second field of `Uid:` in /proc/self/status).
fn is_root() -> bool {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|status| {
            status
                .lines()
                .find_map(|l| l.strip_prefix("Uid:"))
                .and_then(|ids| ids.split_whitespace().nth(1).map(|e| e == "0"))
        })
        .unwrap_or(false)
}

fn ip(args: &[&str]) -> Result<(), String> {
    let output = Command::new("ip")
        .args(args)
        .output()
        .map_err(|e| format!("ip {}: {e}", args.join(" ")))?;
    if output.status.success() {
        Ok(())
    } else {
        Err(format!(
            "ip {}: {}",
            args.join(" "),
            String::from_utf8_lossy(&output.stderr).trim()
        ))
    }
}

impl Netns {
    /// Creates a namespace of this test process (at most 100 per process), or says why it cannot. Tests run on
    /// parallel threads of one process, so each namespace gets the next number of a process-wide counter.
    pub fn create() -> Result<Netns, String> {
        static NEXT: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        if !is_root() {
            return Err("network namespaces need root".into());
        }
        let index = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if index >= 100 {
            return Err("this test process already made 100 namespaces".into());
        }
        let tag = (std::process::id() % 10_000) * 100 + index;
        let subnet = (std::process::id() % 200) + 20;
        let ns = Netns {
            name: format!("swarm-test-{tag}"),
            outer: format!("swo{tag}"),
            outer_ip: format!("10.{subnet}.{index}.1"),
            inner_ip: format!("10.{subnet}.{index}.2"),
        };
        let inner = format!("swi{tag}");
        ip(&["netns", "add", &ns.name])?;
        let setup = || -> Result<(), String> {
            ip(&[
                "link", "add", &ns.outer, "type", "veth", "peer", "name", &inner,
            ])?;
            ip(&["link", "set", &inner, "netns", &ns.name])?;
            ip(&[
                "addr",
                "add",
                &format!("{}/24", ns.outer_ip),
                "dev",
                &ns.outer,
            ])?;
            ip(&["link", "set", &ns.outer, "up"])?;
            ip(&[
                "-n",
                &ns.name,
                "addr",
                "add",
                &format!("{}/24", ns.inner_ip),
                "dev",
                &inner,
            ])?;
            ip(&["-n", &ns.name, "link", "set", &inner, "up"])?;
            ip(&["-n", &ns.name, "link", "set", "lo", "up"])
        };
        // On failure `ns` is dropped here, which deletes whatever was created.
        setup().map(|()| ns)
    }

    /// Cuts (false) or restores (true) the link between the namespace and the test's namespace.
    pub fn set_link(&self, up: bool) -> Result<(), String> {
        ip(&["link", "set", &self.outer, if up { "up" } else { "down" }])
    }
}

impl Drop for Netns {
    fn drop(&mut self) {
        let _ = ip(&["link", "del", &self.outer]);
        let _ = ip(&["netns", "del", &self.name]);
    }
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
    remove_run_leftovers(run_prefix);
}

/// Waits until process `pid` (any process, not only a child) has ended, at most `limit`; whether it ended.
/// Uses a pidfd, which becomes readable when the process exits, so nothing is polled.
pub fn wait_gone(pid: u32, limit: std::time::Duration) -> bool {
    // SAFETY: pidfd_open takes a pid and flags and returns a new descriptor or -1.
    let fd = unsafe { libc::syscall(libc::SYS_pidfd_open, pid as libc::pid_t, 0) };
    if fd < 0 {
        // No such process (any more).
        return true;
    }
    let fd = fd as libc::c_int;
    let mut poll = libc::pollfd {
        fd,
        events: libc::POLLIN,
        revents: 0,
    };
    let timeout = libc::c_int::try_from(limit.as_millis()).unwrap_or(libc::c_int::MAX);
    // SAFETY: one valid pollfd for the duration of the call; the descriptor is ours and closed once.
    let ready = unsafe { libc::poll(&mut poll, 1, timeout) };
    // SAFETY: `fd` was returned by pidfd_open above and is not used after this.
    unsafe { libc::close(fd) };
    ready > 0
}

/// Runs `swarm run <config> --out <out> --no-progress <extra>` from the workspace (`config` relative to it, or
/// absolute) to its end; the run must succeed and leave nothing behind.
pub fn run_to_completion(config: &str, out: &Path, extra: &[&str]) -> SwarmOutcome {
    let out = out.display().to_string();
    let mut args = vec!["run", config, "--out", &out, "--no-progress"];
    args.extend_from_slice(extra);
    let outcome = swarm(&args);
    assert!(
        outcome.output.status.success(),
        "swarm run {config} failed:\n{}",
        outcome.stderr()
    );
    assert_clean(&outcome);
    outcome
}

/// The shipped configuration `config` (relative to the workspace) with `edit` applied, written into `dir` under its
/// own file name, its `supervisors="models"` pointed at the `models` folder beside it by absolute path; returns the
/// new file's path.
pub fn edited_config(dir: &Path, config: &str, edit: impl Fn(String) -> String) -> String {
    let shipped = workspace_file(config);
    let text = std::fs::read_to_string(&shipped).unwrap_or_else(|e| panic!("{config}: {e}"));
    let models = shipped.with_file_name("models");
    let text = text.replace(
        "supervisors=\"models\"",
        &format!("supervisors=\"{}\"", models.display()),
    );
    let path = dir.join(shipped.file_name().expect("a file name"));
    std::fs::write(&path, edit(text)).expect("write the configuration");
    path.display().to_string()
}

/// The line of the first `<element` of the configuration at `path`, where errors about it point (task errors
/// point at `<loop_functions`).
pub fn element_line(path: &str, element: &str) -> usize {
    let text = std::fs::read_to_string(path).expect("the configuration");
    1 + text
        .lines()
        .position(|l| l.contains(&format!("<{element}")))
        .unwrap_or_else(|| panic!("no <{element}> element in {path}"))
}

/// Asserts that `swarm run <config>` (a file in `dir`) is refused with an error at the line of the config's first
/// `<element` that says `expected`.
pub fn assert_refused(dir: &Path, config: &str, element: &str, expected: &str) {
    let run = dir.join("run").display().to_string();
    let outcome = swarm(&["run", config, "--out", &run, "--overwrite"]);
    assert!(
        !outcome.output.status.success(),
        "{config} was accepted (expected: {expected})"
    );
    let stderr = outcome.stderr();
    let place = format!("{config}:{}:", element_line(config, element));
    assert!(stderr.contains(&place), "no `{place}` in\n{stderr}");
    assert!(stderr.contains(expected), "no `{expected}` in\n{stderr}");
}

/// The run's `summary.json`.
pub fn run_summary(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

/// Runs `config` to completion twice, each into a fresh temporary folder (for determinism checks).
pub fn run_twice(config: &str, extra: &[&str]) -> [tempfile::TempDir; 2] {
    let runs = [(); 2].map(|_| tempfile::tempdir().expect("tempdir"));
    for out in &runs {
        run_to_completion(config, out.path(), extra);
    }
    runs
}

/// The shipped configuration `config` with `faults` (elements of a `<faults>` section) added to its schedule,
/// written into `dir` as [`edited_config`] does.
pub fn with_faults(dir: &Path, config: &str, faults: &str) -> String {
    edited_config(dir, config, |text| match text.find("</faults>") {
        Some(end) => format!("{}    {faults}\n  {}", &text[..end], &text[end..]),
        None => text.replace(
            "</argos-configuration>",
            &format!("  <faults>{faults}</faults>\n</argos-configuration>"),
        ),
    })
}

/// The bytes of the file `name` of the run folder `dir`. A record table's CSV name (`trajectory.csv`,
/// `events.csv`, `messages.csv`) gives its CSV text also when the run left the table as Parquet (the default): the
/// Parquet file is converted back with `swarm export`'s code in a temporary folder, which gives the world's CSV
/// byte for byte. The CSV file is read while it exists (a live run, or `--records csv`).
pub fn run_file(dir: &Path, name: &str) -> Vec<u8> {
    match std::fs::read(dir.join(name)) {
        Ok(bytes) => return bytes,
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => panic!("{name}: {e}"),
        Err(_) => {}
    }
    let Some(table) = swarm_records::Table::ALL
        .into_iter()
        .find(|t| t.csv_name() == name)
    else {
        panic!("{}: no such file", dir.join(name).display());
    };
    let parquet = dir.join(table.parquet_name());
    let scratch = tempfile::tempdir().expect("a temporary directory");
    match std::fs::copy(&parquet, scratch.path().join(table.parquet_name())) {
        Ok(_) => {}
        // The run converted its records between the two reads.
        Err(_) if dir.join(name).exists() => return run_file(dir, name),
        Err(e) => panic!("{name}: no such file, and {}: {e}", parquet.display()),
    }
    swarm_records::export(scratch.path(), swarm_records::Format::Csv)
        .unwrap_or_else(|e| panic!("{} back to CSV: {e}", parquet.display()));
    std::fs::read(scratch.path().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// [`run_file`] as text.
pub fn run_text(dir: &Path, name: &str) -> String {
    String::from_utf8(run_file(dir, name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Asserts that the record `files` of the run folders `a` and `b` are the same, byte for byte ([`run_file`]).
pub fn assert_same_records(a: &Path, b: &Path, files: &[&str]) {
    for file in files {
        let read = |dir: &Path| run_file(dir, file);
        assert!(
            read(a) == read(b),
            "{file} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

/// A `swarm run` going on in the background, for `swarm ctl` tests: its launcher log is followed line by line.
pub struct LiveSwarm {
    child: std::process::Child,
    log: std::io::BufReader<std::process::ChildStderr>,
}

impl LiveSwarm {
    /// Starts `swarm run <config> --out <out>` (`config` relative to the workspace) paced in real time and
    /// practically endless, with `extra` arguments; returns once its first tick completed.
    pub fn run(config: &str, out: &Path, extra: &[&str]) -> LiveSwarm {
        let config = workspace_file(config).display().to_string();
        let out = out.display().to_string();
        let mut args = vec![
            "run",
            &config,
            "--no-progress",
            "--real-time",
            "--ticks",
            "1000000",
            "--out",
            &out,
        ];
        args.extend_from_slice(extra);
        LiveSwarm::start(&args)
    }

    /// Starts `swarm <args>` and returns once its first tick completed.
    pub fn start(args: &[&str]) -> LiveSwarm {
        let mut child = spawn_swarm(args);
        let log = std::io::BufReader::new(child.stderr.take().expect("stderr is piped"));
        let mut live = LiveSwarm { child, log };
        live.wait_for("first tick completed");
        live
    }

    /// The launcher's next log line (the launcher must not have ended).
    pub fn next_line(&mut self) -> String {
        use std::io::BufRead;
        let mut line = String::new();
        let read = self.log.read_line(&mut line).expect("the launcher's log");
        assert!(read > 0, "the launcher ended early");
        line
    }

    /// Reads the launcher's log up to the first line containing `needle` and returns that line.
    pub fn wait_for(&mut self, needle: &str) -> String {
        loop {
            let line = self.next_line();
            if line.contains(needle) {
                return line;
            }
        }
    }

    /// Interrupts the run (Ctrl-C), checks that it ended as an interrupted run (exit 130) and left nothing.
    pub fn interrupt(mut self) {
        use std::io::BufRead;
        let pid = self.child.id();
        nix::sys::signal::kill(
            nix::unistd::Pid::from_raw(pid as i32),
            nix::sys::signal::Signal::SIGINT,
        )
        .expect("interrupt the launcher");
        let mut rest = String::new();
        while self.log.read_line(&mut rest).unwrap_or(0) > 0 {}
        let status = self.child.wait().expect("the launcher exits");
        assert_eq!(status.code(), Some(130), "{rest}");
        assert_nothing_left(pid);
        remove_run_leftovers(&format!("sw{pid:x}-"));
    }
}

impl Drop for LiveSwarm {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
            remove_run_leftovers(&format!("sw{:x}-", self.child.id()));
        }
    }
}

/// The `(what, robot)` of every entry of a run summary's `arrivals` made `by` (`schedule` or `ctl`), in order.
pub fn arrivals_by(summary: &serde_json::Value, by: &str) -> Vec<(String, u64)> {
    summary["arrivals"]
        .as_array()
        .map(Vec::as_slice)
        .unwrap_or_default()
        .iter()
        .filter(|a| a["by"] == by)
        .map(|a| {
            (
                a["what"].as_str().unwrap_or_default().to_owned(),
                a["robot"].as_u64().unwrap_or(u64::MAX),
            )
        })
        .collect()
}
