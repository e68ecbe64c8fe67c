//! Admitting hosts before the first tick and again after they were lost: each host that announces itself is sent
//! its share (an assignment: its robots, the run's settings, a fresh epoch) and is live once it answers that its
//! agents joined.

use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::sync::mpsc::RecvTimeoutError;
use std::time::{Duration, Instant};

use zenoh::Wait;
use zenoh::qos::CongestionControl;

use super::super::auth::{HostKeys, Seal, answer_channel};
use super::super::codec;
use super::super::host_to_world::AssignmentReply;
use super::super::session::zenoh_error;
use super::super::world_to_host::Assignment;
use super::super::{RemoteError, keys};
use super::{HostEvent, Incoming, QueryEnded, RETRY_PERIOD, RemoteHosts, State};

impl RemoteHosts {
    /// Waits until every host of the placement announced itself and started its share (its agents joined).
    pub fn wait_for_hosts(&mut self, timeout: Duration) -> Result<(), RemoteError> {
        let deadline = Instant::now() + timeout;
        while self.hosts.iter().any(|h| h.state != State::Live) {
            let now = Instant::now();
            if now >= deadline {
                let missing: Vec<String> = self
                    .hosts
                    .iter()
                    .filter(|h| h.state != State::Live)
                    .map(|h| {
                        let what = if h.up {
                            "did not start its robots"
                        } else {
                            "did not announce itself"
                        };
                        format!("'{}' {what}", h.share.name)
                    })
                    .collect();
                let keys = match self.options.keys {
                    HostKeys::On(_) => {
                        "; each needs its key from this machine (`swarm host-key <name>` says where it is): a host \
                         with another key or none is never admitted"
                    }
                    HostKeys::Off => " --insecure",
                };
                return Err(RemoteError::HostsMissing(format!(
                    "hosts not ready within {timeout:?}: {} (start them with `swarm host --connect {} --name \
                     <name>`{keys})",
                    missing.join(", "),
                    self.options
                        .listen
                        .first()
                        .map_or("<endpoint>", String::as_str)
                )));
            }
            match self
                .incoming
                .recv_timeout((deadline - now).min(RETRY_PERIOD))
            {
                Ok(event) => self.handle(event, true)?,
                Err(RecvTimeoutError::Timeout) => self.retry_assignments()?,
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        Ok(())
    }

    /// Sends their share again to hosts that are up but whose last assignment went unanswered.
    pub(super) fn retry_assignments(&mut self) -> Result<(), RemoteError> {
        for index in 0..self.hosts.len() {
            if self.hosts[index].up && self.hosts[index].state == State::Absent {
                self.assign(index)?;
            }
        }
        Ok(())
    }

    /// Sends host `index` its share with a new epoch; the answer arrives as an event.
    pub(super) fn assign(&mut self, index: usize) -> Result<(), RemoteError> {
        let host = &mut self.hosts[index];
        host.epoch += 1;
        host.state = State::Assigning;
        let assignment = Assignment {
            run: self.run,
            host: index as u16,
            name: host.share.name.clone(),
            epoch: host.epoch,
            config: self.options.config.clone(),
            seed: self.options.seed,
            robots_override: self.options.robots_override,
            robots: host
                .share
                .robots
                .iter()
                .map(|&r| {
                    let controller = self
                        .options
                        .controllers
                        .get(r as usize)
                        .cloned()
                        .unwrap_or_default();
                    (r, controller)
                })
                .collect(),
            tick_deadline_ms: (self.options.tick_deadline / 2).as_millis() as u64,
            join_timeout_ms: self.options.join_timeout.as_millis() as u64,
            agent_exit_grace_ms: self.options.agent_exit_grace.as_millis() as u64,
            pin_agents: self.options.pin_agents,
            realtime_priority: self.options.realtime_priority,
            mail: self.options.mail,
            compiled_supervisors: self.options.compiled_supervisors.clone(),
            limits: self.options.limits.clone(),
            resume: if host.epoch > 1 {
                host.share
                    .robots
                    .iter()
                    .map(|&r| {
                        let last = &self.commands[r as usize];
                        (last.tick, last.supervisors)
                    })
                    .collect()
            } else {
                Vec::new()
            },
        };
        let key = keys::assign(&host.share.name);
        let mut payload = codec::encode_versioned(&assignment)?;
        host.seal.seal(&key, &mut payload);
        tracing::info!(
            host = host.share.name,
            epoch = host.epoch,
            robots = host.share.robots.len(),
            "assigning"
        );
        let ended = Incoming::AssignEnded(index, host.epoch);
        let seal = host.seal.clone();
        self.query(
            key,
            payload,
            seal,
            self.options.join_timeout + Duration::from_secs(5),
            move |answer| Incoming::Assigned(index, answer),
            ended,
        )
        .map_err(zenoh_error("sending a host its share"))
    }

    /// Sends a query whose answer arrives as the event `answered` makes of it, followed by `ended` when the
    /// query is finished (answered or not). An answer not tagged for this request with `seal` counts as
    /// unauthenticated and is dropped.
    pub(super) fn query(
        &self,
        key: String,
        payload: Vec<u8>,
        seal: Seal,
        timeout: Duration,
        answered: impl Fn(Result<Vec<u8>, String>) -> Incoming + Send + Sync + 'static,
        ended: Incoming,
    ) -> Result<(), zenoh::Error> {
        let sender = self.sender.clone();
        let ended = QueryEnded {
            sender: self.sender.clone(),
            ended: Some(ended),
        };
        let channel = answer_channel(&key, &payload);
        let unauthenticated = Arc::clone(&self.unauthenticated);
        self.session
            .get(key)
            .payload(payload)
            .timeout(timeout)
            // A host that stopped reading must not block the world: an unsent query goes unanswered.
            .congestion_control(CongestionControl::Drop)
            .callback(move |reply| {
                let _ = &ended;
                let answer = match reply.result() {
                    Ok(sample) => match seal.open(&channel, &sample.payload().to_bytes()) {
                        Ok(payload) => Ok(payload.to_vec()),
                        Err(e) => {
                            unauthenticated.fetch_add(1, Ordering::Relaxed);
                            tracing::debug!("dropping an answer: {e}");
                            return;
                        }
                    },
                    Err(e) => Err(String::from_utf8_lossy(&e.payload().to_bytes()).into_owned()),
                };
                let _ = sender.send(answered(answer));
            })
            .wait()
    }

    pub(super) fn assigned(
        &mut self,
        index: usize,
        answer: Result<Vec<u8>, String>,
        before_run: bool,
    ) -> Result<(), RemoteError> {
        let Some(host) = self.hosts.get_mut(index) else {
            return Ok(());
        };
        let reply = answer
            .map_err(|e| format!("zenoh error: {e}"))
            .and_then(|bytes| {
                codec::decode_message::<AssignmentReply>(&bytes, self.options.max_payload)
                    .map_err(|e| e.to_string())
            });
        match reply {
            Ok(AssignmentReply::Ready { epoch })
                if epoch == host.epoch && host.state == State::Assigning =>
            {
                host.state = State::Live;
                host.answered = 0;
                // The host gets frames from the first tick whose frames are not sent yet.
                host.live_from = if self.sent {
                    self.tick + 1
                } else {
                    self.tick.max(1)
                };
                for &robot in &host.share.robots {
                    self.present[robot as usize] = true;
                    self.held[robot as usize] = false;
                }
                host.returning = !before_run;
                if !before_run {
                    host.events.push(HostEvent::Rejoined {
                        tick: host.live_from,
                    });
                    tracing::info!(
                        host = host.share.name,
                        tick = host.live_from,
                        "host rejoined"
                    );
                }
                Ok(())
            }
            Ok(AssignmentReply::Ready { .. }) => {
                self.dropped.stale += 1;
                Ok(())
            }
            // Epoch 0: the host could not read the assignment, so it cannot read this one either.
            Ok(AssignmentReply::Refused { epoch, reason }) if epoch == host.epoch || epoch == 0 => {
                host.state = State::Absent;
                if before_run {
                    Err(RemoteError::Refused {
                        host: host.share.name.clone(),
                        reason,
                    })
                } else {
                    tracing::error!(host = host.share.name, "host refused to rejoin: {reason}");
                    Ok(())
                }
            }
            Ok(AssignmentReply::Refused { .. }) => Ok(()),
            Err(reason) => {
                self.dropped.rejected += 1;
                tracing::warn!(
                    host = host.share.name,
                    "bad answer to an assignment: {reason}"
                );
                Ok(())
            }
        }
    }
}
