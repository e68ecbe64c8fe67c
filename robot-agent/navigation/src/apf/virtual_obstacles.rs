//! Virtual obstacles: discs that do not exist but repel like real ones (eq. 4).
//!
//! - [`gap_plugs`] (eq. 9): where two obstacles, or a stopped robot and an obstacle, are closer than the sum of
//!   their caution radii, a robot would be caught in the narrow gap between them: a virtual obstacle fills it.
//! - [`cluster_obstacles`] (eq. 10): a group of moving robots close together is covered by one virtual obstacle,
//!   so that others go round the group instead of into it.

use super::enclosing_circle::enclosing_circle;
use super::{Disc, Field, Me, Neighbour, Params, PlugRadius, Status};
use crate::V2;

/// The plug between two repelling discs whose caution circles overlap, or `None` when they do not. Its centre
/// is the centre of the smallest circle enclosing both caution circles (the midpoint for equal radii); its
/// caution radius follows `rule`; its proximity radius keeps the real obstacles' margin.
pub fn plug(a: &Field, b: &Field, rule: PlugRadius, influence: f32) -> Option<Field> {
    let between = b.centre - a.centre;
    let d = between.length();
    if d >= a.caution + b.caution {
        return None;
    }
    let enclosing = (d + a.caution + b.caution) / 2.0;
    let centre = if d > 0.0 {
        a.centre + between * ((enclosing - a.caution).clamp(0.0, d) / d)
    } else {
        a.centre
    };
    let caution = match rule {
        PlugRadius::Published => d + (a.caution + b.caution) / 2.0,
        PlugRadius::Enclosing => enclosing,
    };
    Some(Field {
        centre,
        caution,
        proximity: caution + influence,
    })
}

/// Eq. 9 for robot `me`: appends to `out` a plug for every pair of obstacles, and every pair of a stopped
/// robot and an obstacle, whose caution circles overlap.
pub fn gap_plugs(
    params: &Params,
    me: &Me,
    obstacles: &[Disc],
    neighbours: &[Neighbour],
    out: &mut Vec<Field>,
) {
    let field = |d: &Disc| params.field(me.radius, d.centre, d.radius);
    for (i, a) in obstacles.iter().enumerate() {
        let a = field(a);
        for b in &obstacles[i + 1..] {
            out.extend(plug(&a, &field(b), params.plug_radius, params.influence));
        }
        for n in neighbours
            .iter()
            .filter(|n| n.status == Status::Stopped && n.id != me.id)
        {
            let stopped = params.robot_field(me.radius, n.position, n.radius);
            out.extend(plug(&a, &stopped, params.plug_radius, params.influence));
        }
    }
}

/// Buffers [`cluster_obstacles`] reuses from tick to tick, so that a planner step does not allocate.
#[derive(Debug, Default)]
pub struct ClusterScratch {
    members: Vec<Neighbour>,
    parent: Vec<usize>,
    points: Vec<V2>,
}

impl ClusterScratch {
    /// Buffers for up to `robots` neighbours.
    pub fn with_capacity(robots: usize) -> ClusterScratch {
        ClusterScratch {
            members: Vec::with_capacity(robots),
            parent: Vec::with_capacity(robots),
            points: Vec::with_capacity(robots),
        }
    }
}

fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Eq. 10 for robot `me`: the moving robots within the cluster radius of it (itself excluded) are grouped by
/// single linkage (a chain of neighbours at most `linkage` apart); every group of two or more becomes a virtual
/// obstacle on its members' minimum enclosing circle, widened by a member's radius (the largest) so that it
/// covers their bodies. A cluster whose proximity circle holds `me`'s goal is left out. Appends to `out`.
pub fn cluster_obstacles(
    params: &Params,
    me: &Me,
    neighbours: &[Neighbour],
    scratch: &mut ClusterScratch,
    out: &mut Vec<Field>,
) {
    let ClusterScratch {
        members,
        parent,
        points,
    } = scratch;
    members.clear();
    members.extend(neighbours.iter().filter(|n| {
        n.status == Status::Moving
            && n.id != me.id
            && (n.position - me.position).length() <= params.cluster_radius
    }));
    parent.clear();
    parent.extend(0..members.len());
    for i in 0..members.len() {
        for j in i + 1..members.len() {
            if (members[i].position - members[j].position).length() <= params.linkage {
                let (ri, rj) = (root(parent, i), root(parent, j));
                parent[ri.max(rj)] = ri.min(rj);
            }
        }
    }
    for cluster in 0..members.len() {
        if root(parent, cluster) != cluster {
            continue;
        }
        points.clear();
        let mut widest = 0.0f32;
        for (i, m) in members.iter().enumerate() {
            if root(parent, i) == cluster {
                points.push(m.position);
                widest = widest.max(m.radius);
            }
        }
        if points.len() < 2 {
            continue;
        }
        let circle = enclosing_circle(points);
        let field = params.robot_field(me.radius, circle.centre, circle.radius + widest);
        if (me.goal - field.centre).length() > field.proximity {
            out.push(field);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn disc(x: f32, y: f32, r: f32) -> Disc {
        Disc {
            centre: V2::new(x, y),
            radius: r,
        }
    }

    fn me(goal: V2) -> Me {
        Me {
            id: 0,
            position: V2::ZERO,
            heading: 0.0,
            radius: 0.1,
            goal,
            priority: 0.0,
        }
    }

    fn moving(id: u32, x: f32, y: f32) -> Neighbour {
        Neighbour {
            id,
            position: V2::new(x, y),
            heading: 0.0,
            radius: 0.1,
            status: Status::Moving,
            priority: 0.0,
        }
    }

    #[test]
    fn overlapping_caution_circles_are_plugged_in_the_middle() {
        let params = Params::default();
        // Two 0.3 m obstacles 0.9 m apart seen by a 0.1 m robot: caution radii 0.5 each, sum 1.0 > 0.9.
        let a = params.field(0.1, V2::new(0.0, 0.0), 0.3);
        let b = params.field(0.1, V2::new(0.9, 0.0), 0.3);
        let enclosing = plug(&a, &b, PlugRadius::Enclosing, 0.6).unwrap();
        assert!((enclosing.centre - V2::new(0.45, 0.0)).length() < 1e-5);
        assert!((enclosing.caution - 0.95).abs() < 1e-5); // (0.9 + 0.5 + 0.5) / 2
        assert!((enclosing.proximity - 1.55).abs() < 1e-5);
        let published = plug(&a, &b, PlugRadius::Published, 0.6).unwrap();
        assert!((published.caution - 1.4).abs() < 1e-5); // 0.9 + (0.5 + 0.5) / 2
        // 1.2 m apart: the caution circles do not touch.
        let far = params.field(0.1, V2::new(1.2, 0.0), 0.3);
        assert_eq!(plug(&a, &far, PlugRadius::Enclosing, 0.6), None);
    }

    #[test]
    fn unequal_plugs_lean_towards_the_bigger_disc() {
        let a = Field {
            centre: V2::ZERO,
            caution: 1.0,
            proximity: 1.6,
        };
        let b = Field {
            centre: V2::new(1.0, 0.0),
            caution: 0.5,
            proximity: 1.1,
        };
        // Enclosing radius (1 + 1 + 0.5) / 2 = 1.25, centre 0.25 from a towards b.
        let p = plug(&a, &b, PlugRadius::Enclosing, 0.6).unwrap();
        assert!((p.centre - V2::new(0.25, 0.0)).length() < 1e-5 && (p.caution - 1.25).abs() < 1e-5);
    }

    #[test]
    fn gap_plugs_pair_obstacles_and_stopped_robots_with_obstacles() {
        let params = Params::default();
        let obstacles = [
            disc(0.0, 1.0, 0.3),
            disc(0.9, 1.0, 0.3),
            disc(5.0, 5.0, 0.3),
        ];
        let mut stopped = moving(3, 5.6, 5.0);
        stopped.status = Status::Stopped;
        let neighbours = [stopped, moving(4, 0.45, 1.6)];
        let mut out = Vec::new();
        gap_plugs(
            &params,
            &me(V2::new(9.0, 9.0)),
            &obstacles,
            &neighbours,
            &mut out,
        );
        // Obstacles 0 and 1, and the stopped robot with obstacle 2; the moving robot makes none.
        assert_eq!(out.len(), 2);
        assert!((out[0].centre - V2::new(0.45, 1.0)).length() < 1e-5);
        assert!(out[1].centre.x > 5.0 && out[1].centre.x < 5.6);
    }

    #[test]
    fn clusters_are_single_linkage_groups_of_two_or_more_moving_robots() {
        let params = Params::default();
        // 1-2-3 chained (0.7 apart), 4 alone, 5 too far from me, 6 stopped.
        let mut stopped = moving(6, 0.5, -0.5);
        stopped.status = Status::Stopped;
        let neighbours = [
            moving(1, 1.0, 0.0),
            moving(2, 1.0, 0.7),
            moving(3, 1.0, 1.4),
            moving(4, -1.5, 0.0),
            moving(5, 3.0, 0.0),
            stopped,
        ];
        let mut scratch = ClusterScratch::with_capacity(8);
        let mut out = Vec::new();
        cluster_obstacles(
            &params,
            &me(V2::new(-5.0, -5.0)),
            &neighbours,
            &mut scratch,
            &mut out,
        );
        assert_eq!(out.len(), 1);
        // Enclosing circle of the chain: centre (1, 0.7), radius 0.7; widened by 0.1 (member) and seen by a
        // 0.1 m robot with 0.1 m caution: caution radius 0.7 + 0.1 + 0.1 + 0.1 = 1.0.
        assert!((out[0].centre - V2::new(1.0, 0.7)).length() < 1e-5);
        assert!((out[0].caution - 1.0).abs() < 1e-5);
    }

    #[test]
    fn a_cluster_around_my_goal_is_ignored() {
        let params = Params::default();
        let neighbours = [moving(1, 1.0, 0.0), moving(2, 1.0, 0.5)];
        let mut scratch = ClusterScratch::with_capacity(4);
        let mut out = Vec::new();
        cluster_obstacles(
            &params,
            &me(V2::new(1.2, 0.2)),
            &neighbours,
            &mut scratch,
            &mut out,
        );
        assert!(out.is_empty());
    }
}
