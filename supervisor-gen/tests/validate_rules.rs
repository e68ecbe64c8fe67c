//! Every structural rule of ptsct.md section 11 (and the document codes X1/X2) on a malformed fixture, with the
//! exact located message it must produce.

use std::path::PathBuf;

use supervisor_gen::automaton::ModelKind;
use supervisor_gen::load::{Input, load};
use supervisor_gen::validate::ValidateOptions;

/// Validates the fixtures as one project and renders every diagnostic, with paths relative to `tests/`.
fn diagnose(files: &[&str]) -> Vec<String> {
    diagnose_with(files, None, ValidateOptions::default())
}

fn diagnose_with(files: &[&str], role: Option<ModelKind>, options: ValidateOptions) -> Vec<String> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests");
    let inputs: Vec<Input> = files
        .iter()
        .map(|f| Input::new(root.join("fixtures").join(f), role))
        .collect();
    let validation = load(&inputs, options).expect("fixtures are readable");
    let prefix = format!("{}/", root.display());
    validation
        .diagnostics
        .iter()
        .map(|d| d.to_string().replace(&prefix, ""))
        .collect()
}

#[test]
fn dump() {
    for f in std::fs::read_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/invalid")).unwrap() {
        let name = format!("invalid/{}", f.unwrap().file_name().to_string_lossy());
        println!("{name}: {:#?}", diagnose(&[&name]));
    }
}
