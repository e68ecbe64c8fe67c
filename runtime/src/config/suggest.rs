//! "Did you mean ...?" hints: the closest known name to a misspelt one.

/// Levenshtein distance between two strings, in characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut previous: Vec<usize> = (0..=b.len()).collect();
    let mut current = vec![0; b.len() + 1];
    for (i, ca) in a.chars().enumerate() {
        current[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitution = previous[j] + usize::from(ca != *cb);
            current[j + 1] = substitution.min(previous[j + 1] + 1).min(current[j] + 1);
        }
        std::mem::swap(&mut previous, &mut current);
    }
    previous[b.len()]
}

/// The known name closest to `wrong`, if any is close enough to be a plausible typo: a name that starts with
/// `wrong` (an abbreviation such as `epuck_prox`), or one within an edit distance of a third of its length.
pub(crate) fn closest<'a>(
    wrong: &str,
    known: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
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
pub(crate) fn did_you_mean<'a>(
    wrong: &str,
    known: impl IntoIterator<Item = &'a str>,
) -> Option<String> {
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
    }

    #[test]
    fn abbreviations_and_typos_find_their_name() {
        let known = ["epuck_proximity", "epuck_light", "proximity"];
        assert_eq!(closest("epuck_prox", known), Some("epuck_proximity"));
        assert_eq!(closest("epuck_ligth", known), Some("epuck_light"));
        assert_eq!(closest("camera", known), None);
    }
}
