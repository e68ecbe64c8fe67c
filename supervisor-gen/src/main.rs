//! `supervisor-gen` command line: validate, synthesise, draw and compile ptSCT supervisors.
//!
//! Exit codes: 0 success; 1 invalid input (any validation error) or an impossible specification; 2 usage or I/O
//! problems; 3 a reduced supervisor failed its equivalence check (`synth --reduce`; nothing is written). Diagnostics go to stderr in `file:line:col: error[CODE]: message` form; summaries go to stdout.

use std::collections::HashMap;
use std::fs::File;
use std::io::{BufWriter, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod drawing;
mod synth_output;
mod terminal_progress;

use drawing::{Drawer, draw_synthesis};
use synth_output::{print_summary, supervisors_xml, write_compiled, write_models};

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};

use supervisor_gen::architecture::Architecture;
use supervisor_gen::automaton::ModelKind;
use supervisor_gen::build::{BuildError, BuildRequest, Built, Synthesised, build, synthesise};
use supervisor_gen::codegen::generate_rust;
use supervisor_gen::convert::to_automata;
use supervisor_gen::diagnostics::{Diagnostic, Severity};
use supervisor_gen::dot::{self, ImageFormat, Images, ProbLabels};
use supervisor_gen::load::{Input, load};
use supervisor_gen::reduce::{ReduceLimits, reduce_synthesis};
use supervisor_gen::report::{ReductionFiles, Report, SkippedOutput};
use supervisor_gen::validate::{CheckedModel, ValidateOptions};

/// ptSCT toolchain: validate plant and specification automata, synthesise, minimise, draw and compile supervisors.
///
/// Model files are plain paths (no globs): the thesis XML format (`<automata>`) or Nadzoru2 FSA files
/// (`<model type="FSA">`), told apart by their root element.
/// Exit codes: 0 success, 1 invalid input or impossible specification, 2 usage or I/O error, 3 a reduced supervisor
/// failed its equivalence check (`synth --reduce`).
#[derive(Debug, Parser)]
#[command(
    name = "supervisor-gen",
    version,
    after_help = "The model format, every attribute and every diagnostic code: docs/models.md. The theory the \
                  tool follows: docs/ptsct.md. A first task from models to a running swarm: docs/tutorial.md."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Validate, synthesise and write supervisors XML, supervisors.ptsct, supervisors.rs, report.json (and drawings).
    Synth(SynthArgs),
    /// Validate model files only and print every diagnostic.
    Check(CheckArgs),
    /// Draw model files as DOT (and SVG/PNG when Graphviz `dot` is on PATH).
    Draw(DrawArgs),
    /// Synthesise and write only the generated Rust module.
    Codegen(CodegenArgs),
}

/// The models of a project.
#[derive(Debug, Args)]
struct ProjectArgs {
    /// Plant (free-behaviour) model files; repeat the flag or list several paths.
    #[arg(long = "plant", value_name = "FILE", num_args = 1.., required = true)]
    plants: Vec<PathBuf>,
    /// Specification model files; repeat the flag or list several paths.
    #[arg(long = "spec", value_name = "FILE", num_args = 1.., required = true)]
    specs: Vec<PathBuf>,
    /// Supervisor architecture (section 6.6).
    #[arg(long, value_enum, default_value_t = Mode::LocalModular)]
    mode: Mode,
    /// Keep specification weights as written (no input normalisation, no monolithic renormalisation).
    #[arg(long)]
    raw_weights: bool,
    /// Keep plant probabilities as factors (compatibility with the thesis' literal composition rule, A5).
    #[arg(long)]
    thesis_literal_probabilities: bool,
}

#[derive(Debug, Args)]
struct SynthArgs {
    #[command(flatten)]
    project: ProjectArgs,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Also draw every input, intermediate (G, E, K, SupC) and final supervisor into DIR/drawings.
    #[arg(long)]
    draw: bool,
    /// Reduce every supervisor (control congruence, Su and Wonham), check each reduction against the unreduced
    /// closed loop, and write the reduced set with the plant observers it needs; exit 3 if a check fails.
    #[arg(long)]
    reduce: bool,
    #[command(flatten)]
    images: ImageArgs,
}

/// Image options of drawings (used only when Graphviz `dot` is on PATH; DOT files are always written).
#[derive(Debug, Args)]
struct ImageArgs {
    /// Image formats rendered next to each DOT file; repeat or separate with commas.
    #[arg(long = "image-format", value_enum, value_delimiter = ',', default_values_t = [Format::Svg, Format::Png])]
    formats: Vec<Format>,
    /// Resolution of PNG images in dots per inch (Graphviz' default is 96).
    #[arg(long, value_name = "DPI")]
    dpi: Option<u32>,
}

impl ImageArgs {
    fn images(&self) -> Images {
        Images {
            formats: self.formats.iter().map(|&f| f.into()).collect(),
            dpi: self.dpi,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum Format {
    Svg,
    Png,
    Pdf,
}

impl From<Format> for ImageFormat {
    fn from(format: Format) -> Self {
        match format {
            Format::Svg => ImageFormat::Svg,
            Format::Png => ImageFormat::Png,
            Format::Pdf => ImageFormat::Pdf,
        }
    }
}

#[derive(Debug, Args)]
struct CheckArgs {
    /// Model files whose own `type` attribute says what they are.
    #[arg(value_name = "FILE")]
    files: Vec<PathBuf>,
    /// Files to check as plants (needed for Nadzoru2 files, which have no type).
    #[arg(long = "plant", value_name = "FILE", num_args = 1..)]
    plants: Vec<PathBuf>,
    /// Files to check as specifications.
    #[arg(long = "spec", value_name = "FILE", num_args = 1..)]
    specs: Vec<PathBuf>,
    /// Keep plant probabilities (no W4; V12 applies to plants).
    #[arg(long)]
    thesis_literal_probabilities: bool,
}

#[derive(Debug, Args)]
struct DrawArgs {
    #[command(flatten)]
    files: CheckArgs,
    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    #[command(flatten)]
    images: ImageArgs,
}

#[derive(Debug, Args)]
struct CodegenArgs {
    #[command(flatten)]
    project: ProjectArgs,
    /// The Rust file to write.
    #[arg(long, value_name = "FILE.rs")]
    out: PathBuf,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum Mode {
    Monolithic,
    Modular,
    LocalModular,
}

impl From<Mode> for Architecture {
    fn from(mode: Mode) -> Self {
        match mode {
            Mode::Monolithic => Architecture::Monolithic,
            Mode::Modular => Architecture::Modular,
            Mode::LocalModular => Architecture::LocalModular,
        }
    }
}

/// How a command ended when it did not fail with an I/O or usage error.
enum Outcome {
    Success,
    /// Invalid input or an impossible specification (already explained on stderr).
    Rejected,
    /// A reduced supervisor failed its equivalence check (already explained on stderr).
    ReductionRefused,
}

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn")),
        )
        .with_writer(std::io::stderr)
        .with_ansi(std::io::stderr().is_terminal())
        .init();
    let cli = Cli::parse();
    terminal_progress::install();
    let result = match cli.command {
        Command::Synth(args) => synth(&args),
        Command::Check(args) => check(&args),
        Command::Draw(args) => draw(&args),
        Command::Codegen(args) => codegen(&args),
    };
    terminal_progress::finish();
    match result {
        Ok(Outcome::Success) => ExitCode::SUCCESS,
        Ok(Outcome::Rejected) => ExitCode::from(1),
        Ok(Outcome::ReductionRefused) => ExitCode::from(3),
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(2)
        }
    }
}

/// Inputs of the files of a `check`/`draw` command.
fn check_inputs(args: &CheckArgs) -> Vec<Input> {
    let typed = args.files.iter().map(|p| Input::new(p, None));
    let plants = args
        .plants
        .iter()
        .map(|p| Input::new(p, Some(ModelKind::Plant)));
    let specs = args
        .specs
        .iter()
        .map(|p| Input::new(p, Some(ModelKind::Spec)));
    typed.chain(plants).chain(specs).collect()
}

/// Prints every diagnostic and a count line to stderr.
fn print_diagnostics(diagnostics: &[Diagnostic]) {
    for d in diagnostics {
        eprintln!("{d}");
    }
    let errors = diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .count();
    let warnings = diagnostics.len() - errors;
    if errors > 0 {
        eprintln!("{errors} error(s), {warnings} warning(s)");
    } else if warnings > 0 {
        eprintln!("{warnings} warning(s)");
    }
}

/// Loads and validates; prints diagnostics. `None` if the input is invalid.
fn validated(inputs: &[Input], options: ValidateOptions) -> Result<Option<Vec<CheckedModel>>> {
    if inputs.is_empty() {
        anyhow::bail!("no model files given");
    }
    let validation = load(inputs, options)?;
    print_diagnostics(&validation.diagnostics);
    Ok(validation.models)
}

fn check(args: &CheckArgs) -> Result<Outcome> {
    let options = ValidateOptions {
        thesis_literal_probabilities: args.thesis_literal_probabilities,
        ..ValidateOptions::default()
    };
    let inputs = check_inputs(args);
    Ok(match validated(&inputs, options)? {
        Some(_) => {
            println!("{} model(s) valid", inputs.len());
            Outcome::Success
        }
        None => Outcome::Rejected,
    })
}

fn draw(args: &DrawArgs) -> Result<Outcome> {
    let options = ValidateOptions {
        thesis_literal_probabilities: args.files.thesis_literal_probabilities,
        ..ValidateOptions::default()
    };
    let Some(models) = validated(&check_inputs(&args.files), options)? else {
        return Ok(Outcome::Rejected);
    };
    let (events, automata) = to_automata(&models)?;
    create_dir(&args.out)?;
    let mut drawer = Drawer {
        dir: &args.out,
        events: &events,
        images: args.images.images(),
        skipped: Vec::new(),
    };
    let mut written = 0;
    for a in &automata {
        // Weights count in specifications (and in plants only with thesis-literal probabilities); supervisors
        // already carry the probabilities the runtime uses.
        let probs = match a.kind() {
            ModelKind::Spec => ProbLabels::PerState,
            ModelKind::Plant if options.thesis_literal_probabilities => ProbLabels::PerState,
            _ => ProbLabels::Stored,
        };
        written += drawer.draw(&dot::file_stem(a.name()), a, &HashMap::new(), probs)?;
    }
    println!(
        "{written} drawing file(s) written to {}",
        args.out.display()
    );
    for s in &drawer.skipped {
        eprintln!("warning: {} not written: {}", s.output, s.reason);
    }
    Ok(Outcome::Success)
}

/// The build request of a project's arguments; `keep_targets` keeps each K for the drawings.
fn request(args: &ProjectArgs, keep_targets: bool) -> BuildRequest {
    BuildRequest {
        plants: args.plants.clone(),
        specs: args.specs.clone(),
        architecture: args.mode.into(),
        raw_weights: args.raw_weights,
        thesis_literal_probabilities: args.thesis_literal_probabilities,
        keep_targets,
    }
}

/// Builds a project; `None` (with every diagnostic or the reason printed) if the input is invalid, the
/// specification impossible or the result too large to compile. I/O problems are errors.
fn built(args: &ProjectArgs) -> Result<Option<Built>> {
    accepted(build(&request(args, false)), |built| &built.warnings)
}

/// Synthesises a project without compiling it; `None` (with every diagnostic or the reason printed) if the input
/// is invalid or the specification impossible. I/O problems are errors.
fn synthesised(args: &ProjectArgs, keep_targets: bool) -> Result<Option<Synthesised>> {
    accepted(synthesise(&request(args, keep_targets)), |synthesised| {
        &synthesised.warnings
    })
}

/// The result with its validation `warnings` printed, or why it was refused.
fn accepted<T>(
    result: Result<T, BuildError>,
    warnings: fn(&T) -> &[Diagnostic],
) -> Result<Option<T>> {
    terminal_progress::finish();
    match result {
        Ok(value) => {
            print_diagnostics(warnings(&value));
            Ok(Some(value))
        }
        Err(err) => refused(err),
    }
}

/// Prints why a project was refused (`None`), or passes an I/O problem on.
fn refused<T>(err: BuildError) -> Result<Option<T>> {
    match err {
        BuildError::Load(err) => Err(err.into()),
        BuildError::Invalid(diagnostics) => {
            print_diagnostics(&diagnostics);
            Ok(None)
        }
        BuildError::Codegen(err) => {
            eprintln!("error[V15]: {err}");
            Ok(None)
        }
        err => {
            eprintln!("error: {err}");
            Ok(None)
        }
    }
}

fn codegen(args: &CodegenArgs) -> Result<Outcome> {
    let Some(Built { synthesis, set, .. }) = built(&args.project)? else {
        return Ok(Outcome::Rejected);
    };
    let origin = origin(&args.project, synthesis.architecture, false);
    write(&args.out, generate_rust(&set, &origin))?;
    println!(
        "{} supervisor(s), MemCons {} bytes: {}",
        set.supervisors.len(),
        set.mem_cons(),
        args.out.display()
    );
    Ok(Outcome::Success)
}

fn synth(args: &SynthArgs) -> Result<Outcome> {
    let Some(Synthesised {
        synthesis,
        warnings,
    }) = synthesised(&args.project, args.draw)?
    else {
        return Ok(Outcome::Rejected);
    };
    // Every reduction is checked before anything is written: a refused one leaves no output behind.
    let limits = ReduceLimits::default();
    let reduction = match args.reduce.then(|| reduce_synthesis(&synthesis, limits)) {
        None => None,
        Some(Ok(reduction)) => Some(reduction),
        Some(Err(err)) => {
            terminal_progress::finish();
            eprintln!("error: {err}");
            return Ok(Outcome::ReductionRefused);
        }
    };
    let out = &args.out;
    create_dir(out)?;
    let events = &synthesis.normalised.events;
    let (files, models) = supervisors_xml(&synthesis, reduction.as_ref());
    // A result is never lost: a set too large for the compiled format skips only the compiled outputs.
    let mut skipped = Vec::new();
    let (bytes_written, mem_cons) =
        write_compiled(args, &synthesis, reduction.as_ref(), &mut skipped)?;
    // A large supervisor's XML is the bulk of the output: it is written while the rest is prepared.
    let report = std::thread::scope(|scope| {
        let xml = scope.spawn(|| write_models(out, &models, events));
        let report = (|| -> Result<Report> {
            if args.draw {
                let dir = out.join("drawings");
                create_dir(&dir)?;
                let mut drawer = Drawer {
                    dir: &dir,
                    events,
                    images: args.images.images(),
                    skipped: Vec::new(),
                };
                draw_synthesis(&mut drawer, &synthesis, reduction.as_ref())?;
                skipped.extend(drawer.skipped.into_iter().map(|s| SkippedOutput {
                    output: format!("drawings/{}", s.output),
                    ..s
                }));
            }
            let mut report = Report::new(&synthesis, &files.supervisors, bytes_written, &warnings);
            if let Some(r) = &reduction {
                let files = ReductionFiles {
                    reduced: &files.reduced,
                    observers: &files.observers,
                };
                report = report.with_reduction(r, events, files, limits, bytes_written);
            }
            report.skipped = skipped;
            write_with(&out.join("report.json"), |w| report.write_json(w))?;
            Ok(report)
        })();
        xml.join().expect("writing the XML does not panic")?;
        report
    })?;
    print_summary(&synthesis, reduction.as_ref(), mem_cons, out);
    for s in &report.skipped {
        eprintln!("warning: {} not written: {}", s.output, s.reason);
    }
    Ok(Outcome::Success)
}

/// A one-line description of the inputs for the generated module's header.
pub(crate) fn origin(args: &ProjectArgs, architecture: Architecture, reduce: bool) -> String {
    let names = |paths: &[PathBuf]| {
        paths
            .iter()
            .map(|p| {
                p.file_name().map_or_else(
                    || p.display().to_string(),
                    |n| n.to_string_lossy().into_owned(),
                )
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    format!(
        "supervisor-gen synth --mode {architecture}{} --plant {} --spec {}",
        if reduce { " --reduce" } else { "" },
        names(&args.plants),
        names(&args.specs)
    )
}

pub(crate) fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))
}

/// Writes a file through a buffer as `contents` produces it.
pub(crate) fn write_with(
    path: &Path,
    contents: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<()> {
    let file = File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut w = BufWriter::with_capacity(1 << 20, file);
    contents(&mut w)
        .and_then(|()| w.flush())
        .with_context(|| format!("cannot write {}", path.display()))
}

pub(crate) fn write(path: &Path, contents: impl AsRef<[u8]>) -> Result<()> {
    std::fs::write(path, contents).with_context(|| format!("cannot write {}", path.display()))
}
