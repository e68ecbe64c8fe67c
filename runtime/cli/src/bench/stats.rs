//! Order statistics for benchmark samples.

/// The median of `values` (the upper middle one for an even count); `None` when empty.
pub fn median(values: &[f64]) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.get(sorted.len() / 2).copied()
}

/// The `q` quantile (0..=1) of `sorted`, nearest rank; `None` when empty.
pub fn quantile<T: Copy>(sorted: &[T], q: f64) -> Option<T> {
    if sorted.is_empty() {
        return None;
    }
    let rank = ((sorted.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize;
    sorted.get(rank).copied()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_an_odd_and_an_even_count() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(3.0));
        assert_eq!(median(&[]), None);
    }

    #[test]
    fn quantiles_pick_the_nearest_rank() {
        let sorted = [10, 20, 30, 40, 50];
        assert_eq!(quantile(&sorted, 0.5), Some(30));
        assert_eq!(quantile(&sorted, 0.99), Some(50));
        assert_eq!(quantile(&sorted, 0.0), Some(10));
        assert_eq!(quantile::<u32>(&[], 0.5), None);
    }
}
