//! The minimum enclosing circle of a set of points (Welzl's algorithm in its incremental form), for the
//! virtual obstacles that cover a cluster of robots (eq. 10).

use super::Disc;
use crate::V2;

/// Slack for "on the circle" under rounding, in metres.
const SLACK: f32 = 1e-5;

fn contains(circle: &Disc, p: V2) -> bool {
    (p - circle.centre).length() <= circle.radius + SLACK
}

fn through_two(a: V2, b: V2) -> Disc {
    let centre = (a + b) * 0.5;
    Disc {
        centre,
        radius: (a - centre).length(),
    }
}

/// The circle through three points; for (nearly) collinear points, the widest circle on two of them.
fn through_three(a: V2, b: V2, c: V2) -> Disc {
    let (ab, ac) = (b - a, c - a);
    let d = 2.0 * ab.cross(ac);
    if d.abs() < 1e-9 {
        let widest = [through_two(a, b), through_two(a, c), through_two(b, c)];
        return widest.into_iter().fold(
            widest[0],
            |best, c| if c.radius > best.radius { c } else { best },
        );
    }
    let (l_ab, l_ac) = (ab.dot(ab), ac.dot(ac));
    let offset = V2::new(ac.y * l_ab - ab.y * l_ac, ab.x * l_ac - ac.x * l_ab) * (1.0 / d);
    Disc {
        centre: a + offset,
        radius: offset.length(),
    }
}

/// The smallest circle containing every point of `points` (a zero circle at the origin for none). Expected
/// linear time for points in random order, cubic in the worst case: the clusters it serves have a handful of
/// members.
pub fn enclosing_circle(points: &[V2]) -> Disc {
    let Some(&first) = points.first() else {
        return Disc {
            centre: V2::ZERO,
            radius: 0.0,
        };
    };
    let mut circle = Disc {
        centre: first,
        radius: 0.0,
    };
    for i in 1..points.len() {
        if contains(&circle, points[i]) {
            continue;
        }
        circle = Disc {
            centre: points[i],
            radius: 0.0,
        };
        for j in 0..i {
            if contains(&circle, points[j]) {
                continue;
            }
            circle = through_two(points[i], points[j]);
            for k in 0..j {
                if !contains(&circle, points[k]) {
                    circle = through_three(points[i], points[j], points[k]);
                }
            }
        }
    }
    circle
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    #[test]
    fn hand_computed_circles() {
        let two = enclosing_circle(&[V2::new(0.0, 0.0), V2::new(2.0, 0.0)]);
        assert_eq!(two.centre, V2::new(1.0, 0.0));
        assert_eq!(two.radius, 1.0);
        // A right triangle's circle has its hypotenuse as diameter.
        let right = enclosing_circle(&[V2::new(0.0, 0.0), V2::new(4.0, 0.0), V2::new(0.0, 3.0)]);
        assert!((right.centre - V2::new(2.0, 1.5)).length() < 1e-5);
        assert!((right.radius - 2.5).abs() < 1e-5);
        // An obtuse triangle's circle is its longest side's.
        let obtuse = enclosing_circle(&[V2::new(0.0, 0.0), V2::new(1.0, 0.1), V2::new(2.0, 0.0)]);
        assert!((obtuse.centre - V2::new(1.0, 0.0)).length() < 1e-5);
        // An equilateral triangle of side 1: radius 1/sqrt(3).
        let h = 3f32.sqrt() / 2.0;
        let equilateral =
            enclosing_circle(&[V2::new(0.0, 0.0), V2::new(1.0, 0.0), V2::new(0.5, h)]);
        assert!((equilateral.radius - 1.0 / 3f32.sqrt()).abs() < 1e-5);
    }

    proptest! {
        #[test]
        fn every_point_is_inside_and_some_point_is_on_the_circle(
            points in prop::collection::vec((-5.0f32..5.0, -5.0f32..5.0), 1..12)
        ) {
            let points: Vec<V2> = points.into_iter().map(|(x, y)| V2::new(x, y)).collect();
            let circle = enclosing_circle(&points);
            let farthest = points
                .iter()
                .map(|&p| (p - circle.centre).length())
                .fold(0.0f32, f32::max);
            prop_assert!(farthest <= circle.radius + 1e-3);
            prop_assert!(farthest >= circle.radius - 1e-3);
            // No smaller than the widest pair needs.
            for &a in &points {
                for &b in &points {
                    prop_assert!((a - b).length() <= 2.0 * circle.radius + 1e-3);
                }
            }
        }
    }
}
