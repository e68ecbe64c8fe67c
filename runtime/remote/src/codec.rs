//! The cross-host wire format: a versioned header and a batch of per-robot entries, bincode 2 encoded.
//!
//! One message carries one host's share of one tick: `[Header][count: u32][count x (robot: u32, entry)]`, where an
//! entry is a [`SensorFrame`](swarm_contract::messages::SensorFrame) (world to host) or a
//! [`Reply`](crate::host_to_world::Reply) (host to world). Every field is encoded explicitly (bincode,
//! little-endian, variable-length integers), never as raw memory, so hosts of different architectures interoperate. Decoding checks the size, magic, version, kind and that the robots are
//! exactly the ones the receiver expects, in order; decoding into a caller's slice allocates nothing.
//!
//! This module must never panic on a payload: whatever arrives from the network is either decoded or rejected with
//! a [`WireError`] that says what was wrong.

use bincode::config::Configuration;
use bincode::{Decode, Encode};

use swarm_contract::messages::MESSAGE_VERSION;

/// First field of every message: `SWRM` read as a little-endian u32.
pub const WIRE_MAGIC: u32 = u32::from_le_bytes(*b"SWRM");
/// Revision of the encoding within one message layout: 2 since frames and commands leave out the unused ends of
/// their arrays (`swarm_contract`'s `compact_encoding`).
const WIRE_REVISION: u32 = 2;
/// Version of the wire format: the message layout version and the encoding's revision, so hosts built from
/// different message layouts or encodings reject each other's payloads instead of misreading them.
pub const WIRE_VERSION: u32 = MESSAGE_VERSION << 8 | WIRE_REVISION;
/// Default largest payload accepted (bytes): far above 1,000 robots' frames (at most about 1 kB each).
pub const DEFAULT_MAX_PAYLOAD: usize = 16 << 20;

/// The bincode configuration of every cross-host message.
fn config() -> Configuration {
    bincode::config::standard()
}

/// What a message carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Encode, Decode)]
pub enum Kind {
    /// World to host: the sensor frames of the host's robots.
    Frames,
    /// Host to world: the host's answers for its robots.
    Replies,
}

/// The versioned header of every message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Encode, Decode)]
pub struct Header {
    magic: u32,
    version: u32,
    /// What the message carries.
    pub kind: Kind,
    /// Identity of the run (the world draws it at start); messages of another run are stale.
    pub run: u64,
    /// Index of the host in the run's placement.
    pub host: u16,
    /// Assignment epoch of the host: it grows each time the host (re)joins, so answers of an earlier incarnation
    /// are stale.
    pub epoch: u32,
    /// The world's tick the message belongs to.
    pub tick: u64,
}

impl Header {
    /// A header of the current wire version.
    pub fn new(kind: Kind, run: u64, host: u16, epoch: u32, tick: u64) -> Header {
        Header {
            magic: WIRE_MAGIC,
            version: WIRE_VERSION,
            kind,
            run,
            host,
            epoch,
            tick,
        }
    }
}

/// Why a payload was rejected.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    /// Larger than the receiver accepts.
    #[error("payload of {len} bytes exceeds the limit of {max} bytes")]
    Oversized {
        /// Payload length.
        len: usize,
        /// The limit.
        max: usize,
    },
    /// Not a swarm message.
    #[error("not a swarm message (magic {found:#010x})")]
    BadMagic {
        /// The first field found.
        found: u32,
    },
    /// A message of another wire version.
    #[error("wire version {found}, this build speaks version {expected}")]
    Version {
        /// Version in the message.
        found: u32,
        /// Version of this build.
        expected: u32,
    },
    /// A message of another kind than expected.
    #[error("expected a {expected:?} message, got {found:?}")]
    Kind {
        /// Kind in the header.
        found: Kind,
        /// Kind the receiver expected.
        expected: Kind,
    },
    /// The batch does not hold exactly the receiver's robots.
    #[error("the batch holds {found} robots, expected {expected}")]
    Count {
        /// Robots in the batch.
        found: u32,
        /// Robots expected.
        expected: usize,
    },
    /// An entry for a robot the sender does not own (or out of order).
    #[error("entry {index} is for robot {found}, expected robot {expected}")]
    NotOwned {
        /// Position in the batch.
        index: usize,
        /// Robot named by the entry.
        found: u32,
        /// Robot expected at that position.
        expected: u32,
    },
    /// Bytes that do not decode.
    #[error("malformed payload: {0}")]
    Malformed(String),
    /// Bytes left after the batch.
    #[error("{0} bytes after the end of the batch")]
    Trailing(usize),
}

/// Encodes one batch into `buf` (cleared first): the header, then `(robot, entry)` for each robot. Allocates only
/// when `buf` has to grow.
pub fn encode_batch<T: Encode>(
    buf: &mut Vec<u8>,
    header: &Header,
    robots: &[u32],
    entries: impl IntoIterator<Item = T>,
) -> Result<(), WireError> {
    buf.clear();
    let malformed = |e: bincode::error::EncodeError| WireError::Malformed(e.to_string());
    bincode::encode_into_std_write(header, buf, config()).map_err(malformed)?;
    let count = u32::try_from(robots.len()).map_err(|_| WireError::Count {
        found: u32::MAX,
        expected: robots.len(),
    })?;
    bincode::encode_into_std_write(count, buf, config()).map_err(malformed)?;
    for (robot, entry) in robots.iter().zip(entries) {
        bincode::encode_into_std_write((robot, entry), buf, config()).map_err(malformed)?;
    }
    Ok(())
}

/// Reads only the header of a payload (after the size, magic and version checks), e.g. to drop a stale message
/// before decoding its batch.
pub fn decode_header(bytes: &[u8], max_payload: usize) -> Result<(Header, usize), WireError> {
    if bytes.len() > max_payload {
        return Err(WireError::Oversized {
            len: bytes.len(),
            max: max_payload,
        });
    }
    let (header, used): (Header, usize) = decode(bytes).map_err(|e| match first_u32(bytes) {
        Some(found) if found != WIRE_MAGIC => WireError::BadMagic { found },
        _ => e,
    })?;
    if header.magic != WIRE_MAGIC {
        return Err(WireError::BadMagic {
            found: header.magic,
        });
    }
    if header.version != WIRE_VERSION {
        return Err(WireError::Version {
            found: header.version,
            expected: WIRE_VERSION,
        });
    }
    Ok((header, used))
}

/// Decodes a batch of `kind` into `out` (one entry per robot of `robots`, in that order) and returns its header.
/// The entries must name exactly `robots`: a batch with another robot is rejected whole. Allocates nothing.
pub fn decode_batch<T: Decode<()>>(
    bytes: &[u8],
    kind: Kind,
    robots: &[u32],
    out: &mut [T],
    max_payload: usize,
) -> Result<Header, WireError> {
    let (header, mut at) = decode_header(bytes, max_payload)?;
    if header.kind != kind {
        return Err(WireError::Kind {
            found: header.kind,
            expected: kind,
        });
    }
    let (count, used): (u32, usize) = decode(&bytes[at..])?;
    at += used;
    if count as usize != robots.len() || out.len() < robots.len() {
        return Err(WireError::Count {
            found: count,
            expected: robots.len(),
        });
    }
    for (index, (&expected, slot)) in robots.iter().zip(out.iter_mut()).enumerate() {
        let ((found, entry), used): ((u32, T), usize) = decode(&bytes[at..])?;
        if found != expected {
            return Err(WireError::NotOwned {
                index,
                found,
                expected,
            });
        }
        *slot = entry;
        at += used;
    }
    if at != bytes.len() {
        return Err(WireError::Trailing(bytes.len() - at));
    }
    Ok(header)
}

fn decode<T: Decode<()>>(bytes: &[u8]) -> Result<(T, usize), WireError> {
    bincode::decode_from_slice(bytes, config().with_limit::<DEFAULT_MAX_PAYLOAD>())
        .map_err(|e| WireError::Malformed(e.to_string()))
}

/// The leading varint-encoded u32 of a payload, if there is one.
fn first_u32(bytes: &[u8]) -> Option<u32> {
    bincode::decode_from_slice::<u32, _>(bytes, config())
        .ok()
        .map(|(v, _)| v)
}

/// Encodes any control message (assignments and their replies) with the wire's bincode configuration.
pub fn encode_message<T: Encode>(message: &T) -> Result<Vec<u8>, WireError> {
    bincode::encode_to_vec(message, config()).map_err(|e| WireError::Malformed(e.to_string()))
}

/// Encodes the first message of a share (the assignment) after the wire version, so a host built from another
/// source can say so instead of misreading it or every batch after it.
pub fn encode_versioned<T: Encode>(message: &T) -> Result<Vec<u8>, WireError> {
    encode_message(&(WIRE_VERSION, message))
}

/// Decodes a message encoded by [`encode_versioned`]: [`WireError::Version`] when it is of another wire version,
/// whatever follows.
pub fn decode_versioned<T: Decode<()>>(bytes: &[u8], max_payload: usize) -> Result<T, WireError> {
    match first_u32(bytes) {
        Some(WIRE_VERSION) => {
            decode_message::<(u32, T)>(bytes, max_payload).map(|(_, message)| message)
        }
        Some(found) => Err(WireError::Version {
            found,
            expected: WIRE_VERSION,
        }),
        None => Err(WireError::Malformed(
            "the message does not start with a wire version".into(),
        )),
    }
}

/// Decodes a control message encoded by [`encode_message`], rejecting oversized and trailing bytes.
pub fn decode_message<T: Decode<()>>(bytes: &[u8], max_payload: usize) -> Result<T, WireError> {
    if bytes.len() > max_payload {
        return Err(WireError::Oversized {
            len: bytes.len(),
            max: max_payload,
        });
    }
    let (message, used) = decode(bytes)?;
    if used != bytes.len() {
        return Err(WireError::Trailing(bytes.len() - used));
    }
    Ok(message)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host_to_world::Reply;
    use swarm_contract::messages::{ActuatorCommand, SensorFrame};

    fn frames(robots: &[u32], tick: u64) -> Vec<SensorFrame> {
        robots
            .iter()
            .map(|&r| {
                let mut f = SensorFrame::empty(r);
                f.tick = tick;
                f.proximity[3] = 0.25 * r as f32;
                f.position = [r as f32, -1.5];
                f
            })
            .collect()
    }

    fn encoded(robots: &[u32], tick: u64) -> Vec<u8> {
        let mut buf = Vec::new();
        let header = Header::new(Kind::Frames, 77, 1, 3, tick);
        encode_batch(&mut buf, &header, robots, frames(robots, tick)).expect("encodes");
        buf
    }

    #[test]
    fn a_versioned_message_of_another_build_is_refused_by_its_version() {
        let bytes = encode_versioned(&(7u64, String::from("share"))).expect("encodes");
        assert_eq!(
            decode_versioned::<(u64, String)>(&bytes, DEFAULT_MAX_PAYLOAD),
            Ok((7, "share".into()))
        );
        let older =
            encode_message(&(WIRE_VERSION - 1, 7u64, String::from("share"))).expect("encodes");
        assert_eq!(
            decode_versioned::<(u64, String)>(&older, DEFAULT_MAX_PAYLOAD),
            Err(WireError::Version {
                found: WIRE_VERSION - 1,
                expected: WIRE_VERSION
            })
        );
        // A build that sent the message without a version: its first field is read as one, and refused.
        let unversioned = encode_message(&(7u64, String::from("share"))).expect("encodes");
        assert!(matches!(
            decode_versioned::<(u64, String)>(&unversioned, DEFAULT_MAX_PAYLOAD),
            Err(WireError::Version { found: 7, .. })
        ));
    }

    #[test]
    fn frames_round_trip_bit_exactly_with_their_header() {
        let robots = [5, 6, 9];
        let buf = encoded(&robots, 42);
        let mut out = vec![SensorFrame::empty(0); 3];
        let header = decode_batch(&buf, Kind::Frames, &robots, &mut out, DEFAULT_MAX_PAYLOAD)
            .expect("decodes");
        assert_eq!(header, Header::new(Kind::Frames, 77, 1, 3, 42));
        assert_eq!(out, frames(&robots, 42));
    }

    #[test]
    fn replies_round_trip_with_every_status() {
        let robots = [0, 1, 2];
        let mut command = ActuatorCommand::idle(0, 8);
        command.wheels = [3.5, -2.25];
        let replies = [Reply::Answered(command), Reply::Missing, Reply::Dead];
        let mut buf = Vec::new();
        encode_batch(
            &mut buf,
            &Header::new(Kind::Replies, 1, 0, 0, 8),
            &robots,
            replies,
        )
        .expect("encodes");
        let mut out = [Reply::Missing; 3];
        decode_batch(&buf, Kind::Replies, &robots, &mut out, DEFAULT_MAX_PAYLOAD).expect("decodes");
        assert_eq!(out, replies);
    }

    #[test]
    fn a_batch_naming_a_robot_the_sender_does_not_own_is_rejected() {
        let buf = encoded(&[5, 6, 7], 1);
        let mut out = vec![SensorFrame::empty(0); 3];
        let err = decode_batch(
            &buf,
            Kind::Frames,
            &[5, 6, 9],
            &mut out,
            DEFAULT_MAX_PAYLOAD,
        )
        .expect_err("robot 7 is not robot 9");
        assert_eq!(
            err,
            WireError::NotOwned {
                index: 2,
                found: 7,
                expected: 9
            }
        );
    }

    #[test]
    fn oversized_payloads_are_rejected_before_decoding() {
        let buf = encoded(&[1, 2], 1);
        let mut out = vec![SensorFrame::empty(0); 2];
        let err = decode_batch(&buf, Kind::Frames, &[1, 2], &mut out, 64).expect_err("too big");
        assert_eq!(
            err,
            WireError::Oversized {
                len: buf.len(),
                max: 64
            }
        );
    }

    #[test]
    fn wrong_magic_version_and_kind_are_named() {
        let mut out = vec![SensorFrame::empty(0); 1];
        let err = decode_batch(b"GET / HTTP/1.1\r\n", Kind::Frames, &[1], &mut out, 1 << 20)
            .expect_err("not ours");
        assert!(matches!(err, WireError::BadMagic { .. }), "{err}");

        let mut header = Header::new(Kind::Frames, 1, 0, 0, 1);
        header.version = WIRE_VERSION + 1;
        let mut buf = Vec::new();
        encode_batch(&mut buf, &header, &[1], frames(&[1], 1)).expect("encodes");
        let err = decode_batch(&buf, Kind::Frames, &[1], &mut out, 1 << 20).expect_err("version");
        assert_eq!(
            err,
            WireError::Version {
                found: WIRE_VERSION + 1,
                expected: WIRE_VERSION
            }
        );

        let buf = encoded(&[1], 1);
        let mut replies = [Reply::Missing];
        let err = decode_batch(&buf, Kind::Replies, &[1], &mut replies, 1 << 20).expect_err("kind");
        assert_eq!(
            err,
            WireError::Kind {
                found: Kind::Frames,
                expected: Kind::Replies
            }
        );
    }

    #[test]
    fn every_truncation_of_a_batch_is_an_error_not_a_panic() {
        let robots = [3, 4];
        let buf = encoded(&robots, 9);
        let mut out = vec![SensorFrame::empty(0); 2];
        for len in 0..buf.len() {
            assert!(
                decode_batch(&buf[..len], Kind::Frames, &robots, &mut out, 1 << 20).is_err(),
                "a batch cut to {len} of {} bytes decoded",
                buf.len()
            );
        }
        let mut long = buf.clone();
        long.push(0);
        assert_eq!(
            decode_batch(&long, Kind::Frames, &robots, &mut out, 1 << 20),
            Err(WireError::Trailing(1))
        );
    }

    #[test]
    fn every_single_byte_corruption_decodes_or_errs_without_panicking() {
        let robots = [0];
        let mut buf = Vec::new();
        let replies = [Reply::Answered(ActuatorCommand::idle(0, 1))];
        encode_batch(
            &mut buf,
            &Header::new(Kind::Replies, 1, 0, 0, 1),
            &robots,
            replies,
        )
        .expect("encodes");
        // Flip every byte in turn: each result is a decoded batch or a named error, never a panic.
        for i in 0..buf.len() {
            let mut bad = buf.clone();
            bad[i] ^= 0xff;
            let mut out = [Reply::Missing];
            let _ = decode_batch(&bad, Kind::Replies, &robots, &mut out, 1 << 20);
        }
    }
}
