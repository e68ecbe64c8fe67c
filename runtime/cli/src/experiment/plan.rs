//! The configurations of a grid: every combination of factor levels applied to the base `.argos` text, with
//! relative paths made absolute (a derived file lives in the batch folder, not next to its base), each one
//! validated by the configuration parser before any run starts.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use super::address::Address;
use super::document::{Document, Edit};
use super::grid::Grid;
use swarm_contract::config::{ConfigErrors, Diagnostic, Experiment, Location};

/// Attributes whose values are paths relative to the configuration file (comma-separated lists allowed), per
/// `docs/configuration.md`.
const PATH_ATTRIBUTES: &[&str] = &[
    "controllers/*/params@supervisors",
    "arena/floor[@source=image]@path",
];

/// One configuration of the grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Configuration {
    /// File-name-safe id made of the factor levels, e.g. `Nr-10_E-0.05`.
    pub id: String,
    /// The level (index) of each factor.
    pub levels: Vec<usize>,
    /// Robots in the configuration (from the validated experiment).
    pub robots: u32,
    /// The derived `.argos` text.
    pub text: String,
}

/// Builds and validates every configuration of `grid`; on failure every distinct error, located in the grid
/// (and quoting the configuration parser's message).
pub fn configurations(grid: &Grid) -> Result<Vec<Configuration>, ConfigErrors> {
    let fail = |message: String| ConfigErrors {
        errors: vec![Diagnostic::new(
            grid.path.clone(),
            Location::default(),
            message,
        )],
    };
    let base_text = swarm_contract::config::input::read_text(
        &grid.base,
        swarm_contract::config::input::MAX_CONFIG_BYTES,
    )
    .map_err(|d| ConfigErrors { errors: vec![d] })?;
    let (_, base_warnings) = Experiment::parse(&grid.base, &base_text)?;
    let known_warnings: BTreeSet<String> = base_warnings.iter().map(message_of).collect();
    let document =
        Document::parse(&base_text).map_err(|e| fail(format!("{}: {e}", grid.base.display())))?;
    // A base named without a folder (a grid run from its own folder) lies in the current one.
    let base_folder = grid
        .base
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or_else(|| Path::new("."));
    let base_dir = std::path::absolute(base_folder)
        .map_err(|e| fail(format!("cannot resolve {}: {e}", grid.base.display())))?;

    let mut errors: BTreeMap<String, Diagnostic> = BTreeMap::new();
    let report = |errors: &mut BTreeMap<String, Diagnostic>,
                  location: Location,
                  message: String,
                  key: String| {
        errors
            .entry(key)
            .or_insert_with(|| grid.diagnostic(location, message));
    };

    // The edits of each level of each factor, computed once.
    let mut level_edits: Vec<Vec<Vec<Edit>>> = Vec::new();
    for factor in &grid.factors {
        let mut per_level = Vec::new();
        for level in &factor.levels {
            let mut edits = Vec::new();
            for (address, value) in factor.addresses.iter().zip(&level.values) {
                match document.edits(address, value) {
                    Ok(found) => edits.extend(found),
                    Err(e) => {
                        let message =
                            format!("factor '{}': {e} in {}", factor.name, grid.base.display());
                        report(&mut errors, factor.location, message.clone(), message);
                    }
                }
            }
            per_level.push(edits);
        }
        level_edits.push(per_level);
    }
    if !errors.is_empty() {
        return Err(ConfigErrors {
            errors: errors.into_values().collect(),
        });
    }

    let path_addresses: Vec<Address> = PATH_ATTRIBUTES
        .iter()
        .filter_map(|a| Address::parse(a).ok())
        .collect();
    let mut configurations = Vec::new();
    let mut ids = BTreeSet::new();
    for levels in combinations(grid) {
        let id = configuration_id(grid, &levels);
        let location = grid
            .factors
            .iter()
            .zip(&levels)
            .map(|(f, &l)| f.levels[l].location)
            .next_back()
            .unwrap_or_default();
        if !ids.insert(id.clone()) {
            report(
                &mut errors,
                location,
                format!("two configurations get the id '{id}': make the factor labels distinct"),
                id,
            );
            continue;
        }
        let edits: Vec<Edit> = levels
            .iter()
            .enumerate()
            .flat_map(|(f, &l)| level_edits[f][l].iter().cloned())
            .collect();
        let text = match absolute_paths(&document.apply(&edits), &path_addresses, &base_dir) {
            Ok(text) => text,
            Err(e) => {
                report(
                    &mut errors,
                    location,
                    format!("configuration {id}: {e}"),
                    e.clone(),
                );
                continue;
            }
        };
        match Experiment::parse(&grid.base, &text) {
            Ok((experiment, warnings)) => {
                for warning in warnings
                    .iter()
                    .filter(|w| !known_warnings.contains(&message_of(w)))
                {
                    report(
                        &mut errors,
                        location,
                        format!(
                            "configuration {id}: the values set make the configuration say: {warning}"
                        ),
                        message_of(warning),
                    );
                }
                configurations.push(Configuration {
                    id,
                    levels,
                    robots: experiment.arena.robots().len() as u32,
                    text,
                });
            }
            Err(config_errors) => {
                for error in config_errors.errors {
                    report(
                        &mut errors,
                        location,
                        format!(
                            "configuration {id}: the values set make the configuration invalid: {error}"
                        ),
                        message_of(&error),
                    );
                }
            }
        }
    }
    if errors.is_empty() {
        Ok(configurations)
    } else {
        let mut errors: Vec<Diagnostic> = errors.into_values().collect();
        errors.sort_by_key(|d| d.location);
        Err(ConfigErrors { errors })
    }
}

/// A diagnostic's message and hint without its location (values set can shift columns).
fn message_of(diagnostic: &Diagnostic) -> String {
    format!("{} {:?}", diagnostic.message, diagnostic.hint)
}

/// Every combination of level indices, the first factor varying slowest.
fn combinations(grid: &Grid) -> Vec<Vec<usize>> {
    let mut all = vec![Vec::new()];
    for factor in &grid.factors {
        all = all
            .into_iter()
            .flat_map(|prefix: Vec<usize>| {
                (0..factor.levels.len()).map(move |l| {
                    let mut next = prefix.clone();
                    next.push(l);
                    next
                })
            })
            .collect();
    }
    all
}

/// `Nr-10_E-0.05`: each factor's name and level label, made safe for file names.
pub fn configuration_id(grid: &Grid, levels: &[usize]) -> String {
    if grid.factors.is_empty() {
        return "base".to_owned();
    }
    grid.factors
        .iter()
        .zip(levels)
        .map(|(f, &l)| format!("{}-{}", f.name, file_safe(&f.levels[l].label)))
        .collect::<Vec<_>>()
        .join("_")
}

/// `text` with every character other than ASCII letters, digits, `.`, `-`, `+` and `_` replaced by `~`.
pub(super) fn file_safe(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '+' | '_') {
                c
            } else {
                '~'
            }
        })
        .collect()
}

/// Rewrites every relative path at `addresses` to an absolute one under `base_dir`.
fn absolute_paths(text: &str, addresses: &[Address], base_dir: &Path) -> Result<String, String> {
    let document = Document::parse(text).map_err(|e| e.to_string())?;
    let mut edits = Vec::new();
    for address in addresses {
        let Ok(targets) = document.edits(address, "") else {
            continue;
        };
        for (target, value) in targets.into_iter().zip(document.values(address)) {
            let Some(value) = value else { continue };
            let absolute: Vec<String> = value
                .split(',')
                .map(str::trim)
                .map(|item| {
                    if item.is_empty() || Path::new(item).is_absolute() {
                        item.to_owned()
                    } else {
                        base_dir.join(item).display().to_string()
                    }
                })
                .collect();
            edits.push(target.with_value(absolute.join(",")));
        }
    }
    Ok(document.apply(&edits))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid over the shipped 10-robot obstacle-avoidance configuration.
    fn grid(factors: &str) -> Grid {
        let base = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../configs/obstacle_avoidance/density_N10.argos");
        let text = format!(
            "base = \"{}\"\nrepetitions = 1\nmedian_metric = \"collisions\"\n{factors}",
            base.display()
        );
        Grid::parse(Path::new("grid.toml"), &text).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn robots_factor_gives_one_validated_configuration_per_level() {
        let grid = grid("[[factor]]\nname = \"Nr\"\nset = [\"robots\"]\nvalues = [4, 8]\n");
        let configurations = configurations(&grid).unwrap_or_else(|e| panic!("{e}"));
        let summary: Vec<(&str, u32)> = configurations
            .iter()
            .map(|c| (c.id.as_str(), c.robots))
            .collect();
        assert_eq!(summary, [("Nr-4", 4), ("Nr-8", 8)]);
    }

    #[test]
    fn derived_configuration_names_its_supervisors_by_absolute_path() {
        let grid = grid("");
        let configurations = configurations(&grid).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(configurations.len(), 1);
        assert_eq!(configurations[0].id, "base");
        let models = std::path::absolute(grid.base.parent().unwrap_or(Path::new("")))
            .unwrap_or_default()
            .join("models/ptsct");
        assert!(
            configurations[0]
                .text
                .contains(&format!("supervisors=\"{}\"", models.display())),
            "{}",
            configurations[0].text
        );
    }

    #[test]
    fn value_the_parser_rejects_is_an_error_located_at_the_level() {
        let grid = grid("[[factor]]\nname = \"E\"\nset = [\"noise\"]\nvalues = [0, -1]\n");
        let err = configurations(&grid).expect_err("negative noise");
        let text = err.to_string();
        assert!(
            text.starts_with(
                "grid.toml:7:14: configuration E--1: the values set make the configuration invalid"
            ),
            "{text}"
        );
        assert_eq!(err.errors.len(), 1, "{text}");
    }

    #[test]
    fn shipped_grids_derive_valid_configurations() {
        let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs");
        for (file, count, robots) in [
            ("obstacle_avoidance/grid_small.toml", 2, vec![4, 8]),
            ("foraging/grid_reduced.toml", 16, vec![10, 20]),
            ("foraging/grid_thesis.toml", 480, vec![10, 20, 40, 70, 100]),
            (
                "foraging/grid_thesis_5min.toml",
                480,
                vec![10, 20, 40, 70, 100],
            ),
            (
                "foraging/grid_thesis_5min_plotted.toml",
                40,
                vec![10, 20, 40, 70, 100],
            ),
            (
                "foraging/grid_thesis_full_sample.toml",
                16,
                vec![20, 40, 70, 100],
            ),
            (
                "pheromone_foraging/grid_pheromones.toml",
                6,
                vec![20, 40, 70],
            ),
            ("pheromone_foraging/grid_solitary.toml", 6, vec![20, 40, 70]),
        ] {
            let grid = Grid::load(&configs.join(file)).unwrap_or_else(|e| panic!("{e}"));
            let configurations = configurations(&grid).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(configurations.len(), count, "{file}");
            let mut seen: Vec<u32> = configurations.iter().map(|c| c.robots).collect();
            seen.sort_unstable();
            seen.dedup();
            assert_eq!(seen, robots, "{file}");
        }
    }

    #[test]
    fn misspelt_attribute_is_an_error_not_a_silent_warning() {
        let grid = grid(
            "[[factor]]\nname = \"No\"\nset = [\"arena/distribute[entity/box]/entity@quantiy\"]\nvalues = [2]\n",
        );
        let err = configurations(&grid).expect_err("unknown attribute");
        assert!(err.to_string().contains("quantiy"), "{err}");
    }
}
