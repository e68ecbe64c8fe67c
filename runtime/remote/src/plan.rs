//! Placing a run's robots on hosts: which machines (`--hosts` or the experiment's `<hosts>`), how many robots each
//! gets (in proportion to its weight), and the zenoh settings the world listens with.
//!
//! A run without hosts resolves to `None` and never touches zenoh. The launcher uses the plan to start no local
//! agents and to pass the flags on; the world resolves the same plan from the same flags and configuration, so
//! both always agree on the placement.

use std::path::PathBuf;
use std::time::Duration;

use clap::Args;

use crate::auth::HostKeys;
use crate::session::{DEFAULT_LEASE, DEFAULT_LISTEN, ZenohOptions};
use crate::world_bridge::HostShare;
use swarm_contract::config::hosts::TlsFileError;
use swarm_contract::config::hosts::{HostsConfig, check_host_name};

/// Flags of `swarm run` and of the world process that place robots on hosts.
#[derive(Debug, Clone, Default, PartialEq, Eq, Args)]
pub struct HostsArgs {
    /// Run the robots on these `swarm host` daemons instead of locally: NAME[:WEIGHT],... (overrides the
    /// experiment's <hosts> list; robots are shared in proportion to the weights, default 1).
    #[arg(long)]
    pub hosts: Option<String>,
    /// zenoh endpoint the world listens on for hosts, e.g. tcp/10.0.0.1:7447 (repeatable; overrides
    /// <hosts listen>; default tcp/127.0.0.1:7447).
    #[arg(long = "listen")]
    pub listen: Vec<String>,
    /// Folder of the hosts' keys, one `<name>.key` per host (overrides <hosts keys>; default
    /// ~/.config/swarm/keys). A missing key is created there; give it to its host (`swarm host --key`).
    #[arg(long = "keys", value_name = "DIR")]
    pub keys: Option<PathBuf>,
    /// Turn host authentication off: anyone who can reach the world's endpoint can then join, listen in and
    /// command robots. Only for a network you trust (the same as <hosts insecure="true">).
    #[arg(long = "insecure-hosts", conflicts_with = "keys")]
    pub insecure_hosts: bool,
}

impl HostsArgs {
    /// The flags as a command line.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = Vec::new();
        if let Some(hosts) = &self.hosts {
            args.extend(["--hosts".into(), hosts.clone()]);
        }
        for endpoint in &self.listen {
            args.extend(["--listen".into(), endpoint.clone()]);
        }
        if let Some(dir) = &self.keys {
            args.extend(["--keys".into(), dir.display().to_string()]);
        }
        if self.insecure_hosts {
            args.push("--insecure-hosts".into());
        }
        args
    }
}

/// Why the hosts of a run cannot be resolved.
#[derive(Debug, thiserror::Error)]
pub enum HostsError {
    /// `--hosts` is malformed.
    #[error("--hosts {value}: {reason}")]
    Flag {
        /// The flag's value.
        value: String,
        /// What is wrong.
        reason: String,
    },
    /// The password file cannot be read.
    #[error("reading the zenoh password file {path}: {source}")]
    Password {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A TLS file cannot be read.
    #[error("{0}")]
    TlsFile(#[from] TlsFileError),
    /// Authentication is on and there is no key folder.
    #[error(
        "no folder for the hosts' keys: pass --keys DIR (or <hosts keys=\"DIR\">), set HOME, or turn \
         authentication off with --insecure-hosts on a trusted network"
    )]
    NoKeyFolder,
    /// A key cannot be read or created.
    #[error(transparent)]
    Key(#[from] crate::auth::KeyError),
    /// The world is to listen on a `tls/...` endpoint without a certificate.
    #[error(
        "the world listens on {endpoint}, which needs the experiment's <hosts tls_certificate=\"…\" tls_private_key=\"…\">"
    )]
    TlsWithoutCertificate {
        /// The endpoint.
        endpoint: String,
    },
}

/// One host and its share weight.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WeightedHost {
    /// Host name.
    pub name: String,
    /// Share weight, at least 1.
    pub weight: u32,
}

/// How the hosts of a run prove who they are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Authentication {
    /// Each host has a key in this folder (`<name>.key`), see [`crate::auth`].
    Keys(PathBuf),
    /// Off: anyone who reaches the endpoint can speak.
    Off,
}

/// The hosts of a run and how to reach them.
#[derive(Debug, Clone)]
pub struct HostsPlan {
    /// The hosts, in order.
    pub hosts: Vec<WeightedHost>,
    /// Endpoints the world listens on.
    pub listen: Vec<String>,
    /// Session settings.
    pub zenoh: ZenohOptions,
    /// How hosts are authenticated.
    pub authentication: Authentication,
}

/// Parses `NAME[:WEIGHT],...`.
pub fn parse_hosts_flag(value: &str) -> Result<Vec<WeightedHost>, HostsError> {
    let flag_error = |reason: String| HostsError::Flag {
        value: value.to_owned(),
        reason,
    };
    let mut hosts: Vec<WeightedHost> = Vec::new();
    for item in value.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (name, weight) = match item.split_once(':') {
            Some((name, weight)) => {
                let weight = weight
                    .parse::<u32>()
                    .ok()
                    .filter(|w| *w > 0)
                    .ok_or_else(|| {
                        flag_error(format!(
                            "weight '{weight}' of '{name}' must be a whole number above 0"
                        ))
                    })?;
                (name, weight)
            }
            None => (item, 1),
        };
        check_host_name(name).map_err(|e| flag_error(e.to_string()))?;
        if hosts.iter().any(|h| h.name == name) {
            return Err(flag_error(format!("host '{name}' is listed twice")));
        }
        hosts.push(WeightedHost {
            name: name.to_owned(),
            weight,
        });
    }
    if hosts.is_empty() {
        return Err(flag_error("no host named".into()));
    }
    Ok(hosts)
}

impl HostsPlan {
    /// The plan of a run: `--hosts` over the experiment's `<hosts>` (`element`, as the configuration parser read
    /// it); `None` when neither names a host (a local run).
    pub fn resolve(
        element: Option<&HostsConfig>,
        args: &HostsArgs,
    ) -> Result<Option<HostsPlan>, HostsError> {
        let hosts = match (&args.hosts, element) {
            (Some(flag), _) => parse_hosts_flag(flag)?,
            (None, Some(element)) => element
                .hosts
                .iter()
                .map(|h| WeightedHost {
                    name: h.name.clone(),
                    weight: h.weight,
                })
                .collect(),
            (None, None) => return Ok(None),
        };
        let mut listen = if args.listen.is_empty() {
            element.map(|e| e.listen.clone()).unwrap_or_default()
        } else {
            args.listen.clone()
        };
        if listen.is_empty() {
            listen.push(DEFAULT_LISTEN.to_owned());
        }
        let mut zenoh = ZenohOptions::default();
        if let Some(element) = element {
            zenoh.lease = element
                .lease_ms
                .map_or(DEFAULT_LEASE, Duration::from_millis);
            zenoh.config_file = element.zenoh_config.clone();
            zenoh.user = element.user.clone();
            zenoh.credentials_file = element.credentials_file.clone();
            zenoh.tls = element.tls.clone();
            if let Some(path) = element.password_file.clone() {
                let text = std::fs::read_to_string(&path)
                    .map_err(|source| HostsError::Password { path, source })?;
                zenoh.password = Some(text.trim_end_matches(['\r', '\n']).to_owned());
            }
        }
        if let Some(endpoint) = listen.iter().find(|e| e.starts_with("tls/"))
            && zenoh.tls.certificate.is_none()
        {
            return Err(HostsError::TlsWithoutCertificate {
                endpoint: endpoint.clone(),
            });
        }
        zenoh.tls.check_readable()?;
        let insecure = args.insecure_hosts || element.is_some_and(|e| e.insecure);
        let authentication = if insecure {
            Authentication::Off
        } else {
            let dir = args
                .keys
                .clone()
                .or_else(|| element.and_then(|e| e.keys.clone()))
                .or_else(crate::auth::default_key_dir)
                .ok_or(HostsError::NoKeyFolder)?;
            Authentication::Keys(dir)
        };
        Ok(Some(HostsPlan {
            hosts,
            listen,
            zenoh,
            authentication,
        }))
    }

    /// Creates the keys of the plan's hosts that do not exist yet (the launcher does, before the world starts);
    /// returns the files created, which the operator hands to their hosts.
    pub fn create_missing_keys(&self) -> Result<Vec<PathBuf>, HostsError> {
        match &self.authentication {
            Authentication::Keys(dir) => Ok(crate::auth::create_missing_keys(
                dir,
                self.hosts.iter().map(|h| h.name.as_str()),
            )?),
            Authentication::Off => Ok(Vec::new()),
        }
    }

    /// Reads the hosts' keys for the world, and has its session admit exactly those hosts.
    pub fn load_keys(&mut self) -> Result<HostKeys, HostsError> {
        let keys = match &self.authentication {
            Authentication::Keys(dir) => {
                HostKeys::load(dir, self.hosts.iter().map(|h| h.name.as_str()))?
            }
            Authentication::Off => HostKeys::Off,
        };
        self.zenoh.admitted = keys.admitted();
        Ok(keys)
    }

    /// Shares `robots` robots among the hosts in proportion to their weights (largest remainder, ties to the
    /// earlier host), each host getting a contiguous range of robot ids. Hosts left with no robot are omitted.
    pub fn place(&self, robots: u32) -> Vec<HostShare> {
        place(robots, &self.hosts)
    }
}

/// See [`HostsPlan::place`].
pub fn place(robots: u32, hosts: &[WeightedHost]) -> Vec<HostShare> {
    let total: u64 = hosts.iter().map(|h| u64::from(h.weight)).sum();
    if total == 0 {
        return Vec::new();
    }
    let quota = |h: &WeightedHost| u64::from(robots) * u64::from(h.weight);
    let mut counts: Vec<u64> = hosts.iter().map(|h| quota(h) / total).collect();
    let mut left = u64::from(robots) - counts.iter().sum::<u64>();
    let mut order: Vec<usize> = (0..hosts.len()).collect();
    // Largest remainder first; the sort is stable, so ties go to the earlier host.
    order.sort_by_key(|&i| std::cmp::Reverse(quota(&hosts[i]) % total));
    for &i in order.iter().cycle() {
        if left == 0 {
            break;
        }
        counts[i] += 1;
        left -= 1;
    }
    let mut next = 0u32;
    hosts
        .iter()
        .zip(counts)
        .filter(|(_, count)| *count > 0)
        .map(|(host, count)| {
            let count = count as u32;
            let share = HostShare {
                name: host.name.clone(),
                robots: (next..next + count).collect(),
            };
            next += count;
            share
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    use swarm_contract::config::Experiment;

    fn hosts(spec: &str) -> Vec<WeightedHost> {
        parse_hosts_flag(spec).expect("valid")
    }

    fn sizes(shares: &[HostShare]) -> Vec<(String, usize)> {
        shares
            .iter()
            .map(|s| (s.name.clone(), s.robots.len()))
            .collect()
    }

    #[test]
    fn robots_are_shared_in_proportion_to_weights_in_contiguous_ranges() {
        let shares = place(10, &hosts("a:2,b:3"));
        assert_eq!(shares[0].robots, (0..4).collect::<Vec<_>>());
        assert_eq!(shares[1].robots, (4..10).collect::<Vec<_>>());
    }

    #[test]
    fn remainders_go_to_the_largest_fraction_then_the_earlier_host() {
        assert_eq!(
            sizes(&place(10, &hosts("a,b,c"))),
            [("a".into(), 4), ("b".into(), 3), ("c".into(), 3)]
        );
        assert_eq!(
            sizes(&place(7, &hosts("a:1,b:2"))),
            [("a".into(), 2), ("b".into(), 5)]
        );
    }

    #[test]
    fn a_host_left_without_robots_is_not_waited_for() {
        assert_eq!(sizes(&place(1, &hosts("a,b"))), [("a".into(), 1)]);
    }

    /// The `<hosts>` of an experiment written into `dir`, as the configuration parser reads it.
    fn experiment(dir: &Path, hosts: &str) -> Option<HostsConfig> {
        let path = dir.join("x.argos");
        let text = format!(
            "<argos-configuration><framework><experiment length=\"1\" ticks_per_second=\"10\" />{hosts}\
             </framework><controllers><test_controller id=\"c\" library=\"agent\"><actuators/><sensors/>\
             <params/></test_controller></controllers><arena size=\"1,1,1\" center=\"0,0,0.5\"/>\
             <physics_engines><dynamics2d id=\"d\"/></physics_engines><media/></argos-configuration>"
        );
        std::fs::write(&path, text).expect("write");
        let (experiment, _) = Experiment::load(&path).expect("a valid experiment");
        experiment.framework.hosts
    }

    #[test]
    fn a_run_without_hosts_is_local_and_the_flag_overrides_the_experiments_list() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let local = experiment(dir.path(), "");
        assert!(
            HostsPlan::resolve(local.as_ref(), &HostsArgs::default())
                .expect("valid")
                .is_none()
        );

        std::fs::write(dir.path().join("pw"), "secret\n").expect("write");
        let config = experiment(
            dir.path(),
            r#"<hosts listen="tcp/10.0.0.1:7447" lease_ms="700" user="swarm" password_file="pw"><host name="a" /></hosts>"#,
        );
        let plan = HostsPlan::resolve(config.as_ref(), &HostsArgs::default())
            .expect("valid")
            .expect("hosts");
        assert_eq!(plan.hosts, hosts("a"));
        assert_eq!(plan.listen, ["tcp/10.0.0.1:7447"]);
        assert_eq!(plan.zenoh.lease, Duration::from_millis(700));
        assert_eq!(plan.zenoh.password.as_deref(), Some("secret"));

        let args = HostsArgs {
            hosts: Some("b:2,c".into()),
            listen: vec!["tcp/127.0.0.1:9000".into()],
            ..HostsArgs::default()
        };
        let plan = HostsPlan::resolve(config.as_ref(), &args)
            .expect("valid")
            .expect("hosts");
        assert_eq!(plan.hosts, hosts("b:2,c"));
        assert_eq!(plan.listen, ["tcp/127.0.0.1:9000"]);
        assert_eq!(
            plan.zenoh.lease,
            Duration::from_millis(700),
            "the other attributes still apply"
        );
    }

    #[test]
    fn malformed_hosts_flags_say_what_is_wrong() {
        for (flag, expected) in [
            ("a:0", "weight '0' of 'a' must be a whole number above 0"),
            ("a,a", "host 'a' is listed twice"),
            ("a/b", "invalid host name 'a/b'"),
            (",", "no host named"),
        ] {
            let err = parse_hosts_flag(flag).expect_err(flag).to_string();
            assert!(err.contains(expected), "{flag}: {err}");
        }
    }

    #[test]
    fn tls_endpoints_need_a_readable_certificate() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let plain = experiment(dir.path(), r#"<hosts><host name="a" /></hosts>"#);
        let args = HostsArgs {
            hosts: None,
            listen: vec!["tls/127.0.0.1:9000".into()],
            ..HostsArgs::default()
        };
        let err = HostsPlan::resolve(plain.as_ref(), &args)
            .expect_err("no certificate")
            .to_string();
        assert!(
            err.contains("the world listens on tls/127.0.0.1:9000, which needs"),
            "{err}"
        );

        let missing = experiment(
            dir.path(),
            r#"<hosts listen="tls/127.0.0.1:9000" tls_certificate="w.pem" tls_private_key="w.key"><host name="a" /></hosts>"#,
        );
        let err = HostsPlan::resolve(missing.as_ref(), &HostsArgs::default())
            .expect_err("missing files")
            .to_string();
        assert!(
            err.contains(&format!(
                "cannot read the TLS certificate {}",
                dir.path().join("w.pem").display()
            )),
            "{err}"
        );
    }
}
