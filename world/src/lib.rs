//! swarm-world: the simulator every robot process senses and acts in.
//!
//! A 2-D e-puck arena (`shared/reference/epuck-and-world.md`): rigid-body physics, the e-puck sensors and
//! actuators, LED / range-and-bearing / pheromone media, loop functions for task metrics, and the recorder.
//! It implements the control interface defined in `swarm_runtime::messages`; it never depends on robot-agent.
