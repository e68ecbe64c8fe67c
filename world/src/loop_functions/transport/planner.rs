//! The global planner as the task server runs it for a `PathRequest`: a tree plan (ORT or RRT) of the box's centre
//! from where it is to the goal, on the formation's map, with its own random stream; and the plan as path chunks.

use std::time::Instant;

use swarm_navigation::V2;
use swarm_navigation::planning::Map;
use swarm_navigation::planning::tree::{TreeError, plan};
use swarm_navigation::wire::PAYLOAD;
use swarm_navigation::wire::transport::encode_path;

use super::config::Settings;
use crate::rng::{Purpose, stream};

/// One plan and what it took.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Plan {
    /// Its number: 1 for the run's first plan.
    pub number: u32,
    /// The box centre's way to the goal; empty when planning failed.
    pub path: Vec<V2>,
    /// The path's length (m), for a plan that found one.
    pub length: Option<f32>,
    /// Points in the tree (a failed plan's too, when it grew one).
    pub nodes: Option<usize>,
    /// Wall time in microseconds (machine-dependent).
    pub micros: u64,
}

impl Plan {
    /// Plan number `number` from `start` to the goal of `settings` on `map`, drawing from the run `seed`'s
    /// loop-functions stream of that number: a function of the seed, the number and the inputs. The start is moved
    /// into the map's bounds if it lies outside (a box nearer the arena's edge than the formation's radius), and an
    /// obstacle that holds it is shrunk to leave it on its edge ([`Map::opened_at`]), so a box that starts close to
    /// an obstacle can be carried away from it. A path of more points than a chunk can number counts as failed.
    pub fn make(settings: &Settings, map: &Map, start: V2, seed: u64, number: u32) -> Plan {
        let began = Instant::now();
        let from = if map.bounds.is_valid() {
            map.bounds.clamp(start)
        } else {
            start
        };
        let mut rng = stream(seed, Purpose::LoopFunctions, number);
        let result = plan(
            settings.tree,
            from,
            settings.goal,
            &map.opened_at(from),
            &settings.params,
            &mut rng,
        );
        let micros = u64::try_from(began.elapsed().as_micros()).unwrap_or(u64::MAX);
        let failed = |nodes| Plan {
            number,
            path: Vec::new(),
            length: None,
            nodes,
            micros,
        };
        match result {
            Ok(found) if found.path.len() <= usize::from(u16::MAX) => Plan {
                number,
                path: found.path,
                length: Some(found.length),
                nodes: Some(found.nodes),
                micros,
            },
            Ok(found) => failed(Some(found.nodes)),
            Err(TreeError::NoPath { nodes, .. }) => failed(Some(nodes)),
            Err(_) => failed(None),
        }
    }

    /// The payloads of the path's chunks, in order; a failed plan's path is one chunk of no points.
    pub fn chunks(&self) -> Vec<Vec<u8>> {
        let mut payload = [0u8; PAYLOAD];
        let mut chunks = Vec::new();
        let mut first = 0;
        loop {
            let (len, next) = encode_path(self.number, &self.path, first, &mut payload);
            chunks.push(payload[..len].to_vec());
            if next >= self.path.len() {
                return chunks;
            }
            first = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use swarm_navigation::planning::Bounds;

    use super::*;
    use crate::loop_functions::LoopFunctionsParams;

    #[test]
    fn a_path_of_more_points_than_a_chunk_can_number_counts_as_failed() {
        let attributes = [("object", "crate"), ("goal", "9,5,0"), ("step", "0.0001")]
            .iter()
            .map(|&(k, v)| (format!("transport.{k}"), v.to_owned()))
            .collect();
        let params = LoopFunctionsParams {
            attributes,
            ..LoopFunctionsParams::default()
        };
        let mut settings = Settings::read(&params).unwrap();
        let map = Map {
            bounds: Bounds {
                min: V2::ZERO,
                max: V2::new(10.0, 10.0),
            },
            discs: Vec::new(),
        };
        // 8 m in steps of 0.1 mm: 80,001 points.
        let plan = Plan::make(&settings, &map, V2::new(1.0, 5.0), 1, 1);
        assert_eq!(
            (plan.path.len(), plan.length, plan.nodes),
            (0, None, Some(80_001))
        );
        assert_eq!(plan.chunks().len(), 1);
        settings.params.step = 0.2;
        let plan = Plan::make(&settings, &map, V2::new(1.0, 5.0), 1, 1);
        assert_eq!((plan.path.len(), plan.nodes), (41, Some(41)));
        assert_eq!(plan.chunks().len(), 2);
    }
}
