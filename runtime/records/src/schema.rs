//! The three record tables: their files, their columns as the world's CSV headers name them
//! (`world/src/recorder/{trajectory,events,messages}.rs`, docs/records.md), and each column's Parquet type.

use std::sync::Arc;

use parquet::basic::{ConvertedType, LogicalType, Repetition, Type as PhysicalType};
use parquet::errors::Result as ParquetResult;
use parquet::schema::types::{ColumnDescriptor, Type, TypePtr};
use swarm_contract::mail::{FROM_WORLD, TO_WORLD};
use swarm_contract::run_dir::{
    EVENTS_FILE, EVENTS_PARQUET_FILE, MESSAGES_FILE, MESSAGES_PARQUET_FILE, TRAJECTORY_FILE,
    TRAJECTORY_PARQUET_FILE,
};

/// A record table of a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Table {
    /// `trajectory.csv`: pose, LED and alive flag of every robot at every tick.
    Trajectory,
    /// `events.csv`: supervisor events, faults, joins and leaves.
    Events,
    /// `messages.csv`: every decision of the messages medium.
    Messages,
}

/// How a column's values are spelt in CSV and stored in Parquet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// An unsigned integer of `bits` bits (8, 16, 32 or 64): INT32 or INT64 with the unsigned logical type.
    Unsigned {
        /// 8, 16, 32 or 64.
        bits: u8,
    },
    /// A participant's index (UINT_32), where the world itself is spelt `world` in CSV and stored as `world`, the
    /// number the contract gives it (`swarm_contract::mail::{FROM_WORLD, TO_WORLD}`).
    Participant {
        /// The world's number in this column.
        world: u32,
    },
    /// A 32-bit float (FLOAT), written in `ryu`'s shortest round-trip form; `NaN` stays NaN.
    Float,
    /// `0` or `1` (BOOLEAN).
    Flag,
    /// UTF-8 text (BYTE_ARRAY, UTF8), dictionary-encoded.
    Text,
}

/// One column of a table.
#[derive(Clone, Copy, Debug)]
pub struct Column {
    /// The CSV header's name, also the Parquet column's.
    pub name: &'static str,
    /// Its values.
    pub kind: Kind,
    /// Whether the field may be empty in CSV: a null in Parquet (an OPTIONAL column).
    pub optional: bool,
}

const fn required(name: &'static str, kind: Kind) -> Column {
    Column {
        name,
        kind,
        optional: false,
    }
}

const TICK: Column = required("tick", Kind::Unsigned { bits: 64 });
const ROBOT: Column = required("robot", Kind::Unsigned { bits: 32 });
const ROBOT_ID: Column = required("robot_id", Kind::Text);
const LED: Kind = Kind::Unsigned { bits: 8 };

const TRAJECTORY: [Column; 10] = [
    TICK,
    ROBOT,
    ROBOT_ID,
    required("x", Kind::Float),
    required("y", Kind::Float),
    required("heading", Kind::Float),
    required("led_r", LED),
    required("led_g", LED),
    required("led_b", LED),
    required("alive", Kind::Flag),
];

const EVENTS: [Column; 4] = [TICK, ROBOT, ROBOT_ID, required("event", Kind::Text)];

const MESSAGES: [Column; 7] = [
    TICK,
    required("from", Kind::Participant { world: FROM_WORLD }),
    Column {
        name: "to",
        kind: Kind::Participant { world: TO_WORLD },
        // A broadcast refused as a whole has no recipient.
        optional: true,
    },
    required("address", Kind::Text),
    required("bytes", Kind::Unsigned { bits: 16 }),
    required("outcome", Kind::Text),
    Column {
        name: "reason",
        kind: Kind::Text,
        // Empty for a delivered message.
        optional: true,
    },
];

impl Table {
    /// Every table, in the order the world writes their files.
    pub const ALL: [Table; 3] = [Table::Trajectory, Table::Events, Table::Messages];

    /// The CSV file's name in the run folder.
    pub fn csv_name(self) -> &'static str {
        match self {
            Table::Trajectory => TRAJECTORY_FILE,
            Table::Events => EVENTS_FILE,
            Table::Messages => MESSAGES_FILE,
        }
    }

    /// The Parquet file's name in the run folder, beside the CSV file.
    pub fn parquet_name(self) -> &'static str {
        match self {
            Table::Trajectory => TRAJECTORY_PARQUET_FILE,
            Table::Events => EVENTS_PARQUET_FILE,
            Table::Messages => MESSAGES_PARQUET_FILE,
        }
    }

    /// The file's name in the run folder in `format`.
    pub fn file_name(self, format: crate::Format) -> &'static str {
        match format {
            crate::Format::Csv => self.csv_name(),
            crate::Format::Parquet => self.parquet_name(),
        }
    }

    /// The columns, in file order.
    pub fn columns(self) -> &'static [Column] {
        match self {
            Table::Trajectory => &TRAJECTORY,
            Table::Events => &EVENTS,
            Table::Messages => &MESSAGES,
        }
    }

    /// The CSV header line, without its line end.
    pub fn header(self) -> String {
        let names: Vec<&str> = self.columns().iter().map(|c| c.name).collect();
        names.join(",")
    }

    /// The Parquet schema: one flat message of the columns.
    pub fn parquet_schema(self) -> ParquetResult<TypePtr> {
        let fields = self
            .columns()
            .iter()
            .map(|c| c.parquet_type().map(Arc::new))
            .collect::<ParquetResult<Vec<_>>>()?;
        Ok(Arc::new(
            Type::group_type_builder(self.csv_name().trim_end_matches(".csv"))
                .with_fields(fields)
                .build()?,
        ))
    }
}

impl Kind {
    /// The physical type its values are stored as.
    pub fn physical(self) -> PhysicalType {
        match self {
            Kind::Unsigned { bits: 64 } => PhysicalType::INT64,
            Kind::Unsigned { .. } | Kind::Participant { .. } => PhysicalType::INT32,
            Kind::Float => PhysicalType::FLOAT,
            Kind::Flag => PhysicalType::BOOLEAN,
            Kind::Text => PhysicalType::BYTE_ARRAY,
        }
    }

    fn logical(self) -> Option<LogicalType> {
        match self {
            Kind::Unsigned { bits } => Some(LogicalType::integer(bits as i8, false)),
            Kind::Participant { .. } => Some(LogicalType::integer(32, false)),
            Kind::Float | Kind::Flag => None,
            Kind::Text => Some(LogicalType::String),
        }
    }
}

impl Column {
    fn repetition(&self) -> Repetition {
        if self.optional {
            Repetition::OPTIONAL
        } else {
            Repetition::REQUIRED
        }
    }

    fn parquet_type(&self) -> ParquetResult<Type> {
        Type::primitive_type_builder(self.name, self.kind.physical())
            .with_repetition(self.repetition())
            .with_logical_type(self.kind.logical())
            .build()
    }

    /// Whether a Parquet file's column is this one: same name, type and nullability, not nested.
    pub fn matches(&self, found: &ColumnDescriptor) -> bool {
        found.max_rep_level() == 0
            && found.max_def_level() == i16::from(self.optional)
            && describe_found(found) == self.describe()
    }

    /// How the column reads in an error message: `tick` (INT64, UINT_64, required).
    pub fn describe(&self) -> String {
        describe(
            self.name,
            self.kind.physical(),
            ConvertedType::from(self.kind.logical()),
            self.repetition(),
        )
    }
}

/// How a Parquet file's column reads in an error message, as [`Column::describe`].
pub(crate) fn describe_found(found: &ColumnDescriptor) -> String {
    let info = found.self_type().get_basic_info();
    let repetition = if info.has_repetition() {
        info.repetition()
    } else {
        Repetition::REQUIRED
    };
    describe(
        &found.path().string(),
        found.physical_type(),
        found.converted_type(),
        repetition,
    )
}

fn describe(
    name: &str,
    physical: PhysicalType,
    converted: ConvertedType,
    repetition: Repetition,
) -> String {
    let repetition = repetition.to_string().to_lowercase();
    match converted {
        ConvertedType::NONE => format!("`{name}` ({physical}, {repetition})"),
        _ => format!("`{name}` ({physical}, {converted}, {repetition})"),
    }
}
