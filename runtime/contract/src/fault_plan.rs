//! The fault schedule in time: which fault hits which robot at which tick.
//!
//! A [`FaultPlan`] turns a [`FaultSchedule`] into actions tick by tick. Random choices (`fraction`, `count`,
//! `<chaos>`) draw from one ChaCha8 stream keyed by the run seed with the fixed stream number [`FAULT_STREAM`]
//! (robot streams use the robot index, so they never meet), among the robots alive at that tick, in schedule
//! order. The world and the launcher build the same plan, so both know the same picks without talking.
//!
//! A fault "at tick k" happens between ticks k − 1 and k: the robot takes no part in tick k. Tick 0 is
//! start-up: the launcher kills those robots right after starting them, before the first tick. A freeze, thaw
//! or world kill cannot happen at start-up and moves to tick 1.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::config::faults::{FaultKind, FaultSchedule, ScheduledFault, Targets};

/// Stream number of the fault stream (above every robot index, which are the robots' stream numbers).
pub const FAULT_STREAM: u64 = 0xFA17_0000_0000_0001;

/// One fault to apply now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultAction {
    /// What to do.
    pub kind: FaultKind,
    /// The robot, or `None` for the world.
    pub robot: Option<u32>,
}

/// A schedule entry with its occurrences resolved to ticks.
#[derive(Debug, Clone)]
struct Entry {
    kind: FaultKind,
    targets: Targets,
    /// Next tick it happens at, `None` once done.
    next: Option<u64>,
    /// Period in ticks for repeated faults.
    every: Option<u64>,
    /// Last tick a repeated fault may happen at.
    until: Option<u64>,
}

/// The schedule of one run, executed tick by tick.
#[derive(Debug, Clone)]
pub struct FaultPlan {
    entries: Vec<Entry>,
    rng: ChaCha8Rng,
    /// Scratch list of candidate robots for random picks.
    candidates: Vec<u32>,
}

impl FaultPlan {
    /// The plan of `schedule` for a run at `ticks_per_second` seeded with `seed`.
    pub fn new(schedule: &FaultSchedule, ticks_per_second: u32, seed: u64) -> FaultPlan {
        let entries = schedule
            .faults
            .iter()
            .map(|f: &ScheduledFault| {
                let mut first = f.at.tick(ticks_per_second);
                if first == 0 && f.kind != FaultKind::Kill {
                    first = 1;
                }
                Entry {
                    kind: f.kind,
                    targets: f.targets.clone(),
                    next: Some(first),
                    every: f.every.map(|e| e.tick(ticks_per_second).max(1)),
                    until: f.until.map(|u| u.tick(ticks_per_second)),
                }
            })
            .collect();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(FAULT_STREAM);
        FaultPlan {
            entries,
            rng,
            candidates: Vec::new(),
        }
    }

    /// Whether nothing is scheduled at all.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The first tick at or after `tick` with something due, if any.
    pub fn next_due(&self, tick: u64) -> Option<u64> {
        self.entries
            .iter()
            .filter_map(|e| e.next)
            .filter(|&t| t >= tick)
            .min()
    }

    /// Appends to `out` the faults due at `tick`, in schedule order. `alive[r]` says whether robot r is alive
    /// now; random picks choose among live robots not already hit at this tick, and every robot named is hit
    /// at most once per tick. Call it for every tick in increasing order (ticks without anything due are cheap).
    pub fn due(&mut self, tick: u64, alive: &[bool], out: &mut Vec<FaultAction>) {
        let start = out.len();
        for index in 0..self.entries.len() {
            if self.entries[index].next != Some(tick) {
                continue;
            }
            let entry = &mut self.entries[index];
            entry.next = match (entry.every, entry.until) {
                (Some(every), Some(until)) if tick + every <= until => Some(tick + every),
                (Some(every), None) => Some(tick + every),
                _ => None,
            };
            let kind = entry.kind;
            let hit = |out: &Vec<FaultAction>, robot: u32| {
                out[start..]
                    .iter()
                    .any(|a| a.robot == Some(robot) && a.kind == kind)
            };
            let wanted = match &entry.targets {
                Targets::World => {
                    out.push(FaultAction { kind, robot: None });
                    continue;
                }
                Targets::Robots(list) => {
                    for &robot in list {
                        if !hit(out, robot) {
                            out.push(FaultAction {
                                kind,
                                robot: Some(robot),
                            });
                        }
                    }
                    continue;
                }
                Targets::Fraction(f) => ((f * alive.len() as f64).round() as usize).max(1),
                Targets::Count(n) => *n as usize,
            };
            self.candidates.clear();
            self.candidates
                .extend((0..alive.len() as u32).filter(|&r| alive[r as usize] && !hit(out, r)));
            let wanted = wanted.min(self.candidates.len());
            // Partial Fisher-Yates: the first `wanted` candidates become a uniform sample.
            for i in 0..wanted {
                let j = self.rng.random_range(i..self.candidates.len());
                self.candidates.swap(i, j);
            }
            let picked = &mut self.candidates[..wanted];
            picked.sort_unstable();
            out.extend(picked.iter().map(|&robot| FaultAction {
                kind,
                robot: Some(robot),
            }));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::faults::{At, Origin};

    fn fault(kind: FaultKind, at: At, targets: Targets) -> ScheduledFault {
        ScheduledFault {
            kind,
            at,
            every: None,
            until: None,
            targets,
            origin: Origin {
                path: "x.argos".into(),
                location: Default::default(),
            },
        }
    }

    fn schedule(faults: Vec<ScheduledFault>) -> FaultSchedule {
        FaultSchedule {
            faults,
            ..FaultSchedule::default()
        }
    }

    fn due(plan: &mut FaultPlan, tick: u64, alive: &[bool]) -> Vec<FaultAction> {
        let mut out = Vec::new();
        plan.due(tick, alive, &mut out);
        out
    }

    #[test]
    fn time_converts_to_ticks_with_ticks_per_second() {
        let s = schedule(vec![fault(
            FaultKind::Kill,
            At::Seconds(2.5),
            Targets::Robots(vec![3]),
        )]);
        let mut plan = FaultPlan::new(&s, 10, 1);
        assert_eq!(plan.next_due(0), Some(25));
        assert!(due(&mut plan, 24, &[true; 5]).is_empty());
        assert_eq!(
            due(&mut plan, 25, &[true; 5]),
            vec![FaultAction {
                kind: FaultKind::Kill,
                robot: Some(3)
            }]
        );
        assert_eq!(plan.next_due(26), None);
    }

    #[test]
    fn ten_percent_of_forty_kills_four_live_robots_the_same_for_the_same_seed() {
        let s = schedule(vec![fault(
            FaultKind::Kill,
            At::Tick(10),
            Targets::Fraction(0.1),
        )]);
        let mut alive = [true; 40];
        alive[0] = false;
        let first = due(&mut FaultPlan::new(&s, 10, 7), 10, &alive);
        let again = due(&mut FaultPlan::new(&s, 10, 7), 10, &alive);
        let other = due(&mut FaultPlan::new(&s, 10, 8), 10, &alive);
        assert_eq!(first.len(), 4);
        assert!(
            first.iter().all(|a| a.robot != Some(0)),
            "dead robot 0 is not picked"
        );
        assert_eq!(first, again);
        assert_ne!(first, other);
    }

    #[test]
    fn chaos_repeats_every_period_until_its_stop() {
        let mut f = fault(FaultKind::Kill, At::Seconds(1.0), Targets::Count(2));
        f.every = Some(At::Seconds(1.0));
        f.until = Some(At::Seconds(3.0));
        let mut plan = FaultPlan::new(&schedule(vec![f]), 10, 3);
        let mut alive = vec![true; 10];
        let mut hits = Vec::new();
        for tick in 0..=50 {
            for a in due(&mut plan, tick, &alive) {
                let r = a.robot.unwrap();
                assert!(alive[r as usize]);
                alive[r as usize] = false;
                hits.push(tick);
            }
        }
        assert_eq!(hits, vec![10, 10, 20, 20, 30, 30]);
    }

    #[test]
    fn startup_freeze_moves_to_the_first_tick() {
        let s = schedule(vec![
            fault(FaultKind::Kill, At::Tick(0), Targets::Robots(vec![1])),
            fault(FaultKind::Freeze, At::Tick(0), Targets::Robots(vec![2])),
        ]);
        let mut plan = FaultPlan::new(&s, 10, 3);
        assert_eq!(due(&mut plan, 0, &[true; 4]).len(), 1);
        assert_eq!(due(&mut plan, 1, &[true; 4])[0].kind, FaultKind::Freeze);
    }
}
