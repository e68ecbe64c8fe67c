//! Sensor noise: additive uniform `noise_level` (the thesis' and ARGoS' model) and additive Gaussian, each
//! followed by clamping to [0, 1]. Draws come from the caller's per-robot stream.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// `v <- clamp(v + U(-level, level), 0, 1)` for every value; nothing is drawn when `level` is 0.
pub fn uniform(level: f32, rng: &mut ChaCha8Rng, values: &mut [f32]) {
    if level > 0.0 {
        for v in values.iter_mut() {
            *v = (*v + rng.random_range(-level..=level)).clamp(0.0, 1.0);
        }
    }
}

/// The distribution of Gaussian noise of `std_dev`; `None` when there is none (0) or it cannot be (not finite).
pub fn normal(std_dev: f32) -> Option<Normal<f32>> {
    (std_dev > 0.0)
        .then(|| Normal::new(0.0f32, std_dev).ok())
        .flatten()
}

/// `v <- clamp(v + N(0, std_dev), 0, 1)` for every value; nothing is drawn when `std_dev` is 0.
pub fn gaussian(std_dev: f32, rng: &mut ChaCha8Rng, values: &mut [f32]) {
    if let Some(normal) = normal(std_dev) {
        for v in values.iter_mut() {
            *v = (*v + normal.sample(rng)).clamp(0.0, 1.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::{Purpose, stream};

    #[test]
    fn uniform_noise_stays_within_level_and_clamps() {
        let mut rng = stream(1, Purpose::Proximity, 0);
        let mut values = [0.5f32; 64];
        uniform(0.02, &mut rng, &mut values);
        assert!(values.iter().all(|v| (v - 0.5).abs() <= 0.02 + 1e-6));
        assert!(values.iter().any(|&v| v != 0.5));
        let mut edge = [0.0f32; 64];
        uniform(0.05, &mut rng, &mut edge);
        assert!(edge.iter().all(|v| (0.0..=0.05).contains(v)));
    }
}
