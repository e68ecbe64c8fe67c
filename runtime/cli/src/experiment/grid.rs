//! The grid file (TOML) of `swarm experiment`: a base `.argos`, seeds, factors and plots. `docs/experiments.md`
//! describes the format; every problem is a [`Diagnostic`] located in the grid file.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;

use super::address::{Address, SHORTCUTS};
use swarm_contract::config::{ConfigErrors, Diagnostic, Location};

/// Where batches go when neither the grid nor the command line names a folder.
pub const DEFAULT_BATCHES_DIR: &str = "runs";

/// A parsed grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// The grid file.
    pub path: PathBuf,
    /// The grid file's text (kept for located errors found later and for the batch's copy).
    pub text: String,
    /// The base configuration, resolved against the grid file's folder.
    pub base: PathBuf,
    /// The batch folder (`out`, relative to the current directory; default `runs/<grid file stem>`).
    pub out: PathBuf,
    /// One run per seed in every configuration.
    pub seeds: Vec<u64>,
    /// Ticks per run, overriding the configuration's length.
    pub ticks: Option<u64>,
    /// The metric whose median over the seeds selects a configuration's representative run.
    pub median_metric: String,
    /// Where `median_metric` is written.
    pub median_metric_location: Location,
    /// The factors; configurations are their cartesian product, the first factor varying slowest.
    pub factors: Vec<Factor>,
    /// The factor whose levels set the robot count (plotted on the x axis as the run's robot count), if any.
    pub x_factor: Option<usize>,
    /// One set of figures per entry: the factor drawn as one line per level.
    pub line_factors: Vec<usize>,
}

/// One factor: configuration values it sets and its levels.
#[derive(Debug, Clone, PartialEq)]
pub struct Factor {
    /// Column name, e.g. `Nr`.
    pub name: String,
    /// Every address the factor sets.
    pub addresses: Vec<Address>,
    /// The levels, in the order written.
    pub levels: Vec<Level>,
    /// Where the factor's `set` is written.
    pub location: Location,
}

/// One level of a factor.
#[derive(Debug, Clone, PartialEq)]
pub struct Level {
    /// Label in tables, file names and legends.
    pub label: String,
    /// The value written to each of the factor's addresses (same order).
    pub values: Vec<String>,
    /// Where the level is written.
    pub location: Location,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GridFile {
    base: Spanned<String>,
    out: Option<String>,
    seeds: Option<Spanned<Vec<u64>>>,
    repetitions: Option<Spanned<u64>>,
    ticks: Option<u64>,
    median_metric: Spanned<String>,
    #[serde(default, rename = "factor")]
    factors: Vec<FactorFile>,
    plots: Option<PlotsFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FactorFile {
    name: Spanned<String>,
    set: Spanned<Vec<Spanned<String>>>,
    values: Spanned<Vec<Spanned<toml::Value>>>,
    labels: Option<Spanned<Vec<Spanned<String>>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlotsFile {
    x: Option<Spanned<String>>,
    #[serde(default)]
    lines: Vec<Spanned<String>>,
}

/// Maps byte offsets of the grid text to lines and columns.
struct Locator<'a> {
    path: &'a Path,
    text: &'a str,
}

impl Locator<'_> {
    fn location(&self, offset: usize) -> Location {
        let before = self.text.get(..offset.min(self.text.len())).unwrap_or("");
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        Location {
            line: u32::try_from(line).unwrap_or(u32::MAX),
            column: u32::try_from(column).unwrap_or(u32::MAX),
        }
    }

    fn error(&self, offset: usize, message: impl Into<String>) -> Diagnostic {
        Diagnostic::new(self.path.to_path_buf(), self.location(offset), message)
    }
}

/// Largest grid file read (grids are a few lines; the limit bounds what a wrong path can cost).
pub const MAX_GRID_BYTES: u64 = 1024 * 1024;

impl Grid {
    /// Reads and checks a grid file; on failure every error found, located in the grid file.
    pub fn load(path: &Path) -> Result<Grid, ConfigErrors> {
        let text = swarm_contract::config::input::read_text(path, MAX_GRID_BYTES)
            .map_err(|d| ConfigErrors { errors: vec![d] })?;
        Grid::parse(path, &text)
    }

    /// Parses grid text as if read from `path` (relative paths resolve against its folder).
    pub fn parse(path: &Path, text: &str) -> Result<Grid, ConfigErrors> {
        let at = Locator { path, text };
        let file: GridFile = toml::from_str(text).map_err(|e| ConfigErrors {
            errors: vec![at.error(
                e.span().map_or(0, |s| s.start),
                e.message().trim().to_owned(),
            )],
        })?;
        let mut errors = Vec::new();
        let folder = path.parent().unwrap_or_else(|| Path::new(""));

        let seeds = match (&file.seeds, &file.repetitions) {
            (Some(seeds), None) if !seeds.get_ref().is_empty() => seeds.get_ref().clone(),
            (Some(seeds), None) => {
                errors.push(at.error(
                    seeds.span().start,
                    "'seeds' is empty: a grid needs at least one seed",
                ));
                Vec::new()
            }
            (None, Some(n)) if *n.get_ref() > 0 => (1..=*n.get_ref()).collect(),
            (None, Some(n)) => {
                errors.push(at.error(n.span().start, "'repetitions' must be at least 1"));
                Vec::new()
            }
            (Some(seeds), Some(_)) => {
                errors.push(at.error(
                    seeds.span().start,
                    "give either 'seeds' (a list) or 'repetitions' (seeds 1..=n), not both",
                ));
                Vec::new()
            }
            (None, None) => {
                errors.push(at.error(
                    0,
                    "the grid names no seeds: add 'repetitions = n' or 'seeds = [..]'",
                ));
                Vec::new()
            }
        };
        if let Some(seeds) = &file.seeds {
            let distinct: BTreeSet<u64> = seeds.get_ref().iter().copied().collect();
            if distinct.len() != seeds.get_ref().len() {
                errors.push(at.error(seeds.span().start, "'seeds' lists a seed twice"));
            }
        }

        let mut factors = Vec::new();
        let mut names = BTreeSet::new();
        for factor in &file.factors {
            let name = factor.name.get_ref().trim().to_owned();
            if name.is_empty()
                || !name
                    .chars()
                    .all(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | '.'))
            {
                errors.push(at.error(
                    factor.name.span().start,
                    format!("factor name '{name}' must be letters, digits, '_', '-' or '.' (it names a column)"),
                ));
            }
            if !names.insert(name.clone()) {
                errors.push(at.error(
                    factor.name.span().start,
                    format!("factor '{name}' is defined twice"),
                ));
            }
            if let Some(factor) = parse_factor(&at, factor, name, &mut errors) {
                factors.push(factor);
            }
        }

        let index_of = |name: &Spanned<String>, errors: &mut Vec<Diagnostic>| {
            let found = factors.iter().position(|f| f.name == *name.get_ref());
            if found.is_none() {
                let known: Vec<&str> = factors.iter().map(|f| f.name.as_str()).collect();
                errors.push(at.error(
                    name.span().start,
                    format!(
                        "no factor named '{}' (factors: {})",
                        name.get_ref(),
                        known.join(", ")
                    ),
                ));
            }
            found
        };
        let robots = Address::parse("robots").ok();
        let x_factor = match file.plots.as_ref().and_then(|p| p.x.as_ref()) {
            Some(x) => index_of(x, &mut errors),
            None => factors
                .iter()
                .position(|f| f.addresses.iter().any(|a| Some(a) == robots.as_ref())),
        };
        let line_factors = match file.plots.as_ref().map(|p| &p.lines) {
            Some(lines) if !lines.is_empty() => lines
                .iter()
                .filter_map(|l| index_of(l, &mut errors))
                .collect(),
            _ => (0..factors.len())
                .find(|&i| Some(i) != x_factor)
                .into_iter()
                .collect(),
        };

        if file.median_metric.get_ref().trim().is_empty() {
            errors.push(at.error(file.median_metric.span().start, "'median_metric' is empty"));
        }
        if !errors.is_empty() {
            errors.sort_by_key(|d| d.location);
            return Err(ConfigErrors { errors });
        }
        let out = file.out.as_ref().map_or_else(
            || {
                let stem = path
                    .file_stem()
                    .map_or_else(|| "grid".to_owned(), |s| s.to_string_lossy().into_owned());
                Path::new(DEFAULT_BATCHES_DIR).join(stem)
            },
            PathBuf::from,
        );
        Ok(Grid {
            path: path.to_path_buf(),
            text: text.to_owned(),
            base: folder.join(file.base.get_ref()),
            out,
            seeds,
            ticks: file.ticks,
            median_metric: file.median_metric.get_ref().trim().to_owned(),
            median_metric_location: at.location(file.median_metric.span().start),
            factors,
            x_factor,
            line_factors,
        })
    }

    /// Number of configurations (the product of the factors' level counts).
    pub fn configuration_count(&self) -> usize {
        self.factors.iter().map(|f| f.levels.len()).product()
    }

    /// A located error about this grid file.
    pub fn diagnostic(&self, location: Location, message: impl Into<String>) -> Diagnostic {
        Diagnostic::new(self.path.clone(), location, message)
    }
}

fn parse_factor(
    at: &Locator<'_>,
    factor: &FactorFile,
    name: String,
    errors: &mut Vec<Diagnostic>,
) -> Option<Factor> {
    let before = errors.len();
    let mut addresses = Vec::new();
    for set in factor.set.get_ref() {
        match Address::parse(set.get_ref()) {
            Ok(address) => addresses.push(address),
            Err(e) => errors.push(at.error(set.span().start, e.to_string())),
        }
    }
    if factor.set.get_ref().is_empty() {
        let shortcuts: Vec<&str> = SHORTCUTS.iter().map(|(n, _)| *n).collect();
        errors.push(at.error(
            factor.set.span().start,
            format!(
                "factor '{name}' sets nothing: 'set' lists addresses or shortcuts ({})",
                shortcuts.join(", ")
            ),
        ));
    }
    let values = factor.values.get_ref();
    if values.is_empty() {
        errors.push(at.error(
            factor.values.span().start,
            format!("factor '{name}' has no values"),
        ));
    }
    let labels = factor.labels.as_ref();
    if let Some(labels) = labels
        && labels.get_ref().len() != values.len()
    {
        errors.push(at.error(
            labels.span().start,
            format!(
                "factor '{name}' has {} labels for {} values",
                labels.get_ref().len(),
                values.len()
            ),
        ));
    }
    let mut levels = Vec::new();
    for (i, value) in values.iter().enumerate() {
        let written = match value.get_ref() {
            toml::Value::Array(items) => {
                if items.len() != factor.set.get_ref().len() {
                    errors.push(at.error(
                        value.span().start,
                        format!(
                            "a list value gives one value per address: {} values for {} addresses",
                            items.len(),
                            factor.set.get_ref().len()
                        ),
                    ));
                    continue;
                }
                items.iter().map(scalar_text).collect::<Option<Vec<_>>>()
            }
            scalar => scalar_text(scalar).map(|v| vec![v; factor.set.get_ref().len()]),
        };
        let Some(written) = written else {
            errors.push(at.error(
                value.span().start,
                "a value is a number, a boolean, a string, or a list of those (one per address)",
            ));
            continue;
        };
        let label = match labels {
            Some(labels) => labels.get_ref().get(i).map(|l| l.get_ref().clone()),
            None => None,
        }
        .unwrap_or_else(|| {
            let mut distinct = written.clone();
            distinct.dedup();
            distinct.join("+")
        });
        levels.push(Level {
            label,
            values: written,
            location: at.location(value.span().start),
        });
    }
    let mut labels_seen = BTreeSet::new();
    for level in &levels {
        if !labels_seen.insert(level.label.clone()) {
            errors.push(Diagnostic::new(
                at.path.to_path_buf(),
                level.location,
                format!("factor '{name}' has two levels labelled '{}'", level.label),
            ));
        }
    }
    (errors.len() == before).then_some(Factor {
        name,
        addresses,
        levels,
        location: at.location(factor.set.span().start),
    })
}

/// A scalar TOML value as it is written into the configuration.
fn scalar_text(value: &toml::Value) -> Option<String> {
    match value {
        toml::Value::String(s) => Some(s.clone()),
        toml::Value::Integer(i) => Some(i.to_string()),
        toml::Value::Float(f) => Some(f.to_string()),
        toml::Value::Boolean(b) => Some(b.to_string()),
        toml::Value::Datetime(_) | toml::Value::Array(_) | toml::Value::Table(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_device_or_a_fifo_is_refused_as_a_grid_without_being_read() {
        let err = Grid::load(Path::new("/dev/zero")).expect_err("not a grid file");
        assert!(err.to_string().contains("/dev/zero"), "{err}");
        assert!(err.to_string().contains("is not a regular file"), "{err}");
    }

    const GRID: &str = r#"
base = "base.argos"
repetitions = 3
ticks = 20
median_metric = "collisions"

[[factor]]
name = "Nr"
set = ["robots"]
values = [4, 8]

[[factor]]
name = "No"
set = ["arena/distribute[entity/box]/entity@quantity", "arena/distribute[entity/cylinder]/entity@quantity"]
values = [0, [3, 2]]
labels = ["0", "5"]
"#;

    fn parse(text: &str) -> Result<Grid, ConfigErrors> {
        Grid::parse(Path::new("dir/grid.toml"), text)
    }

    #[test]
    fn grid_expands_repetitions_into_seeds_and_lists_per_address_values() {
        let grid = parse(GRID).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(grid.seeds, [1, 2, 3]);
        assert_eq!(grid.base, Path::new("dir/base.argos"));
        assert_eq!(grid.out, Path::new("runs/grid"));
        assert_eq!(grid.configuration_count(), 4);
        let no = &grid.factors[1];
        assert_eq!(no.levels[0].values, ["0", "0"]);
        assert_eq!(no.levels[1].values, ["3", "2"]);
        assert_eq!(no.levels[1].label, "5");
        assert_eq!(
            grid.x_factor,
            Some(0),
            "the factor setting robots is the x axis"
        );
        assert_eq!(
            grid.line_factors,
            [1],
            "the first other factor draws the lines"
        );
    }

    #[test]
    fn bad_address_is_located_at_its_string() {
        let text = GRID.replace(r#"set = ["robots"]"#, r#"set = ["robot"]"#);
        let err = parse(&text).expect_err("unknown shortcut");
        assert!(
            err.to_string()
                .starts_with("dir/grid.toml:9:8: bad address 'robot'"),
            "{err}"
        );
    }

    #[test]
    fn list_value_must_give_one_value_per_address() {
        let text = GRID.replace("[3, 2]", "[3, 2, 1]");
        let err = parse(&text).expect_err("three values for two addresses");
        assert!(
            err.to_string().contains("3 values for 2 addresses"),
            "{err}"
        );
        assert!(err.to_string().starts_with("dir/grid.toml:15:14:"), "{err}");
    }

    #[test]
    fn unknown_key_is_a_located_error() {
        let err = parse(&GRID.replace("ticks = 20", "tics = 20")).expect_err("typo");
        assert!(err.to_string().starts_with("dir/grid.toml:4:1:"), "{err}");
        assert!(err.to_string().contains("tics"), "{err}");
    }

    #[test]
    fn seeds_and_repetitions_exclude_each_other() {
        let err = parse(&GRID.replace("repetitions = 3", "repetitions = 3\nseeds = [1]"))
            .expect_err("both");
        assert!(err.to_string().contains("not both"), "{err}");
    }
}
