//! The parser never panics on user input: random edits of a valid configuration either load or fail with errors
//! located inside the file.

use proptest::prelude::*;
use swarm_contract::config::Experiment;

const THESIS: &str = include_str!("../../../../configs/obstacle_avoidance/thesis_example.argos");

/// One edit: delete `len` characters at a relative position, then insert `text` there.
fn edit(source: &str, at: f64, len: usize, text: &str) -> String {
    let chars: Vec<char> = source.chars().collect();
    let start = ((chars.len() as f64) * at) as usize;
    let end = (start + len).min(chars.len());
    chars[..start]
        .iter()
        .chain(text.chars().collect::<Vec<_>>().iter())
        .chain(chars[end..].iter())
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn random_edits_never_panic_and_errors_stay_inside_the_file(
        edits in proptest::collection::vec((0.0f64..1.0, 0usize..12, "[<>/=\"' a-z0-9,.&;!?-]{0,8}"), 1..4)
    ) {
        let mut text = THESIS.to_string();
        for (at, len, insert) in &edits {
            text = edit(&text, *at, *len, insert);
        }
        let lines = u32::try_from(text.lines().count()).unwrap_or(u32::MAX) + 1;
        if let Err(errors) = Experiment::parse("edited.argos", &text) {
            prop_assert!(!errors.errors.is_empty());
            for e in &errors.errors {
                prop_assert!(e.location.line >= 1 && e.location.line <= lines, "{e} outside {lines} lines");
                prop_assert!(e.location.column >= 1, "{e}");
            }
        }
    }
}
