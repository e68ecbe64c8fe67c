//! Removes dead agents' iceoryx2 resources on a thread of its own.
//!
//! A dead agent's node keeps its places in the run's services (a frame-board reader, a node slot) until someone
//! removes its stale resources. Finding dead nodes means scanning every node of the run, which takes tens of
//! milliseconds at 100 robots; on the world's thread that scan would stall the tick in which a robot died, and
//! the world would report the death that much later. The scan touches only the run's iceoryx2 files, not the
//! world's ports, so it runs beside the ticks.

use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::thread::JoinHandle;
use std::time::Instant;

use iceoryx2::node::{Node, NodeState, NodeView};
use iceoryx2::prelude::{CallbackProgression, Config, ipc};

use super::TransportError;

/// The cleanup thread of one run. Dropping it finishes the scan under way and ends the thread.
pub(super) struct Cleaner {
    requests: Option<SyncSender<()>>,
    thread: Option<JoinHandle<()>>,
}

impl Cleaner {
    /// Starts the thread for the run whose iceoryx2 configuration is `config`.
    pub(super) fn start(config: Config) -> Result<Cleaner, TransportError> {
        // One pending request is enough: a scan that starts after it was queued sees every death before it.
        let (requests, pending) = mpsc::sync_channel(1);
        let thread = std::thread::Builder::new()
            .name("dead-node-cleanup".into())
            .spawn(move || serve(&config, &pending))
            .map_err(|e| TransportError::iceoryx("starting the dead-node cleanup thread", e))?;
        Ok(Cleaner {
            requests: Some(requests),
            thread: Some(thread),
        })
    }

    /// Asks for a scan; returns at once. Requests made while one is pending are merged into it.
    pub(super) fn request(&self) {
        if let Some(requests) = &self.requests {
            match requests.try_send(()) {
                Ok(()) | Err(TrySendError::Full(())) => {}
                Err(TrySendError::Disconnected(())) => {
                    tracing::warn!("the dead-node cleanup thread has ended");
                }
            }
        }
    }
}

impl Drop for Cleaner {
    fn drop(&mut self) {
        self.requests = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn serve(config: &Config, pending: &Receiver<()>) {
    while pending.recv().is_ok() {
        let started = Instant::now();
        let (mut removed, mut failed) = (0u32, 0u32);
        let listed = Node::<ipc::Service>::list(config, |state| {
            if let NodeState::Dead(node) = state {
                let id = *node.id();
                match node.try_remove_stale_resources() {
                    Ok(()) => removed += 1,
                    Err(e) => {
                        failed += 1;
                        tracing::debug!(?id, ?e, "a dead node's resources could not be removed");
                    }
                }
            }
            CallbackProgression::Continue
        });
        if let Err(e) = listed {
            tracing::debug!(?e, "the run's nodes could not be listed");
        }
        tracing::debug!(removed, failed, took = ?started.elapsed(), "dead-node cleanup");
    }
}
