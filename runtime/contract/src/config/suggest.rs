//! "Did you mean ...?" hints: the closest known name to a misspelt one.

/// Edit distance between two strings in characters: insertions, deletions, substitutions and swaps of two
/// neighbouring characters each cost 1 (optimal string alignment).
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let width = b.len() + 1;
    let mut d = vec![0usize; (a.len() + 1) * width];
    for i in 0..=a.len() {
        d[i * width] = i;
    }
    for (j, cell) in d.iter_mut().enumerate().take(width) {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut best = (d[(i - 1) * width + j] + 1)
                .min(d[i * width + j - 1] + 1)
                .min(d[(i - 1) * width + j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[(i - 2) * width + j - 2] + 1);
            }
            d[i * width + j] = best;
        }
    }
    d[a.len() * width + b.len()]
}

/// The known name closest to `wrong`, if any is close enough to be a plausible typo: a name that starts with
/// `wrong` (an abbreviation such as `epuck_prox`), or one within an edit distance of a third of its length.
pub fn closest<'a>(wrong: &str, known: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let known: Vec<&str> = known.into_iter().collect();
    if wrong.chars().count() >= 3
        && let Some(prefixed) = known
            .iter()
            .filter(|k| k.starts_with(wrong))
            .min_by_key(|k| k.len())
    {
        return Some(prefixed);
    }
    known
        .into_iter()
        .map(|k| (edit_distance(wrong, k), k))
        .filter(|(d, k)| *d <= (k.chars().count().max(wrong.chars().count()) / 3).max(1))
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k)
}

/// A hint `did you mean 'x'?` for `wrong`, if a close name exists.
pub fn did_you_mean<'a>(wrong: &str, known: impl IntoIterator<Item = &'a str>) -> Option<String> {
    closest(wrong, known).map(|k| format!("did you mean '{k}'?"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_counts_insertions_deletions_substitutions() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("same", "same"), 0);
        assert_eq!(
            edit_distance("fdc", "fcd"),
            1,
            "a swap of neighbours costs 1"
        );
    }

    #[test]
    fn abbreviations_and_typos_find_their_name() {
        let known = ["epuck_proximity", "epuck_light", "proximity"];
        assert_eq!(closest("epuck_prox", known), Some("epuck_proximity"));
        assert_eq!(closest("epuck_ligth", known), Some("epuck_light"));
        assert_eq!(closest("camera", known), None);
    }
}
