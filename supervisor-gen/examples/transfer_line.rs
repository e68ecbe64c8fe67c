//! Writes the transfer line of `families::transfer_line` as model files, for timing `supervisor-gen synth` on it:
//! machines `m1.xml`..`mN.xml` (plants) and buffers `b1.xml`..`b(N-1).xml` (specifications).
//!
//! `cargo run --release -p supervisor-gen --example transfer_line -- <machines> <capacity> <dir>`

use std::path::PathBuf;
use std::process::ExitCode;

use supervisor_gen::families::transfer_line;
use supervisor_gen::xml_write::to_xml;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let parsed = match args.as_slice() {
        [n, k, dir] => n
            .parse::<usize>()
            .ok()
            .zip(k.parse::<usize>().ok())
            .map(|nk| (nk, PathBuf::from(dir))),
        _ => None,
    };
    let Some(((machines, capacity), dir)) = parsed.filter(|((n, k), _)| *n >= 2 && *k >= 1) else {
        eprintln!("usage: transfer_line <machines >= 2> <capacity >= 1> <dir>");
        return ExitCode::from(2);
    };
    let project = transfer_line(machines, capacity);
    let files = project
        .plants
        .iter()
        .enumerate()
        .map(|(i, a)| (format!("m{}.xml", i + 1), a))
        .chain(
            project
                .specs
                .iter()
                .enumerate()
                .map(|(i, a)| (format!("b{}.xml", i + 1), a)),
        );
    if let Err(err) = std::fs::create_dir_all(&dir) {
        eprintln!("error: cannot create {}: {err}", dir.display());
        return ExitCode::FAILURE;
    }
    for (name, automaton) in files {
        let path = dir.join(name);
        if let Err(err) = std::fs::write(&path, to_xml(automaton, &project.events)) {
            eprintln!("error: cannot write {}: {err}", path.display());
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}
