//! `swarm ctl`: driving a live run from another terminal through a Unix socket in its run directory.
//!
//! The launcher listens on `<run dir>/control.sock` while the run goes on. A client connects, writes one line
//! (`list`, `kill 3`, `freeze 3`, `thaw 3`) and reads the reply until the launcher closes the connection. The
//! socket thread only passes requests to the supervision loop, which owns the processes and answers; the socket
//! file is removed when the run ends. A run directory is found by its path, so no registry of runs is needed.

use std::fmt;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, Sender};
use std::time::Duration;

use swarm_contract::protocol::launcher_to_world::SpawnPose;
use swarm_contract::run_dir::CONTROL_SOCKET;

/// A request to the launcher of a live run.
#[derive(Debug, Clone, PartialEq)]
pub enum CtlCommand {
    /// Every robot with its agent's process id and state.
    List,
    /// SIGKILL the robot's agent.
    Kill(u32),
    /// SIGSTOP the robot's agent.
    Freeze(u32),
    /// SIGCONT the robot's agent.
    Thaw(u32),
    /// Make the named `swarm host` daemon of a multi-host run die.
    KillHost(String),
    /// Bring an absent robot into the arena (where it was configured to join, or at a pose).
    Spawn {
        /// The robot.
        robot: u32,
        /// Where, if not where the configuration put it.
        pose: Option<SpawnPose>,
    },
    /// Take a robot out of the run for good (its agent is stopped, its body leaves the arena).
    Remove(u32),
}

impl fmt::Display for CtlCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CtlCommand::List => write!(f, "list"),
            CtlCommand::Kill(r) => write!(f, "kill {r}"),
            CtlCommand::Freeze(r) => write!(f, "freeze {r}"),
            CtlCommand::Thaw(r) => write!(f, "thaw {r}"),
            CtlCommand::KillHost(host) => write!(f, "kill-host {host}"),
            CtlCommand::Spawn { robot, pose: None } => write!(f, "spawn {robot}"),
            CtlCommand::Spawn {
                robot,
                pose: Some(pose),
            } => write!(f, "spawn {robot} {pose}"),
            CtlCommand::Remove(r) => write!(f, "remove {r}"),
        }
    }
}

impl CtlCommand {
    /// Parses one request line.
    pub fn parse(line: &str) -> Result<CtlCommand, String> {
        let words: Vec<&str> = line.split_whitespace().collect();
        let robot = |r: &str| {
            r.parse::<u32>()
                .map_err(|_| format!("'{r}' is not a robot index"))
        };
        match words.as_slice() {
            ["list"] => Ok(CtlCommand::List),
            ["kill", r] => Ok(CtlCommand::Kill(robot(r)?)),
            ["freeze", r] => Ok(CtlCommand::Freeze(robot(r)?)),
            ["thaw", r] => Ok(CtlCommand::Thaw(robot(r)?)),
            ["kill-host", host] => Ok(CtlCommand::KillHost((*host).to_owned())),
            ["remove", r] => Ok(CtlCommand::Remove(robot(r)?)),
            ["spawn", r, rest @ ..] => Ok(CtlCommand::Spawn {
                robot: robot(r)?,
                pose: SpawnPose::parse_words(rest)?,
            }),
            _ => Err(format!(
                "unknown request '{line}': use list, kill <robot>, freeze <robot>, thaw <robot>, \
                 spawn <robot> [x y [heading]], remove <robot> or kill-host <host>"
            )),
        }
    }
}

/// A request waiting for the supervision loop's answer.
pub struct CtlRequest {
    /// What is asked.
    pub command: CtlCommand,
    reply: Sender<Result<String, String>>,
}

impl CtlRequest {
    /// Answers the client: `Ok` text, or `Err` reason (the client exits non-zero).
    pub fn answer(self, reply: Result<String, String>) {
        let _ = self.reply.send(reply);
    }
}

/// Why a `swarm ctl` request failed.
#[derive(Debug, thiserror::Error)]
pub enum CtlError {
    /// No live run listens there.
    #[error("no live run at {path}: {source} (is the run still going? give its run directory)")]
    NotRunning {
        /// The socket path.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The conversation failed.
    #[error("talking to the run at {path}: {source}")]
    Io {
        /// The socket path.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The launcher refused the request.
    #[error("{0}")]
    Refused(String),
}

/// The launcher's end: a listening socket and the requests that came in.
pub struct ControlServer {
    path: PathBuf,
    stop: Arc<AtomicBool>,
    requests: Receiver<CtlRequest>,
}

impl ControlServer {
    /// Listens on `<run_dir>/control.sock`; a request waits up to `reply_timeout` for the supervision loop's
    /// answer ([`Limits::ctl_reply_timeout_ms`](swarm_contract::limits::Limits)).
    pub fn listen(run_dir: &Path, reply_timeout: Duration) -> std::io::Result<ControlServer> {
        let path = run_dir.join(CONTROL_SOCKET);
        // A socket left by a killed launcher would make bind fail.
        let _ = std::fs::remove_file(&path);
        let listener = UnixListener::bind(&path)?;
        let (sender, requests) = mpsc::channel();
        let stop = Arc::new(AtomicBool::new(false));
        let stopping = Arc::clone(&stop);
        std::thread::spawn(move || {
            for stream in listener.incoming() {
                if stopping.load(Ordering::Acquire) {
                    break;
                }
                if let Ok(stream) = stream {
                    serve(stream, &sender, reply_timeout);
                }
            }
        });
        Ok(ControlServer {
            path,
            stop,
            requests,
        })
    }

    /// The requests that arrived so far.
    pub fn pending(&self) -> impl Iterator<Item = CtlRequest> + '_ {
        self.requests.try_iter()
    }
}

impl Drop for ControlServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        // Wakes the accepting thread so it sees the flag.
        let _ = UnixStream::connect(&self.path);
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Handles one connection: one request line, one answer.
fn serve(mut stream: UnixStream, requests: &Sender<CtlRequest>, reply_timeout: Duration) {
    let _ = stream.set_read_timeout(Some(reply_timeout));
    let mut line = String::new();
    let Ok(reader) = stream.try_clone() else {
        return;
    };
    if BufReader::new(reader).read_line(&mut line).is_err() || line.trim().is_empty() {
        return;
    }
    let answer = match CtlCommand::parse(line.trim()) {
        Err(reason) => Err(reason),
        Ok(command) => {
            let (reply, answer) = mpsc::channel();
            if requests.send(CtlRequest { command, reply }).is_err() {
                Err("the run is ending".to_owned())
            } else {
                answer
                    .recv_timeout(reply_timeout)
                    .unwrap_or_else(|_| Err("the launcher did not answer".to_owned()))
            }
        }
    };
    let text = match answer {
        Ok(text) => format!("ok\n{text}"),
        Err(reason) => format!("error\n{reason}\n"),
    };
    let _ = stream.write_all(text.as_bytes());
}

/// Sends `command` to the live run in `run` (its run directory, or the socket itself) and returns the answer.
pub fn request(run: &Path, command: CtlCommand) -> Result<String, CtlError> {
    let path = if run.is_dir() {
        run.join(CONTROL_SOCKET)
    } else {
        run.to_path_buf()
    };
    let mut stream = UnixStream::connect(&path).map_err(|source| CtlError::NotRunning {
        path: path.clone(),
        source,
    })?;
    let io = |source| CtlError::Io {
        path: path.clone(),
        source,
    };
    writeln!(stream, "{command}").map_err(io)?;
    let mut text = String::new();
    stream.read_to_string(&mut text).map_err(io)?;
    match text.split_once('\n') {
        Some(("ok", rest)) => Ok(rest.to_owned()),
        Some(("error", reason)) => Err(CtlError::Refused(reason.trim().to_owned())),
        _ => Err(CtlError::Refused(format!(
            "unexpected answer from {}: '{text}'",
            path.display()
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const REPLY_TIMEOUT: Duration = Duration::from_secs(10);

    #[test]
    fn a_request_reaches_the_supervision_loop_and_its_answer_the_client() {
        let dir = tempfile::tempdir().expect("temp dir");
        let server = ControlServer::listen(dir.path(), REPLY_TIMEOUT).expect("listening");
        let client = {
            let dir = dir.path().to_path_buf();
            std::thread::spawn(move || request(&dir, CtlCommand::Freeze(3)))
        };
        let request = server
            .requests
            .recv_timeout(REPLY_TIMEOUT)
            .expect("the request arrives");
        assert_eq!(request.command, CtlCommand::Freeze(3));
        request.answer(Ok("robot 3 frozen\n".into()));
        assert_eq!(
            client.join().expect("client").expect("answered"),
            "robot 3 frozen\n"
        );
        drop(server);
        assert!(
            !dir.path().join(CONTROL_SOCKET).exists(),
            "the socket is removed"
        );
    }

    #[test]
    fn every_request_parses_back_from_its_line() {
        for command in [
            CtlCommand::List,
            CtlCommand::Kill(3),
            CtlCommand::Freeze(3),
            CtlCommand::Thaw(3),
            CtlCommand::KillHost("beta".into()),
            CtlCommand::Spawn {
                robot: 9,
                pose: None,
            },
            CtlCommand::Spawn {
                robot: 9,
                pose: Some(SpawnPose {
                    x: -0.25,
                    y: 1.5,
                    heading_deg: Some(45.0),
                }),
            },
            CtlCommand::Remove(2),
        ] {
            assert_eq!(CtlCommand::parse(&command.to_string()), Ok(command));
        }
        assert!(
            CtlCommand::parse("spawn 9 1.0")
                .unwrap_err()
                .contains("optionally x y")
        );
        assert!(
            CtlCommand::parse("spawn 9 1.0 nan")
                .unwrap_err()
                .contains("'nan' is not a number")
        );
    }

    #[test]
    fn bad_requests_and_absent_runs_are_explained() {
        assert!(
            CtlCommand::parse("kill three")
                .unwrap_err()
                .contains("'three' is not a robot index")
        );
        let dir = tempfile::tempdir().expect("temp dir");
        let err = request(dir.path(), CtlCommand::List)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("no live run at"), "{err}");
    }
}
