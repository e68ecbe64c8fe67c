//! The team's protocol (B.5) as one robot runs it: presence and the election, the synchronised lift, the
//! waypoint barrier, the put-down and the stop, with repeats for lost messages and timeouts for lost teammates.
//! Pure: it takes in signals and the robot's own progress, and says what to send; the profile does the rest.
//!
//! - **Election.** A robot gripping its face waits `stagger` ticks per participant index, then says `Here`
//!   (again every `repeat` ticks until the lift). The smallest index among the robots heard and not lost
//!   coordinates, once the whole team is present.
//! - **Lift.** The coordinator asks `ReadyToTake` (every `repeat` ticks) until every member answered `Yes`; then
//!   it says `Take` and decides the path (`LocalPath` or `GlobalPath`), both again every `repeat` ticks until
//!   every member has reported the first waypoint (and `Take` at once to anyone still answering `Yes`).
//! - **Barrier.** A robot at waypoint k sends `Arrived(k)` to the coordinator (every `repeat` ticks until it is
//!   released); when every member has arrived, the coordinator broadcasts `Arrived(k)` (again, to the reporter
//!   alone, to anyone who reports k later), or `Put` after the last waypoint. An `Arrived` from the coordinator
//!   releases; one to the coordinator reports.
//! - **Timeouts.** A coordinator that waits more than `step_timeout` ticks at a barrier counts the silent
//!   members lost; a member released by nobody for that long counts the coordinator lost, and the next smallest
//!   index takes over the barrier. With fewer members left than the box needs, the team stops.
//! - **Stop.** A robot that finds the box dropped, or a team without a path or too small, says `Stop` with the
//!   reason (three times, `repeat` ticks apart); every robot then puts the box down.

use std::collections::{BTreeMap, BTreeSet};

use swarm_contract::mail::Address;
use swarm_navigation::V2;
use swarm_navigation::wire::transport::{Code, Ending, Signal};

/// How the path is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathMode {
    /// Every robot builds the straight path.
    Local,
    /// The supervisor plans it.
    Global,
}

/// The protocol's times, in ticks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Timing {
    /// Wait per participant index before the first `Here`.
    pub stagger: u64,
    /// Between repeats of an unanswered message.
    pub repeat: u64,
    /// Longest wait at a barrier before a teammate counts as lost.
    pub step_timeout: u64,
}

const STOP_REPEATS: u32 = 3;

/// A message to send.
pub type Outgoing = (Address, Signal);

fn signal(code: Code, step: u32) -> Signal {
    Signal {
        code,
        step,
        value: V2::ZERO,
    }
}

/// One robot's view of the team.
#[derive(Debug, Clone)]
pub struct Team {
    me: u32,
    timing: Timing,
    size: usize,
    lift_by: usize,
    gripped_at: Option<u64>,
    present: BTreeSet<u32>,
    lost: BTreeSet<u32>,
    ready: BTreeSet<u32>,
    /// This robot may answer `Yes` to `ReadyToTake` (it grips and knows the box's pose since).
    pub able: bool,
    took_at: Option<u64>,
    path_mode: Option<PathMode>,
    arrived: BTreeMap<u32, u32>,
    mine: Option<(u32, u64)>,
    released: u32,
    last: Option<u32>,
    put: bool,
    stop: Option<Ending>,
    stops_sent: u32,
    /// When the current barrier (coordinator) or wait for release (member) began.
    waiting_since: u64,
    sent: BTreeMap<(u8, u32), u64>,
    answers: Vec<Outgoing>,
    shifts: Vec<(u32, V2)>,
}

impl Team {
    /// A robot of participant index `me` that knows nothing of its team yet.
    pub fn new(me: u32, timing: Timing) -> Team {
        Team {
            me,
            timing,
            size: usize::MAX,
            lift_by: 1,
            gripped_at: None,
            present: BTreeSet::new(),
            lost: BTreeSet::new(),
            ready: BTreeSet::new(),
            able: false,
            took_at: None,
            path_mode: None,
            arrived: BTreeMap::new(),
            mine: None,
            released: 0,
            last: None,
            put: false,
            stop: None,
            stops_sent: 0,
            waiting_since: 0,
            sent: BTreeMap::new(),
            answers: Vec::new(),
            shifts: Vec::new(),
        }
    }

    /// The team's size and the grips the box needs, from the supervisor's letter.
    pub fn set_task(&mut self, size: usize, lift_by: usize) {
        self.size = size;
        self.lift_by = lift_by;
    }

    /// This robot grips its face from `tick` on.
    pub fn gripped(&mut self, tick: u64) {
        if self.gripped_at.is_none() {
            self.gripped_at = Some(tick);
            self.present.insert(self.me);
        }
    }

    fn active(&self) -> impl Iterator<Item = u32> + '_ {
        self.present.difference(&self.lost).copied()
    }

    /// The coordinator: the smallest index present and not lost (B.5's election).
    pub fn coordinator(&self) -> Option<u32> {
        self.active().next()
    }

    fn leads(&self) -> bool {
        self.coordinator() == Some(self.me)
    }

    /// The tick the team took the box, if it has.
    pub fn took_at(&self) -> Option<u64> {
        self.took_at
    }

    /// How the path is made, once the coordinator said.
    pub fn path_mode(&self) -> Option<PathMode> {
        self.path_mode
    }

    /// The last waypoint's number, once the path is known.
    pub fn set_last(&mut self, last: u32) {
        self.last = Some(last);
    }

    /// The highest waypoint the coordinator released (0: none).
    pub fn released(&self) -> u32 {
        self.released
    }

    /// Whether the box is to be put down at the end of the path.
    pub fn put(&self) -> bool {
        self.put
    }

    /// Why the team stopped, if it did.
    pub fn stopped(&self) -> Option<Ending> {
        self.stop
    }

    /// Stops the team for `reason` (the first reason stays).
    pub fn stop(&mut self, reason: Ending) {
        self.stop.get_or_insert(reason);
    }

    /// This robot reached waypoint `step` at `tick`.
    pub fn arrive(&mut self, step: u32, tick: u64) {
        if self.mine.is_none_or(|(k, _)| k < step) {
            self.mine = Some((step, tick));
        }
    }

    /// Shifts of the path announced since the last call: (first waypoint, shift).
    pub fn take_shifts(&mut self) -> Vec<(u32, V2)> {
        std::mem::take(&mut self.shifts)
    }

    /// Announces a shift of the path from waypoint `step` on, and applies it here too.
    pub fn deviate(&mut self, step: u32, by: V2) {
        self.shifts.push((step, by));
        self.answers.push((
            Address::All,
            Signal {
                code: Code::Deviate,
                step,
                value: by,
            },
        ));
    }

    /// The coordinator decided how the path is made.
    pub fn decide_path(&mut self, mode: PathMode, tick: u64) {
        self.path_mode = Some(mode);
        self.waiting_since = tick;
    }

    /// Takes in a signal from participant `from`, addressed `to`, at `tick`.
    pub fn hear(&mut self, from: u32, to: Address, heard: Signal, tick: u64) {
        if self.lost.contains(&from) {
            return;
        }
        let k = heard.step;
        match heard.code {
            Code::Here => {
                self.present.insert(from);
            }
            Code::ReadyToTake if self.able => {
                self.answers
                    .push((Address::To(from), signal_yes(Code::ReadyToTake)));
            }
            Code::ReadyToTake => {}
            Code::Yes => {
                self.ready.insert(from);
                if self.took_at.is_some() && self.leads() {
                    self.answers
                        .push((Address::To(from), signal(Code::Take, 0)));
                }
            }
            Code::Take => {
                self.took_at.get_or_insert(tick);
                self.waiting_since = tick;
            }
            Code::LocalPath => {
                self.path_mode.get_or_insert(PathMode::Local);
            }
            Code::GlobalPath => {
                self.path_mode.get_or_insert(PathMode::Global);
            }
            // From the coordinator (to all, or again to this robot after a lost one): go on past `k`.
            Code::Arrived if to == Address::All || Some(from) == self.coordinator() => {
                if k > self.released {
                    self.released = k;
                    self.waiting_since = tick;
                }
            }
            Code::Arrived => {
                let best = self.arrived.entry(from).or_insert(0);
                *best = (*best).max(k);
                if self.leads() && k <= self.released {
                    self.answers
                        .push((Address::To(from), signal(Code::Arrived, k)));
                }
                if self.leads() && self.put {
                    self.answers.push((Address::To(from), signal(Code::Put, k)));
                }
            }
            Code::Put => self.put = true,
            Code::Stop => {
                let reason = match k {
                    1 => Ending::TeammateLost,
                    2 => Ending::Dropped,
                    _ => Ending::NoPath,
                };
                self.stop.get_or_insert(reason);
                // Heard: no need to repeat it ourselves.
                self.stops_sent = STOP_REPEATS;
            }
            Code::Deviate => self.shifts.push((k, heard.value)),
        }
    }

    fn due(&mut self, code: Code, step: u32, tick: u64) -> bool {
        let key = (code as u8, step);
        let due = self
            .sent
            .get(&key)
            .is_none_or(|&at| tick >= at + self.timing.repeat);
        if due {
            self.sent.insert(key, tick);
        }
        due
    }

    /// What to send at `tick`.
    pub fn outgoing(&mut self, tick: u64) -> Vec<Outgoing> {
        let mut out = std::mem::take(&mut self.answers);
        if let Some(reason) = self.stop {
            let code = match reason {
                Ending::TeammateLost => 1,
                Ending::Dropped => 2,
                _ => 3,
            };
            if self.stops_sent < STOP_REPEATS && self.due(Code::Stop, 0, tick) {
                self.stops_sent += 1;
                out.push((Address::All, signal(Code::Stop, code)));
            }
            return out;
        }
        let Some(gripped) = self.gripped_at else {
            return out;
        };
        if self.took_at.is_none() {
            self.before_take(gripped, tick, &mut out);
        } else {
            self.carrying(tick, &mut out);
        }
        out
    }

    fn before_take(&mut self, gripped: u64, tick: u64, out: &mut Vec<Outgoing>) {
        let first = gripped + self.timing.stagger * u64::from(self.me);
        if tick >= first && self.due(Code::Here, 0, tick) {
            out.push((Address::All, signal(Code::Here, 0)));
        }
        let complete = self.active().count() >= self.size;
        if !(complete && self.leads()) {
            return;
        }
        let everyone_ready = self
            .active()
            .all(|m| m == self.me || self.ready.contains(&m));
        if everyone_ready && self.able {
            self.took_at = Some(tick);
            self.waiting_since = tick;
            out.push((Address::All, signal(Code::Take, 0)));
        } else if self.due(Code::ReadyToTake, 0, tick) {
            out.push((Address::All, signal(Code::ReadyToTake, 0)));
        }
    }

    fn carrying(&mut self, tick: u64, out: &mut Vec<Outgoing>) {
        // `Take` and the path decision are repeated until every member has shown, by reaching the first waypoint,
        // that it heard them.
        let unheard = self
            .active()
            .any(|m| m != self.me && !self.arrived.contains_key(&m));
        if self.leads() && self.released == 0 && unheard && self.due(Code::Take, 0, tick) {
            out.push((Address::All, signal(Code::Take, 0)));
        }
        if self.leads()
            && let Some(mode) = self.path_mode
            && self.released == 0
            && self.due(Code::LocalPath, 0, tick)
        {
            let code = match mode {
                PathMode::Local => Code::LocalPath,
                PathMode::Global => Code::GlobalPath,
            };
            out.push((Address::All, signal(code, 0)));
        }
        if self.put {
            return;
        }
        let step = self.released + 1;
        if let Some((k, at)) = self.mine
            && k >= step
        {
            if self.leads() {
                self.arrived.insert(self.me, k);
            } else if let Some(coordinator) = self.coordinator() {
                if self.due(Code::Arrived, k, tick) {
                    out.push((Address::To(coordinator), signal(Code::Arrived, k)));
                }
                if tick > at.max(self.waiting_since) + self.timing.step_timeout {
                    tracing::info!(coordinator, "transport: the coordinator is lost");
                    self.lose(coordinator, tick);
                    return;
                }
            }
        }
        if !self.leads() {
            return;
        }
        let members: Vec<u32> = self.active().collect();
        let missing: Vec<u32> = members
            .iter()
            .copied()
            .filter(|m| self.arrived.get(m).is_none_or(|&k| k < step))
            .collect();
        if missing.is_empty() {
            self.waiting_since = tick;
            if Some(step) >= self.last {
                self.put = true;
                out.push((Address::All, signal(Code::Put, step)));
            } else {
                self.released = step;
                out.push((Address::All, signal(Code::Arrived, step)));
            }
        } else if self.mine.is_some_and(|(k, _)| k >= step)
            && tick > self.waiting_since + self.timing.step_timeout
        {
            for m in missing {
                tracing::info!(member = m, step, "transport: a teammate is lost");
                self.lose(m, tick);
            }
        }
    }

    fn lose(&mut self, member: u32, tick: u64) {
        self.lost.insert(member);
        self.waiting_since = tick;
        if self.active().count() < self.lift_by {
            self.stop(Ending::TeammateLost);
        }
    }
}

fn signal_yes(to: Code) -> Signal {
    signal(Code::Yes, to as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TIMING: Timing = Timing {
        stagger: 10,
        repeat: 10,
        step_timeout: 50,
    };

    fn codes(out: &[Outgoing]) -> Vec<(Address, Code, u32)> {
        out.iter().map(|(a, s)| (*a, s.code, s.step)).collect()
    }

    /// Two robots (0 and 1) gripping from tick 0.
    fn pair() -> (Team, Team) {
        let mut a = Team::new(0, TIMING);
        let mut b = Team::new(1, TIMING);
        for t in [&mut a, &mut b] {
            t.set_task(2, 2);
            t.gripped(0);
            t.able = true;
        }
        (a, b)
    }

    /// Delivers `out` of `from` to `to`.
    fn deliver(out: &[Outgoing], from: u32, to: &mut Team, tick: u64) {
        for (address, s) in out {
            if *address == Address::All || *address == Address::To(to.me) {
                to.hear(from, *address, *s, tick);
            }
        }
    }

    #[test]
    fn the_smallest_index_coordinates_the_lift_and_the_barrier() {
        let (mut a, mut b) = pair();
        // Robot 1 waits 10 ticks before it says Here; robot 0 at once.
        let out = a.outgoing(0);
        assert_eq!(codes(&out), vec![(Address::All, Code::Here, 0)]);
        deliver(&out, 0, &mut b, 0);
        assert!(b.outgoing(5).is_empty());
        let out = b.outgoing(10);
        assert_eq!(codes(&out), vec![(Address::All, Code::Here, 0)]);
        deliver(&out, 1, &mut a, 10);
        assert_eq!(a.coordinator(), Some(0));
        assert_eq!(b.coordinator(), Some(0));
        let out = a.outgoing(11);
        assert!(codes(&out).contains(&(Address::All, Code::ReadyToTake, 0)));
        deliver(&out, 0, &mut b, 11);
        let out = b.outgoing(12);
        assert_eq!(codes(&out), vec![(Address::To(0), Code::Yes, 1)]);
        deliver(&out, 1, &mut a, 12);
        let out = a.outgoing(13);
        assert!(codes(&out).contains(&(Address::All, Code::Take, 0)));
        deliver(&out, 0, &mut b, 13);
        assert_eq!((a.took_at(), b.took_at()), (Some(13), Some(13)));
        a.decide_path(PathMode::Local, 13);
        a.set_last(2);
        b.set_last(2);
        let out = a.outgoing(14);
        deliver(&out, 0, &mut b, 14);
        assert_eq!(b.path_mode(), Some(PathMode::Local));
        // Waypoint 1: the barrier waits for both.
        a.arrive(1, 20);
        assert!(!codes(&a.outgoing(20)).iter().any(|c| c.1 == Code::Arrived));
        b.arrive(1, 25);
        let out = b.outgoing(25);
        assert_eq!(codes(&out), vec![(Address::To(0), Code::Arrived, 1)]);
        deliver(&out, 1, &mut a, 25);
        let out = a.outgoing(26);
        assert!(
            codes(&out).contains(&(Address::All, Code::Arrived, 1)),
            "{out:?}"
        );
        deliver(&out, 0, &mut b, 26);
        assert_eq!(b.released(), 1);
        // The last waypoint: Put instead.
        a.arrive(2, 30);
        b.arrive(2, 31);
        let out = b.outgoing(31);
        deliver(&out, 1, &mut a, 31);
        let out = a.outgoing(32);
        assert_eq!(codes(&out), vec![(Address::All, Code::Put, 2)]);
        deliver(&out, 0, &mut b, 32);
        assert!(a.put() && b.put());
    }

    #[test]
    fn a_lost_arrival_is_repeated_and_answered_again() {
        let (mut a, mut b) = pair();
        for t in [&mut a, &mut b] {
            t.present.extend([0, 1]);
            t.took_at = Some(0);
            t.set_last(5);
        }
        b.arrive(1, 0);
        let first = b.outgoing(0);
        assert_eq!(codes(&first), vec![(Address::To(0), Code::Arrived, 1)]);
        // Lost; nothing again before `repeat` ticks, then the same report.
        assert!(b.outgoing(5).is_empty());
        assert_eq!(codes(&b.outgoing(10)), codes(&first));
        // The coordinator released 1 already and hears a late report: it answers the reporter alone.
        a.released = 1;
        a.hear(1, Address::To(0), first[0].1, 11);
        let answer: Vec<Outgoing> = a
            .outgoing(11)
            .into_iter()
            .filter(|(_, s)| s.code == Code::Arrived)
            .collect();
        assert_eq!(codes(&answer), vec![(Address::To(1), Code::Arrived, 1)]);
        // The answer to it alone releases it too.
        deliver(&answer, 0, &mut b, 12);
        assert_eq!(b.released(), 1);
    }

    #[test]
    fn silence_at_a_barrier_loses_the_teammate_and_a_team_too_small_stops() {
        let (mut a, _) = pair();
        a.present.insert(1);
        a.took_at = Some(0);
        a.set_last(5);
        a.arrive(1, 0);
        let only = |out: Vec<Outgoing>, code: Code| {
            out.into_iter().filter(|(_, s)| s.code == code).count()
        };
        // Until the member reports the first waypoint, only `Take` is repeated.
        assert_eq!(only(a.outgoing(0), Code::Take), 1);
        assert_eq!(only(a.outgoing(50), Code::Arrived), 0);
        assert!(a.stopped().is_none());
        a.outgoing(51);
        assert_eq!(a.stopped(), Some(Ending::TeammateLost));
        // Three stops, `repeat` ticks apart, then quiet.
        let stops: usize = (52..200)
            .map(|tick| only(a.outgoing(tick), Code::Stop))
            .sum();
        assert_eq!(stops, 3);
        // With three robots and a box two can lift, the team goes on without the silent one.
        let mut c = Team::new(0, TIMING);
        c.set_task(3, 2);
        c.gripped(0);
        c.present.extend([1, 2]);
        c.took_at = Some(0);
        c.set_last(5);
        c.arrive(1, 0);
        c.hear(2, Address::To(0), signal(Code::Arrived, 1), 1);
        c.outgoing(51);
        assert!(c.stopped().is_none());
        let out = c.outgoing(52);
        assert_eq!(codes(&out), vec![(Address::All, Code::Arrived, 1)]);
    }

    #[test]
    fn a_member_whose_coordinator_falls_silent_takes_over() {
        let (_, mut b) = pair();
        b.present.insert(0);
        b.took_at = Some(0);
        b.set_last(5);
        let mut three = Team::new(2, TIMING);
        three.set_task(3, 2);
        three.gripped(0);
        three.present.extend([0, 1]);
        three.took_at = Some(0);
        three.set_last(5);
        // Robot 1 of a three-robot team: the coordinator 0 stops answering.
        b.set_task(3, 2);
        b.present.insert(2);
        b.arrive(1, 0);
        for tick in 0..=51 {
            b.outgoing(tick);
        }
        assert_eq!(b.coordinator(), Some(1));
        assert!(b.stopped().is_none());
        // The other member reports to the new coordinator, which releases the step.
        b.hear(2, Address::To(1), signal(Code::Arrived, 1), 52);
        let out = b.outgoing(53);
        assert!(
            codes(&out).contains(&(Address::All, Code::Arrived, 1)),
            "{out:?}"
        );
    }
}
