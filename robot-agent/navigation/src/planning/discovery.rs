//! Obstacles a robot finds with its range finder that its map does not have (paper D's hidden obstacles): every
//! ray hit that no known obstacle and no edge of the box explains is remembered, and hits close together form one
//! obstacle. Obstacles are taken to be discs: three or more hits that lie on a circle (within the tolerance)
//! give that circle, the whole cylinder including its unseen side; otherwise the obstacle is the smallest disc
//! holding its hits, which grows as more of it comes into view.

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
    /// Largest radius a circle through the hits may have to be taken as the obstacle (m); hits along a wall or
    /// a nearly straight arc fit huge circles, and fall back to the smallest disc holding them.
    pub max_radius: f32,
}

impl Default for Sensing {
    fn default() -> Self {
        Sensing {
            tolerance: 0.05,
            spacing: 0.03,
            linkage: 0.3,
            capacity: 4096,
            max_radius: 1.5,
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
        let inner = bounds.inset(tol);
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
        self.regroup(sensing);
        true
    }

    /// Clusters the hits by single linkage and makes each cluster an obstacle.
    fn regroup(&mut self, sensing: &Sensing) {
        let linkage = sensing.linkage;
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
            let enclosing = enclosing_circle(&self.members);
            let obstacle = fit_circle(&self.members)
                .filter(|fit| fit.radius <= sensing.max_radius)
                .filter(|fit| {
                    self.members.iter().all(|p| {
                        ((*p - fit.centre).length() - fit.radius).abs() <= sensing.tolerance
                    })
                })
                .unwrap_or(enclosing);
            self.obstacles.push(obstacle);
        }
    }
}

/// The circle that best fits three or more points (Kasa's algebraic least squares: minimises
/// `sum (x^2 + y^2 + D x + E y + F)^2`), or `None` for fewer points or points on a line.
pub fn fit_circle(points: &[V2]) -> Option<Disc> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let (mx, my) = points.iter().fold((0.0, 0.0), |(x, y), p| {
        (x + f64::from(p.x) / n, y + f64::from(p.y) / n)
    });
    // Normal equations in coordinates centred on the mean (better conditioned).
    let (mut sxx, mut sxy, mut syy, mut sxz, mut syz, mut sz) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for p in points {
        let (x, y) = (f64::from(p.x) - mx, f64::from(p.y) - my);
        let z = x * x + y * y;
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
        sxz += x * z;
        syz += y * z;
        sz += z;
    }
    // With centred coordinates sum x = sum y = 0, so D and E solve a 2 x 2 system and F = -mean z.
    let det = sxx * syy - sxy * sxy;
    if det.abs() < 1e-12 * (sxx + syy).powi(2).max(1e-30) {
        return None;
    }
    let d = (-sxz * syy + syz * sxy) / det;
    let e = (-syz * sxx + sxz * sxy) / det;
    let f = -sz / n;
    let (cx, cy) = (-d / 2.0, -e / 2.0);
    let r2 = cx * cx + cy * cy - f;
    if !(r2 > 0.0 && r2.is_finite()) {
        return None;
    }
    Some(Disc {
        centre: V2::new((cx + mx) as f32, (cy + my) as f32),
        radius: r2.sqrt() as f32,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::map::Map;

    fn bounds() -> Bounds {
        Bounds {
            min: V2::ZERO,
            max: V2::new(10.0, 10.0),
        }
    }

    /// What a 24-ray ring at `position` facing +x reads of a disc, with nothing else in range (1 m).
    fn ring(position: V2, disc: &Disc) -> Vec<f32> {
        let map = Map {
            bounds: bounds(),
            discs: vec![*disc],
        };
        (0..24)
            .map(|k| {
                map.ray(
                    position,
                    V2::from_angle(std::f32::consts::TAU * k as f32 / 24.0),
                    1.0,
                )
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
        // Three or more hits on its edge give the whole cylinder, its unseen side too.
        assert!((found[0].centre - disc.centre).length() < 1e-3, "{found:?}");
        assert!((found[0].radius - disc.radius).abs() < 1e-3, "{found:?}");
        // Reading the same again finds nothing new.
        assert!(!hidden.sense(&sensing, at, 0.0, &readings, &[], &bounds()));
    }

    #[test]
    fn a_circle_is_fitted_to_points_on_it_and_not_to_a_line() {
        let on_arc: Vec<V2> = [0.1f32, 0.4, 0.9]
            .iter()
            .map(|a| V2::new(2.0, -1.0) + V2::from_angle(*a) * 0.5)
            .collect();
        let fit = fit_circle(&on_arc).unwrap();
        assert!(
            (fit.centre - V2::new(2.0, -1.0)).length() < 1e-4 && (fit.radius - 0.5).abs() < 1e-4
        );
        let line = [V2::ZERO, V2::new(1.0, 1.0), V2::new(2.0, 2.0)];
        assert_eq!(fit_circle(&line), None);
        assert_eq!(fit_circle(&on_arc[..2]), None);
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
