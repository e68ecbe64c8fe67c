//! Adaptive artificial potential fields for many robots (AMR-APF) and its two baselines, DAPF and Khatib's
//! classic field (docs/navigation.md has the equations and the choices made where the method is silent).
//!
//! - [`forces`]: each force of the method, one function per equation.
//! - [`virtual_obstacles`]: the virtual obstacles that plug narrow gaps and that cover congested clusters.
//! - [`enclosing_circle`]: the minimum enclosing circle the cluster obstacles need.
//! - [`velocity`]: the force-to-velocity law.
//! - [`planner`]: one planner step, `(own state, snapshot, map) -> (v, w)`, for each method.

pub mod enclosing_circle;
pub mod forces;
pub mod planner;
pub mod velocity;
pub mod virtual_obstacles;

use crate::V2;

/// A disc of the plane: an obstacle's or a robot's body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disc {
    /// Centre.
    pub centre: V2,
    /// Radius in metres.
    pub radius: f32,
}

/// What repels a robot: a disc seen by that robot, with the two radii of the method (notation of the paper:
/// `rho^c_j` and `rho^p_j`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Field {
    /// Centre of the repelling disc.
    pub centre: V2,
    /// Caution radius: the robot's radius + the disc's radius + the caution distance. On this circle the
    /// repulsion equals the attraction.
    pub caution: f32,
    /// Proximity (influence) radius: the repulsion is zero outside it.
    pub proximity: f32,
}

/// A robot's status as the coordinator publishes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Without a goal, or arrived: an obstacle for the others.
    Stopped,
    /// On its way to its goal.
    Moving,
}

/// Another robot, as the coordinator's snapshot describes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour {
    /// Its participant index.
    pub id: u32,
    /// Position.
    pub position: V2,
    /// Heading in radians.
    pub heading: f32,
    /// Body radius.
    pub radius: f32,
    /// Moving or stopped.
    pub status: Status,
    /// Priority: higher is more important (see [`Priority`]).
    pub priority: f32,
}

/// The planning robot's own state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Me {
    /// Its participant index (breaks priority ties: the lower index is more important).
    pub id: u32,
    /// Position.
    pub position: V2,
    /// Heading in radians.
    pub heading: f32,
    /// Body radius.
    pub radius: f32,
    /// Its current goal.
    pub goal: V2,
    /// Its priority as the coordinator published it.
    pub priority: f32,
}

/// Which method a planner runs; the three share one code path and differ in the forces they add up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// AMR-APF: constant attraction, adaptive obstacle and robot forces, virtual obstacles.
    AmrApf,
    /// DAPF: constant attraction, base repulsion of obstacles and of every robot in a neighbourhood as a plain
    /// moving obstacle (no headings), robots yielding to those of higher priority.
    Dapf,
    /// Khatib's classic field: spring attraction and the classic repulsion of obstacles and robots.
    Apf,
}

/// How the sign `T` of the adaptive force between two moving robots is chosen (eq. 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TurnRule {
    /// Headings on opposite sides of the line of sight: both turn further to their own side (`T = +1`);
    /// otherwise the two split by priority. Reproduces both cases the paper describes.
    Described,
    /// `T = sign(psi_i * psi_j * (P_i - P_j))` as printed; always gives the two robots opposite signs.
    Literal,
}

/// The caution radius of a virtual obstacle that plugs a gap (eq. 9).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlugRadius {
    /// `d + (rho_i + rho_j) / 2`, as printed.
    Published,
    /// `(d + rho_i + rho_j) / 2`: the smallest circle enclosing both caution circles.
    Enclosing,
}

/// What the coordinator's priorities are made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Priority {
    /// The rank by distance to the goal: the closest robot has the highest value.
    Rank,
    /// Minus the distance to the goal (closer is still higher).
    Distance,
}

/// Parts of AMR-APF that can be switched off, for the ablations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Parts {
    /// The adaptive (tangential) obstacle force, eq. 3.
    pub adaptive_obstacles: bool,
    /// The adaptive force between moving robots, eq. 6.
    pub adaptive_robots: bool,
    /// Virtual obstacles plugging narrow gaps, eq. 9.
    pub gap_plugs: bool,
    /// Virtual obstacles covering congested clusters, eq. 10.
    pub clusters: bool,
}

impl Parts {
    /// Every part on.
    pub const ALL: Parts = Parts {
        adaptive_obstacles: true,
        adaptive_robots: true,
        gap_plugs: true,
        clusters: true,
    };
}

/// A planner's parameters (defaults: the suggested ones of docs/navigation.md, a TurtleBot3 Burger).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// The method.
    pub method: Method,
    /// The parts of AMR-APF in use.
    pub parts: Parts,
    /// `F_A`: the attraction's magnitude; every other force is scaled relative to it.
    pub attraction: f32,
    /// Caution distance `rho^c` in metres, for obstacles.
    pub caution: f32,
    /// Caution distance towards other robots (single robots and clusters) in metres.
    pub robot_caution: f32,
    /// Proximity radius minus caution radius, in metres.
    pub influence: f32,
    /// Threshold angle `phi` in radians.
    pub threshold_angle: f32,
    /// Cluster search radius `r_c` in metres (also DAPF's neighbourhood).
    pub cluster_radius: f32,
    /// Cluster linkage distance `d_c` in metres.
    pub linkage: f32,
    /// Gain `k_v` of the forward speed.
    pub k_v: f32,
    /// Gain `k_w` of the turn rate, per second.
    pub k_w: f32,
    /// Speed limit in m/s.
    pub max_speed: f32,
    /// Turn-rate limit in rad/s.
    pub max_turn_rate: f32,
    /// Smallest distance a force is computed at (d is clamped to it), in metres.
    pub min_distance: f32,
    /// Sign rule of the robot-robot adaptive force.
    pub turn_rule: TurnRule,
    /// Caution radius of gap plugs.
    pub plug_radius: PlugRadius,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            method: Method::AmrApf,
            parts: Parts::ALL,
            attraction: 1.0,
            caution: 0.1,
            robot_caution: 0.1,
            influence: 0.6,
            threshold_angle: 30f32.to_radians(),
            cluster_radius: 2.0,
            linkage: 0.8,
            k_v: 1.0,
            k_w: 2.0,
            max_speed: 0.22,
            max_turn_rate: 2.84,
            min_distance: 0.01,
            turn_rule: TurnRule::Described,
            plug_radius: PlugRadius::Enclosing,
        }
    }
}

impl Params {
    /// The field an obstacle of `body_radius` centred at `centre` makes for a robot of `own_radius`.
    pub fn field(&self, own_radius: f32, centre: V2, body_radius: f32) -> Field {
        self.field_with(self.caution, own_radius, centre, body_radius)
    }

    /// The field another robot (or a cluster of robots) of `body_radius` centred at `centre` makes for a robot of
    /// `own_radius`.
    pub fn robot_field(&self, own_radius: f32, centre: V2, body_radius: f32) -> Field {
        self.field_with(self.robot_caution, own_radius, centre, body_radius)
    }

    fn field_with(&self, distance: f32, own_radius: f32, centre: V2, body_radius: f32) -> Field {
        let caution = own_radius + body_radius + distance;
        Field {
            centre,
            caution,
            proximity: caution + self.influence,
        }
    }
}
