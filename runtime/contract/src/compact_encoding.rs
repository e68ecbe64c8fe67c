//! The bincode encoding of [`SensorFrame`], [`ActuatorCommand`] and [`SupervisorSnapshot`]: every fixed-size
//! array only up to its last entry that differs from the empty value.
//!
//! The messages are sized for the largest body and the largest supervisor set (24 proximity sensors, 16 camera
//! blobs, 16 supervisors with 32 timer stamps, ...), and a robot fills a fraction of them. Written whole, an
//! e-puck's frame took about 0.6 kB on the wire, so most of what hosts encoded, authenticated, sent and decoded
//! every tick was padding; now it takes about 90 bytes. Here each array is written as a count and that many
//! entries, and decoding starts from the empty message ([`SensorFrame::empty`], [`ActuatorCommand::idle`],
//! [`SupervisorSnapshot::default`]), so every value comes back bit for bit, whatever the length fields say.
//!
//! Both sides follow the struct's field order. `encode` names every field in a destructuring pattern and `decode`
//! in a struct expression, so a field added to a message fails to compile here until it is encoded.

use std::sync::LazyLock;

use bincode::de::{BorrowDecoder, Decoder};
use bincode::enc::Encoder;
use bincode::error::{DecodeError, EncodeError};
use bincode::{BorrowDecode, Decode, Encode};

use crate::messages::{
    ActuatorCommand, CameraBlob, FiredStamp, RabMessage, SensorFrame, SupervisorSnapshot,
};

/// The empty frame: what a decoded frame starts from, and what trailing entries are compared with.
static EMPTY_FRAME: LazyLock<SensorFrame> = LazyLock::new(|| SensorFrame::empty(0));
/// The idle command: the same for commands.
static IDLE_COMMAND: LazyLock<ActuatorCommand> = LazyLock::new(|| ActuatorCommand::idle(0, 0));

/// Bit-for-bit equality (`-0.0` is not `0.0`, and a NaN equals itself), so trimming never changes a value.
trait SameBits {
    fn same_bits(&self, other: &Self) -> bool;
}

impl SameBits for f32 {
    fn same_bits(&self, other: &Self) -> bool {
        self.to_bits() == other.to_bits()
    }
}

macro_rules! same_bits_by_eq {
    ($($t:ty),*) => {$(
        impl SameBits for $t {
            fn same_bits(&self, other: &Self) -> bool {
                self == other
            }
        }
    )*};
}

same_bits_by_eq!(u8, u16, u64, FiredStamp);

impl SameBits for CameraBlob {
    fn same_bits(&self, other: &Self) -> bool {
        let CameraBlob {
            color,
            bearing,
            distance_cm,
        } = self;
        *color == other.color
            && bearing.same_bits(&other.bearing)
            && distance_cm.same_bits(&other.distance_cm)
    }
}

impl SameBits for RabMessage {
    fn same_bits(&self, other: &Self) -> bool {
        let RabMessage {
            sender,
            payload,
            len,
            range_cm,
            bearing,
        } = self;
        *sender == other.sender
            && *payload == other.payload
            && *len == other.len
            && range_cm.same_bits(&other.range_cm)
            && bearing.same_bits(&other.bearing)
    }
}

/// Writes how many leading entries of `items` are kept (up to the last one that differs from `empty`'s entry at
/// the same place), then those entries.
fn encode_prefix<T: Encode + SameBits, E: Encoder>(
    items: &[T],
    empty: &[T],
    encoder: &mut E,
) -> Result<(), EncodeError> {
    let kept = items
        .iter()
        .zip(empty)
        .rposition(|(item, blank)| !item.same_bits(blank))
        .map_or(0, |last| last + 1);
    (kept as u32).encode(encoder)?;
    items[..kept]
        .iter()
        .try_for_each(|item| item.encode(encoder))
}

/// Reads what [`encode_prefix`] wrote into the leading entries of `items`, whose others keep their empty values.
fn decode_prefix<T: Decode<C>, const N: usize, C, D: Decoder<Context = C>>(
    decoder: &mut D,
    mut items: [T; N],
) -> Result<[T; N], DecodeError> {
    let kept = u32::decode(decoder)? as usize;
    if kept > N {
        return Err(DecodeError::OtherString(format!(
            "{kept} entries for an array of {N}"
        )));
    }
    for item in &mut items[..kept] {
        *item = T::decode(decoder)?;
    }
    Ok(items)
}

impl Encode for SensorFrame {
    fn encode<E: Encoder>(&self, encoder: &mut E) -> Result<(), EncodeError> {
        let SensorFrame {
            tick,
            robot,
            held_object,
            alive,
            gripper_holding,
            proximity_len,
            light_len,
            ground_len,
            ranges_len,
            camera_len,
            rab_len,
            inbox_len,
            proximity,
            light,
            ground,
            ranges,
            scan_start,
            scan_span,
            camera,
            rab,
            pheromone,
            pheromone_gradient,
            position,
            heading,
        } = self;
        let empty = &*EMPTY_FRAME;
        (tick, robot, held_object, alive, gripper_holding).encode(encoder)?;
        (proximity_len, light_len, ground_len, ranges_len).encode(encoder)?;
        (camera_len, rab_len, inbox_len).encode(encoder)?;
        encode_prefix(proximity, &empty.proximity, encoder)?;
        encode_prefix(light, &empty.light, encoder)?;
        encode_prefix(ground, &empty.ground, encoder)?;
        encode_prefix(ranges, &empty.ranges, encoder)?;
        (scan_start, scan_span).encode(encoder)?;
        encode_prefix(camera, &empty.camera, encoder)?;
        encode_prefix(rab, &empty.rab, encoder)?;
        (pheromone, pheromone_gradient, position, heading).encode(encoder)
    }
}

impl<Context> Decode<Context> for SensorFrame {
    fn decode<D: Decoder<Context = Context>>(decoder: &mut D) -> Result<Self, DecodeError> {
        let empty = &*EMPTY_FRAME;
        // A struct expression evaluates its fields in the order written: the order `encode` wrote them.
        Ok(SensorFrame {
            tick: Decode::decode(decoder)?,
            robot: Decode::decode(decoder)?,
            held_object: Decode::decode(decoder)?,
            alive: Decode::decode(decoder)?,
            gripper_holding: Decode::decode(decoder)?,
            proximity_len: Decode::decode(decoder)?,
            light_len: Decode::decode(decoder)?,
            ground_len: Decode::decode(decoder)?,
            ranges_len: Decode::decode(decoder)?,
            camera_len: Decode::decode(decoder)?,
            rab_len: Decode::decode(decoder)?,
            inbox_len: Decode::decode(decoder)?,
            proximity: decode_prefix(decoder, empty.proximity)?,
            light: decode_prefix(decoder, empty.light)?,
            ground: decode_prefix(decoder, empty.ground)?,
            ranges: decode_prefix(decoder, empty.ranges)?,
            scan_start: Decode::decode(decoder)?,
            scan_span: Decode::decode(decoder)?,
            camera: decode_prefix(decoder, empty.camera)?,
            rab: decode_prefix(decoder, empty.rab)?,
            pheromone: Decode::decode(decoder)?,
            pheromone_gradient: Decode::decode(decoder)?,
            position: Decode::decode(decoder)?,
            heading: Decode::decode(decoder)?,
        })
    }
}

impl Encode for SupervisorSnapshot {
    fn encode<E: Encoder>(&self, encoder: &mut E) -> Result<(), EncodeError> {
        let SupervisorSnapshot {
            count,
            states,
            entered,
            fired_len,
            fired,
        } = self;
        let empty = &IDLE_COMMAND.supervisors;
        count.encode(encoder)?;
        encode_prefix(states, &empty.states, encoder)?;
        encode_prefix(entered, &empty.entered, encoder)?;
        fired_len.encode(encoder)?;
        encode_prefix(fired, &empty.fired, encoder)
    }
}

impl<Context> Decode<Context> for SupervisorSnapshot {
    fn decode<D: Decoder<Context = Context>>(decoder: &mut D) -> Result<Self, DecodeError> {
        let empty = &IDLE_COMMAND.supervisors;
        Ok(SupervisorSnapshot {
            count: Decode::decode(decoder)?,
            states: decode_prefix(decoder, empty.states)?,
            entered: decode_prefix(decoder, empty.entered)?,
            fired_len: Decode::decode(decoder)?,
            fired: decode_prefix(decoder, empty.fired)?,
        })
    }
}

impl Encode for ActuatorCommand {
    fn encode<E: Encoder>(&self, encoder: &mut E) -> Result<(), EncodeError> {
        let ActuatorCommand {
            tick,
            robot,
            drive,
            wheels,
            twist,
            led,
            beacon,
            rab_len,
            rab_payload,
            outbox_len,
            gripper,
            turret_mode,
            turret,
            scanner,
            scanner_setting,
            pheromone_deposit,
            events_len,
            events,
            supervisors,
        } = self;
        (tick, robot, drive, wheels, twist, led, beacon).encode(encoder)?;
        (rab_len, rab_payload, outbox_len, gripper).encode(encoder)?;
        (turret_mode, turret, scanner, scanner_setting).encode(encoder)?;
        (pheromone_deposit, events_len).encode(encoder)?;
        encode_prefix(events, &IDLE_COMMAND.events, encoder)?;
        supervisors.encode(encoder)
    }
}

impl<Context> Decode<Context> for ActuatorCommand {
    fn decode<D: Decoder<Context = Context>>(decoder: &mut D) -> Result<Self, DecodeError> {
        Ok(ActuatorCommand {
            tick: Decode::decode(decoder)?,
            robot: Decode::decode(decoder)?,
            drive: Decode::decode(decoder)?,
            wheels: Decode::decode(decoder)?,
            twist: Decode::decode(decoder)?,
            led: Decode::decode(decoder)?,
            beacon: Decode::decode(decoder)?,
            rab_len: Decode::decode(decoder)?,
            rab_payload: Decode::decode(decoder)?,
            outbox_len: Decode::decode(decoder)?,
            gripper: Decode::decode(decoder)?,
            turret_mode: Decode::decode(decoder)?,
            turret: Decode::decode(decoder)?,
            scanner: Decode::decode(decoder)?,
            scanner_setting: Decode::decode(decoder)?,
            pheromone_deposit: Decode::decode(decoder)?,
            events_len: Decode::decode(decoder)?,
            events: decode_prefix(decoder, IDLE_COMMAND.events)?,
            supervisors: Decode::decode(decoder)?,
        })
    }
}

/// Decoding never borrows from the input: the messages own all their data.
macro_rules! borrow_decode_by_decode {
    ($($t:ty),*) => {$(
        impl<'de, Context> BorrowDecode<'de, Context> for $t {
            fn borrow_decode<D: BorrowDecoder<'de, Context = Context>>(
                decoder: &mut D,
            ) -> Result<Self, DecodeError> {
                Self::decode(decoder)
            }
        }
    )*};
}

borrow_decode_by_decode!(SensorFrame, SupervisorSnapshot, ActuatorCommand);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::{MAX_CAMERA_BLOBS, MAX_FIRED_STAMPS, MAX_PROXIMITY_SENSORS, Rgb};

    fn config() -> bincode::config::Configuration {
        bincode::config::standard()
    }

    fn round_trip<T: Encode + Decode<()>>(value: &T) -> (T, usize) {
        let bytes = bincode::encode_to_vec(value, config()).expect("encodes");
        let (back, used): (T, usize) =
            bincode::decode_from_slice(&bytes, config()).expect("decodes");
        assert_eq!(used, bytes.len());
        (back, bytes.len())
    }

    /// Field by field and bit for bit: `Debug` writes `-0.0` and `0.0` apart, and every other float in its shortest
    /// exact form.
    fn same_bits<T: std::fmt::Debug>(a: &T, b: &T) -> bool {
        format!("{a:?}") == format!("{b:?}")
    }

    /// A frame with entries beyond its length fields, a negative zero and a NaN: all must come back.
    fn unusual_frame() -> SensorFrame {
        let mut frame = SensorFrame::empty(7);
        frame.tick = 41;
        frame.proximity_len = 8;
        frame.proximity[..8].copy_from_slice(&[0.5, 0.0, -0.0, 0.25, 0.0, 0.0, 1.0, 0.0]);
        frame.proximity[MAX_PROXIMITY_SENSORS - 1] = f32::NAN;
        frame.light[3] = 0.75;
        frame.ground = [0.0, 1.0, 0.5, 1.0];
        frame.ranges[2] = 0.3;
        frame.camera_len = 1;
        frame.camera[0] = CameraBlob {
            color: Rgb { r: 255, g: 0, b: 0 },
            bearing: -0.0,
            distance_cm: 12.5,
        };
        frame.camera[MAX_CAMERA_BLOBS - 1].bearing = 1.0;
        frame.rab[1].sender = 3;
        frame.position = [1.5, -2.0];
        frame.heading = 0.1;
        frame
    }

    #[test]
    fn a_frame_comes_back_bit_for_bit_and_padding_is_not_sent() {
        let frame = unusual_frame();
        let (back, len) = round_trip(&frame);
        assert!(same_bits(&frame, &back), "{frame:?}\n{back:?}");
        let (empty, empty_len) = round_trip(&SensorFrame::empty(3));
        assert!(same_bits(&SensorFrame::empty(3), &empty));
        assert!(
            empty_len < size_of::<SensorFrame>() / 8,
            "an empty frame takes {empty_len} bytes"
        );
        assert!(len < size_of::<SensorFrame>(), "{len} bytes");
    }

    #[test]
    fn a_command_comes_back_bit_for_bit() {
        let mut command = ActuatorCommand::idle(4, 9);
        command.set_twist(0.1, -0.0);
        command.events_len = 2;
        command.events[..2].copy_from_slice(&[5, 0]);
        command.events[15] = 1;
        command.supervisors.count = 2;
        command.supervisors.states[..2].copy_from_slice(&[3, 1]);
        command.supervisors.entered[..2].copy_from_slice(&[40, 0]);
        command.supervisors.fired_len = 1;
        command.supervisors.fired[MAX_FIRED_STAMPS - 1] = FiredStamp {
            supervisor: 1,
            event: 2,
            tick: 39,
        };
        let (back, _) = round_trip(&command);
        assert!(same_bits(&command, &back), "{command:?}\n{back:?}");
        let (idle, idle_len) = round_trip(&ActuatorCommand::idle(4, 9));
        assert!(same_bits(&ActuatorCommand::idle(4, 9), &idle));
        assert!(
            idle_len < size_of::<ActuatorCommand>() / 8,
            "an idle command takes {idle_len} bytes"
        );
    }

    #[test]
    fn a_count_beyond_an_array_is_rejected() {
        let mut bytes = bincode::encode_to_vec(SensorFrame::empty(0), config()).expect("encodes");
        // The proximity count follows five scalar fields and seven lengths, each one byte here.
        let at = 1 + 1 + 1 + 1 + 1 + 4 + 3;
        assert_eq!(bytes[at], 0, "the proximity count of an empty frame");
        bytes[at] = MAX_PROXIMITY_SENSORS as u8 + 1;
        let decoded = bincode::decode_from_slice::<SensorFrame, _>(&bytes, config());
        assert!(
            matches!(&decoded, Err(DecodeError::OtherString(m)) if m.contains("entries for an array of 24")),
            "{decoded:?}"
        );
    }
}
