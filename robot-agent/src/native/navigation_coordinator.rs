//! Native controller `navigation_coordinator`: the central coordination function of the navigation task
//! (docs/navigation.md), run as a coordinator (a participant without a body). Every tick it takes in the
//! robots' reports, ranks them into priorities and broadcasts the snapshot of every robot it knows (pose,
//! heading, radius, status, priority) in as many chunks as it needs.
//!
//! A robot not heard from for `stale` ticks (default 10) stays in the snapshot where it was last, as stopped:
//! a dead robot's body is still an obstacle. Parameters: `priority` (`rank`: the closest to its goal ranks
//! highest; `distance`: minus the distance to the goal), `stale`, and `max_robots` (default 1,024: the highest
//! participant index it keeps track of, plus one).

use swarm_contract::mail::{Address, Mailbox};
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_navigation::apf::{Neighbour, Priority, Status};
use swarm_navigation::wire::{self, Letter, PAYLOAD, Report};

use crate::params::{ParamError, Params};

use super::NativeController;

/// A robot as last heard.
#[derive(Debug, Clone, Copy)]
struct Heard {
    report: Report,
    tick: u64,
}

/// The coordinator.
#[derive(Debug)]
pub struct NavigationCoordinator {
    priority: Priority,
    stale: u64,
    robots: Vec<Option<Heard>>,
    snapshot: Vec<Neighbour>,
    order: Vec<(f32, u32)>,
}

impl NavigationCoordinator {
    /// Registry name.
    pub const NAME: &'static str = "navigation_coordinator";

    /// Reads the parameters above.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        let priority = match params.get("priority").map(str::trim) {
            None | Some("rank") => Priority::Rank,
            Some("distance") => Priority::Distance,
            Some(other) => {
                return Err(ParamError::Malformed {
                    name: "priority".into(),
                    value: other.into(),
                    expected: "`rank` or `distance`",
                });
            }
        };
        let capacity = params.capacity_or("max_robots", 1024)?;
        Ok(Self {
            priority,
            stale: params.whole_or("stale", crate::profiles::navigation::DEFAULT_STALE_TICKS)?,
            robots: vec![None; capacity],
            snapshot: Vec::with_capacity(capacity),
            order: Vec::with_capacity(capacity),
        })
    }

    fn take_in(&mut self, inbox: &Mailbox) {
        for mail in inbox.messages() {
            if let Ok(Letter::Report(report)) = wire::decode(mail.payload())
                && let Some(slot) = self.robots.get_mut(mail.from as usize)
            {
                *slot = Some(Heard {
                    report,
                    tick: inbox.tick,
                });
            }
        }
    }

    /// The snapshot of tick `tick`, priorities included, in participant order.
    fn build_snapshot(&mut self, tick: u64) {
        self.snapshot.clear();
        self.order.clear();
        for (id, heard) in (0u32..).zip(&self.robots) {
            let Some(heard) = heard else { continue };
            let r = heard.report;
            let fresh = tick.saturating_sub(heard.tick) <= self.stale;
            let status = if fresh { r.status } else { Status::Stopped };
            let distance = (r.goal - r.position).length();
            self.snapshot.push(Neighbour {
                id,
                position: r.position,
                heading: r.heading,
                radius: r.radius,
                status,
                priority: -distance,
            });
            self.order.push((distance, id));
        }
        if self.priority == Priority::Rank {
            self.order
                .sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let n = self.order.len();
            for (rank, &(_, id)) in self.order.iter().enumerate() {
                if let Ok(at) = self.snapshot.binary_search_by_key(&id, |n| n.id) {
                    self.snapshot[at].priority = (n - rank) as f32;
                }
            }
        }
    }
}

impl NativeController for NavigationCoordinator {
    fn step(&mut self, _frame: &SensorFrame, command: &mut ActuatorCommand) {
        command.wheels = [0.0, 0.0];
    }

    fn step_with_mail(
        &mut self,
        frame: &SensorFrame,
        inbox: &Mailbox,
        outbox: &mut Mailbox,
        command: &mut ActuatorCommand,
    ) {
        self.step(frame, command);
        self.take_in(inbox);
        self.build_snapshot(frame.tick);
        let mut payload = [0u8; PAYLOAD];
        let mut first = 0;
        loop {
            let (len, next) = wire::encode_snapshot(&self.snapshot, first, &mut payload);
            if outbox.send(Address::All, &payload[..len]).is_err() || next >= self.snapshot.len() {
                return;
            }
            first = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use swarm_contract::mail::Mailbox;
    use swarm_navigation::V2;
    use swarm_navigation::wire::encode_report;

    use super::*;

    fn report(x: f32, goal_x: f32, moving: bool) -> Report {
        Report {
            position: V2::new(x, 0.0),
            heading: 0.0,
            radius: 0.1,
            status: if moving {
                Status::Moving
            } else {
                Status::Stopped
            },
            goal: V2::new(goal_x, 0.0),
        }
    }

    fn inbox(tick: u64, reports: &[(u32, Report)]) -> Mailbox {
        let mut inbox = Mailbox::empty(9);
        inbox.tick = tick;
        let mut payload = [0u8; PAYLOAD];
        for (from, r) in reports {
            let len = encode_report(r, &mut payload);
            let mail =
                swarm_contract::mail::Mail::new(*from, Address::To(9), &payload[..len]).unwrap();
            inbox.push(mail).unwrap();
        }
        inbox
    }

    fn snapshot(outbox: &Mailbox) -> Vec<Neighbour> {
        outbox
            .messages()
            .iter()
            .flat_map(|m| match wire::decode(m.payload()) {
                Ok(Letter::Snapshot(c)) => c.neighbours().collect::<Vec<_>>(),
                _ => Vec::new(),
            })
            .collect()
    }

    fn step(c: &mut NavigationCoordinator, tick: u64, inbox: &Mailbox) -> Vec<Neighbour> {
        let mut frame = SensorFrame::empty(9);
        frame.tick = tick;
        let mut outbox = Mailbox::empty(9);
        c.step_with_mail(
            &frame,
            inbox,
            &mut outbox,
            &mut ActuatorCommand::idle(9, tick),
        );
        snapshot(&outbox)
    }

    #[test]
    fn the_closest_to_its_goal_ranks_highest_and_silent_robots_stop() {
        let mut c = NavigationCoordinator::from_params(&Params::default()).unwrap();
        let heard = inbox(
            5,
            &[
                (0, report(0.0, 4.0, true)),
                (1, report(0.0, 1.0, true)),
                (2, report(0.0, 2.0, true)),
            ],
        );
        let s = step(&mut c, 5, &heard);
        assert_eq!(s.iter().map(|n| n.id).collect::<Vec<_>>(), [0, 1, 2]);
        assert_eq!(
            s.iter().map(|n| n.priority).collect::<Vec<_>>(),
            [1.0, 3.0, 2.0]
        );
        assert!(s.iter().all(|n| n.status == Status::Moving));
        // Eleven ticks later nobody has reported: everyone is still there, stopped.
        let s = step(&mut c, 16, &inbox(16, &[]));
        assert_eq!(s.len(), 3);
        assert!(s.iter().all(|n| n.status == Status::Stopped));
    }

    #[test]
    fn a_large_swarm_goes_out_in_chunks_and_garbage_is_ignored() {
        let mut c =
            NavigationCoordinator::from_params(&Params::new([("priority", "distance")])).unwrap();
        let reports: Vec<(u32, Report)> =
            (0..25).map(|i| (i, report(i as f32, 30.0, true))).collect();
        let mut heard = inbox(1, &reports);
        heard
            .push(swarm_contract::mail::Mail::new(3, Address::To(9), &[3, 1, 2]).unwrap())
            .unwrap();
        let s = step(&mut c, 1, &heard);
        assert_eq!(s.len(), 25);
        assert_eq!(s[24].priority, -6.0);
        assert!(
            NavigationCoordinator::from_params(&Params::new([("priority", "closest")])).is_err()
        );
    }
}
