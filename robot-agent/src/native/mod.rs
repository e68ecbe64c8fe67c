//! Native controllers: hand-written control steps that need no supervisors, registered under the names configs
//! use for them.

pub mod disc_wander;
pub mod epuck_obstacleavoidance;
pub mod exploration_coordinator;
pub mod footbot;
pub mod footbot_diffusion;
pub mod footbot_flocking;
pub mod footbot_foraging;
pub mod footbot_gripping;
pub mod footbot_synchronization;
pub mod mail_probe;
pub mod navigation_coordinator;
pub mod sensor_probe;

use swarm_contract::mail::Mailbox;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use thiserror::Error;

use crate::params::{ParamError, Params};
use disc_wander::DiscWander;
use epuck_obstacleavoidance::EpuckObstacleAvoidance;
use exploration_coordinator::ExplorationCoordinator;
use footbot_diffusion::FootbotDiffusion;
use footbot_flocking::FootbotFlocking;
use footbot_foraging::FootbotForaging;
use footbot_gripping::FootbotGripping;
use footbot_synchronization::FootbotSynchronization;
use mail_probe::MailProbe;
use navigation_coordinator::NavigationCoordinator;
use sensor_probe::SensorProbe;

/// A controller that maps each tick's frame straight to a command (ARGoS' `ControlStep`).
pub trait NativeController: Send {
    /// One control step. Must not allocate.
    fn step(&mut self, frame: &SensorFrame, command: &mut ActuatorCommand);

    /// One control step of a controller that talks (docs/messages.md): `inbox` holds the messages delivered this
    /// tick, and whatever the step puts into `outbox` (empty at the start of every tick) is sent with the
    /// command. By default messages are ignored and [`NativeController::step`] runs. Must not allocate.
    fn step_with_mail(
        &mut self,
        frame: &SensorFrame,
        inbox: &Mailbox,
        outbox: &mut Mailbox,
        command: &mut ActuatorCommand,
    ) {
        let _ = (inbox, outbox);
        self.step(frame, command);
    }
}

/// A native controller ready to run.
pub type BoxedNative = Box<dyn NativeController>;

type BuildFn = fn(&Params) -> Result<BoxedNative, ParamError>;

/// Every native controller, by name.
const NATIVE: &[(&str, BuildFn)] = &[
    (EpuckObstacleAvoidance::NAME, |p| {
        Ok(Box::new(EpuckObstacleAvoidance::from_params(p)?))
    }),
    (FootbotDiffusion::NAME, |p| {
        Ok(Box::new(FootbotDiffusion::from_params(p)?))
    }),
    (FootbotFlocking::NAME, |p| {
        Ok(Box::new(FootbotFlocking::from_params(p)?))
    }),
    (FootbotForaging::NAME, |p| {
        Ok(Box::new(FootbotForaging::from_params(p)?))
    }),
    (FootbotGripping::NAME, |p| {
        Ok(Box::new(FootbotGripping::from_params(p)?))
    }),
    (FootbotSynchronization::NAME, |p| {
        Ok(Box::new(FootbotSynchronization::from_params(p)?))
    }),
    (DiscWander::NAME, |p| {
        Ok(Box::new(DiscWander::from_params(p)?))
    }),
    (MailProbe::NAME, |p| {
        Ok(Box::new(MailProbe::from_params(p)?))
    }),
    (ExplorationCoordinator::NAME, |p| {
        Ok(Box::new(ExplorationCoordinator::from_params(p)?))
    }),
    (NavigationCoordinator::NAME, |p| {
        Ok(Box::new(NavigationCoordinator::from_params(p)?))
    }),
    (SensorProbe::NAME, |p| {
        Ok(Box::new(SensorProbe::from_params(p)?))
    }),
];

/// Why a native controller could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum NativeError {
    /// No native controller has this name.
    #[error("unknown native controller `{name}` (known: {known})")]
    Unknown {
        /// The name asked for.
        name: String,
        /// Comma-separated registered names.
        known: String,
    },
    /// A parameter is bad.
    #[error("native controller `{name}`: {problem}")]
    Param {
        /// The controller.
        name: String,
        /// The parameter problem.
        problem: ParamError,
    },
}

/// Names of all registered native controllers.
pub fn native_names() -> impl Iterator<Item = &'static str> {
    NATIVE.iter().map(|(name, _)| *name)
}

/// Whether a native controller of this name is registered.
pub fn is_native(name: &str) -> bool {
    NATIVE.iter().any(|(n, _)| *n == name)
}

/// Builds native controller `name` from `params`.
pub fn build_native(name: &str, params: &Params) -> Result<BoxedNative, NativeError> {
    let Some((_, build)) = NATIVE.iter().find(|(n, _)| *n == name) else {
        return Err(NativeError::Unknown {
            name: name.to_owned(),
            known: NATIVE
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", "),
        });
    };
    build(params).map_err(|problem| NativeError::Param {
        name: name.to_owned(),
        problem,
    })
}
