//! Loop functions: the experiment hooks of ARGoS (`PreStep`, `PostStep`, `GetFloorColor`,
//! `IsExperimentFinished`) plus the task metrics, registered under the label the configuration's
//! `<loop_functions label="...">` uses. Tasks add their own by registering a factory; the core never changes.

pub mod aggregation;
pub mod argos_foraging;
pub mod default;
pub mod exploration;
pub mod foraging;
pub mod navigation;
pub mod obstacle_avoidance;
pub mod params;
pub mod pheromone_foraging;
pub mod phototaxis;
pub mod synchronisation;
pub mod transport;

use std::collections::BTreeMap;

use swarm_contract::mail::Mail;
use swarm_contract::messages::ActuatorCommand;

use crate::arena::Arena;
use crate::error::WorldError;
use crate::geometry::Vec2;

/// The experiment hooks of one task.
pub trait LoopFunctions: Send {
    /// Called once when the world is built, after every entity is in the arena: may move robots to the poses
    /// the task wants them at (with [`Arena::place_robot`]; ARGoS loop functions' `Init`).
    fn place(&mut self, _arena: &mut Arena) -> Result<(), WorldError> {
        Ok(())
    }

    /// Called after every tick in a run with a messages medium: appends to `letters` what the world sends the
    /// participants this tick (each to one participant, from [`swarm_contract::mail::FROM_WORLD`]; delivered
    /// in the next tick like the participants' messages).
    fn post_mail(&mut self, _arena: &Arena, _letters: &mut Vec<Mail>) {}

    /// Called after every tick in a run with a messages medium, before [`LoopFunctions::post_mail`], with what
    /// the participants sent the world this tick (`Address::To(`[`swarm_contract::mail::TO_WORLD`]`)`); `from`
    /// is the true sender. The letters come from robots' code: decode them as hostile input.
    fn read_mail(&mut self, _arena: &Arena, _letters: &[Mail]) {}

    /// Called at the start of every tick's act phase, before the actuators are applied.
    fn pre_step(&mut self, _arena: &mut Arena) {}

    /// Called at the end of every tick, after physics and media; `commands[i]` is robot i's command of this tick
    /// when `has_command[i]`.
    fn post_step(
        &mut self,
        _arena: &mut Arena,
        _commands: &[ActuatorCommand],
        _has_command: &[bool],
    ) {
    }

    /// Grey level of the floor at `p` (1 white, 0 black), or `None` to use the arena's floor regions.
    fn floor_color(&self, _p: Vec2) -> Option<f32> {
        None
    }

    /// Whether the experiment is over (e.g. all targets delivered).
    fn is_finished(&self, _arena: &Arena) -> bool {
        false
    }

    /// The task metrics so far, for `summary.json`.
    fn metrics(&self, arena: &Arena) -> serde_json::Value;

    /// The file name, in the run folder, of the loop functions' own per-tick output (ARGoS loop functions'
    /// output files), if they keep one.
    fn output_name(&self) -> Option<&str> {
        None
    }

    /// Moves the output text produced since the last call to the end of `out`.
    fn drain_output(&mut self, _out: &mut Vec<u8>) {}
}

/// The `<loop_functions>` element as the factories see it.
#[derive(Debug, Clone, Default)]
pub struct LoopFunctionsParams {
    /// The `label` attribute.
    pub label: String,
    /// Where the element is (`path:line:column`), for errors.
    pub location: String,
    /// Attributes of the element's children, flattened as `child.attribute` -> value
    /// (e.g. `foraging.home_y_max` -> `-2.0`).
    pub attributes: BTreeMap<String, String>,
    /// The names of the element's children, in file order (a child without attributes is only here).
    pub children: Vec<String>,
    /// The run's seed, for loop functions that draw random numbers (from their own stream).
    pub seed: u64,
}

impl LoopFunctionsParams {
    /// Refuses a child element other than `known` (a misspelt one would otherwise be ignored silently).
    pub fn check_children(&self, known: &[&str]) -> Result<(), WorldError> {
        let from_attributes = self
            .attributes
            .keys()
            .filter_map(|k| k.split_once('.').map(|(c, _)| c));
        match self
            .children
            .iter()
            .map(String::as_str)
            .chain(from_attributes)
            .find(|child| !known.contains(child))
        {
            None => Ok(()),
            Some(child) => Err(WorldError::Invalid {
                location: self.location.clone(),
                message: format!(
                    "<loop_functions label=\"{}\"> has no child <{child}> ({})",
                    self.label,
                    if known.is_empty() {
                        "it takes none".to_owned()
                    } else {
                        format!(
                            "known: {}",
                            known
                                .iter()
                                .map(|c| format!("<{c}>"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    }
                ),
            }),
        }
    }
}

/// Makes the loop functions of one label from the configuration.
pub type LoopFunctionsFactory =
    fn(&LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError>;

/// The loop functions known by label.
#[derive(Debug, Clone)]
pub struct LoopFunctionsRegistry {
    factories: BTreeMap<String, LoopFunctionsFactory>,
}

impl Default for LoopFunctionsRegistry {
    /// The built-in loop functions: `obstacle_avoidance_loop_functions`, `aggregation_loop_functions`,
    /// `synchronisation_loop_functions`, `foraging_loop_functions`, `pheromone_foraging_loop_functions`,
    /// `phototaxis_loop_functions`, `navigation_loop_functions`, `exploration_loop_functions`,
    /// `transport_loop_functions`.
    fn default() -> Self {
        let mut registry = Self {
            factories: BTreeMap::new(),
        };
        registry.register(
            obstacle_avoidance::LABEL,
            obstacle_avoidance::ObstacleAvoidance::factory,
        );
        registry.register(aggregation::LABEL, aggregation::Aggregation::factory);
        registry.register(
            synchronisation::LABEL,
            synchronisation::Synchronisation::factory,
        );
        registry.register(foraging::LABEL, foraging::Foraging::factory);
        registry.register(
            pheromone_foraging::LABEL,
            pheromone_foraging::PheromoneForaging::factory,
        );
        registry.register(phototaxis::LABEL, phototaxis::Phototaxis::factory);
        registry.register(navigation::LABEL, navigation::Navigation::factory);
        registry.register(exploration::LABEL, exploration::Exploration::factory);
        registry.register(transport::LABEL, transport::Transport::factory);
        registry
    }
}

impl LoopFunctionsRegistry {
    /// Registers (or replaces) the factory for `label`.
    pub fn register(&mut self, label: &str, factory: LoopFunctionsFactory) {
        self.factories.insert(label.to_owned(), factory);
    }

    /// The loop functions for `params`, or the default ones when the configuration has none.
    pub fn create(
        &self,
        params: Option<&LoopFunctionsParams>,
    ) -> Result<Box<dyn LoopFunctions>, WorldError> {
        let Some(params) = params else {
            return Ok(Box::new(default::DefaultLoopFunctions));
        };
        match self.factories.get(&params.label) {
            Some(factory) => factory(params),
            None => Err(WorldError::UnknownLoopFunctions {
                location: params.location.clone(),
                label: params.label.clone(),
                known: self
                    .factories
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", "),
            }),
        }
    }
}
