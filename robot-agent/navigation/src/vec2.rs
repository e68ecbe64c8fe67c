//! A vector of the plane, and the angle helpers the navigation methods use.

use std::f32::consts::PI;
use std::ops::{Add, AddAssign, Mul, Neg, Sub};

/// A vector (or point) of the plane, in metres.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct V2 {
    /// x.
    pub x: f32,
    /// y.
    pub y: f32,
}

impl V2 {
    /// The zero vector.
    pub const ZERO: V2 = V2 { x: 0.0, y: 0.0 };

    /// `(x, y)`.
    pub const fn new(x: f32, y: f32) -> V2 {
        V2 { x, y }
    }

    /// The unit vector at `angle` radians counter-clockwise from +x.
    pub fn from_angle(angle: f32) -> V2 {
        V2::new(angle.cos(), angle.sin())
    }

    /// Euclidean length.
    pub fn length(self) -> f32 {
        self.x.hypot(self.y)
    }

    /// Angle in radians counter-clockwise from +x, in (-pi, pi].
    pub fn angle(self) -> f32 {
        self.y.atan2(self.x)
    }

    /// Dot product.
    pub fn dot(self, other: V2) -> f32 {
        self.x * other.x + self.y * other.y
    }

    /// z component of the cross product `self x other`.
    pub fn cross(self, other: V2) -> f32 {
        self.x * other.y - self.y * other.x
    }

    /// This vector turned by `angle` radians counter-clockwise.
    pub fn rotated(self, angle: f32) -> V2 {
        let (s, c) = angle.sin_cos();
        V2::new(c * self.x - s * self.y, s * self.x + c * self.y)
    }

    /// Whether both coordinates are finite.
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
}

impl Add for V2 {
    type Output = V2;
    fn add(self, o: V2) -> V2 {
        V2::new(self.x + o.x, self.y + o.y)
    }
}

impl AddAssign for V2 {
    fn add_assign(&mut self, o: V2) {
        self.x += o.x;
        self.y += o.y;
    }
}

impl Sub for V2 {
    type Output = V2;
    fn sub(self, o: V2) -> V2 {
        V2::new(self.x - o.x, self.y - o.y)
    }
}

impl Neg for V2 {
    type Output = V2;
    fn neg(self) -> V2 {
        V2::new(-self.x, -self.y)
    }
}

impl Mul<f32> for V2 {
    type Output = V2;
    fn mul(self, k: f32) -> V2 {
        V2::new(self.x * k, self.y * k)
    }
}

/// `angle` mapped into (-pi, pi] (the paper's `wrap`).
pub fn wrap(angle: f32) -> f32 {
    let mut a = angle.rem_euclid(2.0 * PI);
    if a > PI {
        a -= 2.0 * PI;
    }
    a
}

/// The sign with the tie broken towards +1 (`sign(0) := +1`, the paper's suggested tie-break: a zero would cancel
/// the adaptive force).
pub fn sign(x: f32) -> f32 {
    if x < 0.0 { -1.0 } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_maps_into_the_half_open_interval() {
        assert!((wrap(3.0 * PI) - PI).abs() < 1e-5);
        assert!((wrap(-PI) - PI).abs() < 1e-5);
        assert!((wrap(-0.5) + 0.5).abs() < 1e-6);
        assert!((wrap(2.0 * PI + 0.25) - 0.25).abs() < 1e-5);
    }

    #[test]
    fn rotation_is_counter_clockwise() {
        let v = V2::new(1.0, 0.0).rotated(PI / 2.0);
        assert!(v.x.abs() < 1e-6 && (v.y - 1.0).abs() < 1e-6);
        assert_eq!(sign(0.0), 1.0);
        assert_eq!(sign(-2.0), -1.0);
    }
}
