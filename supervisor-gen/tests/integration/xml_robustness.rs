//! User input never panics the reader or the validator: arbitrary edits of a valid model and arbitrary XML-ish text
//! either read and validate or produce located diagnostics.

use std::path::PathBuf;

use proptest::prelude::*;
use supervisor_gen::automaton::ModelKind;
use supervisor_gen::validate::{ValidateOptions, validate};
use supervisor_gen::xml_read::read_model;

fn example() -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/example_10_3.xml");
    std::fs::read_to_string(path).expect("fixture is readable")
}

/// Reads and validates `text`; every diagnostic must lie inside the text.
fn check(text: &str) {
    let lines = u32::try_from(text.lines().count())
        .unwrap_or(u32::MAX)
        .max(1);
    let diagnostics = match read_model("fuzz.xml", text, Some(ModelKind::Spec)) {
        Ok(source) => validate(&[source], ValidateOptions::default()).diagnostics,
        Err(diagnostics) => diagnostics,
    };
    for d in diagnostics {
        assert!(d.line >= 1 && d.line <= lines + 1 && d.column >= 1, "{d}");
    }
}

proptest! {
    #[test]
    fn edited_models_never_panic(edits in prop::collection::vec((any::<prop::sample::Index>(), 0..3u8, "[<>\"'=/&;a-z0-9 \n!?-]{0,3}"), 1..6)) {
        let mut text = example();
        for (at, kind, insert) in edits {
            let mut cut = at.index(text.len() + 1);
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            match kind {
                0 => text.insert_str(cut, &insert),
                1 => {
                    let end = (cut + insert.len()).min(text.len());
                    if text.is_char_boundary(end) {
                        text.replace_range(cut..end, "");
                    }
                }
                _ => {
                    let end = (cut + insert.len()).min(text.len());
                    if text.is_char_boundary(end) {
                        text.replace_range(cut..end, &insert);
                    }
                }
            }
        }
        check(&text);
    }

    #[test]
    fn arbitrary_markup_never_panics(text in "(<[a-z]{0,9}( [a-z]{1,5}=\"[^\"]{0,4}\")*/?>|</[a-z]{0,9}>|[ \na-zé&;]{0,5}){0,12}") {
        check(&text);
    }
}
