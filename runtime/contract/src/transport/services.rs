//! Names and limits of the iceoryx2 services of a run, in one place for the world (which creates them) and the
//! agents (which only open them).
//!
//! Both services are iceoryx2 blackboards: fixed-size entries in shared memory that one writer, the world, updates in
//! place and readers load lock-free. The frame board holds one entry per robot, the inbox board (runs with mail
//! only) one mailbox per robot; each agent reads its own. docs/transport.md says why blackboards and not
//! publish-subscribe. The agents' answers go the other way through the command slots (`command_slots`): a
//! blackboard admits one writer only.

use iceoryx2::node::Node;
use iceoryx2::prelude::{
    NodeBuilder, NodeName, ServiceName, SignalHandlingMode, ZeroCopySend, ipc,
};
use iceoryx2::service::builder::blackboard::BlackboardOpenError;
use iceoryx2::service::port_factory::blackboard::PortFactory;

use super::TransportError;
use super::run::RunSpec;
use crate::mail::Mailbox;
use crate::messages::{MESSAGE_VERSION, SensorFrame};

/// A blackboard of the run, keyed by robot index.
pub(crate) type Board = PortFactory<ipc::Service, u32>;

/// Name of the frame board.
pub(crate) fn frame_service_name() -> String {
    format!("swarm/v{MESSAGE_VERSION}/frames")
}

/// Name of the inbox board (runs with mail only): one [`Mailbox`] per robot, keyed like the frame board.
pub(crate) fn inbox_service_name() -> String {
    format!("swarm/v{MESSAGE_VERSION}/inboxes")
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

/// Places in the frame board beyond one per robot: replacement agents connect while their dead predecessors'
/// places still wait for the dead-node cleanup. More simultaneous replacements retry until it has run.
pub(crate) const SPARE_AGENT_PLACES: usize = 8;

/// World side: creates the frame board with one entry per robot, readable by `robots` agents (plus spares).
pub(crate) fn create_frame_board(
    node: &Node<ipc::Service>,
    robots: u32,
) -> Result<Board, TransportError> {
    create_per_robot_board(node, &frame_service_name(), robots, SensorFrame::empty)
}

/// World side: creates the inbox board with one mailbox per robot, readable by `robots` agents (plus spares).
pub(crate) fn create_inbox_board(
    node: &Node<ipc::Service>,
    robots: u32,
) -> Result<Board, TransportError> {
    create_per_robot_board(node, &inbox_service_name(), robots, Mailbox::empty)
}

/// Creates the board `name` with the entry `initial(robot)` for every robot, readable by `robots` agents (plus
/// spares), written by the world.
fn create_per_robot_board<T: ZeroCopySend + Copy + 'static>(
    node: &Node<ipc::Service>,
    name: &str,
    robots: u32,
    initial: fn(u32) -> T,
) -> Result<Board, TransportError> {
    let mut creator = node
        .service_builder(&service_name(name)?)
        .blackboard_creator::<u32>()
        .max_readers(robots as usize + SPARE_AGENT_PLACES)
        .max_nodes(robots as usize + 1 + SPARE_AGENT_PLACES);
    for robot in 0..robots {
        creator = creator.add::<T>(robot, initial(robot));
    }
    creator
        .create()
        .map_err(|e| TransportError::iceoryx(format!("creating service {name}"), e))
}

/// Agent side: opens the board `name` that has one entry per robot (the frame board, the inbox board) of a run of
/// `robots` robots, as robot `robot`'s agent. A board whose places for nodes are all taken is
/// [`TransportError::ServiceFull`] (the agent may retry once dead nodes are cleaned up).
pub(crate) fn open_per_robot_board(
    node: &Node<ipc::Service>,
    name: &str,
    robot: u32,
    robots: u32,
) -> Result<Board, TransportError> {
    node.service_builder(&service_name(name)?)
        .blackboard_opener::<u32>()
        .open()
        .map_err(|e| match e {
            BlackboardOpenError::ExceedsMaxNumberOfNodes => TransportError::ServiceFull {
                robot,
                service: name.to_owned(),
                limit: robots as usize + 1 + SPARE_AGENT_PLACES,
                what: "nodes",
            },
            other => TransportError::iceoryx(format!("opening service {name}"), other),
        })
}
