//! The per-tick record files as the recorder's thread writes them: `events.csv`, `messages.csv` (runs with
//! mail) and `trajectory.csv` together.
//!
//! A tick's batch ends with its poses, and the events and messages files are flushed before the trajectory file.
//! So whenever the trajectory holds a tick for every robot, the events and messages of that tick are on disk too: the launcher's cut-back
//! after a world death (`runtime/cli/src/launcher/records.rs`) trusts the trajectory to say which ticks are whole.

use super::background::RowWriter;
use super::events::{EventRow, EventsWriter};
use super::messages::MessagesWriter;
use super::objects_file::{ObjectRow, ObjectsWriter};
use super::trajectory::{PoseRow, TrajectoryWriter};
use crate::error::WorldError;
use crate::media::mail::MessageRecord;

/// One row of either file.
#[derive(Clone, Copy, Debug)]
pub enum RecordRow {
    /// A row of `events.csv`.
    Event(EventRow),
    /// A row of `trajectory.csv`.
    Pose(PoseRow),
    /// A row of `messages.csv`.
    Message(MessageRecord),
    /// A row of `objects.csv`.
    Object(ObjectRow),
}

/// Both files.
pub struct RecordFiles {
    /// `events.csv`.
    pub events: EventsWriter,
    /// `trajectory.csv`.
    pub trajectory: TrajectoryWriter,
    /// `messages.csv`, in runs with a messages medium.
    pub messages: Option<MessagesWriter>,
    /// `objects.csv`, in runs with targets or movable obstacles.
    pub objects: Option<ObjectsWriter>,
}

impl RowWriter for RecordFiles {
    type Row = RecordRow;

    fn write_batch(&mut self, rows: &[RecordRow]) -> Result<(), WorldError> {
        for row in rows {
            match row {
                RecordRow::Event(row) => self.events.write_row(row)?,
                RecordRow::Pose(row) => self.trajectory.write_row(row)?,
                RecordRow::Message(row) => {
                    if let Some(messages) = &mut self.messages {
                        messages.write_row(row)?;
                    }
                }
                RecordRow::Object(row) => {
                    if let Some(objects) = &mut self.objects {
                        objects.write_row(row)?;
                    }
                }
            }
        }
        self.events.flush()?;
        if let Some(messages) = &mut self.messages {
            messages.flush()?;
        }
        if let Some(objects) = &mut self.objects {
            objects.flush()?;
        }
        self.trajectory.flush()
    }

    fn close(&mut self) -> Result<(), WorldError> {
        self.events.close()?;
        if let Some(messages) = &mut self.messages {
            messages.close()?;
        }
        if let Some(objects) = &mut self.objects {
            objects.flush()?;
        }
        self.trajectory.close()
    }
}
