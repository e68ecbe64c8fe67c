//! The messages of the exploration task (paper A, docs/exploration.md), in a tag space of their own (16 and up)
//! so that no navigation letter is ever taken for one. Like the navigation letters: at most 256 bytes,
//! little-endian, first byte the tag, and decoding never trusts its input.
//!
//! | tag | letter | from -> to |
//! |---|---|---|
//! | 16 | [`Setup`]: the robot's type, the tick rate, how close counts as at a task, its rays' reach | task server -> robot |
//! | 17 | [`Found`]: a task, as the robot sensed it or as a robot reports it | task server -> robot; robot -> coordinator |
//! | 18 | [`Status`]: type, mode, task, position, distance driven to tasks | robot -> coordinator and task server |
//! | 19 | [`Assign`]: go and do a task | coordinator -> robot |
//! | 20 | `Cancel`: drop the task (a teammate failed) | coordinator -> robot |
//! | 21 | `Done`: a task is complete | task server -> robot; robot -> coordinator; coordinator -> all |
//! | 22 | `Recall`: tell me everything you know (a coordinator that has just started) | coordinator -> all |
//! | 23 | [`Region`]: a local safe region of the sender's exploration tree | robot -> all |
//! | 24 | [`Allocation`]: what one allocator run took | coordinator -> task server |
//!
//! Times are ticks: the task server converts the configuration's seconds, so that a coordinator needs no clock.
//! The one exception is [`Allocation::micros`], the allocator's wall time, which only the machine-dependent
//! part of a run's summary shows.

use swarm_allocation::Kind;

use super::{PAYLOAD, Reader, WireError, Writer, exact};
use crate::V2;

const SETUP: u8 = 16;
const FOUND: u8 = 17;
const STATUS: u8 = 18;
const ASSIGN: u8 = 19;
const CANCEL: u8 = 20;
const DONE: u8 = 21;
const RECALL: u8 = 22;
const REGION: u8 = 23;
const ALLOCATION: u8 = 24;
const SETUP_LEN: usize = 1 + 1 + 4 + 4 + 4;
const FOUND_LEN: usize = 1 + 2 + 2 * 4 + 1 + 4 + 4 + 4 + 1;
const STATUS_LEN: usize = 1 + 1 + 1 + 2 + 2 * 4 + 4;
const ASSIGN_LEN: usize = 1 + 2 + 2 * 4 + 4;
const TASK_ONLY_LEN: usize = 1 + 2;
const ALLOCATION_LEN: usize = 1 + 4 + 2 + 2 + 4;
const REGION_HEADER: usize = 1 + 4 + 3 * 4 + 1;
/// Most rays a [`Region`] carries (the range finder's most).
pub const MAX_REGION_RAYS: usize = 24;
/// The task number that means "none" in a [`Status`].
const NO_TASK: u16 = u16::MAX;
/// Most tasks a run may have: task numbers are 16 bits and one value means "none".
pub const MAX_TASKS: usize = NO_TASK as usize;

/// What the task server tells a robot about itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setup {
    /// The robot's type.
    pub kind: Kind,
    /// The run's tick rate, to turn seconds into ticks.
    pub ticks_per_second: u32,
    /// A robot whose centre is this close to a task's position is at the task (m).
    pub reach: f32,
    /// The reach of the robot's range rays (m): a reading of infinity saw free space this far.
    pub sensor_range: f32,
}

/// A task as sensed or reported.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Found {
    /// The task's number in the run (from 0).
    pub task: u16,
    /// Where it is.
    pub position: V2,
    /// Its type.
    pub kind: Kind,
    /// Its value u_j before any decay.
    pub value: f32,
    /// The tick its window W_j ends: done later, its utility decays.
    pub window_end: u32,
    /// Ticks over which the utility falls linearly to zero after the window.
    pub decay: u32,
    /// Whether the sender knows it is complete.
    pub done: bool,
}

impl Found {
    /// The task's utility if it is completed at `tick`: its value within the window, then falling linearly to
    /// zero over `decay` ticks.
    pub fn utility_at(&self, tick: u64) -> f32 {
        utility_at(self.value, self.window_end, self.decay, tick)
    }
}

/// A task's utility if completed at `tick`: `value` up to `window_end`, then falling linearly to zero over
/// `decay` ticks (at once with no decay).
pub fn utility_at(value: f32, window_end: u32, decay: u32, tick: u64) -> f32 {
    let late = tick.saturating_sub(u64::from(window_end));
    if late == 0 {
        value
    } else if late >= u64::from(decay) {
        0.0
    } else {
        value * (1.0 - late as f32 / decay as f32)
    }
}

/// A robot's mode (A.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Exploring (mode 0).
    Explore,
    /// Travelling to its task (mode 1).
    Travel,
    /// At its task, executing it (mode 2).
    Execute,
    /// Finished a task and exploring again (mode 3; allocated like mode 0).
    Finished,
}

impl Mode {
    /// Whether the allocator may assign the robot (modes 0 and 3).
    pub fn is_available(self) -> bool {
        matches!(self, Mode::Explore | Mode::Finished)
    }
}

/// A robot's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Status {
    /// Its type.
    pub kind: Kind,
    /// Its mode.
    pub mode: Mode,
    /// The task it travels to or executes.
    pub task: Option<u16>,
    /// Where it is.
    pub position: V2,
    /// Metres it has driven in mode 1 so far, over all its tasks.
    pub to_tasks: f32,
}

/// An assignment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Assign {
    /// The task.
    pub task: u16,
    /// Where it is.
    pub position: V2,
    /// The allocation that made it (the coordinator's count), so that a repeated letter is recognised.
    pub allocation: u32,
}

/// One run of the allocator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Allocation {
    /// The coordinator's count of allocator runs, from 1.
    pub number: u32,
    /// Open tasks it allocated.
    pub tasks: u16,
    /// Available robots it allocated.
    pub robots: u16,
    /// Its wall time in microseconds (machine-dependent).
    pub micros: u32,
}

/// A local safe region: where the sender stood, when, and what its rays saw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region<'a> {
    /// The tick it was seen.
    pub tick: u32,
    /// The centre.
    pub centre: V2,
    /// The angle of ray 0 (rad).
    pub heading: f32,
    rays: &'a [u8],
}

impl Region<'_> {
    /// The ray lengths (checked when decoded).
    pub fn rays(&self) -> impl Iterator<Item = f32> + '_ {
        self.rays
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
}

/// A decoded exploration message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Letter<'a> {
    /// About the recipient.
    Setup(Setup),
    /// A task.
    Found(Found),
    /// A robot's state.
    Status(Status),
    /// An assignment.
    Assign(Assign),
    /// Drop this task.
    Cancel(u16),
    /// This task is complete.
    Done(u16),
    /// Report everything again.
    Recall,
    /// A local safe region.
    Region(Region<'a>),
    /// An allocator run.
    Allocation(Allocation),
}

fn kind_byte(kind: Kind) -> u8 {
    match kind {
        Kind::One => 1,
        Kind::Two => 2,
    }
}

fn kind(byte: u8) -> Result<Kind, WireError> {
    match byte {
        1 => Ok(Kind::One),
        2 => Ok(Kind::Two),
        _ => Err(WireError::BadNumber),
    }
}

fn mode_byte(mode: Mode) -> u8 {
    match mode {
        Mode::Explore => 0,
        Mode::Travel => 1,
        Mode::Execute => 2,
        Mode::Finished => 3,
    }
}

fn mode(byte: u8) -> Result<Mode, WireError> {
    match byte {
        0 => Ok(Mode::Explore),
        1 => Ok(Mode::Travel),
        2 => Ok(Mode::Execute),
        3 => Ok(Mode::Finished),
        _ => Err(WireError::BadNumber),
    }
}

fn flag(byte: u8) -> Result<bool, WireError> {
    match byte {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(WireError::BadNumber),
    }
}

/// Writes `setup` into `out`; returns the payload length.
pub fn encode_setup(setup: &Setup, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[SETUP, kind_byte(setup.kind)])
        .bytes(&setup.ticks_per_second.to_le_bytes())
        .f32(setup.reach)
        .f32(setup.sensor_range);
    w.at
}

/// Writes `found` into `out`; returns the payload length.
pub fn encode_found(found: &Found, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[FOUND])
        .bytes(&found.task.to_le_bytes())
        .f32(found.position.x)
        .f32(found.position.y);
    w.bytes(&[kind_byte(found.kind)])
        .f32(found.value)
        .bytes(&found.window_end.to_le_bytes())
        .bytes(&found.decay.to_le_bytes())
        .bytes(&[u8::from(found.done)]);
    w.at
}

/// Writes `status` into `out`; returns the payload length.
pub fn encode_status(status: &Status, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[STATUS, kind_byte(status.kind), mode_byte(status.mode)])
        .bytes(&status.task.unwrap_or(NO_TASK).to_le_bytes())
        .f32(status.position.x)
        .f32(status.position.y);
    w.f32(status.to_tasks);
    w.at
}

/// Writes `assign` into `out`; returns the payload length.
pub fn encode_assign(assign: &Assign, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[ASSIGN])
        .bytes(&assign.task.to_le_bytes())
        .f32(assign.position.x)
        .f32(assign.position.y);
    w.bytes(&assign.allocation.to_le_bytes());
    w.at
}

fn encode_task_only(tag: u8, task: u16, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[tag]).bytes(&task.to_le_bytes());
    w.at
}

/// Writes a `Cancel` of `task` into `out`; returns the payload length.
pub fn encode_cancel(task: u16, out: &mut [u8; PAYLOAD]) -> usize {
    encode_task_only(CANCEL, task, out)
}

/// Writes a `Done` of `task` into `out`; returns the payload length.
pub fn encode_done(task: u16, out: &mut [u8; PAYLOAD]) -> usize {
    encode_task_only(DONE, task, out)
}

/// Writes a `Recall` into `out`; returns the payload length.
pub fn encode_recall(out: &mut [u8; PAYLOAD]) -> usize {
    out[0] = RECALL;
    1
}

/// Writes a region seen at `tick` from `centre` into `out` (at most [`MAX_REGION_RAYS`] rays; more are cut);
/// returns the payload length.
pub fn encode_region(
    tick: u32,
    centre: V2,
    heading: f32,
    rays: &[f32],
    out: &mut [u8; PAYLOAD],
) -> usize {
    let rays = &rays[..rays.len().min(MAX_REGION_RAYS)];
    let mut w = Writer { out, at: 0 };
    w.bytes(&[REGION])
        .bytes(&tick.to_le_bytes())
        .f32(centre.x)
        .f32(centre.y);
    w.f32(heading).bytes(&[rays.len() as u8]);
    for &r in rays {
        w.f32(r);
    }
    w.at
}

/// Writes `allocation` into `out`; returns the payload length.
pub fn encode_allocation(allocation: &Allocation, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[ALLOCATION])
        .bytes(&allocation.number.to_le_bytes())
        .bytes(&allocation.tasks.to_le_bytes())
        .bytes(&allocation.robots.to_le_bytes())
        .bytes(&allocation.micros.to_le_bytes());
    w.at
}

/// Whether `payload` is an exploration message (its tag is one of this module's), whatever else is wrong with it.
pub fn is_exploration(payload: &[u8]) -> bool {
    payload
        .first()
        .is_some_and(|t| (SETUP..=ALLOCATION).contains(t))
}

/// Decodes an exploration payload.
pub fn decode(payload: &[u8]) -> Result<Letter<'_>, WireError> {
    let &tag = payload.first().ok_or(WireError::Empty)?;
    let bad_length = WireError::Length {
        tag,
        len: payload.len(),
    };
    let exact = |len: usize| exact(payload, len);
    match tag {
        SETUP => {
            let mut r = exact(SETUP_LEN)?;
            let setup = Setup {
                kind: kind(r.u8())?,
                ticks_per_second: r.u32(),
                reach: r.positive()?,
                sensor_range: r.positive()?,
            };
            if setup.ticks_per_second == 0 {
                return Err(WireError::BadNumber);
            }
            Ok(Letter::Setup(setup))
        }
        FOUND => {
            let mut r = exact(FOUND_LEN)?;
            let found = Found {
                task: r.u16(),
                position: r.v2()?,
                kind: kind(r.u8())?,
                value: r.f32()?,
                window_end: r.u32(),
                decay: r.u32(),
                done: flag(r.u8())?,
            };
            if found.task == NO_TASK || found.value < 0.0 {
                return Err(WireError::BadNumber);
            }
            Ok(Letter::Found(found))
        }
        STATUS => {
            let mut r = exact(STATUS_LEN)?;
            let kind = kind(r.u8())?;
            let mode = mode(r.u8())?;
            let task = Some(r.u16()).filter(|&t| t != NO_TASK);
            let status = Status {
                kind,
                mode,
                task,
                position: r.v2()?,
                to_tasks: r.f32()?,
            };
            let task_fits_mode =
                status.task.is_some() == matches!(mode, Mode::Travel | Mode::Execute);
            if !task_fits_mode || status.to_tasks < 0.0 {
                return Err(WireError::BadNumber);
            }
            Ok(Letter::Status(status))
        }
        ASSIGN => {
            let mut r = exact(ASSIGN_LEN)?;
            let assign = Assign {
                task: r.u16(),
                position: r.v2()?,
                allocation: r.u32(),
            };
            if assign.task == NO_TASK {
                return Err(WireError::BadNumber);
            }
            Ok(Letter::Assign(assign))
        }
        CANCEL | DONE => {
            let mut r = exact(TASK_ONLY_LEN)?;
            let task = r.u16();
            if task == NO_TASK {
                return Err(WireError::BadNumber);
            }
            Ok(if tag == CANCEL {
                Letter::Cancel(task)
            } else {
                Letter::Done(task)
            })
        }
        RECALL => {
            exact(1)?;
            Ok(Letter::Recall)
        }
        REGION => {
            if payload.len() < REGION_HEADER {
                return Err(bad_length);
            }
            let mut r = Reader {
                bytes: payload,
                at: 1,
            };
            let tick = r.u32();
            let centre = r.v2()?;
            let heading = r.f32()?;
            let n = usize::from(r.u8());
            if n > MAX_REGION_RAYS || payload.len() != REGION_HEADER + 4 * n {
                return Err(bad_length);
            }
            for _ in 0..n {
                if r.f32()? < 0.0 {
                    return Err(WireError::BadNumber);
                }
            }
            Ok(Letter::Region(Region {
                tick,
                centre,
                heading,
                rays: &payload[REGION_HEADER..],
            }))
        }
        ALLOCATION => {
            let mut r = exact(ALLOCATION_LEN)?;
            Ok(Letter::Allocation(Allocation {
                number: r.u32(),
                tasks: r.u16(),
                robots: r.u16(),
                micros: r.u32(),
            }))
        }
        other => Err(WireError::UnknownTag(other)),
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    #[test]
    fn letters_round_trip() {
        let mut out = [0u8; PAYLOAD];
        let setup = Setup {
            kind: Kind::Two,
            ticks_per_second: 10,
            reach: 0.3,
            sensor_range: 1.5,
        };
        let len = encode_setup(&setup, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Setup(setup)));
        let found = Found {
            task: 3,
            position: V2::new(2.5, 7.0),
            kind: Kind::One,
            value: 45.0,
            window_end: 2000,
            decay: 500,
            done: true,
        };
        let len = encode_found(&found, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Found(found)));
        let status = Status {
            kind: Kind::One,
            mode: Mode::Travel,
            task: Some(3),
            position: V2::new(1.0, 1.5),
            to_tasks: 4.25,
        };
        let len = encode_status(&status, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Status(status)));
        let idle = Status {
            mode: Mode::Finished,
            task: None,
            ..status
        };
        let len = encode_status(&idle, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Status(idle)));
        let assign = Assign {
            task: 3,
            position: found.position,
            allocation: 17,
        };
        let len = encode_assign(&assign, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Assign(assign)));
        let len = encode_cancel(4, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Cancel(4)));
        let len = encode_done(5, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Done(5)));
        let allocation = Allocation {
            number: 2,
            tasks: 12,
            robots: 9,
            micros: 1500,
        };
        let len = encode_allocation(&allocation, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Allocation(allocation)));
        let len = encode_recall(&mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Recall));
        let rays: Vec<f32> = (0..20).map(|k| 0.5 + k as f32 * 0.05).collect();
        let len = encode_region(99, V2::new(4.0, 4.0), 0.5, &rays, &mut out);
        let Ok(Letter::Region(region)) = decode(&out[..len]) else {
            panic!("not a region");
        };
        assert_eq!(
            (region.tick, region.centre, region.heading),
            (99, V2::new(4.0, 4.0), 0.5)
        );
        assert_eq!(region.rays().collect::<Vec<_>>(), rays);
    }

    #[test]
    fn the_utility_falls_linearly_after_the_window() {
        assert_eq!(utility_at(40.0, 100, 50, 100), 40.0);
        assert_eq!(utility_at(40.0, 100, 50, 125), 20.0);
        assert_eq!(utility_at(40.0, 100, 50, 150), 0.0);
        assert_eq!(utility_at(40.0, 100, 0, 101), 0.0);
    }

    #[test]
    fn inconsistent_letters_are_errors() {
        let mut out = [0u8; PAYLOAD];
        // Travelling without a task.
        let len = encode_status(
            &Status {
                kind: Kind::One,
                mode: Mode::Travel,
                task: None,
                position: V2::ZERO,
                to_tasks: 0.0,
            },
            &mut out,
        );
        assert_eq!(decode(&out[..len]), Err(WireError::BadNumber));
        let len = encode_setup(
            &Setup {
                kind: Kind::One,
                ticks_per_second: 10,
                reach: 0.3,
                sensor_range: 1.0,
            },
            &mut out,
        );
        out[1] = 3;
        assert_eq!(decode(&out[..len]), Err(WireError::BadNumber));
        let len = encode_region(1, V2::ZERO, 0.0, &[1.0, 1.0], &mut out);
        out[REGION_HEADER - 1] = 3;
        assert_eq!(
            decode(&out[..len]),
            Err(WireError::Length { tag: REGION, len })
        );
        assert_eq!(
            decode(&[RECALL, 0]),
            Err(WireError::Length {
                tag: RECALL,
                len: 2
            })
        );
        assert!(is_exploration(&[RECALL]) && !is_exploration(&[3]) && !is_exploration(&[]));
    }

    proptest! {
        #[test]
        fn tagged_garbage_never_panics(tag in SETUP..=ALLOCATION, bytes in prop::collection::vec(any::<u8>(), 0..260)) {
            let mut payload = vec![tag];
            payload.extend(bytes);
            if let Ok(Letter::Region(region)) = decode(&payload) {
                prop_assert!(region.rays().count() <= MAX_REGION_RAYS);
            }
        }
    }
}
