//! What the navigation judge measures for path planners (paper D, docs/planning.md): the reference optimum of
//! each trip (Theta* on the whole map, and on the map the robot was given), and the statistics a planning robot
//! reports to the world (`wire::PlanReport`).

use serde_json::{Map as JsonMap, Value, json};
use swarm_navigation::V2;
use swarm_navigation::apf::Disc;
use swarm_navigation::planning::theta_star::{SearchError, shortest_length};
use swarm_navigation::planning::{Bounds, Map};
use swarm_navigation::wire::PlanReport;

/// Grid of the reference search (m).
pub const REFERENCE_RESOLUTION: f32 = 0.05;

/// The reference search from `start` to `goal` for a robot of `radius` among `discs` in `bounds`: the length of
/// the shortest way, or why there is none (`SearchError::Unreachable` for a goal walled off; other errors when the
/// search cannot tell, e.g. a map too large for its grid).
pub fn reference(
    start: V2,
    goal: V2,
    discs: &[Disc],
    bounds: Bounds,
    radius: f32,
) -> Result<f32, SearchError> {
    let map = Map::for_body(bounds, discs, radius, 0.0);
    shortest_length(map.bounds.clamp(start), goal, &map, REFERENCE_RESOLUTION)
}

/// One finished trip's planning figures.
#[derive(Debug, Clone, Copy, Default)]
pub struct TripFigures {
    /// Reference optimum on the whole map, to the edge of the goal's tolerance.
    pub optimum: Option<f32>,
    /// Reference optimum on the map the robot was given.
    pub known_optimum: Option<f32>,
    /// Path driven.
    pub driven: f64,
    /// The robot's last statistics for this trip.
    pub report: Option<PlanReport>,
}

/// The run's totals over finished trips.
#[derive(Debug, Clone, Default)]
pub struct Totals {
    path_ratios: Vec<f64>,
    planned_ratios: Vec<f64>,
    followed_ratios: Vec<f64>,
    plans: u64,
    failed: u64,
    replans: u64,
    collision_free: u64,
    agents: u64,
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

impl Totals {
    /// Counts a finished trip in.
    pub fn add(&mut self, trip: &TripFigures) {
        if let Some(optimum) = trip.optimum.filter(|o| *o > 0.0) {
            self.path_ratios.push(trip.driven / f64::from(optimum));
        }
        let Some(report) = trip.report else {
            return;
        };
        self.plans += u64::from(report.plans);
        self.failed += u64::from(report.failed);
        self.replans += u64::from(report.replans);
        self.collision_free += u64::from(report.collision_free);
        self.agents += u64::from(report.agents);
        if let Some(optimum) = trip.known_optimum.filter(|o| *o > 0.0)
            && report.first_planned > 0.0
        {
            self.planned_ratios
                .push(f64::from(report.first_planned / optimum));
            self.followed_ratios
                .push(f64::from(report.first_followed / optimum));
        }
    }

    /// The metrics: always the path ratio; the planner's figures once a robot reported any.
    pub fn metrics(&self, out: &mut JsonMap<String, Value>) {
        out.insert("mean_path_ratio".into(), json!(mean(&self.path_ratios)));
        if self.plans == 0 {
            return;
        }
        out.insert("plans".into(), json!(self.plans));
        out.insert("failed_plans".into(), json!(self.failed));
        out.insert("replans".into(), json!(self.replans));
        out.insert(
            "collision_free_fraction".into(),
            json!((self.agents > 0).then(|| self.collision_free as f64 / self.agents as f64)),
        );
        out.insert(
            "mean_planned_ratio".into(),
            json!(mean(&self.planned_ratios)),
        );
        out.insert(
            "mean_followed_ratio".into(),
            json!(mean(&self.followed_ratios)),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_optimum_goes_round_what_blocks_the_straight_line() {
        let bounds = Bounds {
            min: V2::ZERO,
            max: V2::new(10.0, 10.0),
        };
        let free = reference(V2::new(1.0, 5.0), V2::new(9.0, 5.0), &[], bounds, 0.1).unwrap();
        assert!((free - 8.0).abs() < 1e-4);
        let disc = Disc {
            centre: V2::new(5.0, 5.0),
            radius: 0.9,
        };
        let round = reference(V2::new(1.0, 5.0), V2::new(9.0, 5.0), &[disc], bounds, 0.1).unwrap();
        assert!(round > 8.2 && round < 8.6, "{round}");
        // A ring of discs round the goal.
        let ring: Vec<Disc> = (0..8)
            .map(|k| Disc {
                centre: V2::new(5.0, 5.0)
                    + V2::from_angle(k as f32 * std::f32::consts::FRAC_PI_4) * 0.55,
                radius: 0.3,
            })
            .collect();
        assert_eq!(
            reference(V2::new(1.0, 5.0), V2::new(5.0, 5.0), &ring, bounds, 0.1),
            Err(SearchError::Unreachable)
        );
    }

    #[test]
    fn totals_count_reports_and_ratios() {
        let mut totals = Totals::default();
        totals.add(&TripFigures {
            optimum: Some(4.0),
            known_optimum: Some(4.0),
            driven: 5.0,
            report: Some(PlanReport {
                seq: 1,
                plans: 3,
                failed: 1,
                replans: 1,
                collision_free: 30,
                agents: 150,
                first_planned: 8.0,
                first_followed: 4.4,
            }),
        });
        let mut out = JsonMap::new();
        totals.metrics(&mut out);
        assert_eq!(out["mean_path_ratio"], json!(1.25));
        assert_eq!(out["replans"], json!(1));
        assert_eq!(out["collision_free_fraction"], json!(0.2));
        assert_eq!(out["mean_planned_ratio"], json!(2.0));
    }
}
