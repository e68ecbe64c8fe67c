//! ARGoS side by side (`swarm bench --argos <prefix>`): the same density experiment run by ARGoS 3 headless, with
//! argos3-examples' own e-puck obstacle-avoidance controller, timed like ours (the whole process, start to exit).
//!
//! - [`argos_config`] turns one of our `density_N<N>.argos` files into an ARGoS configuration: `<arena>` (walls,
//!   boxes, cylinders, `<distribute>` blocks, robot count), `<physics_engines>` and `<media>` copied verbatim; a new
//!   `<framework>` with one thread (`threads="0"`: ARGoS steps everything on its main thread), our tick rate, the
//!   bench's ticks as the experiment length and the bench's seed; every controller of ours replaced, under the same
//!   id, by [`CONTROLLER_TAG`] with our `velocity` param; no loop functions and no visualization.
//! - [`ArgosInstall`] finds the programs of an install prefix and the examples' build, and runs one configuration
//!   the way ARGoS' users do (`argos3 -z -c`, from the examples folder, plugin paths in the environment).
//! - [`schedule`] alternates our runs and ARGoS' runs, so that both meet the same machine load.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use quick_xml::Reader;
use quick_xml::escape::escape;
use quick_xml::events::{BytesStart, Event};
use serde::Serialize;
use swarm_contract::run_dir;

use super::stats::median;

/// The ARGoS program, inside an install prefix.
pub const ARGOS_PROGRAM: &str = "bin/argos3";
/// ARGoS' plugins and libraries, inside an install prefix (`ARGOS_PLUGIN_PATH` and `LD_LIBRARY_PATH`: the
/// program has no RPATH).
pub const PLUGIN_DIR: &str = "lib/argos3";
/// The examples' folder relative to the install prefix when `--argos-examples` is not given (the layout of the
/// build recipe: `$A/prefix` beside `$A/argos3-examples`).
pub const DEFAULT_EXAMPLES: &str = "../argos3-examples";
/// XML tag of argos3-examples' e-puck obstacle-avoidance controller.
pub const CONTROLLER_TAG: &str = "epuck_obstacleavoidance_controller";
/// That controller's library, relative to the examples folder (as in its `experiments/epuck_obstacleavoidance.argos`;
/// ARGoS runs from the examples folder, so the path resolves there).
pub const CONTROLLER_LIBRARY: &str =
    "build/controllers/epuck_obstacleavoidance/libepuck_obstacleavoidance.so";
/// The example's wheel speed in cm/s, used when our controller has no `velocity` param.
pub const DEFAULT_VELOCITY: &str = "5";
/// Lines of ARGoS' output quoted when a run fails.
const TAIL_LINES: usize = 20;

/// Why an ARGoS comparison could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ArgosError {
    /// The prefix lacks the program or its plugins.
    #[error(
        "no ARGoS at {prefix}: {missing} is missing (an install prefix holds {ARGOS_PROGRAM} and {PLUGIN_DIR})"
    )]
    NotInstalled {
        /// The prefix given.
        prefix: PathBuf,
        /// What is not there.
        missing: PathBuf,
    },
    /// The examples folder lacks the built controller.
    #[error(
        "no built e-puck obstacle-avoidance controller in {examples}: {missing} is missing (build argos3-examples' \
         `epuck_obstacleavoidance` target there, or name the examples folder with --argos-examples)"
    )]
    NoController {
        /// The examples folder.
        examples: PathBuf,
        /// The library looked for.
        missing: PathBuf,
    },
    /// A path could not be made absolute.
    #[error("resolving {path}")]
    Resolve {
        /// The path.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Our configuration could not be read.
    #[error("reading {path}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Our configuration could not be turned into ARGoS'.
    #[error("making an ARGoS configuration from {path}")]
    Convert {
        /// Our configuration.
        path: PathBuf,
        /// Why.
        #[source]
        source: ConvertError,
    },
    /// A file could not be written.
    #[error("writing {path}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// ARGoS could not be started.
    #[error("starting `{command}` in {dir}")]
    Start {
        /// The command line.
        command: String,
        /// Its working folder.
        dir: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// ARGoS ran and failed.
    #[error("`{command}` in {dir} failed ({status}); the end of its output ({log}):\n{tail}")]
    Failed {
        /// The command line.
        command: String,
        /// Its working folder.
        dir: PathBuf,
        /// Its exit status.
        status: String,
        /// The file holding its whole output.
        log: PathBuf,
        /// The last lines of its output.
        tail: String,
    },
}

/// Why one of our configurations has no ARGoS counterpart.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ConvertError {
    /// The text is not well-formed XML.
    #[error("malformed XML at byte {offset}: {message}")]
    Malformed {
        /// Byte offset of the problem.
        offset: u64,
        /// What quick-xml says.
        message: String,
    },
    /// A required element or attribute is absent.
    #[error("no {0}")]
    Missing(&'static str),
    /// The tick rate is not a positive whole number.
    #[error("ticks_per_second \"{0}\" is not a whole number from 1 to 4294967295 (ARGoS' range)")]
    TickRate(String),
    /// ARGoS cannot run exactly this many ticks (0 would run forever; its clock is 32 bits).
    #[error("ARGoS cannot run {0} ticks (1 to 4294967295)")]
    Ticks(u64),
}

/// What [`argos_config`] reads from our configuration.
#[derive(Debug, Default)]
struct Sections<'a> {
    /// `<framework><experiment ticks_per_second>`.
    ticks_per_second: Option<u32>,
    /// Our controllers: id and `velocity` param.
    controllers: Vec<(String, Option<String>)>,
    /// Raw text of `<arena>`, `<physics_engines>` and `<media>`.
    arena: Option<&'a str>,
    physics_engines: Option<&'a str>,
    media: Option<&'a str>,
}

/// The ARGoS configuration for our configuration `ours` (its text), run for `ticks` ticks with `seed`: see the
/// module's documentation for what is copied and what is replaced.
pub fn argos_config(ours: &str, ticks: u64, seed: u32) -> Result<String, ConvertError> {
    let sections = read_sections(ours)?;
    let ticks_per_second = sections.ticks_per_second.ok_or(ConvertError::Missing(
        "<framework><experiment ticks_per_second>",
    ))?;
    let arena = sections.arena.ok_or(ConvertError::Missing("<arena>"))?;
    if sections.controllers.is_empty() {
        return Err(ConvertError::Missing("controller in <controllers>"));
    }
    let length = experiment_length(ticks, ticks_per_second)?;
    let mut text = String::from(
        "<?xml version=\"1.0\" ?>\n<!-- Written by `swarm bench --argos`: our density experiment for ARGoS, with \
         argos3-examples' e-puck obstacle-avoidance controller. -->\n<argos-configuration>\n",
    );
    text.push_str(&format!(
        "  <framework>\n    <system threads=\"0\" />\n    <experiment length=\"{length}\" \
         ticks_per_second=\"{ticks_per_second}\" random_seed=\"{seed}\" />\n  </framework>\n\n"
    ));
    text.push_str("  <controllers>\n");
    for (id, velocity) in &sections.controllers {
        text.push_str(&controller(id, velocity.as_deref()));
    }
    text.push_str("  </controllers>\n\n  ");
    text.push_str(arena);
    text.push_str("\n\n  ");
    text.push_str(
        sections
            .physics_engines
            .unwrap_or("<physics_engines>\n    <dynamics2d id=\"dyn2d\" />\n  </physics_engines>"),
    );
    text.push_str("\n\n  ");
    text.push_str(sections.media.unwrap_or("<media />"));
    text.push_str("\n</argos-configuration>\n");
    Ok(text)
}

/// `<experiment length>` for `ticks` at `ticks_per_second`: ticks / ticks_per_second seconds, or half a tick more
/// when that quotient, times the rate, would not truncate back to `ticks` (ARGoS runs
/// `UInt32(length * ticks_per_second)` ticks).
pub fn experiment_length(ticks: u64, ticks_per_second: u32) -> Result<String, ConvertError> {
    if ticks == 0 || ticks > u64::from(u32::MAX) {
        return Err(ConvertError::Ticks(ticks));
    }
    let rate = f64::from(ticks_per_second);
    let exact = ticks as f64 / rate;
    if (exact * rate) as u64 == ticks {
        Ok(format!("{exact}"))
    } else {
        Ok(format!("{}", (ticks as f64 + 0.5) / rate))
    }
}

/// One ARGoS controller block standing in for our controller `id`.
fn controller(id: &str, velocity: Option<&str>) -> String {
    let velocity = escape(velocity.unwrap_or(DEFAULT_VELOCITY));
    format!(
        "    <{CONTROLLER_TAG} id=\"{id}\" library=\"{CONTROLLER_LIBRARY}\">\n      <actuators>\n        \
         <differential_steering implementation=\"default\" />\n      </actuators>\n      <sensors>\n        \
         <proximity implementation=\"default\" show_rays=\"false\" />\n      </sensors>\n      \
         <params velocity=\"{velocity}\" />\n    </{CONTROLLER_TAG}>\n",
        id = escape(id),
    )
}

/// Walks our configuration once: the tick rate, the controllers and the raw text of the copied sections.
fn read_sections(text: &str) -> Result<Sections<'_>, ConvertError> {
    let mut reader = Reader::from_str(text);
    let mut sections = Sections::default();
    // Names of the open elements, outermost first.
    let mut open: Vec<String> = Vec::new();
    loop {
        let start = reader.buffer_position();
        let event = reader.read_event().map_err(|e| malformed(&reader, &e))?;
        match event {
            Event::Start(element) => {
                let name = name_of(&element);
                if open.len() == 1 && copied(&name) {
                    reader
                        .read_to_end(element.name())
                        .map_err(|e| malformed(&reader, &e))?;
                    let raw = slice(text, start, reader.buffer_position());
                    store(&mut sections, &name, raw);
                } else {
                    visit(&mut sections, &open, &element)?;
                    open.push(name);
                }
            }
            Event::Empty(element) => {
                let name = name_of(&element);
                if open.len() == 1 && copied(&name) {
                    store(
                        &mut sections,
                        &name,
                        slice(text, start, reader.buffer_position()),
                    );
                } else {
                    visit(&mut sections, &open, &element)?;
                }
            }
            Event::End(_) => {
                open.pop();
            }
            Event::Eof => return Ok(sections),
            _ => {}
        }
    }
}

/// Sections copied verbatim.
fn copied(name: &str) -> bool {
    matches!(name, "arena" | "physics_engines" | "media")
}

fn store<'a>(sections: &mut Sections<'a>, name: &str, raw: &'a str) {
    match name {
        "arena" => sections.arena = Some(raw),
        "physics_engines" => sections.physics_engines = Some(raw),
        _ => sections.media = Some(raw),
    }
}

/// Reads what [`Sections`] needs from `element`, found inside the elements `open`.
fn visit(
    sections: &mut Sections<'_>,
    open: &[String],
    element: &BytesStart<'_>,
) -> Result<(), ConvertError> {
    let parents: Vec<&str> = open.iter().map(String::as_str).collect();
    match (parents.as_slice(), name_of(element).as_str()) {
        ([_, "framework"], "experiment") => {
            if let Some(rate) = attribute(element, "ticks_per_second") {
                let parsed = rate
                    .trim()
                    .parse::<u32>()
                    .ok()
                    .filter(|&r| r > 0)
                    .ok_or(ConvertError::TickRate(rate))?;
                sections.ticks_per_second = Some(parsed);
            }
        }
        ([_, "controllers"], _) => {
            let id = attribute(element, "id").ok_or(ConvertError::Missing("id of a controller"))?;
            sections.controllers.push((id, None));
        }
        ([_, "controllers", _], "params") => {
            if let Some(last) = sections.controllers.last_mut() {
                last.1 = attribute(element, "velocity");
            }
        }
        _ => {}
    }
    Ok(())
}

fn name_of(element: &BytesStart<'_>) -> String {
    String::from_utf8_lossy(element.name().as_ref()).into_owned()
}

/// The unescaped value of attribute `name`, if present and readable.
fn attribute(element: &BytesStart<'_>, name: &str) -> Option<String> {
    element
        .attributes()
        .flatten()
        .find(|a| a.key.as_ref() == name.as_bytes())
        .and_then(|a| a.unescape_value().ok().map(|v| v.into_owned()))
}

fn slice(text: &str, start: u64, end: u64) -> &str {
    let start = usize::try_from(start).unwrap_or(usize::MAX);
    let end = usize::try_from(end).unwrap_or(usize::MAX);
    text.get(start..end).unwrap_or_default().trim()
}

fn malformed(reader: &Reader<&[u8]>, error: &quick_xml::Error) -> ConvertError {
    ConvertError::Malformed {
        offset: reader.error_position(),
        message: error.to_string(),
    }
}

/// Reads our configuration `ours`, and writes its ARGoS counterpart ([`argos_config`]) to `out`.
pub fn write_config(ours: &Path, out: &Path, ticks: u64, seed: u32) -> Result<(), ArgosError> {
    let text = std::fs::read_to_string(ours).map_err(|source| ArgosError::Read {
        path: ours.to_path_buf(),
        source,
    })?;
    let converted = argos_config(&text, ticks, seed).map_err(|source| ArgosError::Convert {
        path: ours.to_path_buf(),
        source,
    })?;
    swarm_contract::run_dir::write_atomically(out, converted.as_bytes()).map_err(|source| {
        ArgosError::Write {
            path: out.to_path_buf(),
            source,
        }
    })
}

/// An ARGoS install: the program, its plugins and the examples' build (all absolute).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArgosInstall {
    /// `<prefix>/bin/argos3`.
    pub program: PathBuf,
    /// `<prefix>/lib/argos3`.
    pub plugins: PathBuf,
    /// The argos3-examples work tree holding the built controller; ARGoS runs from there.
    pub examples: PathBuf,
}

impl ArgosInstall {
    /// Checks the install `prefix` (`bin/argos3`, `lib/argos3`) and the examples folder (`examples`, or
    /// [`DEFAULT_EXAMPLES`] from the prefix) with its built [`CONTROLLER_LIBRARY`].
    pub fn locate(prefix: &Path, examples: Option<&Path>) -> Result<ArgosInstall, ArgosError> {
        let prefix = absolute(prefix)?;
        let program = prefix.join(ARGOS_PROGRAM);
        let plugins = prefix.join(PLUGIN_DIR);
        for (path, present) in [(&program, program.is_file()), (&plugins, plugins.is_dir())] {
            if !present {
                return Err(ArgosError::NotInstalled {
                    prefix: prefix.clone(),
                    missing: path.clone(),
                });
            }
        }
        let examples = match examples {
            Some(dir) => absolute(dir)?,
            None => prefix.join(DEFAULT_EXAMPLES),
        };
        let library = examples.join(CONTROLLER_LIBRARY);
        if !library.is_file() {
            return Err(ArgosError::NoController {
                examples,
                missing: library,
            });
        }
        Ok(ArgosInstall {
            program,
            plugins,
            examples,
        })
    }

    /// The command running `config` headless (`-z`, and `-n` for plain-text output), from the examples folder.
    pub fn command(&self, config: &Path) -> Command {
        let mut command = Command::new(&self.program);
        command
            .args(["-z", "-n", "-c"])
            .arg(config)
            .current_dir(&self.examples)
            .env("ARGOS_PLUGIN_PATH", &self.plugins)
            .env("LD_LIBRARY_PATH", &self.plugins)
            .stdin(Stdio::null());
        command
    }

    /// [`Self::command`] as a shell line, for messages.
    pub fn command_line(&self, config: &Path) -> String {
        format!(
            "ARGOS_PLUGIN_PATH={plugins} LD_LIBRARY_PATH={plugins} {} -z -n -c {}",
            self.program.display(),
            config.display(),
            plugins = self.plugins.display(),
        )
    }

    /// Runs `config` (made absolute) once, its output into `log`; returns the process' wall time from start to
    /// exit.
    pub fn run(&self, config: &Path, log: &Path) -> Result<Duration, ArgosError> {
        let config = absolute(config)?;
        let command_line = self.command_line(&config);
        let start_error = |source| ArgosError::Start {
            command: command_line.clone(),
            dir: self.examples.clone(),
            source,
        };
        let write_error = |source| ArgosError::Write {
            path: log.to_path_buf(),
            source,
        };
        let stdout = File::create(log).map_err(write_error)?;
        let stderr = stdout.try_clone().map_err(write_error)?;
        let mut command = self.command(&config);
        command.stdout(stdout).stderr(stderr);
        let started = Instant::now();
        let status = command
            .spawn()
            .and_then(|mut child| child.wait())
            .map_err(start_error)?;
        let elapsed = started.elapsed();
        if status.success() {
            Ok(elapsed)
        } else {
            Err(ArgosError::Failed {
                command: command_line,
                dir: self.examples.clone(),
                status: status.to_string(),
                log: log.to_path_buf(),
                tail: run_dir::tail(log, TAIL_LINES),
            })
        }
    }
}

fn absolute(path: &Path) -> Result<PathBuf, ArgosError> {
    std::path::absolute(path).map_err(|source| ArgosError::Resolve {
        path: path.to_path_buf(),
        source,
    })
}

/// Which program a run of the comparison runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Engine {
    /// Our world and agents, through the launcher.
    Ours,
    /// ARGoS.
    Argos,
}

/// One run of the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Turn {
    /// Which program.
    pub engine: Engine,
    /// Its repetition, from 0.
    pub repetition: usize,
}

/// The order of the runs for one size: ours, ARGoS, ours, ARGoS, ... (`repeat` each, at least one), or only ours
/// without ARGoS.
pub fn schedule(repeat: usize, argos: bool) -> Vec<Turn> {
    let engines: &[Engine] = if argos {
        &[Engine::Ours, Engine::Argos]
    } else {
        &[Engine::Ours]
    };
    (0..repeat.max(1))
        .flat_map(|repetition| {
            engines
                .iter()
                .map(move |&engine| Turn { engine, repetition })
        })
        .collect()
}

/// Our whole run against ARGoS' for one size, each the wall time of the whole run from start to exit (ours: the
/// launcher's call, configuration read to the last process gone; ARGoS: its process).
#[derive(Debug, Clone, Serialize)]
pub struct ArgosFigures {
    /// The ARGoS configuration run.
    pub config: PathBuf,
    /// Runs of each.
    pub runs: usize,
    /// Median of our runs' wall time, in seconds.
    pub ours_wall_seconds: f64,
    /// Our runs' wall times, in run order.
    pub ours_wall_seconds_runs: Vec<f64>,
    /// Median of ARGoS' runs' wall time, in seconds.
    pub wall_seconds: f64,
    /// ARGoS' runs' wall times, in run order.
    pub wall_seconds_runs: Vec<f64>,
    /// ARGoS' median over ours: "ours is this many times faster".
    pub argos_over_ours: f64,
}

impl ArgosFigures {
    /// The figures of the runs made, walls in seconds.
    pub fn new(config: PathBuf, ours: Vec<f64>, argos: Vec<f64>) -> ArgosFigures {
        let ours_wall_seconds = median(&ours).unwrap_or(0.0);
        let wall_seconds = median(&argos).unwrap_or(0.0);
        ArgosFigures {
            config,
            runs: argos.len(),
            ours_wall_seconds,
            ours_wall_seconds_runs: ours,
            wall_seconds,
            wall_seconds_runs: argos,
            argos_over_ours: if ours_wall_seconds > 0.0 {
                wall_seconds / ours_wall_seconds
            } else {
                0.0
            },
        }
    }

    /// The ratio in words: "ours is 2.1x faster" or "ARGoS is 1.3x faster".
    pub fn verdict(&self) -> String {
        let ratio = self.argos_over_ours;
        if ratio >= 1.0 {
            format!("ours is {ratio:.1}x faster")
        } else if ratio > 0.0 {
            format!("ARGoS is {:.1}x faster", 1.0 / ratio)
        } else {
            "no figure".to_owned()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A parsed element: name, attributes in order, children.
    #[derive(Debug, Clone, PartialEq)]
    struct Element {
        name: String,
        attributes: Vec<(String, String)>,
        children: Vec<Element>,
    }

    impl Element {
        fn attribute(&self, name: &str) -> Option<&str> {
            self.attributes
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, v)| v.as_str())
        }

        fn child(&self, name: &str) -> &Element {
            self.children
                .iter()
                .find(|c| c.name == name)
                .unwrap_or_else(|| panic!("no <{name}> in <{}>", self.name))
        }

        fn all(&self, name: &str) -> Vec<&Element> {
            let mut found = Vec::new();
            self.collect(name, &mut found);
            found
        }

        fn collect<'a>(&'a self, name: &str, found: &mut Vec<&'a Element>) {
            if self.name == name {
                found.push(self);
            }
            for child in &self.children {
                child.collect(name, found);
            }
        }
    }

    /// Parses `text` into its root element (comments and text dropped).
    fn parse(text: &str) -> Element {
        fn element(start: &BytesStart<'_>) -> Element {
            Element {
                name: name_of(start),
                attributes: start
                    .attributes()
                    .map(|a| {
                        let a = a.expect("attribute");
                        (
                            String::from_utf8_lossy(a.key.as_ref()).into_owned(),
                            a.unescape_value().expect("value").into_owned(),
                        )
                    })
                    .collect(),
                children: Vec::new(),
            }
        }
        let mut reader = Reader::from_str(text);
        let mut stack: Vec<Element> = vec![Element {
            name: String::new(),
            attributes: Vec::new(),
            children: Vec::new(),
        }];
        loop {
            match reader.read_event().expect("well-formed XML") {
                Event::Start(start) => stack.push(element(&start)),
                Event::Empty(start) => stack.last_mut().unwrap().children.push(element(&start)),
                Event::End(_) => {
                    let done = stack.pop().unwrap();
                    stack.last_mut().unwrap().children.push(done);
                }
                Event::Eof => break,
                _ => {}
            }
        }
        stack.pop().unwrap().children.remove(0)
    }

    fn density(robots: u32) -> String {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../configs/obstacle_avoidance")
            .join(format!("density_N{robots}.argos"));
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    }

    fn robot_count(root: &Element) -> u32 {
        root.child("arena")
            .all("distribute")
            .iter()
            .map(|d| d.child("entity"))
            .filter(|e| e.children.iter().any(|c| c.name == "e-puck"))
            .map(|e| e.attribute("quantity").unwrap().parse::<u32>().unwrap())
            .sum()
    }

    #[test]
    fn the_argos_configuration_runs_the_same_experiment_with_the_example_controller() {
        for robots in [10, 100, 1000] {
            let ours_text = density(robots);
            let ours = parse(&ours_text);
            let argos = parse(&argos_config(&ours_text, 600, 7).unwrap());
            assert_eq!(argos.name, "argos-configuration");

            // Same arena, walls, boxes, cylinders and distribute blocks, hence the same robot count.
            assert_eq!(argos.child("arena"), ours.child("arena"));
            assert_eq!(robot_count(&argos), robots);
            assert_eq!(
                argos.child("arena").all("box").len(),
                5,
                "4 walls + the box entity"
            );
            assert_eq!(argos.child("arena").all("cylinder").len(), 1);
            assert_eq!(
                argos.child("physics_engines"),
                ours.child("physics_engines")
            );
            assert_eq!(argos.child("media"), ours.child("media"));

            // One thread, our tick rate, the bench's length and seed.
            let framework = argos.child("framework");
            assert_eq!(framework.child("system").attribute("threads"), Some("0"));
            let experiment = framework.child("experiment");
            assert_eq!(experiment.attribute("ticks_per_second"), Some("20"));
            assert_eq!(experiment.attribute("length"), Some("30"));
            assert_eq!(experiment.attribute("random_seed"), Some("7"));

            // ARGoS' example controller under our controller's id, at our speed; nothing of ours left.
            let controllers = &argos.child("controllers").children;
            assert_eq!(controllers.len(), 1);
            let controller = &controllers[0];
            assert_eq!(controller.name, CONTROLLER_TAG);
            assert_eq!(controller.attribute("id"), Some("oa"));
            assert_eq!(controller.attribute("library"), Some(CONTROLLER_LIBRARY));
            assert!(
                controller
                    .child("actuators")
                    .all("differential_steering")
                    .len()
                    == 1
            );
            assert!(controller.child("sensors").all("proximity").len() == 1);
            assert_eq!(
                controller.child("params").attribute("velocity"),
                Some("12.8")
            );
            let names: Vec<&str> = argos.children.iter().map(|c| c.name.as_str()).collect();
            assert_eq!(
                names,
                [
                    "framework",
                    "controllers",
                    "arena",
                    "physics_engines",
                    "media"
                ]
            );
            let robot_controllers: Vec<_> = argos.child("arena").all("controller");
            assert!(
                robot_controllers
                    .iter()
                    .all(|c| c.attribute("config") == Some("oa"))
            );
        }
    }

    #[test]
    fn the_length_gives_exactly_the_ticks_after_argos_truncation() {
        assert_eq!(experiment_length(600, 20).unwrap(), "30");
        assert_eq!(experiment_length(2000, 10).unwrap(), "200");
        assert_eq!(experiment_length(3, 20).unwrap(), "0.15");
        for (ticks, rate) in [(7, 3), (1, 3), (1000, 7), (599, 31), (1, 1)] {
            let length: f64 = experiment_length(ticks, rate).unwrap().parse().unwrap();
            assert_eq!(
                (length * f64::from(rate)) as u64,
                ticks,
                "{ticks} at {rate}"
            );
        }
        assert_eq!(experiment_length(0, 10), Err(ConvertError::Ticks(0)));
        assert!(experiment_length(1 << 33, 10).is_err());
    }

    #[test]
    fn bad_configurations_are_errors_not_panics() {
        let framework = "<framework><experiment length=\"1\" ticks_per_second=\"10\"/></framework>";
        let controllers = "<controllers><c id=\"oa\"><params/></c></controllers>";
        let arena = "<arena size=\"1,1,1\"/>";
        let ok =
            format!("<argos-configuration>{framework}{controllers}{arena}</argos-configuration>");
        let converted = parse(&argos_config(&ok, 10, 1).unwrap());
        // Defaults: the example's speed, dynamics2d, empty media.
        assert_eq!(
            converted.child("controllers").children[0]
                .child("params")
                .attribute("velocity"),
            Some(DEFAULT_VELOCITY)
        );
        assert_eq!(
            converted.child("physics_engines").children[0].name,
            "dynamics2d"
        );
        assert_eq!(converted.child("media").children.len(), 0);

        let cases = [
            ("<argos-configuration><arena>", "malformed"),
            (&ok.replace(arena, "") as &str, "<arena>"),
            (&ok.replace(controllers, "<controllers/>"), "controller"),
            (
                &ok.replace(" ticks_per_second=\"10\"", ""),
                "ticks_per_second",
            ),
            (&ok.replace("\"10\"", "\"2.5\""), "2.5"),
            (&ok.replace("\"10\"", "\"0\""), "\"0\""),
            (&ok.replace(" id=\"oa\"", ""), "id"),
        ];
        for (text, expected) in cases {
            let error = argos_config(text, 10, 1).unwrap_err().to_string();
            assert!(error.contains(expected), "{text}: {error}");
        }
        assert_eq!(argos_config(&ok, 0, 1), Err(ConvertError::Ticks(0)));
    }

    #[test]
    fn runs_alternate_ours_first() {
        use Engine::{Argos, Ours};
        let turns: Vec<(Engine, usize)> = schedule(3, true)
            .into_iter()
            .map(|t| (t.engine, t.repetition))
            .collect();
        assert_eq!(
            turns,
            [
                (Ours, 0),
                (Argos, 0),
                (Ours, 1),
                (Argos, 1),
                (Ours, 2),
                (Argos, 2)
            ]
        );
        let alone: Vec<Engine> = schedule(2, false).into_iter().map(|t| t.engine).collect();
        assert_eq!(alone, [Ours, Ours]);
        assert_eq!(schedule(0, true).len(), 2, "at least one run each");
    }

    #[test]
    fn a_prefix_without_argos_is_a_clear_error() {
        let empty = tempfile::tempdir().unwrap();
        let error = ArgosInstall::locate(empty.path(), None).unwrap_err();
        assert!(matches!(error, ArgosError::NotInstalled { .. }));
        assert!(error.to_string().contains("bin/argos3"), "{error}");

        std::fs::create_dir_all(empty.path().join("bin")).unwrap();
        std::fs::write(empty.path().join(ARGOS_PROGRAM), "").unwrap();
        std::fs::create_dir_all(empty.path().join(PLUGIN_DIR)).unwrap();
        let examples = empty.path().join("examples");
        let error = ArgosInstall::locate(empty.path(), Some(&examples)).unwrap_err();
        assert!(matches!(error, ArgosError::NoController { .. }));
        assert!(error.to_string().contains(CONTROLLER_LIBRARY), "{error}");
    }

    #[test]
    fn a_failing_argos_names_the_command_and_the_end_of_its_output() {
        let dir = tempfile::tempdir().unwrap();
        let program = dir.path().join("argos3");
        std::fs::write(
            &program,
            "#!/bin/sh\necho first line\necho \"bad config $4\" >&2\nexit 3\n",
        )
        .unwrap();
        let mut permissions = std::fs::metadata(&program).unwrap().permissions();
        std::os::unix::fs::PermissionsExt::set_mode(&mut permissions, 0o755);
        std::fs::set_permissions(&program, permissions).unwrap();
        let install = ArgosInstall {
            program,
            plugins: dir.path().to_path_buf(),
            examples: dir.path().to_path_buf(),
        };
        let log = dir.path().join("argos.log");
        let error = install
            .run(Path::new("/x/exp.argos"), &log)
            .unwrap_err()
            .to_string();
        assert!(error.contains("argos3 -z -n -c /x/exp.argos"), "{error}");
        assert!(error.contains("bad config /x/exp.argos"), "{error}");
        assert!(error.contains("first line"), "{error}");
        assert!(error.contains("exit status: 3"), "{error}");
    }

    /// Runs ARGoS for real on the generated N = 10 configuration (prefix from `SWARM_ARGOS_PREFIX`, default
    /// `/work/argos/prefix`):
    /// `cargo test -p swarm-cli --lib bench::argos -- --ignored`.
    #[test]
    #[ignore = "needs an ARGoS build"]
    fn argos_runs_the_generated_configuration() {
        let prefix = std::env::var_os("SWARM_ARGOS_PREFIX")
            .map_or_else(|| PathBuf::from("/work/argos/prefix"), PathBuf::from);
        let install = ArgosInstall::locate(&prefix, None).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("argos_N10.argos");
        let ours = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../configs/obstacle_avoidance/density_N10.argos");
        write_config(&ours, &config, 200, 1).unwrap();
        let log = dir.path().join("argos.log");
        let wall = install.run(&config, &log).unwrap_or_else(|e| panic!("{e}"));
        assert!(wall > Duration::ZERO);
        let output = std::fs::read_to_string(&log).unwrap();
        assert!(output.contains("200"), "{output}");
    }
}
