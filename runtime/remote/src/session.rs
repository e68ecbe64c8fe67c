//! Opening the zenoh sessions of a multi-host run: the world listens, each host daemon connects to it.
//!
//! Multicast scouting is off and every endpoint is explicit, so nothing is discovered by accident (hosts are
//! clients, so the world's peer gossip never reaches them). The world runs in
//! peer mode and listens (loopback by default); hosts run in client mode and connect to one of its endpoints,
//! retrying every second while it is unreachable (so a host whose network came back rejoins by itself). The link
//! lease decides how fast a frozen or cut-off host is noticed (default 1 s; a killed one is noticed in
//! milliseconds, when its TCP connection closes). User/password authentication and TLS certificates are set
//! here; a zenoh configuration file can supply anything else.

use std::path::PathBuf;
use std::time::Duration;

use swarm_contract::config::hosts::TlsFiles;
use zenoh::{Config, Session, Wait};

use super::RemoteError;

/// Default link lease: a frozen or cut-off host is noticed after about this long.
pub const DEFAULT_LEASE: Duration = Duration::from_secs(1);
/// Largest credentials file read.
const MAX_CREDENTIALS_BYTES: u64 = 1 << 20;
/// Default endpoint the world listens on (loopback only).
pub const DEFAULT_LISTEN: &str = "tcp/127.0.0.1:7447";
/// The environment variable zenoh reads the layout of its async runtimes from.
pub const ZENOH_RUNTIME_ENV: &str = "ZENOH_RUNTIME";
/// zenoh's receiving, sending, accepting and network work handed over to its application runtime, which has one
/// worker thread.
const ONE_RUNTIME: &str =
    "(rx: (handover: app), tx: (handover: app), acc: (handover: app), net: (handover: app))";

/// Makes zenoh run all its work on one thread unless `ZENOH_RUNTIME` already says otherwise, and checks a layout
/// the user set there: zenoh would panic on one it cannot parse.
///
/// By default zenoh spreads its work over five runtimes with six threads. A batch then crossed two threads on its
/// way in (the thread watching the socket handed it to a receiving worker, which also woke the second receiving
/// worker) and one on its way out, each a wake-up of some 20 us on the critical path of every tick. On one
/// thread the thread that sees the socket readable reads the batch and runs the callback. docs/hosts.md,
/// "Latency", has the measurement.
///
/// # Safety
///
/// It sets an environment variable and the panic hook for a moment: call it before the process starts its
/// second thread.
pub unsafe fn configure_zenoh_runtime() -> Result<(), RemoteError> {
    let Some(layout) = std::env::var_os(ZENOH_RUNTIME_ENV) else {
        // SAFETY: the caller guarantees that no other thread runs yet.
        unsafe { std::env::set_var(ZENOH_RUNTIME_ENV, ONE_RUNTIME) };
        return Ok(());
    };
    let invalid = |detail: String| RemoteError::Zenoh {
        action: format!("reading {ZENOH_RUNTIME_ENV}={}", layout.to_string_lossy()),
        detail,
    };
    if layout.to_str().is_none() {
        return Err(invalid("not UTF-8".into()));
    }
    // zenoh parses the variable once, in a lazily initialised static that unwraps the result: parse it now, with
    // the panic caught and kept quiet, and say what is wrong instead.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let parsed = std::panic::catch_unwind(|| {
        let _ = &*zenoh_runtime::ZRUNTIME_PARAM;
    });
    std::panic::set_hook(hook);
    parsed.map_err(|panic| {
        let message = panic
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| panic.downcast_ref::<&str>().map(|s| (*s).to_owned()))
            .unwrap_or_default();
        let detail = message
            .trim_start_matches("called `Result::unwrap()` on an `Err` value: ")
            .to_owned();
        invalid(format!(
            "not a zenoh runtime layout ({detail}); e.g. {ONE_RUNTIME}"
        ))
    })
}

/// What every zenoh session of a multi-host run is configured with.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ZenohOptions {
    /// A zenoh configuration file (JSON5) to start from; our settings are applied on top.
    pub config_file: Option<PathBuf>,
    /// Link lease: how long a silent peer stays alive.
    pub lease: Duration,
    /// User name for zenoh's user/password authentication (with `password`).
    pub user: Option<String>,
    /// Password for zenoh's user/password authentication.
    pub password: Option<String>,
    /// File of `user:password` lines the listening side accepts (zenoh's `dictionary_file`).
    pub credentials_file: Option<PathBuf>,
    /// More `(user, password)` pairs the listening side accepts: the hosts' admission passwords
    /// ([`crate::auth`]).
    pub admitted: Vec<(String, String)>,
    /// Certificates for `tls/...` endpoints.
    pub tls: TlsFiles,
}

impl Default for ZenohOptions {
    fn default() -> Self {
        ZenohOptions {
            config_file: None,
            lease: DEFAULT_LEASE,
            user: None,
            password: None,
            credentials_file: None,
            admitted: Vec::new(),
            tls: TlsFiles::default(),
        }
    }
}

/// Wraps a zenoh error with what was being done.
pub(super) fn zenoh_error(action: impl Into<String>) -> impl FnOnce(zenoh::Error) -> RemoteError {
    let action = action.into();
    move |e| RemoteError::Zenoh {
        action,
        detail: e.to_string(),
    }
}

/// A JSON string literal.
fn json(s: &str) -> String {
    serde_json::Value::String(s.to_owned()).to_string()
}

/// A path as a JSON string literal.
fn json_path(path: &std::path::Path) -> String {
    json(&path.display().to_string())
}

/// Sets one key of a zenoh configuration, saying which on failure.
fn set(config: &mut Config, key: &str, value: &str) -> Result<(), RemoteError> {
    config
        .insert_json5(key, value)
        .map_err(zenoh_error(format!("setting zenoh's {key} to {value}")))
}

/// Which end of a link the TLS files are for.
#[derive(Clone, Copy)]
enum TlsSide {
    Listen,
    Connect,
}

const TLS: &str = "transport/link/tls";

impl ZenohOptions {
    /// The zenoh configuration for `mode` with our common settings.
    fn config(&self, mode: &str, side: TlsSide) -> Result<Config, RemoteError> {
        let mut config = match &self.config_file {
            Some(path) => Config::from_file(path).map_err(zenoh_error(format!(
                "reading the zenoh configuration {}",
                path.display()
            )))?,
            None => Config::default(),
        };
        let lease_ms = self.lease.as_millis().max(1);
        set(&mut config, "mode", &json(mode))?;
        set(&mut config, "scouting/multicast/enabled", "false")?;
        set(
            &mut config,
            "transport/link/tx/lease",
            &lease_ms.to_string(),
        )?;
        set(
            &mut config,
            "connect/retry",
            r#"{"period_init_ms": 250, "period_max_ms": 1000, "period_increase_factor": 2}"#,
        )?;
        if let Some(user) = &self.user {
            set(&mut config, "transport/auth/usrpwd/user", &json(user))?;
        }
        if let Some(password) = &self.password {
            // Not through `set`: its error would quote the password.
            config
                .insert_json5("transport/auth/usrpwd/password", &json(password))
                .map_err(zenoh_error("setting zenoh's password"))?;
        }
        if let Some(file) = &self.credentials_file {
            set(
                &mut config,
                "transport/auth/usrpwd/dictionary_file",
                &json_path(file),
            )?;
        }
        self.set_tls(&mut config, side)?;
        Ok(config)
    }

    /// The TLS files as zenoh's `transport/link/tls` settings for one end of the link.
    fn set_tls(&self, config: &mut Config, side: TlsSide) -> Result<(), RemoteError> {
        let tls = &self.tls;
        let (certificate, private_key) = match side {
            TlsSide::Listen => ("listen_certificate", "listen_private_key"),
            TlsSide::Connect => ("connect_certificate", "connect_private_key"),
        };
        // zenoh asks for (listening) or presents (connecting) a client certificate only with `enable_mtls`.
        let mutual = match side {
            TlsSide::Listen => tls.root_ca.is_some(),
            TlsSide::Connect => tls.certificate.is_some(),
        };
        if mutual {
            set(config, &format!("{TLS}/enable_mtls"), "true")?;
        }
        if let Some(path) = &tls.root_ca {
            set(
                config,
                &format!("{TLS}/root_ca_certificate"),
                &json_path(path),
            )?;
        }
        if let Some(path) = &tls.certificate {
            set(config, &format!("{TLS}/{certificate}"), &json_path(path))?;
        }
        if let Some(path) = &tls.private_key {
            set(config, &format!("{TLS}/{private_key}"), &json_path(path))?;
        }
        Ok(())
    }

    /// The world's session: peer mode, listening on `listen` (e.g. `tcp/127.0.0.1:7447`).
    pub fn open_world(&self, listen: &[String]) -> Result<Session, RemoteError> {
        let mut config = self.config("peer", TlsSide::Listen)?;
        // zenoh reads its accepted users from a file when the session opens: the hosts' admission passwords go
        // into a private temporary file (with the operator's own credentials file, if any), removed once open.
        let _dictionary = match self.admitted.is_empty() {
            true => None,
            false => {
                let file = self.write_dictionary()?;
                set(
                    &mut config,
                    "transport/auth/usrpwd/dictionary_file",
                    &json_path(file.path()),
                )?;
                Some(file)
            }
        };
        let endpoints = serde_json::to_string(listen).unwrap_or_else(|_| "[]".into());
        set(&mut config, "listen/endpoints", &endpoints)?;
        set(&mut config, "connect/endpoints", "[]")?;
        zenoh::open(config).wait().map_err(zenoh_error(format!(
            "opening the world's session on {endpoints}"
        )))
    }

    /// The accepted `user:password` lines, the credentials file's first, in a file only this user can read.
    fn write_dictionary(&self) -> Result<tempfile::NamedTempFile, RemoteError> {
        let io = |what: String| move |source| RemoteError::Io { what, source };
        let mut text = match &self.credentials_file {
            Some(path) => swarm_contract::config::input::read_text(path, MAX_CREDENTIALS_BYTES)
                .map_err(|e| RemoteError::Io {
                    what: "reading the credentials file".into(),
                    source: std::io::Error::other(e.to_string()),
                })?,
            None => String::new(),
        };
        if !text.is_empty() && !text.ends_with('\n') {
            text.push('\n');
        }
        for (user, password) in &self.admitted {
            text.push_str(&format!("{user}:{password}\n"));
        }
        // NamedTempFile creates its file readable by its owner only.
        let mut file = tempfile::NamedTempFile::new()
            .map_err(io("creating the hosts' admission file".into()))?;
        std::io::Write::write_all(&mut file, text.as_bytes())
            .map_err(io("writing the hosts' admission file".into()))?;
        Ok(file)
    }

    /// A host's session: client mode, connected to `endpoint` (retried until it answers).
    pub fn open_host(&self, endpoint: &str) -> Result<Session, RemoteError> {
        let mut config = self.config("client", TlsSide::Connect)?;
        let endpoints = serde_json::to_string(&[endpoint]).unwrap_or_else(|_| "[]".into());
        set(&mut config, "connect/endpoints", &endpoints)?;
        set(&mut config, "listen/endpoints", "[]")?;
        set(&mut config, "connect/timeout_ms", "-1")?;
        set(&mut config, "connect/exit_on_failure", "false")?;
        zenoh::open(config)
            .wait()
            .map_err(zenoh_error(format!("connecting to {endpoint}")))
    }
}
