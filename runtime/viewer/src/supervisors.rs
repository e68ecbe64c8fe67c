//! A robot's supervisors' states at any tick, found by replaying the events it fired through the compiled
//! supervisor set of its controller (`supervisors/<controller>.ptsct` in the run directory): every supervisor
//! that owns an event follows its transition on it, the others stay (docs/ptsct.md's player rule).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use supervisor_gen::compiled::SupervisorSet;
use swarm_contract::run_dir::compiled_supervisors;

/// One supervisor's state.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct SupervisorState {
    /// The supervisor's name.
    pub name: String,
    /// Its current state (0 is the initial state).
    pub state: u16,
    /// How many states it has.
    pub states: usize,
}

/// A controller's set with its event names resolved.
struct Loaded {
    set: SupervisorSet,
    ids: HashMap<String, u8>,
}

/// The compiled sets of one run, read on first use.
pub struct Supervisors {
    run_dir: PathBuf,
    sets: HashMap<String, Result<Loaded, String>>,
}

impl Supervisors {
    /// The sets of the run in `run_dir`.
    pub fn new(run_dir: &Path) -> Self {
        Self {
            run_dir: run_dir.to_path_buf(),
            sets: HashMap::new(),
        }
    }

    /// The states of `controller`'s supervisors after `events` (names, in firing order), or why they are not
    /// known (no compiled set, an unreadable one, or an event the set does not have).
    pub fn replay<'a>(
        &mut self,
        controller: &str,
        events: impl IntoIterator<Item = &'a str>,
    ) -> Result<Vec<SupervisorState>, String> {
        let run_dir = &self.run_dir;
        let loaded = self
            .sets
            .entry(controller.to_owned())
            .or_insert_with(|| load(run_dir, controller))
            .as_ref()
            .map_err(Clone::clone)?;
        let set = &loaded.set;
        let mut states = vec![0u16; set.supervisors.len()];
        for name in events {
            if crate::events::written_by_the_world(name) {
                continue;
            }
            let Some(&event) = loaded.ids.get(name) else {
                return Err(format!(
                    "event `{name}` is not in the compiled set of controller `{controller}`"
                ));
            };
            for (state, supervisor) in states.iter_mut().zip(&set.supervisors) {
                if !supervisor.owns(event) {
                    continue;
                }
                let next = supervisor
                    .states
                    .get(usize::from(*state))
                    .and_then(|s| s.transitions.iter().find(|t| t.event == event));
                if let Some(transition) = next {
                    *state = transition.target;
                }
            }
        }
        Ok(states
            .into_iter()
            .zip(&set.supervisors)
            .map(|(state, supervisor)| SupervisorState {
                name: supervisor.name.clone(),
                state,
                states: supervisor.states.len(),
            })
            .collect())
    }
}

fn load(run_dir: &Path, controller: &str) -> Result<Loaded, String> {
    let path = compiled_supervisors(run_dir, controller).map_err(|e| e.to_string())?;
    if !path.exists() {
        return Err(format!(
            "{} is missing: controller `{controller}` has no compiled supervisors in this run",
            path.display()
        ));
    }
    let set = SupervisorSet::read(&path).map_err(|e| e.to_string())?;
    let ids = (0..=u8::MAX)
        .zip(&set.events)
        .map(|(id, event)| (event.name.clone(), id))
        .collect();
    Ok(Loaded { set, ids })
}
