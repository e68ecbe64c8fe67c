//! Securing the link between the world and its hosts: zenoh user/password authentication and mutual TLS, with
//! real `swarm host` daemons on loopback (who may join is a property of the zenoh link, not of the network layout,
//! so these tests need no namespaces). Each test runs the experiment once with a host that holds the right
//! credentials, which must join and run its share, and once with one that does not, which must never connect.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::time::Duration;

use rcgen::{BasicConstraints, CertificateParams, DnType, IsCa, Issuer, KeyPair};
use swarm_system_tests::{HostDaemon, TestKeys, assert_clean, free_port, swarm, workspace_file};

const EXPERIMENT: &str = "configs/obstacle_avoidance/obstacle_avoidance.argos";
/// How long the refused run waits for its host: long enough for many connection attempts.
const REFUSED_JOIN_TIMEOUT_MS: &str = "8000";
/// Bound for a daemon to connect (process start-up under a loaded machine).
const CONNECT_TIMEOUT: Duration = Duration::from_secs(120);

/// Writes a copy of the obstacle-avoidance experiment into `dir` with `hosts` as its `<framework><hosts>` and its
/// models named by absolute path, so the copy runs from anywhere.
fn experiment_with_hosts(dir: &Path, hosts: &str) -> PathBuf {
    let text = std::fs::read_to_string(workspace_file(EXPERIMENT)).expect("the experiment");
    let models = workspace_file("configs/obstacle_avoidance/models/ptsct");
    let text = text
        .replacen("<framework>", &format!("<framework>\n    {hosts}"), 1)
        .replace(
            r#"supervisors="models/ptsct""#,
            &format!(r#"supervisors="{}""#, models.display()),
        );
    let path = dir.join("secured.argos");
    std::fs::write(&path, text).expect("write the experiment");
    path
}

/// Writes `text` to `dir/name` and returns the path.
fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap_or_else(|e| panic!("writing {name}: {e}"));
    path
}

/// Runs `experiment` on the host `name` with extra flags; returns whether it succeeded and its stderr.
fn run_on(experiment: &Path, name: &str, keys: &TestKeys, flags: &[&str]) -> (bool, String) {
    let out = tempfile::tempdir().expect("a temporary directory");
    let experiment = experiment.display().to_string();
    let out_dir = out.path().display().to_string();
    let mut args = vec![
        "run",
        &experiment,
        "--robots",
        "4",
        "--ticks",
        "20",
        "--no-progress",
        "--out",
        &out_dir,
        "--hosts",
        name,
    ];
    let key_args = keys.run_args();
    args.extend(key_args.iter().map(String::as_str));
    args.extend(flags);
    let outcome = swarm(&args);
    assert_clean(&outcome);
    (outcome.output.status.success(), outcome.stderr())
}

/// The member joins and runs its share; the intruder never connects and a run naming it gives up.
fn member_joins_and_intruder_is_refused(
    experiment: &Path,
    keys: &TestKeys,
    mut member: HostDaemon,
    mut intruder: HostDaemon,
) {
    let (ok, stderr) = run_on(experiment, &member.name.clone(), keys, &[]);
    assert!(ok, "the run on the member host failed:\n{stderr}");
    assert!(
        member.wait_for("share started", CONNECT_TIMEOUT),
        "the member host never ran its share:\n{}",
        member.log()
    );

    let (ok, stderr) = run_on(
        experiment,
        &intruder.name.clone(),
        keys,
        &["--join-timeout-ms", REFUSED_JOIN_TIMEOUT_MS],
    );
    assert!(!ok, "a run on the intruder host succeeded:\n{stderr}");
    assert!(
        stderr.contains("hosts not ready within"),
        "the run did not give up waiting for the intruder:\n{stderr}"
    );
    assert!(
        !intruder.wait_for("ready for runs", Duration::ZERO),
        "the intruder connected:\n{}",
        intruder.log()
    );
    assert!(member.stop(), "the member host did not stop cleanly");
}

#[test]
fn a_host_with_the_password_joins_and_one_with_a_wrong_password_is_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let endpoint = format!("tcp/127.0.0.1:{}", free_port("127.0.0.1"));
    write(dir.path(), "credentials", "swarm:correct horse\n");
    write(dir.path(), "world-password", "correct horse\n");
    let right = write(dir.path(), "right-password", "correct horse\n");
    let wrong = write(dir.path(), "wrong-password", "battery staple\n");
    let experiment = experiment_with_hosts(
        dir.path(),
        &format!(
            r#"<hosts listen="{endpoint}" user="swarm" password_file="world-password" credentials_file="credentials"><host name="member" /></hosts>"#
        ),
    );
    let keys = TestKeys::new();
    let daemon = |name: &str, password: &Path| {
        let key = keys.key(name);
        HostDaemon::start_with(
            name,
            &endpoint,
            None,
            &[
                OsStr::new("--key"),
                key.as_os_str(),
                OsStr::new("--user"),
                OsStr::new("swarm"),
                OsStr::new("--password-file"),
                password.as_os_str(),
            ],
        )
    };
    member_joins_and_intruder_is_refused(
        &experiment,
        &keys,
        daemon("member", &right),
        daemon("intruder", &wrong),
    );
}

/// A certificate authority for the test: its PEM certificate and the issuer that signs with it.
fn authority(name: &str) -> (String, Issuer<'static, KeyPair>) {
    let key = KeyPair::generate().expect("a key");
    let mut params = CertificateParams::new(Vec::<String>::new()).expect("parameters");
    params.is_ca = IsCa::Ca(BasicConstraints::Unconstrained);
    params.distinguished_name.push(DnType::CommonName, name);
    let certificate = params.self_signed(&key).expect("a self-signed authority");
    (certificate.pem(), Issuer::new(params, key))
}

/// A certificate for `names` signed by `issuer`, written as `<file>.pem` and `<file>.key` into `dir`.
fn certificate(
    dir: &Path,
    file: &str,
    names: &[&str],
    issuer: &Issuer<'_, KeyPair>,
) -> (PathBuf, PathBuf) {
    let key = KeyPair::generate().expect("a key");
    let names: Vec<String> = names.iter().map(|n| (*n).to_owned()).collect();
    let params = CertificateParams::new(names).expect("parameters");
    let certificate = params
        .signed_by(&key, issuer)
        .expect("a signed certificate");
    (
        write(dir, &format!("{file}.pem"), &certificate.pem()),
        write(dir, &format!("{file}.key"), &key.serialize_pem()),
    )
}

#[test]
fn mutual_tls_admits_a_host_certified_by_the_runs_authority_only() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (ca_pem, ca) = authority("swarm test authority");
    let (_, rogue_ca) = authority("rogue authority");
    let ca_file = write(dir.path(), "ca.pem", &ca_pem);
    certificate(dir.path(), "world", &["127.0.0.1", "localhost"], &ca);
    let (member_pem, member_key) = certificate(dir.path(), "member", &["member"], &ca);
    let (intruder_pem, intruder_key) =
        certificate(dir.path(), "intruder", &["intruder"], &rogue_ca);

    let endpoint = format!("tls/127.0.0.1:{}", free_port("127.0.0.1"));
    let experiment = experiment_with_hosts(
        dir.path(),
        &format!(
            r#"<hosts listen="{endpoint}" tls_certificate="world.pem" tls_private_key="world.key" tls_root_ca="ca.pem"><host name="member" /></hosts>"#
        ),
    );
    let keys = TestKeys::new();
    let daemon = |name: &str, pem: &Path, key: &Path| {
        let host_key = keys.key(name);
        HostDaemon::start_with(
            name,
            &endpoint,
            None,
            &[
                OsStr::new("--key"),
                host_key.as_os_str(),
                OsStr::new("--tls-root-ca"),
                ca_file.as_os_str(),
                OsStr::new("--tls-certificate"),
                pem.as_os_str(),
                OsStr::new("--tls-private-key"),
                key.as_os_str(),
            ],
        )
    };
    member_joins_and_intruder_is_refused(
        &experiment,
        &keys,
        daemon("member", &member_pem, &member_key),
        daemon("intruder", &intruder_pem, &intruder_key),
    );
}
