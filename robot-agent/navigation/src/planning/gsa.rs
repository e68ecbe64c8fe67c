//! Path planning with the Gravitational Search Algorithm (paper D, docs/planning.md): a swarm of agents leaves
//! the start, pulled towards the heavier (closer to the goal) among them; each agent's trajectory is a candidate
//! path; the shortest trajectory that reaches the goal without touching an obstacle is the plan.
//!
//! The steps follow the paper: every agent starts at the start with a random non-zero velocity (step 1); fitness
//! is the distance to the goal (2, 3), plus a penalty inside an obstacle (4); masses, forces and the velocity
//! and position updates are Rashedi et al.'s (5, 6); positions are clamped into the box (7); trajectories are
//! remembered (8), filtered for collisions (9) and the shortest is chosen (10). Where the paper is silent the
//! choices are documented on [`GsaParams`].

use rand::Rng;

use super::map::{EndpointError, Map, path_length};
use crate::V2;

/// The planner's parameters. Defaults: docs/planning.md.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GsaParams {
    /// Number of agents N.
    pub agents: usize,
    /// Iteration cap t_max.
    pub iterations: usize,
    /// Initial gravitational constant G0.
    pub g0: f32,
    /// Decay rate of the gravitational constant, `G(t) = G0 exp(-alpha_g t / t_max)`.
    pub alpha_g: f32,
    /// Softening of the distance in the force, epsilon.
    pub epsilon: f32,
    /// Final size of Kbest as a fraction of the attracting bodies (it shrinks linearly from all of them).
    pub kbest_final: f32,
    /// Fitness penalty alpha of an agent inside an obstacle; `None` for 10 times the box's diagonal.
    pub penalty: Option<f32>,
    /// An agent within this distance of the goal has reached it (m).
    pub goal_tolerance: f32,
    /// Initial velocities are drawn uniformly in a disc of this radius (m per iteration).
    pub initial_speed: f32,
    /// Largest distance an agent moves in one iteration (m); 0 for no limit. The paper's update has no limit;
    /// without one the early, strong G throws agents across the map in one step, and a trajectory of long jumps
    /// crosses almost every obstacle.
    pub max_step: f32,
    /// Whether the goal takes part as a fixed body of fitness 0 (the heaviest). Not in the paper: without it
    /// the swarm still advances, agents overshooting the best one; with it every agent runs straight at the goal
    /// and the trajectories are too alike to find a way round an obstacle (docs/planning.md).
    pub goal_anchor: bool,
    /// The iterations stop when this fraction of the agents has reached the goal (or at t_max).
    pub arrive_fraction: f32,
}

impl Default for GsaParams {
    fn default() -> Self {
        GsaParams {
            agents: 50,
            iterations: 500,
            g0: 10.0,
            alpha_g: 1.0,
            epsilon: 1e-6,
            kbest_final: 0.02,
            penalty: None,
            goal_tolerance: 0.1,
            initial_speed: 0.2,
            max_step: 0.3,
            goal_anchor: false,
            arrive_fraction: 0.9,
        }
    }
}

/// Why there is no plan.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum GsaError {
    /// A parameter is out of its range.
    #[error("planner parameter {name}: {rule}")]
    Params {
        /// The parameter.
        name: &'static str,
        /// What it must be.
        rule: &'static str,
    },
    /// The start or the goal is not a place to plan between.
    #[error(transparent)]
    Endpoints(#[from] EndpointError),
    /// No agent's trajectory reached the goal without touching an obstacle.
    #[error(
        "no collision-free trajectory reached the goal ({collision_free} of {agents} collision-free, {reached} reached the goal)"
    )]
    NoPath {
        /// Agents whose trajectories were collision-free.
        collision_free: usize,
        /// Agents that reached the goal.
        reached: usize,
        /// Agents in all.
        agents: usize,
    },
}

/// A plan and what the swarm did to find it.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The chosen trajectory, from the start, ending exactly at the goal.
    pub path: Vec<V2>,
    /// Its length D (m).
    pub length: f32,
    /// |S_cf|: agents whose trajectories touch no obstacle (whether or not they reached the goal).
    pub collision_free: usize,
    /// Agents that reached the goal.
    pub reached: usize,
    /// Iterations run.
    pub iterations: usize,
}

fn check(params: &GsaParams) -> Result<(), GsaError> {
    let rule = |ok: bool, name, rule| {
        if ok {
            Ok(())
        } else {
            Err(GsaError::Params { name, rule })
        }
    };
    let positive = |x: f32| x.is_finite() && x > 0.0;
    rule(
        params.agents >= 1 && params.agents <= 10_000,
        "agents",
        "must be 1 to 10000",
    )?;
    rule(
        params.iterations >= 1 && params.iterations <= 100_000,
        "iterations",
        "must be 1 to 100000",
    )?;
    rule(
        params.g0.is_finite() && params.g0 >= 0.0,
        "g0",
        "must be finite and >= 0",
    )?;
    rule(
        params.alpha_g.is_finite() && params.alpha_g >= 0.0,
        "alpha_g",
        "must be finite and >= 0",
    )?;
    rule(positive(params.epsilon), "epsilon", "must be > 0")?;
    rule(
        params.kbest_final > 0.0 && params.kbest_final <= 1.0,
        "kbest_final",
        "must be in (0, 1]",
    )?;
    rule(
        params.penalty.is_none_or(positive),
        "penalty",
        "must be > 0",
    )?;
    rule(
        positive(params.goal_tolerance),
        "goal_tolerance",
        "must be > 0",
    )?;
    rule(
        positive(params.initial_speed),
        "initial_speed",
        "must be > 0",
    )?;
    rule(
        params.max_step.is_finite() && params.max_step >= 0.0,
        "max_step",
        "must be finite and >= 0",
    )?;
    rule(
        params.arrive_fraction > 0.0 && params.arrive_fraction <= 1.0,
        "arrive_fraction",
        "must be in (0, 1]",
    )
}

/// A uniform draw in the disc of radius `r`, never the zero vector (a zero velocity would leave every force
/// zero at the start, where all agents coincide).
fn random_in_disc(rng: &mut impl Rng, r: f32) -> V2 {
    loop {
        let p = V2::new(rng.random_range(-1.0..=1.0), rng.random_range(-1.0..=1.0));
        let l = p.length();
        if l <= 1.0 && l > 1e-3 {
            return p * r;
        }
    }
}

/// The swarm's state over the iterations.
struct Swarm {
    position: Vec<V2>,
    velocity: Vec<V2>,
    fitness: Vec<f32>,
    mass: Vec<f32>,
    /// Trajectories, each up to the point where the agent first reached the goal.
    trajectory: Vec<Vec<V2>>,
    arrived: Vec<bool>,
    /// Attracting bodies ordered by mass, heaviest first (agents, then the goal anchor at index N).
    order: Vec<usize>,
}

impl Swarm {
    fn new(start: V2, params: &GsaParams, rng: &mut impl Rng) -> Swarm {
        let n = params.agents;
        let bodies = n + usize::from(params.goal_anchor);
        Swarm {
            position: vec![start; n],
            velocity: (0..n)
                .map(|_| random_in_disc(rng, params.initial_speed))
                .collect(),
            fitness: vec![0.0; bodies],
            mass: vec![0.0; bodies],
            trajectory: (0..n)
                .map(|_| {
                    let mut t = Vec::with_capacity(params.iterations.min(1024) + 1);
                    t.push(start);
                    t
                })
                .collect(),
            arrived: vec![false; n],
            order: (0..bodies).collect(),
        }
    }

    fn body(&self, j: usize, goal: V2) -> V2 {
        self.position.get(j).copied().unwrap_or(goal)
    }

    /// Fitness with the obstacle penalty (steps 2-4) and normalised masses (step 5).
    fn weigh(&mut self, goal: V2, map: &Map, penalty: f32) {
        for (i, p) in self.position.iter().enumerate() {
            let distance = (goal - *p).length();
            self.fitness[i] = if map.inside_obstacle(*p) {
                distance + penalty
            } else {
                distance
            };
        }
        // The goal anchor, when present, sits at index N with fitness 0.
        if let Some(anchor) = self.fitness.get_mut(self.position.len()) {
            *anchor = 0.0;
        }
        let best = self.fitness.iter().copied().fold(f32::INFINITY, f32::min);
        let worst = self
            .fitness
            .iter()
            .copied()
            .fold(f32::NEG_INFINITY, f32::max);
        if worst - best <= f32::EPSILON * worst.abs().max(1.0) {
            self.mass.fill(1.0);
        } else {
            for (m, f) in self.mass.iter_mut().zip(&self.fitness) {
                *m = (f - worst) / (best - worst);
            }
        }
        let total: f32 = self.mass.iter().sum();
        for m in &mut self.mass {
            *m /= total;
        }
        let mass = &self.mass;
        self.order
            .sort_by(|&a, &b| mass[b].total_cmp(&mass[a]).then(a.cmp(&b)));
    }

    /// Forces from the `k` heaviest bodies, then the velocity and position updates (steps 5-7). The agent's own
    /// mass cancels between F_i and a_i = F_i / M_i, so it is left out (an agent of mass 0 still moves).
    fn step(
        &mut self,
        goal: V2,
        map: &Map,
        g: f32,
        k: usize,
        params: &GsaParams,
        rng: &mut impl Rng,
    ) {
        for i in 0..self.position.len() {
            let x = self.position[i];
            let mut a = V2::ZERO;
            for &j in self.order.iter().take(k) {
                if j == i {
                    continue;
                }
                let to = self.body(j, goal) - x;
                let r: f32 = rng.random();
                a += to * (r * g * self.mass[j] / (to.length() + params.epsilon));
            }
            let r: f32 = rng.random();
            let mut v = self.velocity[i] * r + a;
            let speed = v.length();
            if params.max_step > 0.0 && speed > params.max_step {
                v = v * (params.max_step / speed);
            }
            self.velocity[i] = v;
            let next = map.bounds.clamp(x + v);
            self.position[i] = next;
            if !self.arrived[i] {
                self.trajectory[i].push(next);
                self.arrived[i] = (goal - next).length() <= params.goal_tolerance;
            }
        }
    }
}

/// Plans a path from `start` to `goal` on `map` (obstacles already grown by the robot's size) with GSA, on the
/// map opened at the start ([`Map::opened_at`]: a robot inside an obstacle's safety margin may leave it). The
/// result is a pure function of the inputs and `rng`'s state.
pub fn plan(
    start: V2,
    goal: V2,
    map: &Map,
    params: &GsaParams,
    rng: &mut impl Rng,
) -> Result<Plan, GsaError> {
    check(params)?;
    let map = &*map.opened_at(start);
    map.check_endpoints(start, goal)?;
    let penalty = params.penalty.unwrap_or(10.0 * map.bounds.diagonal());
    let mut swarm = Swarm::new(start, params, rng);
    let bodies = swarm.mass.len();
    let k_final = ((params.kbest_final * bodies as f32).ceil() as usize).clamp(1, bodies);
    let needed = ((params.arrive_fraction * params.agents as f32).ceil() as usize).max(1);
    let mut iterations = 0;
    while iterations < params.iterations && swarm.arrived.iter().filter(|&&a| a).count() < needed {
        let t = iterations as f32 / params.iterations as f32;
        let g = params.g0 * (-params.alpha_g * t).exp();
        let k = bodies - ((bodies - k_final) as f32 * t).round() as usize;
        swarm.weigh(goal, map, penalty);
        swarm.step(goal, map, g, k, params, rng);
        iterations += 1;
    }
    let mut free = 0;
    let mut best: Option<(f32, usize)> = None;
    for (i, trajectory) in swarm.trajectory.iter_mut().enumerate() {
        // Step 9, collision filtering.
        if map.first_blocked_segment(trajectory).is_some() {
            continue;
        }
        free += 1;
        if !swarm.arrived[i] {
            continue;
        }
        // The goal itself ends the path; the last step to it must be free too.
        let last = *trajectory.last().unwrap_or(&start);
        if map.segment_free(last, goal) {
            trajectory.push(goal);
            let length = path_length(trajectory);
            if best.is_none_or(|(l, _)| length < l) {
                best = Some((length, i));
            }
        }
    }
    let reached = swarm.arrived.iter().filter(|&&a| a).count();
    match best {
        Some((length, i)) => Ok(Plan {
            path: std::mem::take(&mut swarm.trajectory[i]),
            length,
            collision_free: free,
            reached,
            iterations,
        }),
        None => Err(GsaError::NoPath {
            collision_free: free,
            reached,
            agents: params.agents,
        }),
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;

    fn rng(seed: u64) -> ChaCha8Rng {
        ChaCha8Rng::seed_from_u64(seed)
    }

    /// The plans of seeds `0..n` on a map (successes only) and the number of failures.
    fn plans(start: V2, goal: V2, map: &Map, params: &GsaParams, n: u64) -> (Vec<Plan>, usize) {
        let results: Vec<_> = (0..n)
            .map(|seed| plan(start, goal, map, params, &mut rng(seed)))
            .collect();
        let failures = results
            .iter()
            .filter(|r| matches!(r, Err(GsaError::NoPath { .. })))
            .count();
        (
            results.into_iter().filter_map(Result::ok).collect(),
            failures,
        )
    }

    #[test]
    fn in_the_open_every_trajectory_is_collision_free_and_the_plan_ends_at_the_goal() {
        let map = Map::square_with(&[]);
        let (start, goal) = (V2::new(1.0, 1.0), V2::new(8.0, 6.0));
        let plan = plan(start, goal, &map, &GsaParams::default(), &mut rng(1)).unwrap();
        assert_eq!(plan.path.first(), Some(&start));
        assert_eq!(plan.path.last(), Some(&goal));
        assert_eq!(plan.collision_free, 50);
        assert!(plan.reached >= 45, "{}", plan.reached);
        assert!((plan.length - path_length(&plan.path)).abs() < 1e-3);
        assert!(plan.length >= (goal - start).length());
    }

    #[test]
    fn plans_go_round_an_obstacle_on_the_straight_line() {
        let map = Map::square_with(&[(5.0, 5.0, 1.0)]);
        let (start, goal) = (V2::new(2.0, 5.0), V2::new(8.0, 5.0));
        let (found, failures) = plans(start, goal, &map, &GsaParams::default(), 10);
        assert!(
            found.len() >= 5,
            "{} plans, {failures} failures",
            found.len()
        );
        for plan in &found {
            assert_eq!(map.first_blocked_segment(&plan.path), None);
            // The way round the disc is at least the tangent-arc-tangent length.
            assert!(plan.length > 6.3, "{}", plan.length);
        }
    }

    #[test]
    fn with_the_goal_anchor_every_agent_runs_through_the_obstacle() {
        let map = Map::square_with(&[(5.0, 5.0, 1.0)]);
        let params = GsaParams {
            goal_anchor: true,
            ..GsaParams::default()
        };
        let err = plan(
            V2::new(2.0, 5.0),
            V2::new(8.0, 5.0),
            &map,
            &params,
            &mut rng(1),
        )
        .unwrap_err();
        assert!(
            matches!(
                err,
                GsaError::NoPath {
                    collision_free: 0,
                    ..
                }
            ),
            "{err:?}"
        );
    }

    #[test]
    fn the_obstacle_penalty_makes_an_agent_the_lightest() {
        let map = Map::square_with(&[(5.0, 5.0, 1.0)]);
        let params = GsaParams {
            goal_anchor: true,
            ..GsaParams::default()
        };
        let mut swarm = Swarm::new(V2::new(1.0, 1.0), &params, &mut rng(1));
        swarm.position[0] = V2::new(5.0, 5.0); // inside, 3 m from the goal
        swarm.position[1] = V2::new(1.0, 1.0); // outside, 7.07 m from the goal
        swarm.position[2] = V2::new(7.0, 8.0); // outside, on the goal
        swarm.weigh(V2::new(7.0, 8.0), &map, 100.0);
        assert_eq!(swarm.mass[0], 0.0);
        assert!(swarm.mass[2] > swarm.mass[1]);
        // The anchor (fitness 0) and the agent on the goal are equally heaviest, ahead of everyone.
        assert_eq!(swarm.order[..2], [2, 50]);
        assert!((swarm.mass.iter().sum::<f32>() - 1.0).abs() < 1e-5);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let map = Map::square_with(&[(5.0, 5.0, 1.0)]);
        let p = GsaParams::default();
        let inside = plan(V2::new(1.0, 1.0), V2::new(5.2, 5.0), &map, &p, &mut rng(1));
        assert_eq!(
            inside.unwrap_err(),
            GsaError::Endpoints(EndpointError::GoalBlocked)
        );
        let outside = plan(V2::new(-1.0, 1.0), V2::new(8.0, 8.0), &map, &p, &mut rng(1));
        assert_eq!(
            outside.unwrap_err(),
            GsaError::Endpoints(EndpointError::OutOfBounds("start"))
        );
        let nan = plan(
            V2::new(1.0, 1.0),
            V2::new(f32::NAN, 8.0),
            &map,
            &p,
            &mut rng(1),
        );
        assert_eq!(
            nan.unwrap_err(),
            GsaError::Endpoints(EndpointError::OutOfBounds("goal"))
        );
        let none = GsaParams { agents: 0, ..p };
        assert!(matches!(
            plan(
                V2::new(1.0, 1.0),
                V2::new(8.0, 8.0),
                &map,
                &none,
                &mut rng(1)
            ),
            Err(GsaError::Params { name: "agents", .. })
        ));
    }

    #[test]
    fn a_start_inside_the_safety_margin_may_leave_it_but_not_go_deeper() {
        let map = Map::square_with(&[(5.0, 5.0, 1.0)]);
        let start = V2::new(5.0, 4.1); // 0.1 m inside the grown disc
        let (found, _) = plans(start, V2::new(5.0, 1.0), &map, &GsaParams::default(), 5);
        assert!(!found.is_empty());
        let opened = map.opened_at(start);
        assert_eq!(
            opened.first_blocked_segment(&[start, V2::new(5.0, 3.0)]),
            None
        );
        assert_eq!(
            opened.first_blocked_segment(&[start, V2::new(5.0, 4.2)]),
            Some(0)
        );
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]

        /// On random maps a returned path never crosses an obstacle, and the same seed gives the same result.
        #[test]
        fn plans_never_cross_an_obstacle_and_are_reproducible(
            discs in proptest::collection::vec((0.5f32..9.5, 0.5f32..9.5, 0.1f32..0.8), 0..25),
            seed in 0u64..1000,
        ) {
            let map = Map::square_with(&discs);
            let (start, goal) = (V2::new(0.2, 0.2), V2::new(9.8, 9.8));
            proptest::prop_assume!(map.free(start) && map.free(goal));
            let params = GsaParams { iterations: 200, ..GsaParams::default() };
            let first = plan(start, goal, &map, &params, &mut rng(seed));
            proptest::prop_assert_eq!(&first, &plan(start, goal, &map, &params, &mut rng(seed)));
            if let Ok(plan) = first {
                proptest::prop_assert_eq!(map.first_blocked_segment(&plan.path), None);
                proptest::prop_assert!(map.free(plan.path[0]) && plan.path.iter().all(|p| map.bounds.contains(*p)));
            }
        }
    }
}
