//! Obstacles a robot finds with its range finder that its map does not have (paper D's hidden obstacles): every
//! ray hit that no known obstacle and no edge of the box explains is remembered, hits close together form one
//! obstacle, and each obstacle is the smallest disc holding its hits.

use super::map::Bounds;
use crate::V2;
use crate::apf::Disc;
use crate::apf::enclosing_circle::enclosing_circle;

/// How hits are told apart and grouped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensing {
    /// A hit within this distance of a known obstacle's edge, or of the box's edge, is explained by it (m).
    pub tolerance: f32,
    /// A hit within this distance of a remembered one adds nothing (m).
    pub spacing: f32,
    /// Hits closer than this belong to the same obstacle (single linkage, m).
    pub linkage: f32,
    /// Most hits remembered; further ones are dropped (memory stays bounded).
    pub capacity: usize,
}

impl Default for Sensing {
    fn default() -> Self {
        Sensing {
            tolerance: 0.05,
            spacing: 0.03,
            linkage: 0.3,
            capacity: 4096,
        }
    }
}

/// The obstacles found so far.
#[derive(Debug, Clone, Default)]
pub struct Discoveries {
    hits: Vec<V2>,
    obstacles: Vec<Disc>,
    /// Cluster of each hit (scratch of [`Discoveries::regroup`]).
    cluster: Vec<usize>,
    /// Hits of one cluster (scratch).
    members: Vec<V2>,
    /// Hits whose neighbours are still to be labelled (scratch).
    stack: Vec<usize>,
}

impl Discoveries {
    /// The obstacles found, each the smallest disc holding its hits.
    pub fn obstacles(&self) -> &[Disc] {
        &self.obstacles
    }

    /// Forgets everything found.
    pub fn clear(&mut self) {
        self.hits.clear();
        self.obstacles.clear();
    }

    /// Takes in one reading of a ring of `ranges` (ray k at `heading + 2 pi k / n`, distances from `position`,
    /// infinity for no hit) against the `known` obstacles and the `bounds`; returns whether an obstacle was
    /// found or grew.
    pub fn sense(
        &mut self,
        sensing: &Sensing,
        position: V2,
        heading: f32,
        ranges: &[f32],
        known: &[Disc],
        bounds: &Bounds,
    ) -> bool {
        let step = std::f32::consts::TAU / ranges.len().max(1) as f32;
        let tol = sensing.tolerance;
        let inner = Bounds {
            min: bounds.min + V2::new(tol, tol),
            max: bounds.max - V2::new(tol, tol),
        };
        let before = self.hits.len();
        for (k, &range) in ranges.iter().enumerate() {
            if !range.is_finite() || self.hits.len() >= sensing.capacity {
                continue;
            }
            let hit = position + V2::from_angle(heading + step * k as f32) * range;
            let explained = !inner.contains(hit)
                || known
                    .iter()
                    .any(|d| (hit - d.centre).length() <= d.radius + tol)
                || self
                    .hits
                    .iter()
                    .any(|h| (hit - *h).length() < sensing.spacing);
            if !explained {
                self.hits.push(hit);
            }
        }
        if self.hits.len() == before {
            return false;
        }
        self.regroup(sensing.linkage);
        true
    }

    /// Clusters the hits by single linkage and covers each cluster with its enclosing circle.
    fn regroup(&mut self, linkage: f32) {
        const UNLABELLED: usize = usize::MAX;
        self.cluster.clear();
        self.cluster.resize(self.hits.len(), UNLABELLED);
        // Flood fill: each unlabelled hit starts a cluster that takes every hit within reach of a member.
        let mut label = 0;
        for start in 0..self.hits.len() {
            if self.cluster[start] != UNLABELLED {
                continue;
            }
            self.cluster[start] = label;
            self.stack.push(start);
            while let Some(i) = self.stack.pop() {
                let at = self.hits[i];
                for (j, (hit, cluster)) in self.hits.iter().zip(&mut self.cluster).enumerate() {
                    if *cluster == UNLABELLED && (at - *hit).length() <= linkage {
                        *cluster = label;
                        self.stack.push(j);
                    }
                }
            }
            label += 1;
        }
        self.obstacles.clear();
        for c in 0..label {
            self.members.clear();
            self.members.extend(
                self.hits
                    .iter()
                    .zip(&self.cluster)
                    .filter(|(_, k)| **k == c)
                    .map(|(h, _)| *h),
            );
            self.obstacles.push(enclosing_circle(&self.members));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds() -> Bounds {
        Bounds {
            min: V2::ZERO,
            max: V2::new(10.0, 10.0),
        }
    }

    /// What a 24-ray ring at `position` facing +x reads of a disc, with nothing else in range (1 m).
    fn ring(position: V2, disc: &Disc) -> Vec<f32> {
        (0..24)
            .map(|k| {
                let dir = V2::from_angle(std::f32::consts::TAU * k as f32 / 24.0);
                // Ray-circle intersection, nearest positive root.
                let oc = position - disc.centre;
                let b = oc.dot(dir);
                let c = oc.dot(oc) - disc.radius * disc.radius;
                let h = b * b - c;
                let t = -b - h.max(0.0).sqrt();
                if h >= 0.0 && t > 0.0 && t <= 1.0 {
                    t
                } else {
                    f32::INFINITY
                }
            })
            .collect()
    }

    #[test]
    fn a_hidden_disc_is_found_and_a_known_one_is_not() {
        let disc = Disc {
            centre: V2::new(5.0, 5.0),
            radius: 0.3,
        };
        let sensing = Sensing::default();
        let at = V2::new(4.2, 5.0);
        let readings = ring(at, &disc);
        assert!(readings.iter().filter(|r| r.is_finite()).count() >= 3);
        let mut known = Discoveries::default();
        assert!(!known.sense(&sensing, at, 0.0, &readings, &[disc], &bounds()));
        assert!(known.obstacles().is_empty());
        let mut hidden = Discoveries::default();
        assert!(hidden.sense(&sensing, at, 0.0, &readings, &[], &bounds()));
        let found = hidden.obstacles();
        assert_eq!(found.len(), 1);
        // The seen side of the disc lies inside the found obstacle, which lies within the disc's reach.
        assert!((found[0].centre - disc.centre).length() < disc.radius);
        assert!(found[0].radius <= disc.radius + 1e-3);
        // Reading the same again finds nothing new.
        assert!(!hidden.sense(&sensing, at, 0.0, &readings, &[], &bounds()));
    }

    #[test]
    fn hits_far_apart_are_two_obstacles_and_walls_are_no_obstacle() {
        let sensing = Sensing::default();
        let mut d = Discoveries::default();
        // Rays 0 (+x) and 12 (-x) hit 0.9 m away on either side; ray 6 (+y) hits the box's edge.
        let mut ranges = vec![f32::INFINITY; 24];
        ranges[0] = 0.9;
        ranges[12] = 0.9;
        ranges[6] = 0.5;
        assert!(d.sense(&sensing, V2::new(5.0, 9.5), 0.0, &ranges, &[], &bounds()));
        assert_eq!(d.obstacles().len(), 2);
        d.clear();
        assert!(d.obstacles().is_empty());
    }
}
