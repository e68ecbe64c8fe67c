//! The messages of the navigation task, as payloads of the run's messages medium (at most 256 bytes each,
//! little-endian, first byte a tag). Decoding never trusts its input: a payload of the wrong length, an unknown
//! tag or a non-finite number is an error, never a panic.
//!
//! | tag | letter | from -> to |
//! |---|---|---|
//! | 1 | [`Task`]: a goal | task server (the world's loop functions) -> robot |
//! | 2 | [`Chunk`] of [`Disc`]s: the obstacle map | task server -> robot |
//! | 3 | [`Report`]: pose, status, goal | robot -> coordinator |
//! | 4 | [`Chunk`] of [`Neighbour`]s: the snapshot with priorities | coordinator -> every participant |
//! | 5 | [`Bounds`]: the box a path planner keeps to | task server -> robot |
//! | 6 | [`PlanReport`]: a path planner's statistics for its current task | robot -> task server |
//!
//! A map or snapshot longer than one payload is sent as several chunks in the same tick; each says how many
//! entries the whole has and where it starts. The exploration task's letters are in [`exploration`] and cooperative
//! transport's in [`transport`], each with tags of their own.

pub mod exploration;
pub mod transport;

use crate::V2;
use crate::apf::{Disc, Neighbour, Status};
use crate::planning::Bounds;

/// Largest payload (the messages medium's).
pub const PAYLOAD: usize = 256;
const TASK: u8 = 1;
const MAP: u8 = 2;
const REPORT: u8 = 3;
const SNAPSHOT: u8 = 4;
const BOUNDS: u8 = 5;
const PLAN_REPORT: u8 = 6;
const BOUNDS_LEN: usize = 1 + 4 * 4;
const PLAN_REPORT_LEN: usize = 1 + 6 * 4 + 2 * 4;
const TASK_LEN: usize = 1 + 4 + 4 * 4;
const REPORT_LEN: usize = 1 + 4 * 4 + 1 + 2 * 4;
const CHUNK_HEADER: usize = 1 + 2 + 2 + 1;
const DISC_LEN: usize = 3 * 4;
const NEIGHBOUR_LEN: usize = 4 + 4 * 4 + 1 + 4;
/// Obstacles per map chunk.
pub const DISCS_PER_CHUNK: usize = (PAYLOAD - CHUNK_HEADER) / DISC_LEN;
/// Robots per snapshot chunk.
pub const NEIGHBOURS_PER_CHUNK: usize = (PAYLOAD - CHUNK_HEADER) / NEIGHBOUR_LEN;

/// Why a payload is not a navigation message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    /// The payload is empty.
    #[error("empty payload")]
    Empty,
    /// The first byte is no known tag.
    #[error("unknown tag {0}")]
    UnknownTag(u8),
    /// The payload's length does not fit its tag.
    #[error("tag {tag} with a payload of {len} bytes")]
    Length {
        /// The tag.
        tag: u8,
        /// The length found.
        len: usize,
    },
    /// A number is NaN or infinite, a radius or tolerance is not positive, or a status byte is unknown.
    #[error("a number is not finite or out of range")]
    BadNumber,
    /// A chunk's entries overrun the whole it belongs to.
    #[error("a chunk's entries overrun its whole")]
    BadChunk,
}

/// A goal for a robot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Task {
    /// The task's number for this robot, from 1; a new number means a new goal.
    pub seq: u32,
    /// Where to go.
    pub goal: V2,
    /// How close counts as arrived, in metres.
    pub tolerance: f32,
    /// The robot's own body radius, as the world knows it.
    pub radius: f32,
}

/// A robot's state, for the coordinator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Report {
    /// Position.
    pub position: V2,
    /// Heading in radians.
    pub heading: f32,
    /// Body radius.
    pub radius: f32,
    /// Moving or stopped.
    pub status: Status,
    /// Its current goal (its position when it has none).
    pub goal: V2,
}

/// What a path-planning robot did for one task so far (counts from the task's start).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PlanReport {
    /// The task's number.
    pub seq: u32,
    /// Planner runs.
    pub plans: u32,
    /// Planner runs that found no path.
    pub failed: u32,
    /// Replans because the path was found blocked by an obstacle the map did not have.
    pub replans: u32,
    /// Sum over the runs of the agents whose trajectories were collision-free (|S_cf|).
    pub collision_free: u32,
    /// Sum over the runs of the agents (N).
    pub agents: u32,
    /// Length of the first plan's path as the planner chose it (m; 0 before the first plan).
    pub first_planned: f32,
    /// Length of the first plan's path as the robot follows it, after smoothing (m).
    pub first_followed: f32,
}

/// Part of a map or snapshot: `count` entries from `first` of a whole of `total`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chunk<'a> {
    /// Entries in the whole.
    pub total: u16,
    /// Index of this chunk's first entry in the whole.
    pub first: u16,
    entries: &'a [u8],
}

/// A decoded navigation message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Letter<'a> {
    /// A goal.
    Task(Task),
    /// Part of the obstacle map.
    Map(Chunk<'a>),
    /// A robot's state.
    Report(Report),
    /// Part of the coordinator's snapshot.
    Snapshot(Chunk<'a>),
    /// The planning box.
    Bounds(Bounds),
    /// A path planner's statistics.
    PlanReport(PlanReport),
}

struct Writer<'a> {
    out: &'a mut [u8; PAYLOAD],
    at: usize,
}

impl Writer<'_> {
    fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.out[self.at..self.at + b.len()].copy_from_slice(b);
        self.at += b.len();
        self
    }
    fn f32(&mut self, v: f32) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut b = [0u8; N];
        b.copy_from_slice(&self.bytes[self.at..self.at + N]);
        self.at += N;
        b
    }
    fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }
    fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.take())
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn f32(&mut self) -> Result<f32, WireError> {
        let v = f32::from_le_bytes(self.take());
        if v.is_finite() {
            Ok(v)
        } else {
            Err(WireError::BadNumber)
        }
    }
    fn v2(&mut self) -> Result<V2, WireError> {
        Ok(V2::new(self.f32()?, self.f32()?))
    }
    fn positive(&mut self) -> Result<f32, WireError> {
        let v = self.f32()?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(WireError::BadNumber)
        }
    }
}

/// A reader past the tag of `payload` (not empty), which must be `len` bytes long.
fn exact(payload: &[u8], len: usize) -> Result<Reader<'_>, WireError> {
    if payload.len() == len {
        Ok(Reader {
            bytes: payload,
            at: 1,
        })
    } else {
        Err(WireError::Length {
            tag: payload[0],
            len: payload.len(),
        })
    }
}

/// Writes `task` into `out`; returns the payload length.
pub fn encode_task(task: &Task, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[TASK])
        .bytes(&task.seq.to_le_bytes())
        .f32(task.goal.x)
        .f32(task.goal.y);
    w.f32(task.tolerance).f32(task.radius);
    w.at
}

/// Writes `report` into `out`; returns the payload length.
pub fn encode_report(report: &Report, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[REPORT])
        .f32(report.position.x)
        .f32(report.position.y);
    w.f32(report.heading).f32(report.radius);
    w.bytes(&[u8::from(report.status == Status::Moving)]);
    w.f32(report.goal.x).f32(report.goal.y);
    w.at
}

/// Writes `bounds` into `out`; returns the payload length.
pub fn encode_bounds(bounds: &Bounds, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[BOUNDS]).f32(bounds.min.x).f32(bounds.min.y);
    w.f32(bounds.max.x).f32(bounds.max.y);
    w.at
}

/// Writes `report` into `out`; returns the payload length.
pub fn encode_plan_report(report: &PlanReport, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[PLAN_REPORT]);
    for n in [
        report.seq,
        report.plans,
        report.failed,
        report.replans,
        report.collision_free,
        report.agents,
    ] {
        w.bytes(&n.to_le_bytes());
    }
    w.f32(report.first_planned).f32(report.first_followed);
    w.at
}

fn chunk_header(w: &mut Writer<'_>, tag: u8, total: usize, first: usize, count: usize) {
    w.bytes(&[tag])
        .bytes(&(total as u16).to_le_bytes())
        .bytes(&(first as u16).to_le_bytes())
        .bytes(&[count as u8]);
}

/// Writes the map chunk of `obstacles` starting at entry `first` into `out`; returns the payload length and the
/// first entry of the next chunk (`obstacles.len()` when this was the last). At most 65,535 obstacles.
pub fn encode_map(obstacles: &[Disc], first: usize, out: &mut [u8; PAYLOAD]) -> (usize, usize) {
    let end = (first + DISCS_PER_CHUNK).min(obstacles.len());
    let mut w = Writer { out, at: 0 };
    chunk_header(&mut w, MAP, obstacles.len(), first, end - first);
    for d in &obstacles[first..end] {
        w.f32(d.centre.x).f32(d.centre.y).f32(d.radius);
    }
    (w.at, end)
}

/// Writes the snapshot chunk of `robots` starting at entry `first` into `out`; returns the payload length and
/// the first entry of the next chunk (`robots.len()` when this was the last). At most 65,535 robots.
pub fn encode_snapshot(
    robots: &[Neighbour],
    first: usize,
    out: &mut [u8; PAYLOAD],
) -> (usize, usize) {
    let end = (first + NEIGHBOURS_PER_CHUNK).min(robots.len());
    let mut w = Writer { out, at: 0 };
    chunk_header(&mut w, SNAPSHOT, robots.len(), first, end - first);
    for n in &robots[first..end] {
        w.bytes(&n.id.to_le_bytes())
            .f32(n.position.x)
            .f32(n.position.y);
        w.f32(n.heading).f32(n.radius);
        w.bytes(&[u8::from(n.status == Status::Moving)])
            .f32(n.priority);
    }
    (w.at, end)
}

fn status(byte: u8) -> Result<Status, WireError> {
    match byte {
        0 => Ok(Status::Stopped),
        1 => Ok(Status::Moving),
        _ => Err(WireError::BadNumber),
    }
}

fn chunk(payload: &[u8], tag: u8, entry: usize) -> Result<Chunk<'_>, WireError> {
    let bad_length = WireError::Length {
        tag,
        len: payload.len(),
    };
    if payload.len() < CHUNK_HEADER {
        return Err(bad_length);
    }
    let mut r = Reader {
        bytes: payload,
        at: 1,
    };
    let (total, first, count) = (r.u16(), r.u16(), usize::from(r.u8()));
    if payload.len() != CHUNK_HEADER + count * entry {
        return Err(bad_length);
    }
    if usize::from(first) + count > usize::from(total) {
        return Err(WireError::BadChunk);
    }
    let chunk = Chunk {
        total,
        first,
        entries: &payload[CHUNK_HEADER..],
    };
    // Every entry is checked now, so that iterating later cannot fail.
    let read = if tag == MAP {
        |e: &[u8]| read_disc(e).map(drop)
    } else {
        |e: &[u8]| read_neighbour(e).map(drop)
    };
    chunk.entries.chunks_exact(entry).try_for_each(read)?;
    Ok(chunk)
}

/// Decodes a navigation payload.
pub fn decode(payload: &[u8]) -> Result<Letter<'_>, WireError> {
    let &tag = payload.first().ok_or(WireError::Empty)?;
    let exact = |len: usize| exact(payload, len);
    match tag {
        TASK => {
            let mut r = exact(TASK_LEN)?;
            Ok(Letter::Task(Task {
                seq: r.u32(),
                goal: r.v2()?,
                tolerance: r.positive()?,
                radius: r.positive()?,
            }))
        }
        REPORT => {
            let mut r = exact(REPORT_LEN)?;
            Ok(Letter::Report(Report {
                position: r.v2()?,
                heading: r.f32()?,
                radius: r.positive()?,
                status: status(r.u8())?,
                goal: r.v2()?,
            }))
        }
        BOUNDS => {
            let mut r = exact(BOUNDS_LEN)?;
            let bounds = Bounds {
                min: r.v2()?,
                max: r.v2()?,
            };
            if bounds.is_valid() {
                Ok(Letter::Bounds(bounds))
            } else {
                Err(WireError::BadNumber)
            }
        }
        PLAN_REPORT => {
            let mut r = exact(PLAN_REPORT_LEN)?;
            let report = PlanReport {
                seq: r.u32(),
                plans: r.u32(),
                failed: r.u32(),
                replans: r.u32(),
                collision_free: r.u32(),
                agents: r.u32(),
                first_planned: r.f32()?,
                first_followed: r.f32()?,
            };
            let consistent = report.failed <= report.plans
                && report.collision_free <= report.agents
                && report.first_planned >= 0.0
                && report.first_followed >= 0.0;
            if consistent {
                Ok(Letter::PlanReport(report))
            } else {
                Err(WireError::BadNumber)
            }
        }
        MAP => Ok(Letter::Map(chunk(payload, MAP, DISC_LEN)?)),
        SNAPSHOT => Ok(Letter::Snapshot(chunk(payload, SNAPSHOT, NEIGHBOUR_LEN)?)),
        other => Err(WireError::UnknownTag(other)),
    }
}

fn read_disc(entry: &[u8]) -> Result<Disc, WireError> {
    let mut r = Reader {
        bytes: entry,
        at: 0,
    };
    Ok(Disc {
        centre: r.v2()?,
        radius: r.positive()?,
    })
}

fn read_neighbour(entry: &[u8]) -> Result<Neighbour, WireError> {
    let mut r = Reader {
        bytes: entry,
        at: 0,
    };
    Ok(Neighbour {
        id: r.u32(),
        position: r.v2()?,
        heading: r.f32()?,
        radius: r.positive()?,
        status: status(r.u8())?,
        priority: r.f32()?,
    })
}

impl Chunk<'_> {
    /// The obstacles of a map chunk (checked when it was decoded).
    pub fn discs(&self) -> impl Iterator<Item = Disc> + '_ {
        self.entries
            .chunks_exact(DISC_LEN)
            .filter_map(|e| read_disc(e).ok())
    }

    /// The robots of a snapshot chunk (checked when it was decoded).
    pub fn neighbours(&self) -> impl Iterator<Item = Neighbour> + '_ {
        self.entries
            .chunks_exact(NEIGHBOUR_LEN)
            .filter_map(|e| read_neighbour(e).ok())
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    fn neighbour(id: u32) -> Neighbour {
        Neighbour {
            id,
            position: V2::new(id as f32, -1.5),
            heading: 0.25,
            radius: 0.105,
            status: if id.is_multiple_of(2) {
                Status::Moving
            } else {
                Status::Stopped
            },
            priority: id as f32 * 2.0,
        }
    }

    #[test]
    fn letters_round_trip() {
        let mut out = [0u8; PAYLOAD];
        let task = Task {
            seq: 7,
            goal: V2::new(1.5, -2.0),
            tolerance: 0.1,
            radius: 0.105,
        };
        let len = encode_task(&task, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Task(task)));
        let report = Report {
            position: V2::new(0.5, 0.25),
            heading: -1.0,
            radius: 0.105,
            status: Status::Moving,
            goal: V2::new(3.0, 3.0),
        };
        let len = encode_report(&report, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Report(report)));
        let bounds = Bounds {
            min: V2::new(-1.0, 0.0),
            max: V2::new(9.0, 10.0),
        };
        let len = encode_bounds(&bounds, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Bounds(bounds)));
        let stats = PlanReport {
            seq: 2,
            plans: 3,
            failed: 1,
            replans: 1,
            collision_free: 40,
            agents: 150,
            first_planned: 12.5,
            first_followed: 9.25,
        };
        let len = encode_plan_report(&stats, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::PlanReport(stats)));
    }

    #[test]
    fn inconsistent_bounds_and_reports_are_errors() {
        let mut out = [0u8; PAYLOAD];
        let inverted = Bounds {
            min: V2::new(1.0, 0.0),
            max: V2::new(0.0, 1.0),
        };
        let len = encode_bounds(&inverted, &mut out);
        assert_eq!(decode(&out[..len]), Err(WireError::BadNumber));
        let more_failures_than_runs = PlanReport {
            plans: 1,
            failed: 2,
            ..PlanReport::default()
        };
        let len = encode_plan_report(&more_failures_than_runs, &mut out);
        assert_eq!(decode(&out[..len]), Err(WireError::BadNumber));
    }

    #[test]
    fn snapshots_and_maps_split_into_chunks_that_fit_a_payload() {
        assert_eq!((NEIGHBOURS_PER_CHUNK, DISCS_PER_CHUNK), (10, 20));
        let robots: Vec<Neighbour> = (0..25).map(neighbour).collect();
        let (mut first, mut seen) = (0, Vec::new());
        let mut out = [0u8; PAYLOAD];
        while first < robots.len() {
            let (len, next) = encode_snapshot(&robots, first, &mut out);
            let Ok(Letter::Snapshot(chunk)) = decode(&out[..len]) else {
                panic!("not a snapshot");
            };
            assert_eq!((chunk.total, usize::from(chunk.first)), (25, first));
            seen.extend(chunk.neighbours());
            first = next;
        }
        assert_eq!(seen, robots);
        let discs: Vec<Disc> = (0..3)
            .map(|i| Disc {
                centre: V2::new(i as f32, 1.0),
                radius: 0.3,
            })
            .collect();
        let (len, next) = encode_map(&discs, 0, &mut out);
        assert_eq!(next, 3);
        let Ok(Letter::Map(chunk)) = decode(&out[..len]) else {
            panic!("not a map");
        };
        assert_eq!(chunk.discs().collect::<Vec<_>>(), discs);
        // An empty snapshot is one chunk of no entries.
        let (len, next) = encode_snapshot(&[], 0, &mut out);
        assert_eq!((len, next), (CHUNK_HEADER, 0));
    }

    #[test]
    fn bad_payloads_are_errors() {
        let mut out = [0u8; PAYLOAD];
        assert_eq!(decode(&[]), Err(WireError::Empty));
        assert_eq!(decode(&[9, 1, 2]), Err(WireError::UnknownTag(9)));
        let len = encode_task(
            &Task {
                seq: 1,
                goal: V2::ZERO,
                tolerance: 0.1,
                radius: 0.1,
            },
            &mut out,
        );
        assert_eq!(
            decode(&out[..len - 1]),
            Err(WireError::Length {
                tag: 1,
                len: len - 1
            })
        );
        out[5..9].copy_from_slice(&f32::NAN.to_le_bytes());
        assert_eq!(decode(&out[..len]), Err(WireError::BadNumber));
        // A chunk claiming entries beyond its whole.
        let (len, _) = encode_snapshot(&[neighbour(0), neighbour(1)], 0, &mut out);
        out[1..3].copy_from_slice(&1u16.to_le_bytes());
        assert_eq!(decode(&out[..len]), Err(WireError::BadChunk));
    }

    proptest! {
        #[test]
        fn any_bytes_decode_or_fail_without_panicking(bytes in prop::collection::vec(any::<u8>(), 0..300)) {
            let _ = decode(&bytes);
        }

        #[test]
        fn tagged_garbage_never_panics(tag in 1u8..7, bytes in prop::collection::vec(any::<u8>(), 0..260)) {
            let mut payload = vec![tag];
            payload.extend(bytes);
            if let Ok(Letter::Snapshot(c) | Letter::Map(c)) = decode(&payload) {
                prop_assert!(usize::from(c.first) <= usize::from(c.total));
            }
        }
    }
}
