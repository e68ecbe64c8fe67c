//! One planner step: the total force on a robot (eq. 11) under its method, and the velocity it commands.
//! A pure function of the robot's own state, the coordinator's snapshot of the others and the map.

use super::forces::{
    Encounter, attraction, base_repulsion, khatib_repulsion, moving_robot_force, obstacle_force,
    spring_attraction,
};
use super::velocity::{Twist, twist};
use super::virtual_obstacles::{ClusterScratch, cluster_obstacles, gap_plugs};
use super::{Disc, Me, Method, Neighbour, Params, Status};
use crate::V2;
use crate::vec2::wrap;

/// Buffers a planner reuses from step to step, so that a step does not allocate once they are large enough.
#[derive(Debug, Default)]
pub struct Scratch {
    virtual_obstacles: Vec<super::Field>,
    clusters: ClusterScratch,
}

impl Scratch {
    /// Buffers sized for `robots` robots and `obstacles` obstacles.
    pub fn with_capacity(robots: usize, obstacles: usize) -> Scratch {
        Scratch {
            virtual_obstacles: Vec::with_capacity(
                obstacles * obstacles / 2 + robots * obstacles + robots,
            ),
            clusters: ClusterScratch::with_capacity(robots),
        }
    }
}

/// Whether robot `me` outranks `other` (higher priority; the lower index on a tie).
fn outranks(me: &Me, other: &Neighbour) -> bool {
    me.priority > other.priority || (me.priority == other.priority && me.id < other.id)
}

/// Eq. 11, `F = F_A + F_O + F_R + F_OA`, under `params.method` (see [`Method`]). `neighbours` may include
/// `me` itself (it is skipped).
pub fn total_force(
    params: &Params,
    me: &Me,
    neighbours: &[Neighbour],
    obstacles: &[Disc],
    scratch: &mut Scratch,
) -> V2 {
    let others = neighbours.iter().filter(|n| n.id != me.id);
    let field_of = |n: &Neighbour| params.robot_field(me.radius, n.position, n.radius);
    let d_min = params.min_distance;
    let f_a = params.attraction;
    match params.method {
        Method::Apf => {
            let mut force = spring_attraction(f_a, me.position, me.goal);
            for o in obstacles {
                let field = params.field(me.radius, o.centre, o.radius);
                force += khatib_repulsion(f_a, &field, me.position, d_min);
            }
            for n in others {
                force += khatib_repulsion(f_a, &field_of(n), me.position, d_min);
            }
            force
        }
        Method::Dapf => {
            let mut force = attraction(f_a, me.position, me.goal);
            for o in obstacles {
                let field = params.field(me.radius, o.centre, o.radius);
                force += base_repulsion(f_a, &field, me.position, d_min);
            }
            for n in others.filter(|n| {
                (n.position - me.position).length() <= params.cluster_radius
                    && (n.status == Status::Stopped || !outranks(me, n))
            }) {
                force += base_repulsion(f_a, &field_of(n), me.position, d_min);
            }
            force
        }
        Method::AmrApf => {
            let parts = params.parts;
            let obstacle = |field: &super::Field, adaptive: bool| {
                obstacle_force(params, field, me.position, me.heading, me.goal, adaptive)
            };
            let mut force = attraction(f_a, me.position, me.goal);
            for o in obstacles {
                force += obstacle(
                    &params.field(me.radius, o.centre, o.radius),
                    parts.adaptive_obstacles,
                );
            }
            for n in others {
                let field = field_of(n);
                force += match n.status {
                    Status::Stopped => obstacle(&field, parts.adaptive_obstacles),
                    Status::Moving => {
                        let encounter = Encounter {
                            psi_i: wrap(me.heading - (n.position - me.position).angle()),
                            psi_j: wrap(n.heading - (me.position - n.position).angle()),
                            priority_i: me.priority,
                            priority_j: n.priority,
                            i_wins_ties: me.id < n.id,
                        };
                        moving_robot_force(
                            f_a,
                            &field,
                            me.position,
                            params.turn_rule,
                            &encounter,
                            parts.adaptive_robots,
                            d_min,
                        )
                    }
                };
            }
            let virtual_obstacles = &mut scratch.virtual_obstacles;
            virtual_obstacles.clear();
            if parts.gap_plugs {
                gap_plugs(params, me, obstacles, neighbours, virtual_obstacles);
            }
            if parts.clusters {
                cluster_obstacles(
                    params,
                    me,
                    neighbours,
                    &mut scratch.clusters,
                    virtual_obstacles,
                );
            }
            for field in virtual_obstacles.iter() {
                force += obstacle(field, parts.adaptive_obstacles);
            }
            force
        }
    }
}

/// One planner step: the velocity command of the total force (docs/navigation.md, "From force to velocity").
pub fn plan(
    params: &Params,
    me: &Me,
    neighbours: &[Neighbour],
    obstacles: &[Disc],
    scratch: &mut Scratch,
) -> Twist {
    let force = total_force(params, me, neighbours, obstacles, scratch);
    if !force.is_finite() {
        return Twist::default();
    }
    twist(params, me.heading, force)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::apf::Parts;

    fn me(x: f32, y: f32, heading: f32, goal: V2) -> Me {
        Me {
            id: 0,
            position: V2::new(x, y),
            heading,
            radius: 0.105,
            goal,
            priority: 0.0,
        }
    }

    fn obstacle(x: f32, y: f32) -> Disc {
        Disc {
            centre: V2::new(x, y),
            radius: 0.3,
        }
    }

    /// Integrates a lone robot's unicycle for `steps` of `dt` and returns its closest approach to the
    /// obstacles' surfaces and whether it arrived.
    fn drive(params: &Params, mut robot: Me, obstacles: &[Disc], steps: usize) -> (f32, bool) {
        let dt = 0.05;
        let mut scratch = Scratch::with_capacity(1, obstacles.len());
        let mut clearance = f32::INFINITY;
        for _ in 0..steps {
            if (robot.goal - robot.position).length() < 0.1 {
                return (clearance, true);
            }
            let t = plan(params, &robot, &[], obstacles, &mut scratch);
            robot.heading += t.w * dt;
            robot.position += V2::from_angle(robot.heading) * (t.v * dt);
            for o in obstacles {
                clearance =
                    clearance.min((robot.position - o.centre).length() - o.radius - robot.radius);
            }
        }
        (clearance, false)
    }

    #[test]
    fn alone_with_no_obstacle_the_robot_drives_straight_to_its_goal() {
        let params = Params::default();
        let robot = me(0.0, 0.0, 0.0, V2::new(3.0, 0.0));
        let t = plan(&params, &robot, &[], &[], &mut Scratch::default());
        assert_eq!(t, Twist { v: 0.22, w: 0.0 });
        assert!(drive(&params, robot, &[], 400).1);
    }

    #[test]
    fn amr_apf_goes_round_an_obstacle_on_the_goal_line_where_the_base_field_stalls() {
        let blocked = [obstacle(2.0, 0.0)];
        let robot = me(0.0, 0.0, 0.0, V2::new(4.0, 0.0));
        let (clearance, arrived) = drive(&Params::default(), robot, &blocked, 2000);
        assert!(arrived && clearance > 0.0, "clearance {clearance}");
        let base_only = Params {
            parts: Parts {
                adaptive_obstacles: false,
                ..Parts::ALL
            },
            ..Params::default()
        };
        assert!(!drive(&base_only, robot, &blocked, 2000).1);
    }

    #[test]
    fn the_three_methods_differ_on_the_same_scene() {
        let robot = me(0.0, 0.0, 0.0, V2::new(4.0, 0.0));
        let neighbour = Neighbour {
            id: 1,
            position: V2::new(0.5, 0.05),
            heading: std::f32::consts::PI,
            radius: 0.105,
            status: Status::Moving,
            priority: 1.0,
        };
        let force = |method| {
            let params = Params {
                method,
                ..Params::default()
            };
            total_force(&params, &robot, &[neighbour], &[], &mut Scratch::default())
        };
        let (amr, dapf, apf) = (
            force(Method::AmrApf),
            force(Method::Dapf),
            force(Method::Apf),
        );
        // The spring pulls four times harder from 4 m; DAPF only repels; AMR-APF also pushes sideways.
        assert!(apf.x > 3.5, "{apf:?}");
        assert!(dapf.y.abs() < amr.y.abs(), "{dapf:?} {amr:?}");
        assert!(dapf.x < 1.0);
    }

    proptest! {
        #[test]
        fn the_command_is_always_finite_and_within_the_limits(
            x in -5.0f32..5.0, y in -5.0f32..5.0, heading in -4.0f32..4.0,
            ox in -5.0f32..5.0, oy in -5.0f32..5.0, nx in -5.0f32..5.0, ny in -5.0f32..5.0,
            moving in any::<bool>(), method in 0..3u8,
        ) {
            let params = Params {
                method: [Method::AmrApf, Method::Dapf, Method::Apf][method as usize],
                ..Params::default()
            };
            let robot = me(x, y, heading, V2::new(1.0, 1.0));
            let n = Neighbour {
                id: 1,
                position: V2::new(nx, ny),
                heading: 0.3,
                radius: 0.105,
                status: if moving { Status::Moving } else { Status::Stopped },
                priority: 1.0,
            };
            let t = plan(&params, &robot, &[n, n], &[obstacle(ox, oy), obstacle(ox, oy)], &mut Scratch::default());
            prop_assert!(t.v.is_finite() && t.w.is_finite());
            prop_assert!((0.0..=params.max_speed).contains(&t.v));
            prop_assert!(t.w.abs() <= params.max_turn_rate);
        }
    }
}
