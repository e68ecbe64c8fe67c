//! `<framework><hosts>`: the machines a run's robots are placed on, and how the world talks to them.
//!
//! ```xml
//! <hosts listen="tcp/127.0.0.1:7447" lease_ms="1000">
//!   <host name="rack-a" weight="2" />
//!   <host name="rack-b" />
//! </hosts>
//! ```
//!
//! Attributes of `<hosts>`: `listen` (comma-separated zenoh endpoints the world listens on, default loopback),
//! `lease_ms` (how fast a frozen or cut-off host is noticed, default 1000), `zenoh_config` (a zenoh JSON5
//! configuration file to start from), `user` and `password_file` (zenoh user/password authentication),
//! `credentials_file` (the `user:password` lines the world accepts), and for `tls/...` endpoints
//! `tls_certificate` and `tls_private_key` (the world's PEM certificate and key) and `tls_root_ca` (mutual TLS: hosts
//! must present a certificate signed by this authority). Paths are relative to the experiment file.
//! Each `<host>` has a `name` (as given to `swarm host --name`) and an optional integer `weight` (default 1):
//! robots are shared in proportion to the weights. Without `<hosts>` every robot runs on the launcher's machine.
//!
//! The framework parser reads it with the rest of the configuration (every error located) into
//! [`Framework::hosts`](super::Framework::hosts).

use std::path::{Path, PathBuf};

use super::model::{Element, Location};
use super::values::Value;

/// Longest host name (it is one zenoh key chunk and part of log lines).
pub const MAX_HOST_NAME: usize = 64;

/// A name that cannot name a host.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid host name '{name}': use 1-64 ASCII letters, digits, '-' or '_'")]
pub struct InvalidHostName {
    /// The rejected name.
    pub name: String,
}

/// Checks that `name` can name a host: 1-64 ASCII letters, digits, `-` or `_`.
pub fn check_host_name(name: &str) -> Result<(), InvalidHostName> {
    let valid = !name.is_empty()
        && name.len() <= MAX_HOST_NAME
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_');
    if valid {
        Ok(())
    } else {
        Err(InvalidHostName {
            name: name.to_owned(),
        })
    }
}

/// The PEM files of a TLS link. On the listening side (the world) `certificate` and `private_key` identify the
/// world, and `root_ca` turns on mutual TLS: every host must present a certificate signed by it. On the
/// connecting side (a host) `root_ca` is what the world's certificate must be signed by, and `certificate` and
/// `private_key` identify the host for mutual TLS.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct TlsFiles {
    /// Certificate authority the other side's certificate must be signed by.
    pub root_ca: Option<PathBuf>,
    /// This side's certificate chain.
    pub certificate: Option<PathBuf>,
    /// This side's private key.
    pub private_key: Option<PathBuf>,
}

/// A TLS file that cannot be used.
#[derive(Debug, thiserror::Error)]
#[error("cannot read the TLS {role} {path}: {source}")]
pub struct TlsFileError {
    /// What the file is for (e.g. "certificate").
    pub role: &'static str,
    /// The file.
    pub path: PathBuf,
    /// The cause.
    #[source]
    pub source: std::io::Error,
}

impl TlsFiles {
    /// Checks that every file set can be read, so a wrong path is reported by name before zenoh starts.
    pub fn check_readable(&self) -> Result<(), TlsFileError> {
        let files = [
            ("root certificate authority", &self.root_ca),
            ("certificate", &self.certificate),
            ("private key", &self.private_key),
        ];
        for (role, path) in files {
            if let Some(path) = path {
                std::fs::File::open(path).map_err(|source| TlsFileError {
                    role,
                    path: path.clone(),
                    source,
                })?;
            }
        }
        Ok(())
    }
}

/// One `<host>`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HostEntry {
    /// Host name.
    pub name: String,
    /// Share weight (at least 1).
    pub weight: u32,
    /// Where the element is.
    pub location: Location,
}

/// The `<hosts>` element.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HostsConfig {
    /// Endpoints the world listens on (empty: the default loopback endpoint).
    pub listen: Vec<String>,
    /// Link lease in milliseconds, if set.
    pub lease_ms: Option<u64>,
    /// zenoh configuration file to start from.
    pub zenoh_config: Option<PathBuf>,
    /// zenoh user name.
    pub user: Option<String>,
    /// File holding the zenoh password.
    pub password_file: Option<PathBuf>,
    /// File of `user:password` lines the world accepts.
    pub credentials_file: Option<PathBuf>,
    /// The world's TLS certificate and key, and the authority hosts' certificates must be signed by.
    pub tls: TlsFiles,
    /// Folder of the hosts' keys (`<name>.key`), if set.
    pub keys: Option<PathBuf>,
    /// Whether authentication is off (`insecure="true"`: anyone who reaches the endpoint can speak).
    pub insecure: bool,
    /// The hosts, in file order.
    pub hosts: Vec<HostEntry>,
    /// Where the element is.
    pub location: Location,
}

const ATTRIBUTES: &[&str] = &[
    "listen",
    "lease_ms",
    "zenoh_config",
    "user",
    "password_file",
    "credentials_file",
    "tls_certificate",
    "tls_private_key",
    "tls_root_ca",
    "keys",
    "insecure",
];

/// Parses a `<hosts>` element; relative paths are resolved against `base`. Returns the element (when usable)
/// and every error found, located.
pub(crate) fn parse(el: &Element, base: &Path) -> (Option<HostsConfig>, Vec<(Location, String)>) {
    let mut errors = Vec::new();
    for (name, attribute) in &el.attributes {
        if !ATTRIBUTES.contains(&name.as_str()) {
            errors.push((
                attribute.location,
                format!(
                    "unknown attribute '{name}' in <hosts> (known: {})",
                    ATTRIBUTES.join(", ")
                ),
            ));
        }
    }
    let text = |name: &str| {
        el.attributes
            .get(name)
            .map(|a| (a.value.trim(), a.location))
    };
    let path = |name: &str| text(name).map(|(v, _)| base.join(v));
    let listen: Vec<String> = text("listen")
        .map(|(v, _)| {
            v.split(',')
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(str::to_owned)
                .collect()
        })
        .unwrap_or_default();
    if let Some((value, at)) = text("listen")
        && listen.iter().any(|e| !e.contains('/'))
    {
        errors.push((
            at,
            format!("invalid 'listen' in <hosts>: '{value}' is not a list of zenoh endpoints like tcp/127.0.0.1:7447"),
        ));
    }
    let lease_ms = text("lease_ms").and_then(|(v, at)| match v.parse::<u64>() {
        Ok(ms) if ms > 0 => Some(ms),
        _ => {
            errors.push((
                at,
                format!("'lease_ms' in <hosts> must be a whole number of milliseconds above 0, got '{v}'"),
            ));
            None
        }
    });
    if text("user").is_some() != text("password_file").is_some() {
        errors.push((
            el.location,
            "<hosts> needs both 'user' and 'password_file' for zenoh authentication, or neither"
                .into(),
        ));
    }
    if text("tls_certificate").is_some() != text("tls_private_key").is_some() {
        errors.push((
            el.location,
            "<hosts> needs both 'tls_certificate' and 'tls_private_key' for TLS, or neither".into(),
        ));
    }
    if let Some((_, at)) = text("tls_root_ca")
        && text("tls_certificate").is_none()
    {
        errors.push((
            at,
            "'tls_root_ca' in <hosts> asks hosts for certificates (mutual TLS), which needs the world's own \
             'tls_certificate' and 'tls_private_key'"
                .into(),
        ));
    }
    let insecure = text("insecure").is_some_and(|(v, at)| {
        bool::parse_value(v).unwrap_or_else(|e| {
            errors.push((at, format!("invalid 'insecure' in <hosts>: {e}")));
            false
        })
    });
    if insecure && text("keys").is_some() {
        errors.push((
            el.location,
            "<hosts> has both 'keys' and insecure=\"true\": keys authenticate hosts, insecure turns that off"
                .into(),
        ));
    }
    let mut hosts: Vec<HostEntry> = Vec::new();
    for child in &el.children {
        if child.name != "host" {
            errors.push((
                child.location,
                format!(
                    "unknown element <{}> in <hosts> (expected <host>)",
                    child.name
                ),
            ));
            continue;
        }
        if let Some(entry) = host(child, &mut errors) {
            if let Some(first) = hosts.iter().find(|h| h.name == entry.name) {
                errors.push((
                    child.location,
                    format!(
                        "host '{}' appears twice in <hosts> (first at {})",
                        entry.name, first.location
                    ),
                ));
            } else {
                hosts.push(entry);
            }
        }
    }
    if el.children.is_empty() {
        errors.push((el.location, "<hosts> lists no <host>".into()));
    }
    let config = HostsConfig {
        listen,
        lease_ms,
        zenoh_config: path("zenoh_config"),
        user: text("user").map(|(v, _)| v.to_owned()),
        password_file: path("password_file"),
        credentials_file: path("credentials_file"),
        tls: TlsFiles {
            root_ca: path("tls_root_ca"),
            certificate: path("tls_certificate"),
            private_key: path("tls_private_key"),
        },
        keys: path("keys"),
        insecure,
        hosts,
        location: el.location,
    };
    (Some(config), errors)
}

fn host(el: &Element, errors: &mut Vec<(Location, String)>) -> Option<HostEntry> {
    for (name, attribute) in &el.attributes {
        if name != "name" && name != "weight" {
            errors.push((
                attribute.location,
                format!("unknown attribute '{name}' in <host> (known: name, weight)"),
            ));
        }
    }
    let Some(name) = el.attributes.get("name") else {
        errors.push((el.location, "<host> is missing the attribute 'name'".into()));
        return None;
    };
    if let Err(e) = check_host_name(&name.value) {
        errors.push((name.location, e.to_string()));
        return None;
    }
    let weight = match el.attributes.get("weight") {
        None => 1,
        Some(w) => match w.value.trim().parse::<u32>() {
            Ok(weight) if weight > 0 => weight,
            _ => {
                errors.push((
                    w.location,
                    format!(
                        "'weight' in <host> must be a whole number above 0, got '{}'",
                        w.value
                    ),
                ));
                return None;
            }
        },
    };
    Some(HostEntry {
        name: name.value.clone(),
        weight,
        location: el.location,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::ConfigErrors;

    /// An experiment whose `<hosts>` starts on line 4, written into `dir`; returns its path.
    fn write_experiment(dir: &Path, hosts: &str) -> PathBuf {
        let path = dir.join("x.argos");
        let text = format!(
            "<argos-configuration>\n<framework>\n<experiment length=\"10\" ticks_per_second=\"10\" />\n{hosts}\n\
             </framework>\n{}\n</argos-configuration>\n",
            crate::config::TEST_SECTIONS
        );
        std::fs::write(&path, text).expect("write");
        path
    }

    fn read(path: &Path) -> Result<Option<HostsConfig>, ConfigErrors> {
        crate::config::Experiment::load(path).map(|(experiment, _)| experiment.framework.hosts)
    }

    fn load(hosts: &str) -> Result<Option<HostsConfig>, ConfigErrors> {
        let dir = tempfile::tempdir().expect("a temporary directory");
        read(&write_experiment(dir.path(), hosts))
    }

    #[test]
    fn host_names_are_one_zenoh_key_chunk() {
        for good in ["a", "host-1", "rack_2"] {
            assert!(check_host_name(good).is_ok(), "{good}");
        }
        for bad in ["", "a/b", "*", "a b", "h$", &"x".repeat(65)] {
            assert!(check_host_name(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn hosts_with_weights_and_paths_relative_to_the_experiment() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let path = write_experiment(
            dir.path(),
            r#"<hosts listen="tcp/10.0.0.1:7447, tcp/10.0.1.1:7447" lease_ms="800" user="swarm" password_file="pw">
                     <host name="a" weight="3" /><host name="b" /></hosts>"#,
        );
        let config = read(&path).expect("valid").expect("present");
        assert_eq!(config.listen, ["tcp/10.0.0.1:7447", "tcp/10.0.1.1:7447"]);
        assert_eq!(config.lease_ms, Some(800));
        assert_eq!(config.password_file, Some(dir.path().join("pw")));
        let shares: Vec<(&str, u32)> = config
            .hosts
            .iter()
            .map(|h| (h.name.as_str(), h.weight))
            .collect();
        assert_eq!(shares, [("a", 3), ("b", 1)]);
    }

    #[test]
    fn an_experiment_without_hosts_runs_locally() {
        assert_eq!(load("").expect("valid"), None);
    }

    #[test]
    fn bad_hosts_are_located_errors() {
        let errors = load("<hosts lease_ms=\"0\">\n<host name=\"a/b\" />\n<host name=\"c\" weight=\"-1\" />\n<host name=\"d\" /><host name=\"d\" /></hosts>")
        .expect_err("invalid");
        let text = errors.to_string();
        assert!(
            text.contains(":4:8: 'lease_ms' in <hosts> must be"),
            "{text}"
        );
        assert!(text.contains(":5:7: invalid host name 'a/b'"), "{text}");
        assert!(text.contains(":6:16: 'weight' in <host> must be"), "{text}");
        assert!(
            text.contains(":7:18: host 'd' appears twice in <hosts> (first at 7:1)"),
            "{text}"
        );
    }

    #[test]
    fn tls_files_are_relative_to_the_experiment() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let path = write_experiment(
            dir.path(),
            r#"<hosts listen="tls/10.0.0.1:7447" tls_certificate="pki/world.pem" tls_private_key="pki/world.key" tls_root_ca="pki/ca.pem"><host name="a" /></hosts>"#,
        );
        let config = read(&path).expect("valid").expect("present");
        assert_eq!(
            config.tls,
            TlsFiles {
                root_ca: Some(dir.path().join("pki/ca.pem")),
                certificate: Some(dir.path().join("pki/world.pem")),
                private_key: Some(dir.path().join("pki/world.key")),
            }
        );
    }

    #[test]
    fn incomplete_tls_settings_are_located_errors() {
        let errors = load("<hosts tls_certificate=\"w.pem\">\n<host name=\"a\" /></hosts>")
            .expect_err("invalid");
        let text = errors.to_string();
        assert!(
            text.contains(":4:1: <hosts> needs both 'tls_certificate' and 'tls_private_key'"),
            "{text}"
        );
        let errors =
            load("<hosts tls_root_ca=\"ca.pem\"><host name=\"a\" /></hosts>").expect_err("invalid");
        let text = errors.to_string();
        assert!(
            text.contains(
                ":4:8: 'tls_root_ca' in <hosts> asks hosts for certificates (mutual TLS)"
            ),
            "{text}"
        );
    }
}
