//! Multi-SRT exploration (paper A, A.3): the sensor-based random tree of one robot, made aware of the other
//! robots' trees. Each node is a configuration with its local safe region (LSR), the star-shaped free region the
//! range rays saw from it. One step from the current node tries up to `attempts` random directions, goes `alpha`
//! of the way to the LSR's edge, and accepts the candidate if it is more than `d_min` away and inside no LSR of
//! another node (of this tree or of any other robot's) remembered within `memory` time units; with no such
//! candidate the robot backtracks to the parent node. Older LSRs are forgotten, so their areas may be explored
//! again.

use rand::Rng;

use crate::V2;

/// Most rays a region keeps (the range finder's most).
pub const MAX_RAYS: usize = 24;

/// A local safe region: the centre and the ray lengths of a ring (ray k at `heading + 2 pi k / n`), each capped
/// at the sensor's range, and when it was seen. Fixed-size, so that robots can keep and exchange regions without
/// allocating.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lsr {
    /// Where the robot stood.
    pub centre: V2,
    /// The angle of ray 0.
    pub heading: f32,
    /// The time it was seen.
    pub time: u64,
    rays: [f32; MAX_RAYS],
    len: usize,
}

impl Lsr {
    /// The LSR of a scan: infinite readings are capped at `range`, and rays beyond [`MAX_RAYS`] are left out.
    pub fn new(centre: V2, heading: f32, ranges: &[f32], range: f32, time: u64) -> Lsr {
        Lsr::from_rays(centre, heading, ranges.iter().map(|r| r.min(range)), time)
    }

    /// A region from its ray lengths as given (at most [`MAX_RAYS`] are kept).
    pub fn from_rays(centre: V2, heading: f32, rays: impl Iterator<Item = f32>, time: u64) -> Lsr {
        let mut lsr = Lsr {
            centre,
            heading,
            time,
            rays: [0.0; MAX_RAYS],
            len: 0,
        };
        for (slot, ray) in lsr.rays.iter_mut().zip(rays) {
            *slot = ray;
            lsr.len += 1;
        }
        lsr
    }

    /// The ray lengths.
    pub fn rays(&self) -> &[f32] {
        &self.rays[..self.len]
    }

    /// RAY(S, theta): the extent of the region in direction `angle`, the smaller of the two rays around it
    /// (conservative between rays).
    pub fn extent(&self, angle: f32) -> f32 {
        let n = self.len;
        if n == 0 {
            return 0.0;
        }
        let step = std::f32::consts::TAU / n as f32;
        let at = (angle - self.heading).rem_euclid(std::f32::consts::TAU) / step;
        let k = (at.floor() as usize) % n;
        self.rays[k].min(self.rays[(k + 1) % n])
    }

    /// Whether `p` lies inside: closer to the centre than the extent in its direction.
    pub fn contains(&self, p: V2) -> bool {
        let d = p - self.centre;
        d.length() < self.extent(d.angle())
    }
}

/// Exploration settings (A.7's suggested defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SrtParams {
    /// Fraction of the way to the LSR's edge a candidate goes (alpha < 1).
    pub alpha: f32,
    /// Least distance of a candidate from the current node (d_min).
    pub d_min: f32,
    /// Random directions tried per step (I_max).
    pub attempts: u32,
    /// LSRs older than this many time units are forgotten.
    pub memory: u64,
}

impl Default for SrtParams {
    fn default() -> Self {
        SrtParams {
            alpha: 0.8,
            d_min: 0.3,
            attempts: 30,
            memory: 10,
        }
    }
}

/// Where to go next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Move {
    /// To a new configuration: once there, call [`Srt::arrive`] with its scan.
    Forward(V2),
    /// Back to the parent node (no valid candidate here).
    Back(V2),
    /// Nothing left: the root has no valid candidate.
    Done,
}

#[derive(Debug, Clone, PartialEq)]
struct Node {
    lsr: Lsr,
    parent: Option<usize>,
}

/// One robot's tree.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Srt {
    nodes: Vec<Node>,
    current: Option<usize>,
}

impl Srt {
    /// The nodes' LSRs, for the other robots.
    pub fn regions(&self) -> impl Iterator<Item = &Lsr> + Clone {
        self.nodes.iter().map(|n| &n.lsr)
    }

    /// The robot reached the configuration of its last `Forward` (or starts there): the node is added with the
    /// LSR seen from it and becomes the current one.
    pub fn arrive(&mut self, lsr: Lsr) {
        self.nodes.push(Node {
            lsr,
            parent: self.current,
        });
        self.current = Some(self.nodes.len() - 1);
    }

    /// The robot is back at the parent node of its last `Back`.
    pub fn back(&mut self) {
        self.current = self.current.and_then(|c| self.nodes[c].parent);
    }

    /// One exploration step at time `now`: the next configuration, or a step back. `others` are the LSRs the
    /// other robots have shared.
    pub fn step<'a>(
        &self,
        params: &SrtParams,
        now: u64,
        others: impl Iterator<Item = &'a Lsr> + Clone,
        rng: &mut impl Rng,
    ) -> Move {
        let Some(current) = self.current else {
            return Move::Done;
        };
        let here = &self.nodes[current].lsr;
        let fresh = |l: &Lsr| now.saturating_sub(l.time) <= params.memory;
        for _ in 0..params.attempts {
            let angle = rng.random_range(0.0..std::f32::consts::TAU);
            let candidate =
                here.centre + V2::from_angle(angle) * (params.alpha * here.extent(angle));
            if (candidate - here.centre).length() <= params.d_min {
                continue;
            }
            let explored = self
                .nodes
                .iter()
                .enumerate()
                .any(|(i, n)| i != current && fresh(&n.lsr) && n.lsr.contains(candidate))
                || others.clone().any(|l| fresh(l) && l.contains(candidate));
            if !explored {
                return Move::Forward(candidate);
            }
        }
        match self.nodes[current].parent {
            Some(parent) => Move::Back(self.nodes[parent].lsr.centre),
            None => Move::Done,
        }
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::apf::Disc;
    use crate::planning::map::{Bounds, Map};

    const RAYS: usize = 20;
    const RANGE: f32 = 1.0;

    /// A 10 x 10 room with four discs; rays stop at the walls too.
    fn room() -> Map {
        Map {
            bounds: Bounds {
                min: V2::ZERO,
                max: V2::new(10.0, 10.0),
            },
            discs: [(3.0, 3.0), (7.0, 3.0), (3.0, 7.0), (7.0, 7.0)]
                .iter()
                .map(|&(x, y)| Disc {
                    centre: V2::new(x, y),
                    radius: 0.8,
                })
                .collect(),
        }
    }

    fn scan(map: &Map, at: V2, time: u64) -> Lsr {
        let ranges: Vec<f32> = (0..RAYS)
            .map(|k| {
                let d = V2::from_angle(std::f32::consts::TAU * k as f32 / RAYS as f32);
                // Distance to the room's walls along d.
                let wall = [
                    (d.x > 0.0).then(|| (map.bounds.max.x - at.x) / d.x),
                    (d.x < 0.0).then(|| (map.bounds.min.x - at.x) / d.x),
                    (d.y > 0.0).then(|| (map.bounds.max.y - at.y) / d.y),
                    (d.y < 0.0).then(|| (map.bounds.min.y - at.y) / d.y),
                ]
                .into_iter()
                .flatten()
                .fold(f32::INFINITY, f32::min);
                map.ray(at, d, RANGE)
                    .min(if wall <= RANGE { wall } else { f32::INFINITY })
            })
            .collect();
        Lsr::new(at, 0.0, &ranges, RANGE, time)
    }

    /// Fraction of a 0.25 m grid's free cells that lie in some LSR of `regions`.
    fn coverage<'a>(map: &Map, regions: impl Iterator<Item = &'a Lsr> + Clone) -> f32 {
        let (mut free, mut seen) = (0, 0);
        for i in 0..40 {
            for j in 0..40 {
                let p = V2::new(0.125 + 0.25 * i as f32, 0.125 + 0.25 * j as f32);
                if !map.free(p) {
                    continue;
                }
                free += 1;
                seen += usize::from(regions.clone().any(|l| l.contains(p)));
            }
        }
        seen as f32 / free as f32
    }

    /// Runs `robots` robots in lockstep for `steps` time units, each moving instantly to its next
    /// configuration; returns their trees.
    fn explore(robots: usize, steps: u64, params: &SrtParams, seed: u64) -> Vec<Srt> {
        let map = room();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let starts = [V2::new(1.0, 1.0), V2::new(9.0, 9.0), V2::new(1.0, 9.0)];
        let mut trees: Vec<Srt> = (0..robots)
            .map(|i| {
                let mut t = Srt::default();
                t.arrive(scan(&map, starts[i], 0));
                t
            })
            .collect();
        for now in 1..=steps {
            for i in 0..robots {
                let shared: Vec<Lsr> = trees
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != i)
                    .flat_map(|(_, t)| t.regions().cloned())
                    .collect();
                match trees[i].step(params, now, shared.iter(), &mut rng) {
                    Move::Forward(q) => {
                        assert!(map.free(q), "a candidate left the free space: {q:?}");
                        trees[i].arrive(scan(&map, q, now));
                    }
                    Move::Back(_) => trees[i].back(),
                    Move::Done => {}
                }
            }
        }
        trees
    }

    #[test]
    fn the_extent_is_the_smaller_of_the_two_rays_around_a_direction() {
        let lsr = Lsr::new(V2::ZERO, 0.0, &[1.0, 0.5, f32::INFINITY, 0.8], 2.0, 0);
        assert_eq!(lsr.extent(0.3), 0.5);
        assert_eq!(lsr.extent(std::f32::consts::PI + 0.1), 0.8);
        assert!(lsr.contains(V2::new(0.4, 0.1)) && !lsr.contains(V2::new(0.6, 0.1)));
        assert_eq!(lsr.rays()[2], 2.0);
    }

    #[test]
    fn a_robot_explores_most_of_a_room_and_never_leaves_the_free_space() {
        let params = SrtParams {
            memory: 1000,
            ..SrtParams::default()
        };
        let trees = explore(1, 400, &params, 1);
        let covered = coverage(&room(), trees[0].regions());
        // Measured: 0.997.
        assert!(covered > 0.8, "covered {covered}");
    }

    #[test]
    fn robots_that_share_their_regions_cover_more_together_than_one_alone() {
        let params = SrtParams {
            memory: 1000,
            ..SrtParams::default()
        };
        let one = explore(1, 60, &params, 2);
        let three = explore(3, 60, &params, 2);
        let map = room();
        let alone = coverage(&map, one.iter().flat_map(Srt::regions));
        let together = coverage(&map, three.iter().flat_map(Srt::regions));
        // Measured: 0.97 against 0.67.
        assert!(
            together > alone,
            "three robots {together} against one {alone}"
        );
        assert_eq!(
            explore(3, 60, &params, 2),
            three,
            "the same seed gives the same trees"
        );
    }

    #[test]
    fn forgotten_regions_may_be_explored_again() {
        let map = room();
        let mut tree = Srt::default();
        tree.arrive(scan(&map, V2::new(1.0, 1.0), 0));
        let old = scan(&map, V2::new(1.5, 1.0), 0);
        let params = SrtParams::default();
        // Every direction from (1, 1) ends inside the old region while it is remembered...
        let blocker = Lsr::new(V2::new(1.0, 1.0), 0.0, &[5.0; 20], 5.0, 0);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        assert!(matches!(
            tree.step(&params, 5, [&blocker, &old].into_iter(), &mut rng),
            Move::Done
        ));
        // ...and not once it is older than the memory.
        assert!(matches!(
            tree.step(&params, 11, [&blocker, &old].into_iter(), &mut rng),
            Move::Forward(_)
        ));
    }
}
