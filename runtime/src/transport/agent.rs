//! An agent's side of the lockstep: join a run for one robot, sleep until the world publishes a tick, read the
//! robot's own frame in place, answer with a command.
//!
//! It must never answer for another robot (its command service is its robot's alone) and never answer a tick
//! the world has not opened yet.

use iceoryx2::node::Node;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::publisher::PublisherCreateError;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::subscriber::SubscriberCreateError;
use iceoryx2::prelude::ipc;
use iceoryx2::sample::Sample;

use super::TransportError;
use super::run::RunSpec;
use super::services::{self, CommandService, FrameService};
use super::sync_block::{JoinClaim, SyncBlock};
use crate::messages::{ActuatorCommand, SensorFrame};

/// Default number of polls of the tick word before an agent sleeps on it (see [`AgentLink::set_spin`]).
pub const DEFAULT_AGENT_SPIN: u32 = 0;

/// One tick's frame of this agent's robot, read in place from the world's shared-memory sample.
pub struct TickFrame {
    sample: Sample<ipc::Service, [SensorFrame], ()>,
    index: usize,
}

impl TickFrame {
    /// The robot's frame.
    pub fn frame(&self) -> &SensorFrame {
        &self.sample.payload()[self.index]
    }

    /// The tick of the frame.
    pub fn tick(&self) -> u64 {
        self.frame().tick
    }
}

/// The iceoryx2 side of an agent: its node, and its ports on the frame service and its robot's command service.
struct Ports {
    frame_subscriber: Subscriber<ipc::Service, [SensorFrame], ()>,
    command_publisher: Publisher<ipc::Service, ActuatorCommand, ()>,
    _command_service: CommandService,
    _frame_service: FrameService,
    _node: Node<ipc::Service>,
}

/// An agent's end of a run's local transport, for one robot.
pub struct AgentLink {
    robot: u32,
    spin: u32,
    seen_epoch: u32,
    pending: Option<Sample<ipc::Service, [SensorFrame], ()>>,
    ports: Ports,
    sync: SyncBlock,
}

impl AgentLink {
    /// Joins `run` as the agent of `robot`. Fails with a message naming the limit when the run has no place for
    /// it, or when another live agent already runs this robot.
    pub fn join(run: &RunSpec, robot: u32) -> Result<AgentLink, TransportError> {
        let sync = SyncBlock::open(&run.sync_block_path())?;
        let capacity = sync.capacity();
        if robot >= capacity {
            return Err(TransportError::RobotOutOfRange { robot, capacity });
        }
        if let JoinClaim::Taken = sync.claim_robot(robot) {
            return Err(TransportError::RobotTaken { robot });
        }
        match Self::connect(run, robot, capacity) {
            Ok(ports) => {
                let seen_epoch = sync.epoch();
                sync.announce_ready(robot);
                Ok(AgentLink {
                    robot,
                    spin: DEFAULT_AGENT_SPIN,
                    seen_epoch,
                    pending: None,
                    ports,
                    sync,
                })
            }
            Err(e) => {
                sync.release_claim(robot);
                Err(e)
            }
        }
    }

    fn connect(run: &RunSpec, robot: u32, capacity: u32) -> Result<Ports, TransportError> {
        let node = services::node(run, &format!("robot-{robot}"))?;
        let frame_service = services::open_frame_service(&node)?;
        let frame_subscriber =
            frame_service
                .subscriber_builder()
                .create()
                .map_err(|e| match e {
                    SubscriberCreateError::ExceedsMaxSupportedSubscribers => {
                        TransportError::ServiceFull {
                            robot,
                            service: services::frame_service_name(),
                            limit: capacity as usize,
                            what: "subscribers",
                        }
                    }
                    other => TransportError::iceoryx("subscribing to the frames", other),
                })?;
        let command_service = services::open_command_service(&node, robot)?;
        let command_publisher =
            command_service
                .publisher_builder()
                .create()
                .map_err(|e| match e {
                    PublisherCreateError::ExceedsMaxSupportedPublishers => {
                        TransportError::ServiceFull {
                            robot,
                            service: services::command_service_name(robot),
                            limit: 1,
                            what: "publishers",
                        }
                    }
                    other => TransportError::iceoryx(
                        format!("publishing robot {robot}'s commands"),
                        other,
                    ),
                })?;
        Ok(Ports {
            frame_subscriber,
            command_publisher,
            _command_service: command_service,
            _frame_service: frame_service,
            _node: node,
        })
    }

    /// The robot this agent runs.
    pub fn robot(&self) -> u32 {
        self.robot
    }

    /// How many times the agent polls the tick word before it sleeps on it (default 0: the lockstep benchmark
    /// on 2 cores is fastest without agent polling). Polling only pays when every agent has a core to itself.
    pub fn set_spin(&mut self, polls: u32) {
        self.spin = polls;
    }

    /// Waits for the next tick the world opens and returns this robot's frame; `None` when the world ended the
    /// run, [`TransportError::WorldGone`] when the world process died without ending it (checked every second
    /// of silence). An agent that fell behind skips straight to the newest tick.
    pub fn next_tick(&mut self) -> Result<Option<TickFrame>, TransportError> {
        let index = self.robot as usize;
        loop {
            if self.sync.stopped() {
                return Ok(None);
            }
            let newest = if self.pending.is_none() {
                self.receive_frames()?
            } else if self
                .ports
                .frame_subscriber
                .has_samples()
                .map_err(|e| TransportError::iceoryx("checking for frames", e))?
            {
                // Only one frame sample is ever borrowed: release the older one first.
                self.pending = None;
                self.receive_frames()?
            } else {
                None
            };
            if newest.is_some() {
                self.pending = newest;
            }
            if let Some(sample) = self.pending.take() {
                let Some(frame) = sample.payload().get(index) else {
                    return Err(TransportError::InvalidSyncBlock {
                        path: std::path::PathBuf::from(services::frame_service_name()),
                        reason: format!(
                            "a frame sample holds {} frames, robot {index} has none",
                            sample.payload().len()
                        ),
                    });
                };
                let open = self.sync.tick();
                if frame.tick == open {
                    return Ok(Some(TickFrame { sample, index }));
                }
                if frame.tick > open {
                    // Published but not opened yet: keep it until the world opens its tick.
                    self.pending = Some(sample);
                }
            }
            self.seen_epoch = self
                .sync
                .wait_epoch_change(self.seen_epoch, self.spin)
                .map_err(|pid| TransportError::WorldGone { pid })?;
        }
    }

    fn receive_frames(
        &self,
    ) -> Result<Option<Sample<ipc::Service, [SensorFrame], ()>>, TransportError> {
        self.ports
            .frame_subscriber
            .receive()
            .map_err(|e| TransportError::iceoryx("receiving the frames", e))
    }

    /// Sends `command` as this robot's answer to `frame`'s tick (its `tick` and `robot` fields are set from the
    /// frame) and releases the frame.
    pub fn answer(
        &mut self,
        frame: TickFrame,
        command: &ActuatorCommand,
    ) -> Result<(), TransportError> {
        let tick = frame.tick();
        drop(frame);
        let mut answer = *command;
        answer.tick = tick;
        answer.robot = self.robot;
        let sample = self.ports.command_publisher.loan_uninit().map_err(|e| {
            TransportError::iceoryx(format!("loaning the command of tick {tick}"), e)
        })?;
        sample.write_payload(answer).send().map_err(|e| {
            TransportError::iceoryx(format!("sending the command of tick {tick}"), e)
        })?;
        self.sync.claim(self.robot, tick);
        Ok(())
    }
}

impl Drop for AgentLink {
    fn drop(&mut self) {
        self.sync.leave(self.robot);
    }
}
