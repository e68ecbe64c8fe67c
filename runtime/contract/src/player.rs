//! The ptSCT player (docs/ptsct.md section 8.4): executes a robot's compiled supervisor set, one step per tick.
//!
//! Per step: the tick advances first (A3); every uncontrollable check is polled on one snapshot and the events
//! that occurred are applied in ascending id, skipping and counting those not enabled in every owner (A7); then
//! at most one controllable event is drawn by roulette over the enabled ones (owners' transitions defined and
//! lower bounds met with per-supervisor counters `k - max(entered, fired[e])`), with weight = product of its
//! owners' probabilities, and its action runs after the supervisors moved.
//!
//! Everything a step touches is built at load time (offset index, owner lists, timer slots, scratch buffers):
//! a step never allocates. Randomness is one ChaCha8 stream per robot positioned by tick (see [`Player::new`]),
//! so a restored player continues the exact random sequence of the one it replaces. docs/player.md has the
//! details.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use supervisor_gen::compiled::{CompiledEvent, CompiledTransition, SupervisorSet};

use crate::messages::{
    ActuatorCommand, FiredStamp, MAX_EVENTS_PER_TICK, MAX_FIRED_STAMPS, MAX_SUPERVISORS,
    SensorFrame, SupervisorSnapshot,
};

/// ChaCha words reserved per tick: one 64-byte block, far more than the at most two draws (four words) a step
/// makes, so tick k's randomness never overlaps tick k+1's.
const WORDS_PER_TICK: u128 = 16;
/// Marks an event with no self-loop timer slot in a supervisor.
const NO_SLOT: u16 = u16::MAX;

/// The operational procedures of a robot: one callback per event (docs/ptsct.md section 8.1, layer 3).
pub trait EventCallbacks {
    /// Uncontrollable event: has it occurred? (level-triggered; read the frame)
    fn check(&mut self, event: u8, frame: &SensorFrame) -> bool;
    /// Controllable event chosen this tick: perform its action on the command.
    fn act(&mut self, event: u8, frame: &SensorFrame, command: &mut ActuatorCommand);
}

/// Why a supervisor set cannot be played or a snapshot cannot be restored.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlayerError {
    /// The set has no supervisors, or more than a command can report.
    #[error("a robot runs 1 to {max} supervisors, this set has {count}")]
    SupervisorCount {
        /// Supervisors in the set.
        count: usize,
        /// Most supported.
        max: usize,
    },
    /// A supervisor without states.
    #[error("supervisor `{supervisor}` has no states")]
    NoStates {
        /// Supervisor name.
        supervisor: String,
    },
    /// A transition that names an event or a state that does not exist.
    #[error(
        "supervisor `{supervisor}`, state {state}: transition on event {event} to state {target} is out of range"
    )]
    BadTransition {
        /// Supervisor name.
        supervisor: String,
        /// Source state.
        state: usize,
        /// Event id.
        event: u8,
        /// Target state.
        target: u16,
    },
    /// A snapshot that does not fit this supervisor set.
    #[error("snapshot does not fit the supervisor set: {reason}")]
    SnapshotMismatch {
        /// What does not fit.
        reason: String,
    },
}

/// Executes one robot's supervisors.
pub struct Player {
    events: Vec<CompiledEvent>,
    /// Uncontrollable event ids, ascending.
    uncontrollable_ids: Vec<u8>,
    /// Controllable event ids, ascending.
    controllable_ids: Vec<u8>,
    /// Owners of event e: `owners[owner_offsets[e]..owner_offsets[e + 1]]`, ascending supervisor index.
    owner_offsets: Vec<u32>,
    owners: Vec<u16>,
    /// All transitions; state s of supervisor i is `transitions[state_offsets[state_base[i] + s]..][..n]`.
    transitions: Vec<CompiledTransition>,
    state_offsets: Vec<u32>,
    state_base: Vec<u32>,
    /// Per supervisor and event: index into `fired` of its self-loop timer, or NO_SLOT.
    timer_slot: Vec<u16>,
    /// Per supervisor: first index of its timers in `fired` (one past the last supervisor's at the end).
    timer_base: Vec<u32>,
    /// Event of each timer in `fired`.
    timer_event: Vec<u8>,
    /// Number of states of each supervisor.
    state_counts: Vec<usize>,
    /// Tick of the last firing of each controllable self-loop (0: never, equivalent to -inf since entered >= 0).
    fired: Vec<u64>,
    current: Vec<u16>,
    entered: Vec<u64>,
    tick: u64,
    rng: ChaCha8Rng,
    mismatches: u64,
    zero_weight_warned: bool,
    /// Scratch for one step.
    occurred: Vec<bool>,
    enabled: Vec<u8>,
    weights: Vec<f64>,
}

impl Player {
    /// Prepares `set` for robot `robot` of a run seeded with `run_seed`. The random stream is ChaCha8 keyed by
    /// `run_seed` (expanded with `seed_from_u64`), stream number `robot`, and each tick k starts at word 16·k.
    pub fn new(set: SupervisorSet, run_seed: u64, robot: u32) -> Result<Player, PlayerError> {
        let count = set.supervisors.len();
        if count == 0 || count > MAX_SUPERVISORS {
            return Err(PlayerError::SupervisorCount {
                count,
                max: MAX_SUPERVISORS,
            });
        }
        let event_count = set.events.len();
        let controllable: Vec<bool> = set.events.iter().map(|e| e.controllable).collect();
        let ids = |want: bool| -> Vec<u8> {
            (0..event_count)
                .filter(|&e| controllable[e] == want)
                .map(|e| e as u8)
                .collect()
        };
        let (uncontrollable_ids, controllable_ids) = (ids(false), ids(true));

        let mut owner_offsets = Vec::with_capacity(event_count + 1);
        let mut owners = Vec::new();
        for event in 0..event_count {
            owner_offsets.push(owners.len() as u32);
            for (index, supervisor) in set.supervisors.iter().enumerate() {
                if supervisor.owns(event as u8) {
                    owners.push(index as u16);
                }
            }
        }
        owner_offsets.push(owners.len() as u32);

        let mut transitions = Vec::new();
        let mut state_offsets = Vec::new();
        let mut state_base = Vec::with_capacity(count);
        let mut timer_slot = vec![NO_SLOT; count * event_count];
        let mut timer_base = Vec::with_capacity(count + 1);
        let mut timer_event = Vec::new();
        for (index, supervisor) in set.supervisors.iter().enumerate() {
            if supervisor.states.is_empty() {
                return Err(PlayerError::NoStates {
                    supervisor: supervisor.name.clone(),
                });
            }
            state_base.push(state_offsets.len() as u32);
            timer_base.push(timer_event.len() as u32);
            let mut slots_here = 0u16;
            for (state, compiled) in supervisor.states.iter().enumerate() {
                state_offsets.push(transitions.len() as u32);
                for t in &compiled.transitions {
                    if usize::from(t.event) >= event_count
                        || usize::from(t.target) >= supervisor.states.len()
                    {
                        return Err(PlayerError::BadTransition {
                            supervisor: supervisor.name.clone(),
                            state,
                            event: t.event,
                            target: t.target,
                        });
                    }
                    let slot = &mut timer_slot[index * event_count + usize::from(t.event)];
                    if controllable[usize::from(t.event)]
                        && usize::from(t.target) == state
                        && *slot == NO_SLOT
                    {
                        *slot = slots_here;
                        slots_here += 1;
                        timer_event.push(t.event);
                    }
                    transitions.push(*t);
                }
            }
        }
        state_offsets.push(transitions.len() as u32);
        timer_base.push(timer_event.len() as u32);
        let state_counts = set.supervisors.iter().map(|s| s.states.len()).collect();

        let mut rng = ChaCha8Rng::seed_from_u64(run_seed);
        rng.set_stream(u64::from(robot));
        Ok(Player {
            occurred: vec![false; event_count],
            enabled: Vec::with_capacity(controllable_ids.len()),
            weights: Vec::with_capacity(controllable_ids.len()),
            events: set.events,
            uncontrollable_ids,
            controllable_ids,
            owner_offsets,
            owners,
            transitions,
            state_offsets,
            state_base,
            timer_slot,
            timer_base,
            fired: vec![0; timer_event.len()],
            timer_event,
            state_counts,
            current: vec![0; count],
            entered: vec![0; count],
            tick: 0,
            rng,
            mismatches: 0,
            zero_weight_warned: false,
        })
    }

    /// The global event table (id = index), for binding callbacks by name.
    pub fn events(&self) -> &[CompiledEvent] {
        &self.events
    }

    /// The last tick stepped (0 before the first step).
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// Current state of each supervisor.
    pub fn states(&self) -> &[u16] {
        &self.current
    }

    /// Number of uncontrollable events skipped because some owner had no transition for them (A7).
    pub fn mismatches(&self) -> u64 {
        self.mismatches
    }

    #[unsafe(link_section = "swarm_hot")]
    fn owners_of(&self, event: u8) -> &[u16] {
        let e = usize::from(event);
        &self.owners[self.owner_offsets[e] as usize..self.owner_offsets[e + 1] as usize]
    }

    /// The transition of supervisor `sup` on `event` from its current state.
    #[unsafe(link_section = "swarm_hot")]
    fn transition(&self, sup: usize, event: u8) -> Option<&CompiledTransition> {
        let state = self.state_base[sup] as usize + usize::from(self.current[sup]);
        let range = self.state_offsets[state] as usize..self.state_offsets[state + 1] as usize;
        self.transitions[range].iter().find(|t| t.event == event)
    }

    #[unsafe(link_section = "swarm_hot")]
    fn enabled_in_every_owner(&self, event: u8) -> bool {
        self.owners_of(event)
            .iter()
            .all(|&sup| self.transition(usize::from(sup), event).is_some())
    }

    #[unsafe(link_section = "swarm_hot")]
    fn last_fired(&self, sup: usize, event: u8) -> u64 {
        let slot = self.timer_slot[sup * self.events.len() + usize::from(event)];
        if slot == NO_SLOT {
            0
        } else {
            self.fired[self.timer_base[sup] as usize + usize::from(slot)]
        }
    }

    /// move(i, e) of section 8.4.
    #[unsafe(link_section = "swarm_hot")]
    fn advance(&mut self, sup: usize, event: u8) {
        let Some(target) = self.transition(sup, event).map(|t| t.target) else {
            return;
        };
        if target != self.current[sup] {
            self.current[sup] = target;
            self.entered[sup] = self.tick;
            // Stamps of the old state need no clearing: they are <= entered, so max(entered, stamp) = entered.
        } else {
            let slot = self.timer_slot[sup * self.events.len() + usize::from(event)];
            if slot != NO_SLOT {
                self.fired[self.timer_base[sup] as usize + usize::from(slot)] = self.tick;
            }
        }
    }

    #[unsafe(link_section = "swarm_hot")]
    fn fire(&mut self, event: u8, command: &mut ActuatorCommand) {
        for index in
            self.owner_offsets[usize::from(event)]..self.owner_offsets[usize::from(event) + 1]
        {
            let sup = usize::from(self.owners[index as usize]);
            self.advance(sup, event);
        }
        let len = usize::from(command.events_len);
        if len < MAX_EVENTS_PER_TICK {
            command.events[len] = event;
            command.events_len += 1;
        }
    }

    /// The weight of controllable `event` if it is enabled now: every owner has the transition and its lower
    /// bound is met; the product of the owners' probabilities (Q0.16 as f64, ascending supervisor order).
    #[unsafe(link_section = "swarm_hot")]
    fn enabled_weight(&self, event: u8) -> Option<f64> {
        let owners = self.owners_of(event);
        if owners.is_empty() {
            return None;
        }
        let mut weight = 1.0;
        for &sup in owners {
            let sup = usize::from(sup);
            let t = self.transition(sup, event)?;
            let since = self.entered[sup].max(self.last_fired(sup, event));
            if self.tick - since < u64::from(t.lower_bound) {
                return None;
            }
            weight *= t.probability();
        }
        Some(weight)
    }

    /// One player iteration (one tick). Fills `command.events`/`events_len` with the events fired, in order,
    /// and `command.supervisors` with the snapshot after the step.
    #[unsafe(link_section = "swarm_hot")]
    pub fn step(
        &mut self,
        frame: &SensorFrame,
        callbacks: &mut impl EventCallbacks,
        command: &mut ActuatorCommand,
    ) {
        self.tick += 1;
        command.events_len = 0;
        self.rng
            .set_word_pos(u128::from(self.tick) * WORDS_PER_TICK);

        // Uncontrollable phase: one snapshot of every check, then ascending id.
        for i in 0..self.uncontrollable_ids.len() {
            let event = self.uncontrollable_ids[i];
            self.occurred[usize::from(event)] = callbacks.check(event, frame);
        }
        for i in 0..self.uncontrollable_ids.len() {
            let event = self.uncontrollable_ids[i];
            if !self.occurred[usize::from(event)] {
                continue;
            }
            if self.enabled_in_every_owner(event) {
                self.fire(event, command);
            } else {
                self.mismatches += 1;
                tracing::trace!(event, tick = self.tick, "uncontrollable event skipped (A7)");
            }
        }

        // Controllable phase.
        self.enabled.clear();
        self.weights.clear();
        let mut total = 0.0;
        for i in 0..self.controllable_ids.len() {
            let event = self.controllable_ids[i];
            if let Some(weight) = self.enabled_weight(event) {
                self.enabled.push(event);
                self.weights.push(weight);
                total += weight;
            }
        }
        if let Some(chosen) = self.choose(total) {
            self.fire(chosen, command);
            callbacks.act(chosen, frame, command);
        }
        self.write_snapshot(&mut command.supervisors);
    }

    /// Roulette over the enabled events: r ~ U[0, total), the first with cumulative weight > r; uniform when
    /// every weight is 0 (section 5.2).
    #[unsafe(link_section = "swarm_hot")]
    fn choose(&mut self, total: f64) -> Option<u8> {
        if self.enabled.is_empty() {
            return None;
        }
        if total <= 0.0 {
            if !self.zero_weight_warned {
                self.zero_weight_warned = true;
                tracing::warn!(
                    tick = self.tick,
                    "every enabled controllable event has weight 0; choosing uniformly (reported once)"
                );
            }
            let index = self.rng.random_range(0..self.enabled.len());
            return Some(self.enabled[index]);
        }
        let r = self.rng.random::<f64>() * total;
        let mut cumulative = 0.0;
        let mut last_positive = None;
        for (&event, &weight) in self.enabled.iter().zip(&self.weights) {
            cumulative += weight;
            if weight > 0.0 {
                last_positive = Some(event);
            }
            if cumulative > r {
                return Some(event);
            }
        }
        // Only reachable when rounding puts r at the total: the last event that can be drawn.
        last_positive
    }

    /// The supervisors' states and timers: enough to resume them exactly with [`Player::restore`].
    pub fn snapshot(&self) -> SupervisorSnapshot {
        let mut snapshot = SupervisorSnapshot::default();
        self.write_snapshot(&mut snapshot);
        snapshot
    }

    /// Writes the snapshot over `snapshot` in place, touching only the entries in use (the step does so into its
    /// command every tick). Stamps the earlier snapshot used beyond the new ones are cleared, so a snapshot only
    /// this player ever wrote equals [`Player::snapshot`].
    #[unsafe(link_section = "swarm_hot")]
    fn write_snapshot(&self, snapshot: &mut SupervisorSnapshot) {
        let count = self.current.len();
        let stale = usize::from(snapshot.fired_len).min(MAX_FIRED_STAMPS);
        snapshot.count = count as u8;
        snapshot.states[..count].copy_from_slice(&self.current);
        snapshot.entered[..count].copy_from_slice(&self.entered);
        let mut stamps = 0;
        'all: for sup in 0..count {
            for timer in self.timer_base[sup] as usize..self.timer_base[sup + 1] as usize {
                let fired = self.fired[timer];
                // Only stamps later than the state's entry affect a counter.
                if fired > self.entered[sup] {
                    if stamps == MAX_FIRED_STAMPS {
                        break 'all;
                    }
                    snapshot.fired[stamps] = FiredStamp {
                        supervisor: sup as u8,
                        event: self.timer_event[timer],
                        tick: fired,
                    };
                    stamps += 1;
                }
            }
        }
        if stale > stamps {
            snapshot.fired[stamps..stale].fill(FiredStamp::default());
        }
        snapshot.fired_len = stamps as u8;
    }

    /// Resumes from `snapshot`, taken after tick `tick`: the next step is tick `tick + 1`, with the random
    /// sequence an uninterrupted player would have used.
    pub fn restore(&mut self, snapshot: &SupervisorSnapshot, tick: u64) -> Result<(), PlayerError> {
        let mismatch = |reason: String| PlayerError::SnapshotMismatch { reason };
        let count = self.current.len();
        if usize::from(snapshot.count) != count {
            return Err(mismatch(format!(
                "it has {} supervisors, the set has {count}",
                snapshot.count
            )));
        }
        for sup in 0..count {
            let states = self.state_counts[sup];
            let state = snapshot.states[sup];
            if usize::from(state) >= states {
                return Err(mismatch(format!(
                    "supervisor {sup} is in state {state}, it has {states} states"
                )));
            }
            if snapshot.entered[sup] > tick {
                return Err(mismatch(format!(
                    "supervisor {sup} entered its state at tick {}, after tick {tick}",
                    snapshot.entered[sup]
                )));
            }
        }
        let stamps = &snapshot.fired[..usize::from(snapshot.fired_len).min(MAX_FIRED_STAMPS)];
        for stamp in stamps {
            let sup = usize::from(stamp.supervisor);
            if sup >= count
                || usize::from(stamp.event) >= self.events.len()
                || self.timer_slot[sup * self.events.len() + usize::from(stamp.event)] == NO_SLOT
                || stamp.tick > tick
            {
                return Err(mismatch(format!(
                    "no self-loop timer for event {} in supervisor {sup} at tick {}",
                    stamp.event, stamp.tick
                )));
            }
        }
        self.current.copy_from_slice(&snapshot.states[..count]);
        self.entered.copy_from_slice(&snapshot.entered[..count]);
        self.fired.fill(0);
        for stamp in stamps {
            let sup = usize::from(stamp.supervisor);
            let slot = self.timer_slot[sup * self.events.len() + usize::from(stamp.event)];
            self.fired[self.timer_base[sup] as usize + usize::from(slot)] = stamp.tick;
        }
        self.tick = tick;
        Ok(())
    }
}
