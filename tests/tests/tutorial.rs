//! docs/tutorial.md cannot rot: every file it shows must be the repository's (whole files equal, Rust excerpts
//! contained), and every command it gives runs in a scratch folder built from the files it shows. The code that
//! docs/controllers.md quotes from the worked example must be in the files it names, too.
//!
//! A fenced block whose info string names a path (```` ```xml configs/phototaxis/phototaxis.argos ````) is a file:
//! the test compares it with the repository and writes it into the scratch folder (Rust code is compared only).
//! Each line of a ```` ```sh ```` block runs in the scratch folder through `sh`, with `cargo run --release --bin
//! NAME --` replaced by the test build's program. A ```` ```python ```` block runs with a Python that has pandas
//! (`.ci/run` installs Debian's `python3-pandas`); the block asserts what it expects.

use std::path::{Path, PathBuf};
use std::process::Command;

use swarm_system_tests::{bin_dir, workspace_file};

/// One fenced block of the page.
struct Block {
    language: String,
    path: Option<String>,
    text: String,
    line: usize,
}

fn blocks(page: &str) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut current: Option<Block> = None;
    for (i, line) in page.lines().enumerate() {
        match (&mut current, line.strip_prefix("```")) {
            (None, Some(info)) => {
                let mut words = info.split_whitespace();
                current = Some(Block {
                    language: words.next().unwrap_or_default().to_owned(),
                    path: words.next().map(str::to_owned),
                    text: String::new(),
                    line: i + 1,
                });
            }
            (Some(_), Some("")) => blocks.extend(current.take()),
            (Some(block), _) => {
                block.text.push_str(line);
                block.text.push('\n');
            }
            (None, None) => {}
        }
    }
    blocks
}

/// A Python interpreter that can import pandas.
fn python_with_pandas() -> Option<&'static str> {
    ["python3", "/usr/bin/python3"].into_iter().find(|python| {
        Command::new(python)
            .args(["-c", "import pandas"])
            .output()
            .is_ok_and(|o| o.status.success())
    })
}

/// `line` with `cargo run --release --bin NAME --` replaced by the test build's program.
fn with_built_programs(line: &str) -> String {
    match line
        .strip_prefix("cargo run --release --bin ")
        .and_then(|rest| rest.split_once(" -- "))
    {
        Some((name, args)) => format!("'{}' {args}", bin_dir().join(name).display()),
        None => line.to_owned(),
    }
}

fn run_in(dir: &Path, mut command: Command, what: &str) {
    let output = command
        .current_dir(dir)
        .env("SWARM_BIN_DIR", bin_dir())
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot start: {e}"));
    assert!(
        output.status.success(),
        "{what} failed ({}):\n--- stdout\n{}\n--- stderr\n{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

#[test]
fn every_file_of_the_tutorial_is_the_repositorys_and_every_command_runs() {
    let page_path = workspace_file("docs/tutorial.md");
    let page = std::fs::read_to_string(&page_path).expect("docs/tutorial.md");
    let scratch = tempfile::tempdir().expect("a temporary directory");
    let blocks = blocks(&page);
    assert!(
        blocks.iter().any(|b| b.language == "sh") && blocks.iter().any(|b| b.path.is_some()),
        "the tutorial shows files and commands"
    );
    for block in &blocks {
        let Some(path) = &block.path else { continue };
        let repository = std::fs::read_to_string(workspace_file(path))
            .unwrap_or_else(|e| panic!("docs/tutorial.md:{} names {path}: {e}", block.line));
        if block.language == "rust" {
            assert!(
                repository.contains(block.text.trim_end()),
                "docs/tutorial.md:{}: the code shown is not in {path}",
                block.line
            );
            continue;
        }
        assert_eq!(
            block.text.trim_end(),
            repository.trim_end(),
            "docs/tutorial.md:{}: the file shown differs from {path}",
            block.line
        );
        let target: PathBuf = scratch.path().join(path);
        std::fs::create_dir_all(target.parent().expect("a folder")).expect("a scratch folder");
        std::fs::write(&target, &block.text).expect("a scratch file");
    }
    for block in &blocks {
        match block.language.as_str() {
            "sh" => {
                for line in block.text.lines().map(str::trim) {
                    if line.is_empty() || line.starts_with('#') {
                        continue;
                    }
                    let mut command = Command::new("sh");
                    command.args(["-c", &with_built_programs(line)]);
                    run_in(
                        scratch.path(),
                        command,
                        &format!("docs/tutorial.md:{}: `{line}`", block.line),
                    );
                }
            }
            "python" => {
                let python = python_with_pandas().unwrap_or_else(|| {
                    panic!(
                        "docs/tutorial.md:{} needs Python with pandas (Debian: apt-get install python3-pandas)",
                        block.line
                    )
                });
                let mut command = Command::new(python);
                command.args(["-c", &block.text]);
                run_in(
                    scratch.path(),
                    command,
                    &format!("docs/tutorial.md:{}: the Python block", block.line),
                );
            }
            _ => {}
        }
    }
    for made in [
        "supervisors/S_E_steer.xml",
        "runs/phototaxis/summary.json",
        "runs/phototaxis_grid/results.csv",
    ] {
        assert!(
            scratch.path().join(made).is_file(),
            "the tutorial made {made}"
        );
    }
}

#[test]
fn the_controller_guide_quotes_the_repositorys_code() {
    let page = std::fs::read_to_string(workspace_file("docs/controllers.md"))
        .expect("docs/controllers.md");
    let quoted: Vec<Block> = blocks(&page)
        .into_iter()
        .filter(|b| b.path.is_some())
        .collect();
    assert!(quoted.len() >= 4, "the guide quotes the worked example");
    for block in quoted {
        let path = block.path.as_deref().unwrap_or_default();
        let file = std::fs::read_to_string(workspace_file(path))
            .unwrap_or_else(|e| panic!("docs/controllers.md:{} names {path}: {e}", block.line));
        assert!(
            file.contains(block.text.trim_end()),
            "docs/controllers.md:{}: the code shown is not in {path}",
            block.line
        );
    }
}
