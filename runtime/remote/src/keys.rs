//! The zenoh key expressions of the cross-host protocol, built in one place so both ends agree.
//!
//! - `swarm/hosts/<host>`: a host daemon's liveliness token (it is up and reachable).
//! - `swarm/hosts/<host>/assign`: the host's queryable; the world sends it its share of a run.
//! - `swarm/hosts/<host>/orders`: the host's queryable for fault orders on its robots' agents.
//! - `swarm/hosts/<host>/kill`: `swarm ctl kill-host`; the payload names the run and the share's epoch.
//! - `swarm/runs/<run>/world`: the world's liveliness token while the run lasts (hosts end their share when it goes).
//! - `swarm/runs/<run>/frames/<host>` and `swarm/runs/<run>/replies/<host>`: one message per host per tick each way.

/// Every host's liveliness token.
pub const HOSTS_WILDCARD: &str = "swarm/hosts/*";

/// Liveliness token of host `name`.
pub fn host_token(name: &str) -> String {
    format!("swarm/hosts/{name}")
}

/// The host name in a liveliness key of [`HOSTS_WILDCARD`], if it is one.
pub fn host_of_token(key: &str) -> Option<&str> {
    key.strip_prefix("swarm/hosts/")
        .filter(|rest| !rest.contains('/'))
}

/// Queryable through which host `name` receives its share of a run.
pub fn assign(name: &str) -> String {
    format!("swarm/hosts/{name}/assign")
}

/// Queryable through which host `name` receives fault orders for its robots' agents.
pub fn orders(name: &str) -> String {
    format!("swarm/hosts/{name}/orders")
}

/// Where the world of a run tells host `name` to die (`swarm ctl kill-host`).
pub fn kill(name: &str) -> String {
    format!("swarm/hosts/{name}/kill")
}

/// The world's liveliness token of run `run`.
pub fn world_token(run: u64) -> String {
    format!("swarm/runs/{run:016x}/world")
}

/// Frames of run `run` for host `name`.
pub fn frames(run: u64, name: &str) -> String {
    format!("swarm/runs/{run:016x}/frames/{name}")
}

/// Replies of host `name` in run `run`.
pub fn replies(run: u64, name: &str) -> String {
    format!("swarm/runs/{run:016x}/replies/{name}")
}

/// Every host's replies in run `run`.
pub fn all_replies(run: u64) -> String {
    format!("swarm/runs/{run:016x}/replies/*")
}

/// The host name in a key of [`all_replies`], if it is one.
pub fn host_of_replies(key: &str) -> Option<&str> {
    key.rsplit_once("/replies/").map(|(_, host)| host)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_give_back_their_host() {
        assert_eq!(host_of_token(&host_token("h1")), Some("h1"));
        assert_eq!(host_of_token(&assign("h1")), None);
        assert_eq!(host_of_replies(&replies(7, "h2")), Some("h2"));
    }
}
