//! The media: what travels between robots and the environment besides bodies. LEDs (who is lit where, for the
//! cameras), range-and-bearing messages, addressed messages between participants, and the pheromone field. Media are updated after physics, so what a robot
//! senses at tick k reflects the actions of tick k - 1 at the positions after its physics step (ARGoS order).

pub mod led;
pub mod mail;
pub mod pheromone;
pub mod rab;
