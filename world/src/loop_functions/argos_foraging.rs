//! The loop functions of ARGoS' foot-bot foraging example, written from their documented behaviour: food items
//! are black spots on a white floor, the nest is the grey strip `x < -1`, and a robot carries an item from the
//! moment it drives over one until it reaches the nest.
//!
//! Selected by `<loop_functions label="foraging_loop_functions">` with a child `<foraging items radius
//! energy_per_item energy_per_walking_robot output/>` (the thesis' foraging task, under the same label, has no
//! `items`). After each tick (where ARGoS does it before the next one, which sees the same state):
//!
//! - a robot with an item inside the nest delivers it: the item reappears at a new uniform place in
//!   x in [-0.9, 1.7], y in [-1.7, 1.7], and the swarm gains `energy_per_item`;
//! - a robot without one, outside the nest and within `radius` of an item, takes it (the spot disappears);
//! - every walking robot costs `energy_per_walking_robot`.
//!
//! A robot resting in the nest is one whose LEDs are red (the example controller shows red exactly while it
//! rests; ARGoS' loop functions ask the controller instead, which a process boundary does not allow). Each tick
//! appends `clock walking resting collected_food energy` to the `output` file, which is written in the run
//! folder rather than the working folder, so that runs never overwrite each other's.

use std::io::Write;

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use swarm_contract::messages::{ActuatorCommand, Rgb};

use crate::arena::Arena;
use crate::error::WorldError;
use crate::geometry::Vec2;
use crate::loop_functions::params::ParamReader;
use crate::loop_functions::{LoopFunctions, LoopFunctionsParams};
use crate::rng::{Purpose, stream};

/// What a robot shows while it rests.
const RESTING_LED: Rgb = Rgb { r: 255, g: 0, b: 0 };
/// The nest: everything left of this x.
const NEST_X: f32 = -1.0;
/// Where items appear: x range.
const ITEMS_X: (f32, f32) = (-0.9, 1.7);
/// Where items appear: y range.
const ITEMS_Y: (f32, f32) = (-1.7, 1.7);
/// Where a taken item is parked, far outside any arena.
const TAKEN: Vec2 = Vec2::new(100.0, 100.0);
/// The nest's grey (ARGoS' 50 % grey, 127 of 255).
const NEST_GREY: f32 = 127.0 / 255.0;

/// The example's loop functions.
pub struct ArgosForaging {
    items: Vec<Vec2>,
    radius_squared: f32,
    energy_per_item: i64,
    energy_per_walking_robot: i64,
    output_name: String,
    output: Vec<u8>,
    rng: ChaCha8Rng,
    /// The item each robot carries, by robot index.
    carried: Vec<Option<usize>>,
    collected: u64,
    energy: i64,
    walking: u64,
    resting: u64,
}

impl ArgosForaging {
    /// Whether `params` are the example's (`<foraging items=...>`) rather than the thesis task's.
    pub fn applies_to(params: &LoopFunctionsParams) -> bool {
        params.attributes.contains_key("foraging.items")
    }

    /// Builds the loop functions from `<foraging items radius energy_per_item energy_per_walking_robot output>`,
    /// all required as in ARGoS.
    pub fn factory(params: &LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError> {
        let reader = ParamReader::new(
            params,
            "foraging",
            &[
                "items",
                "radius",
                "energy_per_item",
                "energy_per_walking_robot",
                "output",
            ],
        )?;
        let required = |name: &str| {
            params
                .attributes
                .get(&format!("foraging.{name}"))
                .ok_or_else(|| WorldError::Invalid {
                    location: params.location.clone(),
                    message: format!("<foraging> needs the attribute '{name}'"),
                })
        };
        for name in [
            "items",
            "radius",
            "energy_per_item",
            "energy_per_walking_robot",
        ] {
            required(name)?;
        }
        let items = reader.u64_at_least("items", 0, 0)?;
        if items > 10_000 {
            return Err(WorldError::Invalid {
                location: params.location.clone(),
                message: format!("<foraging items=\"{items}\"> is more than 10000 items"),
            });
        }
        let radius = reader.positive("radius", 0.1)? as f32;
        let energy_per_item = reader.u64_at_least("energy_per_item", 0, 0)? as i64;
        let energy_per_walking_robot =
            reader.u64_at_least("energy_per_walking_robot", 0, 0)? as i64;
        let output_name = required("output")?.clone();
        if output_name.is_empty()
            || output_name.contains(['/', '\\'])
            || output_name == "."
            || output_name == ".."
        {
            return Err(WorldError::Invalid {
                location: params.location.clone(),
                message: format!(
                    "<foraging output=\"{output_name}\"> must be a plain file name: it is written in the run folder"
                ),
            });
        }
        let mut rng = stream(params.seed, Purpose::LoopFunctions, 0);
        let items = (0..items).map(|_| random_place(&mut rng)).collect();
        let mut output = Vec::new();
        output.extend_from_slice(b"# clock\twalking\tresting\tcollected_food\tenergy\n");
        Ok(Box::new(Self {
            items,
            radius_squared: radius * radius,
            energy_per_item,
            energy_per_walking_robot,
            output_name,
            output,
            rng,
            carried: Vec::new(),
            collected: 0,
            energy: 0,
            walking: 0,
            resting: 0,
        }))
    }
}

fn random_place(rng: &mut ChaCha8Rng) -> Vec2 {
    Vec2::new(
        rng.random_range(ITEMS_X.0..ITEMS_X.1),
        rng.random_range(ITEMS_Y.0..ITEMS_Y.1),
    )
}

impl LoopFunctions for ArgosForaging {
    fn post_step(
        &mut self,
        arena: &mut Arena,
        _commands: &[ActuatorCommand],
        _has_command: &[bool],
    ) {
        self.carried.resize(arena.robots.len(), None);
        let (mut walking, mut resting) = (0u64, 0u64);
        for (robot, carried) in arena.robots.iter_mut().zip(self.carried.iter_mut()) {
            if robot.led == RESTING_LED {
                resting += 1;
            } else {
                walking += 1;
            }
            let p = robot.position;
            match *carried {
                Some(item) if p.x < NEST_X => {
                    self.items[item] = random_place(&mut self.rng);
                    *carried = None;
                    self.collected += 1;
                    self.energy += self.energy_per_item;
                }
                None if p.x > NEST_X => {
                    if let Some(item) = self
                        .items
                        .iter()
                        .position(|&f| (p - f).length_squared() < self.radius_squared)
                    {
                        self.items[item] = TAKEN;
                        *carried = Some(item);
                    }
                }
                _ => {}
            }
            robot.holds_item = carried.is_some();
        }
        self.energy -= walking as i64 * self.energy_per_walking_robot;
        (self.walking, self.resting) = (walking, resting);
        // Writing into a Vec cannot fail.
        let _ = writeln!(
            self.output,
            "{}\t{walking}\t{resting}\t{}\t{}",
            arena.tick, self.collected, self.energy
        );
    }

    fn floor_color(&self, p: Vec2) -> Option<f32> {
        if p.x < NEST_X {
            return Some(NEST_GREY);
        }
        let on_item = self
            .items
            .iter()
            .any(|&f| (p - f).length_squared() < self.radius_squared);
        Some(if on_item { 0.0 } else { 1.0 })
    }

    fn output_name(&self) -> Option<&str> {
        Some(&self.output_name)
    }

    fn drain_output(&mut self, out: &mut Vec<u8>) {
        out.append(&mut self.output);
    }

    fn metrics(&self, _arena: &Arena) -> serde_json::Value {
        serde_json::json!({
            "collected_food": self.collected,
            "energy": self.energy,
            "walking": self.walking,
            "resting": self.resting,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(extra: &[(&str, &str)]) -> LoopFunctionsParams {
        let mut attributes: std::collections::BTreeMap<String, String> = [
            ("foraging.items", "15"),
            ("foraging.radius", "0.1"),
            ("foraging.energy_per_item", "1000"),
            ("foraging.energy_per_walking_robot", "1"),
            ("foraging.output", "foraging.txt"),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v.to_owned()))
        .collect();
        for (k, v) in extra {
            attributes.insert((*k).to_owned(), (*v).to_owned());
        }
        LoopFunctionsParams {
            label: "foraging_loop_functions".into(),
            location: "x.argos:3:5".into(),
            attributes,
            children: vec!["foraging".into()],
            seed: 5,
        }
    }

    #[test]
    fn the_nest_is_grey_items_are_black_and_the_rest_is_white() {
        let lf = ArgosForaging::factory(&params(&[])).expect("builds");
        assert_eq!(lf.floor_color(Vec2::new(-1.5, 0.0)), Some(NEST_GREY));
        assert_eq!(lf.output_name(), Some("foraging.txt"));
        let greys: Vec<f32> = (0..200)
            .flat_map(|i| (0..200).map(move |j| (i, j)))
            .filter_map(|(i, j)| {
                lf.floor_color(Vec2::new(-0.9 + 0.013 * i as f32, -1.7 + 0.017 * j as f32))
            })
            .collect();
        assert!(greys.contains(&0.0) && greys.contains(&1.0));
    }

    #[test]
    fn an_output_path_that_leaves_the_run_folder_is_refused() {
        for bad in ["../foraging.txt", "/tmp/x", "", ".."] {
            let Err(e) = ArgosForaging::factory(&params(&[("foraging.output", bad)])) else {
                panic!("{bad:?} was accepted");
            };
            assert!(e.to_string().contains("plain file name"), "{e}");
        }
    }

    #[test]
    fn a_missing_attribute_is_named() {
        let mut p = params(&[]);
        p.attributes.remove("foraging.radius");
        let Err(e) = ArgosForaging::factory(&p) else {
            panic!("accepted without radius");
        };
        assert!(e.to_string().contains("'radius'"), "{e}");
    }
}
