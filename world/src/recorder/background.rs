//! A record file written by a thread of its own, so that formatting rows does not lengthen the tick.
//!
//! The tick loop pushes plain rows (no formatting) and hands the batch over at the end of the tick; the thread
//! formats, writes and flushes it and gives the emptied batch back for reuse. At most [`QUEUED_BATCHES`] batches
//! wait; after that, handing over blocks, so a slow disk slows the run down instead of growing its memory.
//!
//! [`Background::sync`] returns once everything handed over is in the file. The world calls it before anything
//! that may end its process (a scheduled world kill), so such an end loses nothing. A world killed by hand loses
//! at most the batches still queued, all of them whole ticks the launcher's cut-back removes anyway.

use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, SyncSender};
use std::thread::JoinHandle;

use crate::error::WorldError;

/// How many handed-over batches may wait for the writing thread.
pub const QUEUED_BATCHES: usize = 4;

/// Writes batches of rows into one file; runs on the background thread.
pub trait RowWriter: Send + 'static {
    /// One row, as plain data.
    type Row: Send + 'static;

    /// Formats and writes `rows`, then flushes the file.
    fn write_batch(&mut self, rows: &[Self::Row]) -> Result<(), WorldError>;

    /// Completes the files once the last batch is written ([`Background::finish`]; a handle dropped without it
    /// leaves them as they are).
    fn close(&mut self) -> Result<(), WorldError> {
        Ok(())
    }
}

enum Order<R> {
    Write(Vec<R>),
    Sync(mpsc::Sender<()>),
    Close,
}

/// The tick loop's handle on a file written by a background thread.
pub struct Background<W: RowWriter> {
    path: PathBuf,
    batch: Vec<W::Row>,
    orders: Option<SyncSender<Order<W::Row>>>,
    spare: Receiver<Vec<W::Row>>,
    thread: Option<JoinHandle<Result<(), WorldError>>>,
}

impl<W: RowWriter> Background<W> {
    /// Starts the thread that writes `path` with `writer`.
    pub fn spawn(path: &Path, mut writer: W) -> Result<Self, WorldError> {
        let (orders, incoming) = mpsc::sync_channel::<Order<W::Row>>(QUEUED_BATCHES);
        let (give_back, spare) = mpsc::channel();
        let thread = std::thread::Builder::new()
            .name("record-writer".into())
            .spawn(move || {
                for order in incoming {
                    match order {
                        Order::Write(mut rows) => {
                            writer.write_batch(&rows)?;
                            rows.clear();
                            // The handle may be gone already; then the batch is simply dropped.
                            let _ = give_back.send(rows);
                        }
                        Order::Sync(done) => {
                            let _ = done.send(());
                        }
                        Order::Close => writer.close()?,
                    }
                }
                Ok(())
            })
            .map_err(|source| WorldError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        Ok(Self {
            path: path.to_path_buf(),
            batch: Vec::new(),
            orders: Some(orders),
            spare,
            thread: Some(thread),
        })
    }

    /// Adds a row to the current batch.
    pub fn push(&mut self, row: W::Row) {
        self.batch.push(row);
    }

    /// Hands the current batch to the thread (nothing when it is empty) and starts a new one.
    pub fn end_batch(&mut self) -> Result<(), WorldError> {
        if self.batch.is_empty() {
            return Ok(());
        }
        let next = self.spare.try_recv().unwrap_or_default();
        let rows = std::mem::replace(&mut self.batch, next);
        self.send(Order::Write(rows))
    }

    /// Hands over the current batch and waits until every batch handed over is written and flushed.
    pub fn sync(&mut self) -> Result<(), WorldError> {
        self.end_batch()?;
        let (done, written) = mpsc::channel();
        self.send(Order::Sync(done))?;
        match written.recv() {
            Ok(()) => Ok(()),
            Err(_) => Err(self.stopped()),
        }
    }

    /// Hands over the current batch, lets the thread write everything, complete the files and end, and waits
    /// for it.
    pub fn finish(mut self) -> Result<(), WorldError> {
        self.end_batch()?;
        self.send(Order::Close)?;
        self.orders = None;
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(written)) => written,
            Some(Err(_)) => Err(self.panicked()),
            None => Ok(()),
        }
    }

    fn send(&mut self, order: Order<W::Row>) -> Result<(), WorldError> {
        let sent = match &self.orders {
            Some(orders) => orders.send(order).is_ok(),
            None => false,
        };
        if sent { Ok(()) } else { Err(self.stopped()) }
    }

    /// The thread has ended before it was told to: its own error, or a panic.
    fn stopped(&mut self) -> WorldError {
        self.orders = None;
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(Err(e))) => e,
            _ => self.panicked(),
        }
    }

    fn panicked(&self) -> WorldError {
        WorldError::Io {
            path: self.path.clone(),
            source: std::io::Error::other("the thread writing this file stopped unexpectedly"),
        }
    }
}

impl<W: RowWriter> Drop for Background<W> {
    /// Writes whatever was handed over (an early return of the tick loop must not lose recorded rows).
    fn drop(&mut self) {
        let _ = self.end_batch();
        self.orders = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::{Arc, Mutex};

    use super::*;

    /// Keeps what it was given; fails on the row [`UNLUCKY`].
    const UNLUCKY: u32 = u32::MAX;

    struct Collect(Arc<Mutex<Vec<u32>>>);

    impl RowWriter for Collect {
        type Row = u32;
        fn write_batch(&mut self, rows: &[u32]) -> Result<(), WorldError> {
            if rows.contains(&UNLUCKY) {
                return Err(WorldError::Io {
                    path: PathBuf::from("unlucky"),
                    source: std::io::Error::other("unlucky row"),
                });
            }
            self.0.lock().expect("not poisoned").extend_from_slice(rows);
            Ok(())
        }
    }

    #[test]
    fn rows_arrive_in_order_and_sync_waits_for_them() {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let mut writer =
            Background::spawn(Path::new("t"), Collect(Arc::clone(&seen))).expect("spawns");
        for tick in 0..50 {
            writer.push(tick * 2);
            writer.push(tick * 2 + 1);
            writer.end_batch().expect("handed over");
            if tick == 20 {
                writer.sync().expect("synced");
                assert_eq!(*seen.lock().expect("lock"), (0..42).collect::<Vec<_>>());
            }
        }
        writer.push(100);
        writer.finish().expect("finished");
        assert_eq!(*seen.lock().expect("lock"), (0..101).collect::<Vec<_>>());
    }

    #[test]
    fn dropping_the_handle_still_writes_what_was_pushed() {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let mut writer =
            Background::spawn(Path::new("t"), Collect(Arc::clone(&seen))).expect("spawns");
        writer.push(1);
        writer.end_batch().expect("handed over");
        writer.push(2);
        drop(writer);
        assert_eq!(*seen.lock().expect("lock"), vec![1, 2]);
    }

    #[test]
    fn a_write_error_of_the_thread_reaches_the_tick_loop() {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let mut writer =
            Background::spawn(Path::new("t"), Collect(Arc::clone(&seen))).expect("spawns");
        writer.push(UNLUCKY);
        writer.end_batch().expect("handed over");
        let error = writer.sync().expect_err("the thread failed");
        assert!(error.to_string().contains("unlucky"), "{error}");
    }
}
