//! Taguchi's L9 design for tuning four three-level parameters in nine runs (A.5.4): the orthogonal array, the
//! larger-the-better signal-to-noise ratio of a run's responses, and the level of each factor with the best
//! mean ratio (its main effect).

/// The L9(3^4) orthogonal array: row r gives the level (0, 1 or 2) of each of the four factors in run r. Every
/// pair of columns holds each of the nine level pairs once.
pub const L9: [[usize; 4]; 9] = [
    [0, 0, 0, 0],
    [0, 1, 1, 1],
    [0, 2, 2, 2],
    [1, 0, 1, 2],
    [1, 1, 2, 0],
    [1, 2, 0, 1],
    [2, 0, 2, 1],
    [2, 1, 0, 2],
    [2, 2, 1, 0],
];

/// Larger-the-better signal-to-noise ratio in dB, `-10 log10(mean(1 / y^2))`; `None` for no responses or a
/// response that is not positive.
pub fn larger_the_better(responses: &[f64]) -> Option<f64> {
    if responses.is_empty() || responses.iter().any(|&y| y.is_nan() || y <= 0.0) {
        return None;
    }
    let mean = responses.iter().map(|y| 1.0 / (y * y)).sum::<f64>() / responses.len() as f64;
    Some(-10.0 * mean.log10())
}

/// The mean ratio of each level of each factor over the runs at that level (`effects[factor][level]`), from the
/// nine runs' ratios in L9's row order.
pub fn main_effects(ratios: &[f64; 9]) -> [[f64; 3]; 4] {
    let mut effects = [[0.0; 3]; 4];
    for (row, ratio) in L9.iter().zip(ratios) {
        for (factor, &level) in row.iter().enumerate() {
            effects[factor][level] += ratio / 3.0;
        }
    }
    effects
}

/// The level of each factor with the best mean ratio (the first on ties).
pub fn best_levels(effects: &[[f64; 3]; 4]) -> [usize; 4] {
    effects.map(|levels| (0..3).fold(0, |best, l| if levels[l] > levels[best] { l } else { best }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_array_is_orthogonal() {
        for a in 0..4 {
            for b in a + 1..4 {
                let mut pairs: Vec<(usize, usize)> = L9.iter().map(|r| (r[a], r[b])).collect();
                pairs.sort_unstable();
                pairs.dedup();
                assert_eq!(pairs.len(), 9, "columns {a} and {b}");
            }
        }
    }

    #[test]
    fn ratios_and_effects_of_a_hand_computed_case() {
        // Responses 1 and 10: mean(1/y^2) = (1 + 0.01) / 2 = 0.505 -> 2.967 dB.
        let sn = larger_the_better(&[1.0, 10.0]).unwrap();
        assert!((sn - 2.9671).abs() < 1e-3, "{sn}");
        assert_eq!(larger_the_better(&[]), None);
        assert_eq!(larger_the_better(&[1.0, -0.5]), None);
        // Ratios equal to the run number: factor 0's levels hold runs 1-3, 4-6 and 7-9.
        let ratios = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0];
        let effects = main_effects(&ratios);
        assert_eq!(effects[0], [2.0, 5.0, 8.0]);
        // Factor 1's level 0 holds runs 1, 4 and 7.
        assert_eq!(effects[1][0], 4.0);
        assert_eq!(best_levels(&effects)[0], 2);
    }
}
