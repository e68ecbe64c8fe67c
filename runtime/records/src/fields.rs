//! How each kind of column is spelt in CSV, both ways, exactly as the world's recorder writes it
//! (`world/src/recorder/csv_line.rs`): integers by `itoa`, floats by `ryu` (shortest round-trip digits, `NaN`),
//! flags `0`/`1`, text as is, an empty field for a null.

use parquet::data_type::ByteArray;

use super::schema::{Column, Kind};

/// One field's value, as Parquet stores it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value<'a> {
    /// INT64 (UINT_64 columns hold the bits of the unsigned value).
    Int64(i64),
    /// INT32 (the unsigned columns hold the bits of the unsigned value).
    Int32(i32),
    /// FLOAT.
    Float(f32),
    /// BOOLEAN.
    Boolean(bool),
    /// BYTE_ARRAY.
    Text(&'a [u8]),
    /// An empty field of an optional column.
    Null,
}

/// A field as a program writes it into a CSV line (the world's recorder), before it is a column's value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Field<'a> {
    /// An unsigned integer, written by `itoa`.
    Int(u64),
    /// A float, written in `ryu`'s shortest round-trip form.
    Float(f32),
    /// Text, written as is.
    Text(&'a str),
}

impl Column {
    /// The value `field` stands for in this column: what [`Column::parse`] reads back from the CSV text the
    /// recorder writes for it, found without the text (so a `NaN` of any sign or payload is the one `NaN` that
    /// `"NaN"` reads as).
    pub fn value_of(self, field: Field<'_>) -> Result<Value<'_>, String> {
        let value = match (self.kind, field) {
            (_, Field::Text("")) if self.optional => Value::Null,
            (Kind::Unsigned { bits: 64 }, Field::Int(v)) => Value::Int64(v as i64),
            (Kind::Unsigned { bits }, Field::Int(v)) if v >> bits == 0 => {
                Value::Int32(v as u32 as i32)
            }
            (Kind::Participant { world }, Field::Int(v))
                if v != u64::from(world) && v <= u64::from(u32::MAX) =>
            {
                Value::Int32(v as u32 as i32)
            }
            (Kind::Participant { world }, Field::Text("world")) => Value::Int32(world as i32),
            (Kind::Float, Field::Float(v)) => Value::Float(if v.is_nan() { f32::NAN } else { v }),
            (Kind::Flag, Field::Int(v @ (0 | 1))) => Value::Boolean(v == 1),
            (Kind::Text, Field::Text(text)) => Value::Text(text.as_bytes()),
            (_, field) => return Err(format!("{field:?} is not a value of this column")),
        };
        Ok(value)
    }

    /// Reads one CSV field of this column.
    pub fn parse(self, field: &[u8]) -> Result<Value<'_>, String> {
        if self.optional && field.is_empty() {
            return Ok(Value::Null);
        }
        let value = match self.kind {
            Kind::Unsigned { bits } => {
                let value: u64 = number(field)?;
                if bits < 64 && value >> bits != 0 {
                    return Err(format!("{value} does not fit in {bits} bits"));
                }
                if bits == 64 {
                    Value::Int64(value as i64)
                } else {
                    Value::Int32(value as u32 as i32)
                }
            }
            Kind::Participant { world } => {
                if field == b"world" {
                    Value::Int32(world as i32)
                } else {
                    let value: u32 = number(field)?;
                    if value == world {
                        // It would come back as `world`.
                        return Err(format!("{value} is the world's number, written `world`"));
                    }
                    Value::Int32(value as i32)
                }
            }
            Kind::Float => Value::Float(number(field)?),
            Kind::Flag => match field {
                b"0" => Value::Boolean(false),
                b"1" => Value::Boolean(true),
                _ => return Err("not 0 or 1".into()),
            },
            Kind::Text => Value::Text(utf8(field)?.as_bytes()),
        };
        Ok(value)
    }

    /// Appends `value` as this column's CSV field to `line` (no separator).
    pub fn format(self, value: Value<'_>, line: &mut Vec<u8>) -> Result<(), String> {
        match (self.kind, value) {
            (_, Value::Null) if self.optional => {}
            (Kind::Unsigned { bits: 64 }, Value::Int64(v)) => {
                line.extend_from_slice(itoa::Buffer::new().format(v as u64).as_bytes());
            }
            (Kind::Participant { world }, Value::Int32(v)) if v as u32 == world => {
                line.extend_from_slice(b"world");
            }
            (Kind::Unsigned { .. } | Kind::Participant { .. }, Value::Int32(v)) => {
                line.extend_from_slice(itoa::Buffer::new().format(v as u32).as_bytes());
            }
            (Kind::Float, Value::Float(v)) => {
                line.extend_from_slice(ryu::Buffer::new().format(v).as_bytes());
            }
            (Kind::Flag, Value::Boolean(v)) => line.push(if v { b'1' } else { b'0' }),
            (Kind::Text, Value::Text(text)) => {
                if text.contains(&b',') || text.contains(&b'\n') {
                    return Err(
                        "holds a comma or a line break, which CSV without quotes cannot".into(),
                    );
                }
                line.extend_from_slice(utf8(text)?.as_bytes());
            }
            (_, other) => return Err(format!("holds {other:?}, not a value of this column")),
        }
        Ok(())
    }
}

fn number<T: std::str::FromStr>(field: &[u8]) -> Result<T, String>
where
    T::Err: std::fmt::Display,
{
    utf8(field)?
        .parse()
        .map_err(|e| format!("`{}`: {e}", String::from_utf8_lossy(field)))
}

fn utf8(field: &[u8]) -> Result<&str, String> {
    std::str::from_utf8(field).map_err(|e| format!("not UTF-8 text: {e}"))
}

/// One column's values of a batch of rows, as the Parquet column writer takes them and the reader gives them: the
/// nulls of an optional column are not among them.
#[derive(Debug)]
pub enum Values {
    /// INT64 values.
    Int64(Vec<i64>),
    /// INT32 values.
    Int32(Vec<i32>),
    /// FLOAT values.
    Float(Vec<f32>),
    /// BOOLEAN values.
    Boolean(Vec<bool>),
    /// BYTE_ARRAY values.
    Text(Vec<ByteArray>),
}

impl Values {
    /// An empty buffer for `kind`'s values.
    pub fn new(kind: Kind) -> Values {
        match kind {
            Kind::Unsigned { bits: 64 } => Values::Int64(Vec::new()),
            Kind::Unsigned { .. } | Kind::Participant { .. } => Values::Int32(Vec::new()),
            Kind::Float => Values::Float(Vec::new()),
            Kind::Flag => Values::Boolean(Vec::new()),
            Kind::Text => Values::Text(Vec::new()),
        }
    }

    /// The `index`th value, if there is one.
    pub fn get(&self, index: usize) -> Option<Value<'_>> {
        match self {
            Values::Int64(v) => v.get(index).map(|&v| Value::Int64(v)),
            Values::Int32(v) => v.get(index).map(|&v| Value::Int32(v)),
            Values::Float(v) => v.get(index).map(|&v| Value::Float(v)),
            Values::Boolean(v) => v.get(index).map(|&v| Value::Boolean(v)),
            Values::Text(v) => v.get(index).map(|v| Value::Text(v.data())),
        }
    }

    /// Empties the buffer, keeping its memory.
    pub fn clear(&mut self) {
        match self {
            Values::Int64(v) => v.clear(),
            Values::Int32(v) => v.clear(),
            Values::Float(v) => v.clear(),
            Values::Boolean(v) => v.clear(),
            Values::Text(v) => v.clear(),
        }
    }
}
