//! Tree planners for a carried object's path (paper B, B.3): ORT, the "optimally-connected random tree", and
//! the RRT baseline in the same code path. Both grow a tree of points of the plane from the start in steps of
//! gamma, on a map whose obstacles are already grown by the formation's size, and return a path of points at
//! most gamma apart.
//!
//! ORT samples in the target influence region (a circle of `k` gamma round the goal, `k` random in 1..=t_lb, with
//! t_lb growing with the tree's depth), falls back to a uniform sample after `f` failed extensions, and connects
//! each new point to the first ancestor of its nearest node, counted from the root, that sees it: branches stay
//! straight, so the path needs no smoothing. RRT samples uniformly and connects to the nearest node. Both stop
//! when the goal is in sight (ORT from the newest point, RRT from a point within `reach` of it) and walk the
//! last stretch straight.

use rand::Rng;

use super::map::{EndpointError, Map, path_length};
use crate::V2;

/// Which tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tree {
    /// Optimally-connected random tree.
    Ort,
    /// Rapidly-exploring random tree.
    Rrt,
}

/// The planners' parameters. Defaults: docs/planning.md.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TreeParams {
    /// Step gamma between consecutive points (m).
    pub step: f32,
    /// ORT: failed target-region extensions before a uniform sample (f).
    pub failures: u32,
    /// Most samples drawn before giving up.
    pub iterations: u32,
    /// RRT: the goal is joined once it is in sight from a point at most this far from it (m).
    pub reach: f32,
}

impl Default for TreeParams {
    fn default() -> Self {
        TreeParams {
            step: 0.2,
            failures: 5,
            iterations: 20_000,
            reach: 1.0,
        }
    }
}

/// Why there is no path.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum TreeError {
    /// A parameter is out of its range.
    #[error("tree planner parameter {name}: {rule}")]
    Params {
        /// The parameter.
        name: &'static str,
        /// What it must be.
        rule: &'static str,
    },
    /// The start or the goal is not a place to plan between.
    #[error(transparent)]
    Endpoints(#[from] EndpointError),
    /// The start lies inside an obstacle (grown by the formation).
    #[error("the start lies inside an obstacle")]
    StartBlocked,
    /// The tree did not reach the goal within the sample budget.
    #[error("no path after {iterations} samples ({nodes} tree nodes)")]
    NoPath {
        /// Samples drawn.
        iterations: u32,
        /// Points in the tree.
        nodes: usize,
    },
}

/// A path and what it took to find it.
#[derive(Debug, Clone, PartialEq)]
pub struct TreePlan {
    /// From the start to the goal, consecutive points at most one step apart.
    pub path: Vec<V2>,
    /// Its length (m).
    pub length: f32,
    /// Points in the tree when the goal was joined (the path's own included).
    pub nodes: usize,
    /// Samples drawn.
    pub iterations: u32,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    at: V2,
    parent: u32,
    /// Steps from the root.
    depth: u32,
}

struct Growth<'a> {
    map: &'a Map,
    step: f32,
    nodes: Vec<Node>,
}

impl Growth<'_> {
    fn nearest(&self, p: V2) -> usize {
        let distance = |n: &Node| {
            let d = n.at - p;
            d.dot(d)
        };
        (0..self.nodes.len())
            .min_by(|&a, &b| distance(&self.nodes[a]).total_cmp(&distance(&self.nodes[b])))
            .unwrap_or(0)
    }

    /// `from` moved one step towards `towards`, if that step is free.
    fn extend(&self, from: usize, towards: V2) -> Option<V2> {
        let origin = self.nodes[from].at;
        let d = towards - origin;
        let length = d.length();
        if length < 1e-6 {
            return None;
        }
        let next = origin + d * (self.step.min(length) / length);
        self.map.segment_free(origin, next).then_some(next)
    }

    /// Adds points every step along the free segment from node `from` to `to` (which is added last); returns the
    /// index of `to`'s node.
    fn connect(&mut self, from: usize, to: V2) -> usize {
        let origin = self.nodes[from].at;
        let pieces = ((to - origin).length() / self.step).ceil().max(1.0) as u32;
        let mut parent = from;
        for k in 1..=pieces {
            let at = if k == pieces {
                to
            } else {
                origin + (to - origin) * (k as f32 / pieces as f32)
            };
            let depth = self.nodes[parent].depth + 1;
            self.nodes.push(Node {
                at,
                parent: parent as u32,
                depth,
            });
            parent = self.nodes.len() - 1;
        }
        parent
    }

    /// The first node on the chain from the root to `near` that sees `p`.
    fn first_ancestor_in_sight(&self, near: usize, p: V2) -> usize {
        let mut chain = vec![near];
        let mut at = near;
        while at != 0 {
            at = self.nodes[at].parent as usize;
            chain.push(at);
        }
        chain
            .into_iter()
            .rev()
            .find(|&n| self.map.segment_free(self.nodes[n].at, p))
            .unwrap_or(near)
    }

    fn path_to(&self, end: usize) -> Vec<V2> {
        let mut path = vec![self.nodes[end].at];
        let mut at = end;
        while at != 0 {
            at = self.nodes[at].parent as usize;
            path.push(self.nodes[at].at);
        }
        path.reverse();
        path
    }
}

fn uniform(map: &Map, rng: &mut impl Rng) -> V2 {
    let (lo, hi) = (map.bounds.min, map.bounds.max);
    V2::new(rng.random_range(lo.x..=hi.x), rng.random_range(lo.y..=hi.y))
}

fn check(params: &TreeParams) -> Result<(), TreeError> {
    let rule = |ok: bool, name, rule| {
        if ok {
            Ok(())
        } else {
            Err(TreeError::Params { name, rule })
        }
    };
    rule(
        params.step.is_finite() && params.step > 0.0,
        "step",
        "must be > 0",
    )?;
    rule(params.failures >= 1, "failures", "must be >= 1")?;
    rule(
        (1..=1_000_000).contains(&params.iterations),
        "iterations",
        "must be 1 to 1000000",
    )?;
    rule(
        params.reach.is_finite() && params.reach > 0.0,
        "reach",
        "must be > 0",
    )
}

/// Plans the object's path from `start` to `goal` on `map` (obstacles grown by the formation, box shrunk by it)
/// with `tree`. A pure function of its inputs and `rng`'s state.
pub fn plan(
    tree: Tree,
    start: V2,
    goal: V2,
    map: &Map,
    params: &TreeParams,
    rng: &mut impl Rng,
) -> Result<TreePlan, TreeError> {
    check(params)?;
    map.check_endpoints(start, goal)?;
    if map.inside_obstacle(start) {
        return Err(TreeError::StartBlocked);
    }
    let mut g = Growth {
        map,
        step: params.step,
        nodes: vec![Node {
            at: start,
            parent: 0,
            depth: 0,
        }],
    };
    let finish = |g: &mut Growth<'_>, from: usize, iterations| {
        let end = if g.nodes[from].at == goal {
            from
        } else {
            g.connect(from, goal)
        };
        let path = g.path_to(end);
        Ok(TreePlan {
            length: path_length(&path),
            path,
            nodes: g.nodes.len(),
            iterations,
        })
    };
    if map.segment_free(start, goal) {
        return finish(&mut g, 0, 0);
    }
    let (mut t_lb, mut failures, mut last) = (1u32, 0u32, 0usize);
    for iteration in 1..=params.iterations {
        let (near, new) = match tree {
            Tree::Ort => {
                if t_lb < g.nodes[last].depth {
                    t_lb += 1;
                }
                let k = rng.random_range(1..=t_lb) as f32;
                let angle = rng.random_range(0.0..std::f32::consts::TAU);
                let target = map
                    .bounds
                    .clamp(goal + V2::from_angle(angle) * (k * params.step));
                let near = g.nearest(target);
                match g.extend(near, target) {
                    Some(new) => (near, new),
                    None => {
                        failures += 1;
                        if failures < params.failures {
                            continue;
                        }
                        failures = 0;
                        let target = uniform(map, rng);
                        let near = g.nearest(target);
                        let Some(new) = g.extend(near, target) else {
                            continue;
                        };
                        (near, new)
                    }
                }
            }
            Tree::Rrt => {
                let target = uniform(map, rng);
                let near = g.nearest(target);
                let Some(new) = g.extend(near, target) else {
                    continue;
                };
                (near, new)
            }
        };
        let from = match tree {
            Tree::Ort => g.first_ancestor_in_sight(near, new),
            Tree::Rrt => near,
        };
        last = g.connect(from, new);
        let in_sight = map.segment_free(new, goal);
        let joins = match tree {
            Tree::Ort => in_sight,
            Tree::Rrt => in_sight && (goal - new).length() <= params.reach,
        };
        if joins {
            return finish(&mut g, last, iteration);
        }
    }
    Err(TreeError::NoPath {
        iterations: params.iterations,
        nodes: g.nodes.len(),
    })
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;

    fn run(tree: Tree, map: &Map, start: V2, goal: V2, seed: u64) -> Result<TreePlan, TreeError> {
        plan(
            tree,
            start,
            goal,
            map,
            &TreeParams::default(),
            &mut ChaCha8Rng::seed_from_u64(seed),
        )
    }

    fn steps_within_gamma(path: &[V2]) -> bool {
        path.windows(2)
            .all(|w| (w[1] - w[0]).length() <= 0.2 + 1e-4)
    }

    #[test]
    fn in_sight_the_path_is_the_straight_line_in_steps() {
        let map = Map::square_with(&[(5.0, 8.0, 1.0)]);
        let (start, goal) = (V2::new(1.0, 1.0), V2::new(4.0, 5.0));
        for tree in [Tree::Ort, Tree::Rrt] {
            let plan = run(tree, &map, start, goal, 1).unwrap();
            assert_eq!(plan.path.len(), 26, "5 m in steps of 0.2 m");
            assert!((plan.length - 5.0).abs() < 1e-4);
            assert!(steps_within_gamma(&plan.path));
            assert_eq!(plan.iterations, 0);
        }
    }

    #[test]
    fn round_a_wall_ort_paths_are_shorter_than_rrt_paths_with_more_nodes() {
        // A wall of discs across the middle with a gap near one end.
        let wall: Vec<(f32, f32, f32)> = (0..8).map(|k| (1.0 + k as f32, 5.0, 0.55)).collect();
        let map = Map::square_with(&wall);
        let (start, goal) = (V2::new(3.0, 1.5), V2::new(3.0, 8.5));
        let (mut ort, mut rrt) = (Vec::new(), Vec::new());
        for seed in 0..10 {
            for (tree, out) in [(Tree::Ort, &mut ort), (Tree::Rrt, &mut rrt)] {
                let plan = run(tree, &map, start, goal, seed).unwrap();
                assert_eq!(
                    map.first_blocked_segment(&plan.path),
                    None,
                    "{tree:?} {seed}"
                );
                assert!(steps_within_gamma(&plan.path), "{tree:?} {seed}");
                assert_eq!((plan.path[0], *plan.path.last().unwrap()), (start, goal));
                out.push((plan.length, plan.nodes));
            }
        }
        let median = |v: &mut Vec<f32>| {
            v.sort_by(f32::total_cmp);
            v[v.len() / 2]
        };
        let ort_length = median(&mut ort.iter().map(|p| p.0).collect());
        let rrt_length = median(&mut rrt.iter().map(|p| p.0).collect());
        let ort_nodes = median(&mut ort.iter().map(|p| p.1 as f32).collect());
        let rrt_nodes = median(&mut rrt.iter().map(|p| p.1 as f32).collect());
        // Measured: ORT 8.96 m (the way round the wall's near end) with 2,778 nodes, RRT 17.8 m with 660.
        assert!(
            ort_length < rrt_length && ort_nodes > rrt_nodes,
            "ORT {ort_length} m, {ort_nodes} nodes against RRT {rrt_length} m, {rrt_nodes} nodes"
        );
    }

    #[test]
    fn a_walled_in_goal_exhausts_the_budget_and_bad_inputs_are_errors() {
        let ring: Vec<(f32, f32, f32)> = (0..12)
            .map(|k| {
                let a = k as f32 * std::f32::consts::PI / 6.0;
                (5.0 + 2.0 * a.cos(), 5.0 + 2.0 * a.sin(), 0.6)
            })
            .collect();
        let map = Map::square_with(&ring);
        let params = TreeParams {
            iterations: 500,
            ..TreeParams::default()
        };
        for tree in [Tree::Ort, Tree::Rrt] {
            let result = plan(
                tree,
                V2::new(1.0, 1.0),
                V2::new(5.0, 5.0),
                &map,
                &params,
                &mut ChaCha8Rng::seed_from_u64(1),
            );
            assert!(
                matches!(
                    result,
                    Err(TreeError::NoPath {
                        iterations: 500,
                        ..
                    })
                ),
                "{result:?}"
            );
        }
        assert_eq!(
            run(Tree::Ort, &map, V2::new(1.0, 1.0), V2::new(7.0, 5.0), 1),
            Err(TreeError::Endpoints(EndpointError::GoalBlocked))
        );
        assert_eq!(
            run(Tree::Ort, &map, V2::new(7.0, 5.0), V2::new(1.0, 1.0), 1),
            Err(TreeError::StartBlocked)
        );
        let bad = TreeParams {
            step: 0.0,
            ..TreeParams::default()
        };
        assert!(matches!(
            plan(
                Tree::Rrt,
                V2::new(1.0, 1.0),
                V2::new(9.0, 9.0),
                &map,
                &bad,
                &mut ChaCha8Rng::seed_from_u64(1)
            ),
            Err(TreeError::Params { name: "step", .. })
        ));
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(32))]

        /// On random maps a path never crosses an obstacle, its steps are at most gamma, and the same seed gives
        /// the same result.
        #[test]
        fn paths_never_cross_an_obstacle_and_are_reproducible(
            discs in proptest::collection::vec((0.5f32..9.5, 0.5f32..9.5, 0.1f32..0.8), 0..25),
            seed in 0u64..1000,
            ort in proptest::bool::ANY,
        ) {
            let map = Map::square_with(&discs);
            let (start, goal) = (V2::new(0.2, 0.2), V2::new(9.8, 9.8));
            proptest::prop_assume!(map.free(start) && map.free(goal));
            let tree = if ort { Tree::Ort } else { Tree::Rrt };
            let params = TreeParams { iterations: 3000, ..TreeParams::default() };
            let first = plan(tree, start, goal, &map, &params, &mut ChaCha8Rng::seed_from_u64(seed));
            proptest::prop_assert_eq!(&first, &plan(tree, start, goal, &map, &params, &mut ChaCha8Rng::seed_from_u64(seed)));
            if let Ok(plan) = first {
                proptest::prop_assert_eq!(map.first_blocked_segment(&plan.path), None);
                proptest::prop_assert!(steps_within_gamma(&plan.path));
                proptest::prop_assert_eq!(plan.path[0], start);
                proptest::prop_assert_eq!(*plan.path.last().unwrap(), goal);
            }
        }
    }
}
