//! Fault orders to hosts between ticks: kill, freeze, thaw or restart one robot's agent on the host that runs it.

use std::sync::mpsc::RecvTimeoutError;
use std::time::{Duration, Instant};

use super::super::codec;
use super::super::host_to_world::OrderReply;
use super::super::session::zenoh_error;
use super::super::world_to_host::{Order, OrderAction};
use super::super::{RemoteError, keys};
use super::{Incoming, RemoteHosts, State};

impl RemoteHosts {
    /// Sends `robot`'s host a fault order and waits for the answer (a replacement agent's join included), while
    /// following the hosts' news: `Ok(true)` when carried out, `Ok(false)` when the host is not live, is lost
    /// meanwhile, does not answer in time or cannot carry it out (logged). Never waits past the host's loss.
    pub fn order(&mut self, robot: u32, action: OrderAction) -> Result<bool, RemoteError> {
        let Some(&index) = self.owner.get(robot as usize) else {
            return Ok(false);
        };
        if self.hosts[index].state != State::Live {
            return Ok(false);
        }
        let name = self.hosts[index].share.name.clone();
        let epoch = self.hosts[index].epoch;
        let timeout = match action {
            OrderAction::Respawn { .. } => self.options.join_timeout + Duration::from_secs(5),
            _ => self.options.tick_deadline.max(Duration::from_secs(5)),
        };
        self.orders_sent += 1;
        let number = self.orders_sent;
        let order = Order {
            run: self.run,
            epoch,
            number,
            robot,
            action: action.clone(),
        };
        let key = keys::orders(&name);
        let mut payload = codec::encode_message(&order)?;
        let seal = self.hosts[index].seal.clone();
        seal.seal(&key, &mut payload);
        self.answer = None;
        self.query(
            key,
            payload,
            seal,
            timeout,
            move |answer| Incoming::Ordered(number, answer),
            Incoming::OrderEnded(number),
        )
        .map_err(zenoh_error("sending a host a fault order"))?;
        let deadline = Instant::now() + timeout;
        while self.answer.is_none() {
            let now = Instant::now();
            if now >= deadline
                || self.hosts[index].state != State::Live
                || epoch != self.hosts[index].epoch
            {
                break;
            }
            match self.incoming.recv_timeout(deadline - now) {
                Ok(event) => self.handle(event, false)?,
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        let outcome = match self.answer.take() {
            None => Err("the host was lost or did not answer in time".to_owned()),
            Some(answer) => answer
                .and_then(|bytes| {
                    codec::decode_message::<OrderReply>(&bytes, self.options.max_payload).map_err(
                        |e| {
                            self.dropped.rejected += 1;
                            e.to_string()
                        },
                    )
                })
                .and_then(|reply| match reply {
                    OrderReply::Done => Ok(()),
                    OrderReply::Failed { reason } => Err(reason),
                }),
        };
        if let Err(reason) = outcome {
            tracing::warn!(
                host = name,
                robot,
                order = action.name(),
                "fault order not carried out: {reason}"
            );
            return Ok(false);
        }
        let r = robot as usize;
        match action {
            OrderAction::Kill => (self.present[r], self.held[r]) = (false, true),
            OrderAction::Freeze | OrderAction::Skip => self.held[r] = true,
            OrderAction::Thaw | OrderAction::Revive => self.held[r] = false,
            OrderAction::Respawn { .. } => (self.present[r], self.held[r]) = (true, false),
        }
        Ok(true)
    }
}
