//! Names and limits of the iceoryx2 services of a run, in one place for the world (which creates them) and the
//! agents (which only open them).

use iceoryx2::node::Node;
use iceoryx2::prelude::{NodeBuilder, NodeName, ServiceName, SignalHandlingMode, ipc};
use iceoryx2::service::port_factory::publish_subscribe::PortFactory;

use super::TransportError;
use super::run::RunSpec;
use crate::messages::{ActuatorCommand, MESSAGE_VERSION, SensorFrame};

/// The service carrying every robot's frame as one slice sample per tick.
pub(crate) type FrameService = PortFactory<ipc::Service, [SensorFrame], ()>;
/// The service carrying one robot's commands.
pub(crate) type CommandService = PortFactory<ipc::Service, ActuatorCommand, ()>;

/// Frames queued per agent: only the newest matters, an older one is replaced (safe overflow).
const FRAME_BUFFER: usize = 1;
/// Commands queued per robot: a late answer to the previous tick plus the current one.
const COMMAND_BUFFER: usize = 2;
/// Nodes on a command service: the world and the robot's agent.
const COMMAND_NODES: usize = 2;

/// Name of the frame service.
pub(crate) fn frame_service_name() -> String {
    format!("swarm/v{MESSAGE_VERSION}/frames")
}

/// Name of robot `robot`'s command service.
pub(crate) fn command_service_name(robot: u32) -> String {
    format!("swarm/v{MESSAGE_VERSION}/commands/{robot}")
}

fn service_name(name: &str) -> Result<ServiceName, TransportError> {
    ServiceName::new(name).map_err(|e| TransportError::iceoryx(format!("naming service {name}"), e))
}

/// Creates the node of one process of the run. Signals are left to the process (no iceoryx2 handler).
pub(crate) fn node(run: &RunSpec, name: &str) -> Result<Node<ipc::Service>, TransportError> {
    let config = run.iceoryx_config()?;
    let node_name = NodeName::new(name)
        .map_err(|e| TransportError::iceoryx(format!("naming node {name}"), e))?;
    NodeBuilder::new()
        .name(&node_name)
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| {
            TransportError::iceoryx(format!("creating node {name} in run {}", run.name()), e)
        })
}

/// World side: creates the frame service for `robots` agents.
pub(crate) fn create_frame_service(
    node: &Node<ipc::Service>,
    robots: u32,
) -> Result<FrameService, TransportError> {
    let name = frame_service_name();
    node.service_builder(&service_name(&name)?)
        .publish_subscribe::<[SensorFrame]>()
        .max_publishers(1)
        .max_subscribers(robots as usize)
        .max_nodes(robots as usize + 1)
        .subscriber_max_buffer_size(FRAME_BUFFER)
        .subscriber_max_borrowed_samples(1)
        .history_size(0)
        .enable_safe_overflow(true)
        .create()
        .map_err(|e| TransportError::iceoryx(format!("creating service {name}"), e))
}

/// Agent side: opens the frame service.
pub(crate) fn open_frame_service(
    node: &Node<ipc::Service>,
) -> Result<FrameService, TransportError> {
    let name = frame_service_name();
    node.service_builder(&service_name(&name)?)
        .publish_subscribe::<[SensorFrame]>()
        .open()
        .map_err(|e| TransportError::iceoryx(format!("opening service {name}"), e))
}

/// World side: creates robot `robot`'s command service (one publisher: the robot's agent).
pub(crate) fn create_command_service(
    node: &Node<ipc::Service>,
    robot: u32,
) -> Result<CommandService, TransportError> {
    let name = command_service_name(robot);
    node.service_builder(&service_name(&name)?)
        .publish_subscribe::<ActuatorCommand>()
        .max_publishers(1)
        .max_subscribers(1)
        .max_nodes(COMMAND_NODES)
        .subscriber_max_buffer_size(COMMAND_BUFFER)
        .subscriber_max_borrowed_samples(1)
        .history_size(0)
        .enable_safe_overflow(true)
        .create()
        .map_err(|e| TransportError::iceoryx(format!("creating service {name}"), e))
}

/// Agent side: opens robot `robot`'s command service.
pub(crate) fn open_command_service(
    node: &Node<ipc::Service>,
    robot: u32,
) -> Result<CommandService, TransportError> {
    let name = command_service_name(robot);
    node.service_builder(&service_name(&name)?)
        .publish_subscribe::<ActuatorCommand>()
        .open()
        .map_err(|e| match e {
            iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError::ExceedsMaxNumberOfNodes => {
                TransportError::ServiceFull {
                    robot,
                    service: name.clone(),
                    limit: COMMAND_NODES,
                    what: "nodes",
                }
            }
            other => TransportError::iceoryx(format!("opening service {name}"), other),
        })
}
