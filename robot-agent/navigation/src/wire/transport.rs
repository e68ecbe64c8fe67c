//! The messages of cooperative transport (paper B, docs/cooperative_transport.md), tags 32 and up. Like every
//! letter here: at most 256 bytes, little-endian, first byte the tag, and decoding never trusts its input.
//!
//! | tag | letter | from -> to |
//! |---|---|---|
//! | 32 | [`Object`]: the box now, its goal pose, the team and the robot's face | supervisor (the task server) -> robot |
//! | 33 | `PathRequest`: plan a global path for the box (the method's `Global_PP`) | robot -> supervisor |
//! | 34 | [`PathChunk`]: part of the box's path | supervisor -> robot |
//! | 35 | [`Signal`]: the team's protocol (presence, RT, Y, T, A, P, S, deviations, LPP/GPP) | robot -> robot |
//! | 36 | [`Outcome`]: how the task ended for the team | coordinator robot -> supervisor |
//!
//! A path longer than one letter goes as several chunks in the same tick, each saying how many points the whole
//! has and where it starts.

use super::{PAYLOAD, Reader, WireError, Writer, exact};
use crate::V2;

const OBJECT: u8 = 32;
const PATH_REQUEST: u8 = 33;
const PATH: u8 = 34;
const SIGNAL: u8 = 35;
const OUTCOME: u8 = 36;
const OBJECT_LEN: usize = 1 + 2 * 4 + 2 * 4 + 4 + 2 * 4 + 4 + 3 + 2 * 4 + 4;
const PATH_HEADER: usize = 1 + 4 + 2 + 2 + 1;
const SIGNAL_LEN: usize = 1 + 1 + 4 + 2 * 4;
const OUTCOME_LEN: usize = 1 + 1 + 4;
/// Points per path chunk.
pub const POINTS_PER_CHUNK: usize = (PAYLOAD - PATH_HEADER) / 8;

/// What the supervisor tells each robot about the task.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Object {
    /// The box's centre now.
    pub centre: V2,
    /// Its heading now (rad).
    pub angle: f32,
    /// Half its size along its own x and y (m).
    pub half: V2,
    /// Where its centre must end.
    pub goal: V2,
    /// Its heading there (rad).
    pub goal_angle: f32,
    /// Robots in the team.
    pub team: u8,
    /// Grips the box needs to be lifted.
    pub lift_by: u8,
    /// The face this robot takes: 0 +x, 1 +y, 2 -x, 3 -y of the box's own frame.
    pub face: u8,
    /// Position tolerance at the goal (m).
    pub tolerance: f32,
    /// Heading tolerance at the goal (rad).
    pub angle_tolerance: f32,
    /// The supervisor's count of path plans so far (a new number: a new path follows).
    pub plans: u32,
}

/// The outward normal of face `face` ([`Object::face`]) in the box's own frame: 0 +x, 1 +y, 2 -x, 3 -y.
pub fn face_normal(face: u8) -> V2 {
    match face % 4 {
        0 => V2::new(1.0, 0.0),
        1 => V2::new(0.0, 1.0),
        2 => V2::new(-1.0, 0.0),
        _ => V2::new(0.0, -1.0),
    }
}

/// The distance from the centre of a box of half size `half` to its face `face`.
pub fn face_distance(half: V2, face: u8) -> f32 {
    if face.is_multiple_of(2) {
        half.x
    } else {
        half.y
    }
}

/// Part of the box's path: `points` from `first` of a whole of `total`, for plan number `plan`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathChunk<'a> {
    /// The plan it belongs to.
    pub plan: u32,
    /// Points in the whole path.
    pub total: u16,
    /// Index of this chunk's first point.
    pub first: u16,
    entries: &'a [u8],
}

impl PathChunk<'_> {
    /// The chunk's points (checked when decoded).
    pub fn points(&self) -> impl Iterator<Item = V2> + '_ {
        self.entries.chunks_exact(8).map(|b| {
            V2::new(
                f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                f32::from_le_bytes([b[4], b[5], b[6], b[7]]),
            )
        })
    }
}

/// The team's protocol codes (B.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Code {
    /// "I am at my face and gripping" (the election broadcast: the smallest id present coordinates).
    Here,
    /// Ready to take? (coordinator -> all)
    ReadyToTake,
    /// Yes: an acknowledgement of `step`'s request.
    Yes,
    /// Take: lift (coordinator -> all).
    Take,
    /// Arrived at waypoint `step` (robot -> coordinator), or all arrived: go on past `step` (coordinator -> all).
    Arrived,
    /// Put the box down (coordinator -> all).
    Put,
    /// Stop: abort, put down and hold (anyone -> all), with the reason in `step`.
    Stop,
    /// "I moved aside to avoid an obstacle, follow": the box's next waypoints shift by `value`.
    Deviate,
    /// The path is built locally, by every robot alike (the method's `LPP`; coordinator -> all).
    LocalPath,
    /// The path comes from the supervisor (the method's `GPP`; coordinator -> all).
    GlobalPath,
}

/// One protocol message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Signal {
    /// What it says.
    pub code: Code,
    /// The waypoint (for `Arrived`, `Yes`, `Deviate`) or the reason (for `Stop`).
    pub step: u32,
    /// A shift of the path (`Deviate`), else zero.
    pub value: V2,
}

/// How the task ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ending {
    /// The box was put down at the end of its path.
    Delivered,
    /// A teammate stopped answering and too few are left to lift the box.
    TeammateLost,
    /// The box was dropped.
    Dropped,
    /// No path for the box.
    NoPath,
}

/// The team's report of how the task ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outcome {
    /// How.
    pub ending: Ending,
    /// The last waypoint reached.
    pub step: u32,
}

fn code_byte(code: Code) -> u8 {
    match code {
        Code::Here => 0,
        Code::ReadyToTake => 1,
        Code::Yes => 2,
        Code::Take => 3,
        Code::Arrived => 4,
        Code::Put => 5,
        Code::Stop => 6,
        Code::Deviate => 7,
        Code::LocalPath => 8,
        Code::GlobalPath => 9,
    }
}

fn code(byte: u8) -> Result<Code, WireError> {
    Ok(match byte {
        0 => Code::Here,
        1 => Code::ReadyToTake,
        2 => Code::Yes,
        3 => Code::Take,
        4 => Code::Arrived,
        5 => Code::Put,
        6 => Code::Stop,
        7 => Code::Deviate,
        8 => Code::LocalPath,
        9 => Code::GlobalPath,
        _ => return Err(WireError::BadNumber),
    })
}

/// The byte of an ending.
pub fn ending_byte(ending: Ending) -> u8 {
    match ending {
        Ending::Delivered => 0,
        Ending::TeammateLost => 1,
        Ending::Dropped => 2,
        Ending::NoPath => 3,
    }
}

/// The ending of a byte.
pub fn ending(byte: u8) -> Result<Ending, WireError> {
    Ok(match byte {
        0 => Ending::Delivered,
        1 => Ending::TeammateLost,
        2 => Ending::Dropped,
        3 => Ending::NoPath,
        _ => return Err(WireError::BadNumber),
    })
}

/// A decoded transport message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Letter<'a> {
    /// The task.
    Object(Object),
    /// Plan a path.
    PathRequest,
    /// Part of a path.
    Path(PathChunk<'a>),
    /// The team's protocol.
    Signal(Signal),
    /// The end of the task.
    Outcome(Outcome),
}

/// Writes `object` into `out`; returns the payload length.
pub fn encode_object(object: &Object, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[OBJECT]).f32(object.centre.x).f32(object.centre.y);
    w.f32(object.half.x).f32(object.half.y);
    w.f32(object.angle).f32(object.goal.x).f32(object.goal.y);
    w.f32(object.goal_angle)
        .bytes(&[object.team, object.lift_by, object.face]);
    w.f32(object.tolerance)
        .f32(object.angle_tolerance)
        .bytes(&object.plans.to_le_bytes());
    w.at
}

/// Writes a `PathRequest` into `out`; returns the payload length.
pub fn encode_path_request(out: &mut [u8; PAYLOAD]) -> usize {
    out[0] = PATH_REQUEST;
    1
}

/// Writes the chunk of `path` (plan number `plan`) starting at point `first` into `out`; returns the payload
/// length and the first point of the next chunk (`path.len()` when this was the last). At most 65,535 points.
pub fn encode_path(
    plan: u32,
    path: &[V2],
    first: usize,
    out: &mut [u8; PAYLOAD],
) -> (usize, usize) {
    let end = (first + POINTS_PER_CHUNK).min(path.len());
    let mut w = Writer { out, at: 0 };
    w.bytes(&[PATH])
        .bytes(&plan.to_le_bytes())
        .bytes(&(path.len() as u16).to_le_bytes())
        .bytes(&(first as u16).to_le_bytes())
        .bytes(&[(end - first) as u8]);
    for p in &path[first..end] {
        w.f32(p.x).f32(p.y);
    }
    (w.at, end)
}

/// Writes `signal` into `out`; returns the payload length.
pub fn encode_signal(signal: &Signal, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[SIGNAL, code_byte(signal.code)])
        .bytes(&signal.step.to_le_bytes())
        .f32(signal.value.x)
        .f32(signal.value.y);
    w.at
}

/// Writes `outcome` into `out`; returns the payload length.
pub fn encode_outcome(outcome: &Outcome, out: &mut [u8; PAYLOAD]) -> usize {
    let mut w = Writer { out, at: 0 };
    w.bytes(&[OUTCOME, ending_byte(outcome.ending)])
        .bytes(&outcome.step.to_le_bytes());
    w.at
}

/// Decodes a transport payload.
pub fn decode(payload: &[u8]) -> Result<Letter<'_>, WireError> {
    let &tag = payload.first().ok_or(WireError::Empty)?;
    let bad_length = WireError::Length {
        tag,
        len: payload.len(),
    };
    let exact = |len: usize| exact(payload, len);
    match tag {
        OBJECT => {
            let mut r = exact(OBJECT_LEN)?;
            let centre = r.v2()?;
            let half = V2::new(r.positive()?, r.positive()?);
            let object = Object {
                centre,
                half,
                angle: r.f32()?,
                goal: r.v2()?,
                goal_angle: r.f32()?,
                team: r.u8(),
                lift_by: r.u8(),
                face: r.u8(),
                tolerance: r.positive()?,
                angle_tolerance: r.positive()?,
                plans: r.u32(),
            };
            if object.team == 0 || object.face > 3 {
                return Err(WireError::BadNumber);
            }
            Ok(Letter::Object(object))
        }
        PATH_REQUEST => {
            exact(1)?;
            Ok(Letter::PathRequest)
        }
        PATH => {
            if payload.len() < PATH_HEADER {
                return Err(bad_length);
            }
            let mut r = Reader {
                bytes: payload,
                at: 1,
            };
            let (plan, total, first, count) = (r.u32(), r.u16(), r.u16(), usize::from(r.u8()));
            if payload.len() != PATH_HEADER + 8 * count || count > POINTS_PER_CHUNK {
                return Err(bad_length);
            }
            if usize::from(first) + count > usize::from(total) {
                return Err(WireError::BadChunk);
            }
            for _ in 0..count {
                r.v2()?;
            }
            Ok(Letter::Path(PathChunk {
                plan,
                total,
                first,
                entries: &payload[PATH_HEADER..],
            }))
        }
        SIGNAL => {
            let mut r = exact(SIGNAL_LEN)?;
            Ok(Letter::Signal(Signal {
                code: code(r.u8())?,
                step: r.u32(),
                value: r.v2()?,
            }))
        }
        OUTCOME => {
            let mut r = exact(OUTCOME_LEN)?;
            Ok(Letter::Outcome(Outcome {
                ending: ending(r.u8())?,
                step: r.u32(),
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
        let object = Object {
            centre: V2::new(6.5, 6.0),
            angle: 1.8,
            half: V2::new(0.3, 0.4),
            goal: V2::new(2.0, 2.0),
            goal_angle: 3.4,
            team: 2,
            lift_by: 2,
            face: 1,
            tolerance: 0.02,
            angle_tolerance: 0.05,
            plans: 1,
        };
        let len = encode_object(&object, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Object(object)));
        let len = encode_path_request(&mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::PathRequest));
        let path: Vec<V2> = (0..70).map(|i| V2::new(i as f32 * 0.2, 1.0)).collect();
        let (mut first, mut seen) = (0, Vec::new());
        while first < path.len() {
            let (len, next) = encode_path(3, &path, first, &mut out);
            let Ok(Letter::Path(chunk)) = decode(&out[..len]) else {
                panic!("not a path");
            };
            assert_eq!(
                (chunk.plan, chunk.total, usize::from(chunk.first)),
                (3, 70, first)
            );
            seen.extend(chunk.points());
            first = next;
        }
        assert_eq!(seen, path);
        let signal = Signal {
            code: Code::Deviate,
            step: 7,
            value: V2::new(0.05, -0.02),
        };
        let len = encode_signal(&signal, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Signal(signal)));
        let outcome = Outcome {
            ending: Ending::TeammateLost,
            step: 12,
        };
        let len = encode_outcome(&outcome, &mut out);
        assert_eq!(decode(&out[..len]), Ok(Letter::Outcome(outcome)));
    }

    #[test]
    fn bad_letters_are_errors() {
        let mut out = [0u8; PAYLOAD];
        let len = encode_signal(
            &Signal {
                code: Code::Put,
                step: 0,
                value: V2::ZERO,
            },
            &mut out,
        );
        out[1] = 10;
        assert_eq!(decode(&out[..len]), Err(WireError::BadNumber));
        let (len, _) = encode_path(1, &[V2::ZERO, V2::ZERO], 0, &mut out);
        out[5..7].copy_from_slice(&1u16.to_le_bytes());
        assert_eq!(decode(&out[..len]), Err(WireError::BadChunk));
        assert_eq!(
            decode(&[PATH_REQUEST, 1]),
            Err(WireError::Length {
                tag: PATH_REQUEST,
                len: 2
            })
        );
    }

    proptest! {
        #[test]
        fn tagged_garbage_never_panics(tag in OBJECT..=OUTCOME, bytes in prop::collection::vec(any::<u8>(), 0..260)) {
            let mut payload = vec![tag];
            payload.extend(bytes);
            if let Ok(Letter::Path(chunk)) = decode(&payload) {
                prop_assert!(chunk.points().count() <= POINTS_PER_CHUNK);
            }
        }
    }
}
