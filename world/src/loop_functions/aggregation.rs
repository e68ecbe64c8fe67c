//! Aggregation metrics (docs/tasks.md 1): clusters of robots over time.
//!
//! A cluster is a connected component of live robots whose bodies are at most `gap` apart (default one robot
//! diameter, 0.07 m, so centres at most 0.14 m apart). Every tick the loop functions count the clusters and the
//! size of the largest one, remember the first tick at which the largest cluster holds more than `fraction`
//! (default 0.9) of the live robots, and every `sample_interval` seconds (default 5) add a sample to the series
//! in `summary.json`. docs/tasks.md gives no stop condition: the run ends at the experiment's length or `--ticks`.
//!
//! Configuration: `<loop_functions label="aggregation_loop_functions"><aggregation gap="0.07"
//! sample_interval="5" fraction="0.9"/></loop_functions>` (the child and each attribute are optional).
//! A tick allocates nothing: the scratch buffers grow to the robot count once, and the series is reserved.

use serde::Serialize;
use serde_json::json;
use swarm_contract::messages::ActuatorCommand;

use crate::arena::Arena;
use crate::entities::ROBOT_RADIUS;
use crate::error::WorldError;
use crate::geometry::Vec2;
use crate::loop_functions::{LoopFunctions, LoopFunctionsParams, params::ParamReader};

/// The label under which the configuration selects these loop functions.
pub const LABEL: &str = "aggregation_loop_functions";
/// Default largest body-to-body gap between neighbours of a cluster in metres: one robot diameter, 2 x
/// [`ROBOT_RADIUS`] (docs/tasks.md 1).
pub const DEFAULT_GAP: f64 = 0.07;
/// Default time between two samples of the series, in seconds.
pub const DEFAULT_SAMPLE_INTERVAL: f32 = 5.0;
/// Default fraction of the robots the largest cluster must exceed (docs/tasks.md 1: 0.9).
pub const DEFAULT_FRACTION: f64 = 0.9;
/// Samples the series holds before it would have to grow (one hour at the default interval).
const RESERVED_SAMPLES: usize = 720;

/// The clusters of one moment.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ClusterCount {
    /// Number of clusters (a lone robot is a cluster of one).
    pub clusters: u32,
    /// Size of the largest cluster.
    pub largest: u32,
    /// Robots counted (the live ones).
    pub robots: u32,
}

/// One sample of the series.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sample {
    /// Tick of the sample.
    pub tick: u64,
    /// Simulated time in seconds.
    pub time_s: f64,
    /// Number of clusters.
    pub clusters: u32,
    /// Size of the largest cluster.
    pub largest: u32,
}

/// Reusable buffers of the cluster count: positions, sweep order and a union-find forest.
#[derive(Debug, Clone, Default)]
pub struct ClusterScratch {
    positions: Vec<Vec2>,
    order: Vec<u32>,
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl ClusterScratch {
    fn find(&mut self, mut i: u32) -> u32 {
        while self.parent[i as usize] != i {
            let grandparent = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = grandparent;
            i = grandparent;
        }
        i
    }

    fn union(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a == b {
            return;
        }
        let (big, small) = if self.size[a as usize] >= self.size[b as usize] {
            (a, b)
        } else {
            (b, a)
        };
        self.parent[small as usize] = big;
        self.size[big as usize] += self.size[small as usize];
    }
}

/// Counts the clusters of discs of radius [`ROBOT_RADIUS`] at `positions` whose bodies are at most `gap` apart.
/// Sweeps the discs in x order, so it costs O(n log n) plus the pairs within reach in x; it allocates only when
/// `scratch` is smaller than any earlier input.
pub fn count_clusters(
    positions: impl IntoIterator<Item = Vec2>,
    gap: f32,
    scratch: &mut ClusterScratch,
) -> ClusterCount {
    scratch.positions.clear();
    scratch.positions.extend(positions);
    let n = scratch.positions.len() as u32;
    scratch.order.clear();
    scratch.order.extend(0..n);
    scratch.parent.clear();
    scratch.parent.extend(0..n);
    scratch.size.clear();
    scratch.size.resize(n as usize, 1);
    let reach = 2.0 * ROBOT_RADIUS + gap;
    let positions = std::mem::take(&mut scratch.positions);
    let mut order = std::mem::take(&mut scratch.order);
    order.sort_unstable_by(|&a, &b| positions[a as usize].x.total_cmp(&positions[b as usize].x));
    for (k, &a) in order.iter().enumerate() {
        let pa = positions[a as usize];
        for &b in &order[k + 1..] {
            let pb = positions[b as usize];
            if pb.x - pa.x > reach {
                break;
            }
            if (pb - pa).length() <= reach {
                scratch.union(a, b);
            }
        }
    }
    let mut count = ClusterCount {
        robots: n,
        ..ClusterCount::default()
    };
    for i in 0..n {
        if scratch.parent[i as usize] == i {
            count.clusters += 1;
            count.largest = count.largest.max(scratch.size[i as usize]);
        }
    }
    scratch.positions = positions;
    scratch.order = order;
    count
}

/// Clusters over time.
#[derive(Debug, Clone)]
pub struct Aggregation {
    gap: f64,
    sample_interval_s: f32,
    fraction: f64,
    scratch: ClusterScratch,
    latest: ClusterCount,
    fraction_reached_at: Option<u64>,
    series: Vec<Sample>,
}

impl Aggregation {
    /// Loop functions with the given largest gap (m), sample interval (s) and largest-cluster fraction.
    pub fn new(gap: f64, sample_interval_s: f32, fraction: f64) -> Self {
        Self {
            gap,
            sample_interval_s,
            fraction,
            scratch: ClusterScratch::default(),
            latest: ClusterCount::default(),
            fraction_reached_at: None,
            series: Vec::with_capacity(RESERVED_SAMPLES),
        }
    }

    /// The factory registered under [`LABEL`]: reads the optional `<aggregation gap sample_interval fraction>`.
    pub fn factory(params: &LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError> {
        let reader = ParamReader::new(
            params,
            "aggregation",
            &["gap", "sample_interval", "fraction"],
        )?;
        let gap = reader.non_negative("gap", DEFAULT_GAP)?;
        let interval =
            reader.positive("sample_interval", f64::from(DEFAULT_SAMPLE_INTERVAL))? as f32;
        let fraction = reader.unit("fraction", DEFAULT_FRACTION)?;
        Ok(Box::new(Self::new(gap, interval, fraction)))
    }

    /// The clusters after the last tick.
    pub fn latest(&self) -> ClusterCount {
        self.latest
    }

    /// The first tick at which the largest cluster held more than the fraction of the live robots.
    pub fn fraction_reached_at(&self) -> Option<u64> {
        self.fraction_reached_at
    }

    fn sample_every_ticks(&self, ticks_per_second: u32) -> u64 {
        ((self.sample_interval_s * ticks_per_second as f32).round() as u64).max(1)
    }

    fn record(&mut self, arena: &Arena) {
        let robots = arena.robots.iter().filter(|r| r.alive).map(|r| r.position);
        self.latest = count_clusters(robots, self.gap as f32, &mut self.scratch);
        let ClusterCount {
            clusters,
            largest,
            robots,
        } = self.latest;
        if self.fraction_reached_at.is_none()
            && robots > 0
            && f64::from(largest) > self.fraction * f64::from(robots)
        {
            self.fraction_reached_at = Some(arena.tick);
        }
        if arena
            .tick
            .is_multiple_of(self.sample_every_ticks(arena.ticks_per_second))
        {
            self.series.push(Sample {
                tick: arena.tick,
                time_s: arena.tick as f64 / f64::from(arena.ticks_per_second),
                clusters,
                largest,
            });
        }
    }
}

impl LoopFunctions for Aggregation {
    fn post_step(
        &mut self,
        arena: &mut Arena,
        _commands: &[ActuatorCommand],
        _has_command: &[bool],
    ) {
        self.record(arena);
    }

    fn metrics(&self, arena: &Arena) -> serde_json::Value {
        let ClusterCount {
            clusters,
            largest,
            robots,
        } = self.latest;
        let tps = f64::from(arena.ticks_per_second);
        json!({
            "ticks": arena.tick,
            "robots": robots,
            "gap_m": self.gap,
            "clusters": clusters,
            "largest_cluster": largest,
            "largest_cluster_fraction": if robots > 0 { f64::from(largest) / f64::from(robots) } else { 0.0 },
            "fraction_threshold": self.fraction,
            "fraction_reached_tick": self.fraction_reached_at,
            "fraction_reached_s": self.fraction_reached_at.map(|t| t as f64 / tps),
            "collisions": arena.robots.iter().map(|r| r.collisions).sum::<u64>(),
            "series": self.series,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::devices::Devices;
    use crate::world::WorldBuilder;

    fn count(points: &[(f32, f32)]) -> ClusterCount {
        count_clusters(
            points.iter().map(|&(x, y)| Vec2::new(x, y)),
            DEFAULT_GAP as f32,
            &mut ClusterScratch::default(),
        )
    }

    #[test]
    fn three_robots_in_a_row_0_12_m_apart_form_one_cluster_of_3() {
        // Centres 0.12 m apart: bodies 0.05 m apart, less than one diameter (0.07 m).
        let c = count(&[(0.0, 0.0), (0.12, 0.0), (0.24, 0.0)]);
        assert_eq!(
            c,
            ClusterCount {
                clusters: 1,
                largest: 3,
                robots: 3
            }
        );
    }

    #[test]
    fn default_gap_is_one_robot_diameter() {
        assert!((DEFAULT_GAP - 2.0 * f64::from(ROBOT_RADIUS)).abs() < 1e-6);
    }

    #[test]
    fn bodies_exactly_one_diameter_apart_are_linked() {
        // Centres 0.14 m apart: the bodies are 0.07 m apart, the limit.
        assert_eq!(count(&[(0.0, 0.0), (0.0, 0.14)]).clusters, 1);
    }

    #[test]
    fn bodies_more_than_one_diameter_apart_are_separate_clusters() {
        let c = count(&[(0.0, 0.0), (0.15, 0.0), (0.30, 0.0)]);
        assert_eq!((c.clusters, c.largest), (3, 1));
    }

    #[test]
    fn chain_links_robots_farther_apart_than_the_gap() {
        // The ends are 0.26 m apart but linked through the middle robot.
        let c = count(&[(0.0, 0.0), (0.13, 0.0), (0.26, 0.0), (1.0, 1.0), (1.0, 1.1)]);
        assert_eq!((c.clusters, c.largest), (2, 3));
    }

    #[test]
    fn neighbours_close_in_x_but_far_in_y_are_not_linked() {
        let c = count(&[(0.0, 0.0), (0.01, 0.5), (0.02, 1.0)]);
        assert_eq!((c.clusters, c.largest), (3, 1));
    }

    #[test]
    fn no_robots_means_no_clusters() {
        assert_eq!(count(&[]), ClusterCount::default());
    }

    fn world_with(points: &[(f32, f32)], lf: Aggregation) -> crate::world::World {
        let mut b = WorldBuilder::new(Vec2::new(-2.0, -2.0), Vec2::new(2.0, 2.0), 10, 1);
        for (i, &(x, y)) in points.iter().enumerate() {
            b.robot(
                &format!("r{i}"),
                "c",
                Vec2::new(x, y),
                0.0,
                Devices::PROXIMITY_ONLY,
            );
        }
        b.loop_functions(Box::new(lf));
        b.build()
    }

    #[test]
    fn metrics_report_clusters_largest_and_the_90_percent_tick() {
        // Two still robots 0.12 m apart and one far away: 2 clusters, largest 2 of 3 (0.67 > 0.5).
        let mut world = world_with(
            &[(0.0, 0.0), (0.12, 0.0), (1.5, 1.5)],
            Aggregation::new(DEFAULT_GAP, 1.0, 0.5),
        );
        world.run_in_process(20, |_, c| c.wheels = [0.0, 0.0]);
        let m = world.metrics();
        assert_eq!(m["clusters"], 2);
        assert_eq!(m["largest_cluster"], 2);
        assert_eq!(m["robots"], 3);
        assert_eq!(m["fraction_reached_tick"], 1);
        let series = m["series"].as_array().unwrap();
        assert_eq!(
            series.len(),
            2,
            "one sample per simulated second: ticks 10 and 20"
        );
        assert_eq!(series[1]["tick"], 20);
        assert_eq!(series[1]["clusters"], 2);
    }

    #[test]
    fn fraction_never_reached_is_null() {
        let mut world = world_with(
            &[(0.0, 0.0), (1.0, 0.0)],
            Aggregation::new(DEFAULT_GAP, 1.0, 0.9),
        );
        world.run_in_process(5, |_, c| c.wheels = [0.0, 0.0]);
        assert!(world.metrics()["fraction_reached_tick"].is_null());
    }

    #[test]
    fn dead_robots_are_not_counted() {
        let mut world = world_with(
            &[(0.0, 0.0), (0.12, 0.0), (1.5, 1.5)],
            Aggregation::new(DEFAULT_GAP, 1.0, 0.9),
        );
        world.set_alive(crate::entities::RobotId(2), false);
        world.run_in_process(1, |_, c| c.wheels = [0.0, 0.0]);
        let m = world.metrics();
        assert_eq!(
            (m["clusters"].as_u64(), m["robots"].as_u64()),
            (Some(1), Some(2))
        );
        assert_eq!(m["fraction_reached_tick"], 1);
    }

    fn params(attrs: &[(&str, &str)]) -> LoopFunctionsParams {
        LoopFunctionsParams {
            label: LABEL.to_owned(),
            location: "exp.argos:12:3".to_owned(),
            attributes: attrs
                .iter()
                .map(|&(k, v)| (k.to_owned(), v.to_owned()))
                .collect(),
            ..LoopFunctionsParams::default()
        }
    }

    #[test]
    fn negative_gap_is_rejected_with_its_location() {
        let err = Aggregation::factory(&params(&[("aggregation.gap", "-0.1")]))
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            "exp.argos:12:3: <aggregation gap=\"-0.1\">: must be a number >= 0"
        );
    }

    #[test]
    fn unknown_attribute_is_rejected_with_the_known_ones() {
        let err = Aggregation::factory(&params(&[("aggregation.gapp", "0.1")]))
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            "exp.argos:12:3: <aggregation> has no attribute 'gapp' (known: gap, sample_interval, fraction)"
        );
    }
}
