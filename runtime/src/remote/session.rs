//! Opening the zenoh sessions of a multi-host run: the world listens, each host daemon connects to it.
//!
//! Multicast scouting is off and every endpoint is explicit, so nothing is discovered by accident (hosts are
//! clients, so the world's peer gossip never reaches them). The world runs in
//! peer mode and listens (loopback by default); hosts run in client mode and connect to one of its endpoints,
//! retrying every second while it is unreachable (so a host whose network came back rejoins by itself). The link
//! lease decides how fast a frozen or cut-off host is noticed (default 1 s; a killed one is noticed in
//! milliseconds, when its TCP connection closes). A zenoh configuration file can supply anything else (e.g. TLS
//! when zenoh is built with `transport_tls`); user/password authentication is set here.

use std::path::PathBuf;
use std::time::Duration;

use zenoh::{Config, Session, Wait};

use super::RemoteError;

/// Default link lease: a frozen or cut-off host is noticed after about this long.
pub const DEFAULT_LEASE: Duration = Duration::from_secs(1);
/// Default endpoint the world listens on (loopback only).
pub const DEFAULT_LISTEN: &str = "tcp/127.0.0.1:7447";

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
}

impl Default for ZenohOptions {
    fn default() -> Self {
        ZenohOptions {
            config_file: None,
            lease: DEFAULT_LEASE,
            user: None,
            password: None,
            credentials_file: None,
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

impl ZenohOptions {
    /// The zenoh configuration for `mode` with our common settings.
    fn config(&self, mode: &str) -> Result<Config, RemoteError> {
        let mut config = match &self.config_file {
            Some(path) => Config::from_file(path).map_err(zenoh_error(format!(
                "reading the zenoh configuration {}",
                path.display()
            )))?,
            None => Config::default(),
        };
        let lease_ms = self.lease.as_millis().max(1);
        let mut set = |key: &str, value: String| {
            config
                .insert_json5(key, &value)
                .map_err(zenoh_error(format!("setting zenoh's {key} to {value}")))
        };
        set("mode", json(mode))?;
        set("scouting/multicast/enabled", "false".into())?;
        set("transport/link/tx/lease", lease_ms.to_string())?;
        set(
            "connect/retry",
            r#"{"period_init_ms": 250, "period_max_ms": 1000, "period_increase_factor": 2}"#.into(),
        )?;
        if let Some(user) = &self.user {
            set("transport/auth/usrpwd/user", json(user))?;
        }
        if let Some(password) = &self.password {
            set("transport/auth/usrpwd/password", json(password))?;
        }
        if let Some(file) = &self.credentials_file {
            set(
                "transport/auth/usrpwd/dictionary_file",
                json(&file.display().to_string()),
            )?;
        }
        Ok(config)
    }

    /// The world's session: peer mode, listening on `listen` (e.g. `tcp/127.0.0.1:7447`).
    pub fn open_world(&self, listen: &[String]) -> Result<Session, RemoteError> {
        let mut config = self.config("peer")?;
        let endpoints = serde_json::to_string(listen).unwrap_or_else(|_| "[]".into());
        config
            .insert_json5("listen/endpoints", &endpoints)
            .map_err(zenoh_error(format!("listening on {endpoints}")))?;
        config
            .insert_json5("connect/endpoints", "[]")
            .map_err(zenoh_error("clearing connect endpoints"))?;
        zenoh::open(config).wait().map_err(zenoh_error(format!(
            "opening the world's session on {endpoints}"
        )))
    }

    /// A host's session: client mode, connected to `endpoint` (retried until it answers).
    pub fn open_host(&self, endpoint: &str) -> Result<Session, RemoteError> {
        let mut config = self.config("client")?;
        let endpoints = serde_json::to_string(&[endpoint]).unwrap_or_else(|_| "[]".into());
        let mut set = |key: &str, value: &str| {
            config
                .insert_json5(key, value)
                .map_err(zenoh_error(format!("setting zenoh's {key} to {value}")))
        };
        set("connect/endpoints", &endpoints)?;
        set("listen/endpoints", "[]")?;
        set("connect/timeout_ms", "-1")?;
        set("connect/exit_on_failure", "false")?;
        zenoh::open(config)
            .wait()
            .map_err(zenoh_error(format!("connecting to {endpoint}")))
    }
}
