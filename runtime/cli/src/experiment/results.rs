//! Results of a batch: the metrics of each finished run (read from its `summary.json`), the per-configuration
//! median selection (the thesis' protocol: the run whose main metric is the median over the seeds represents the
//! configuration), aggregates, and `results.csv`.
//!
//! Generic over metric names: every number under `metrics` in `summary.json` is a metric (nested objects give
//! dotted names).

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::Path;

use super::grid::Grid;
use super::plan::Configuration;

/// One finished run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunResult {
    /// Index of the configuration.
    pub configuration: usize,
    /// The run seed.
    pub seed: u64,
    /// Ticks run.
    pub ticks: u64,
    /// Wall time of the run in seconds.
    pub wall_seconds: f64,
    /// Robots whose agent died during the run.
    pub deaths: usize,
    /// Commands that missed their tick's deadline (robot-ticks); 0 in a run that is a pure function of its seed.
    pub commands_missing: u64,
    /// The task metrics by name.
    pub metrics: BTreeMap<String, f64>,
}

/// Why a finished run's summary cannot be read.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {reason}")]
pub struct SummaryError {
    /// The summary file.
    pub path: String,
    /// What is wrong.
    pub reason: String,
}

impl RunResult {
    /// Reads a finished run directory's `summary.json`.
    pub fn read(dir: &Path, configuration: usize, seed: u64) -> Result<RunResult, SummaryError> {
        let path = dir.join(swarm_contract::run_dir::SUMMARY_FILE);
        let fail = |reason: String| SummaryError {
            path: path.display().to_string(),
            reason,
        };
        let text = std::fs::read_to_string(&path).map_err(|e| fail(e.to_string()))?;
        let summary: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| fail(format!("not JSON: {e}")))?;
        let mut metrics = BTreeMap::new();
        if let Some(object) = summary.get("metrics") {
            flatten("", object, &mut metrics);
        }
        Ok(RunResult {
            configuration,
            seed,
            ticks: summary["ticks"].as_u64().unwrap_or(0),
            wall_seconds: summary["wall_seconds"].as_f64().unwrap_or(0.0),
            deaths: summary["deaths"].as_array().map_or(0, Vec::len),
            commands_missing: summary["commands_missing"].as_u64().unwrap_or(0),
            metrics,
        })
    }
}

fn flatten(prefix: &str, value: &serde_json::Value, out: &mut BTreeMap<String, f64>) {
    match value {
        serde_json::Value::Number(n) => {
            if let Some(x) = n.as_f64().filter(|x| x.is_finite()) {
                out.insert(prefix.to_owned(), x);
            }
        }
        serde_json::Value::Object(map) => {
            for (key, inner) in map {
                let name = if prefix.is_empty() {
                    key.clone()
                } else {
                    format!("{prefix}.{key}")
                };
                flatten(&name, inner, out);
            }
        }
        _ => {}
    }
}

/// Summary statistics of one metric over a configuration's runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Mean.
    pub mean: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

/// One configuration's results.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigResult {
    /// Index of the configuration.
    pub configuration: usize,
    /// Indices (into the run results) of its finished runs.
    pub runs: Vec<usize>,
    /// The run whose main metric is the median over the runs (the lower median for an even count); a run that
    /// does not report the metric ranks after every run that does (a time not reached before the run ended, such
    /// as the last delivery of a run cut at its tick limit). `None` when the configuration has no finished run.
    pub median_run: Option<usize>,
    /// Statistics of every metric over the runs.
    pub stats: BTreeMap<String, Stats>,
}

/// Groups runs by configuration and selects each configuration's median run by `metric` (runs without it rank
/// last); ties go to the smaller seed.
pub fn select_medians(
    configurations: usize,
    runs: &[RunResult],
    metric: &str,
) -> Vec<ConfigResult> {
    (0..configurations)
        .map(|configuration| {
            let mine: Vec<usize> = (0..runs.len())
                .filter(|&i| runs[i].configuration == configuration)
                .collect();
            let mut ranked: Vec<(f64, u64, usize)> = mine
                .iter()
                .map(|&i| {
                    let value = runs[i].metrics.get(metric).copied();
                    (value.unwrap_or(f64::INFINITY), runs[i].seed, i)
                })
                .collect();
            ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let median_run = (!ranked.is_empty()).then(|| ranked[(ranked.len() - 1) / 2].2);
            let names: BTreeSet<&String> =
                mine.iter().flat_map(|&i| runs[i].metrics.keys()).collect();
            let stats = names
                .into_iter()
                .filter_map(|name| {
                    let values: Vec<f64> = mine
                        .iter()
                        .filter_map(|&i| runs[i].metrics.get(name).copied())
                        .collect();
                    let n = values.len() as f64;
                    (!values.is_empty()).then(|| {
                        (
                            name.clone(),
                            Stats {
                                mean: values.iter().sum::<f64>() / n,
                                min: values.iter().copied().fold(f64::INFINITY, f64::min),
                                max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                            },
                        )
                    })
                })
                .collect();
            ConfigResult {
                configuration,
                runs: mine,
                median_run,
                stats,
            }
        })
        .collect()
}

/// Every metric name any run reports, sorted.
pub fn metric_names(runs: &[RunResult]) -> Vec<String> {
    let names: BTreeSet<&String> = runs.iter().flat_map(|r| r.metrics.keys()).collect();
    names.into_iter().cloned().collect()
}

/// Columns of `results.csv` between the factors and the metrics.
const FIXED_COLUMNS: [&str; 7] = [
    "robots",
    "seed",
    "runs",
    "ticks",
    "wall_seconds",
    "deaths",
    "commands_missing",
];

/// `results.csv`: one row per finished run (`kind` = `run`) and one per configuration (`kind` =
/// `configuration`: the median run's values, the number of runs and each metric's mean, min and max).
pub fn csv(
    grid: &Grid,
    configurations: &[Configuration],
    runs: &[RunResult],
    results: &[ConfigResult],
) -> String {
    let metrics = metric_names(runs);
    let mut header: Vec<String> = vec!["kind".into(), "configuration".into()];
    header.extend(grid.factors.iter().map(|f| f.name.clone()));
    header.extend(FIXED_COLUMNS.iter().map(|s| (*s).to_owned()));
    // A metric named like another column (e.g. the loop functions' `ticks`) keeps its place as `metrics.<name>`.
    let columns: Vec<String> = metrics
        .iter()
        .map(|m| {
            if header.contains(m) {
                format!("metrics.{m}")
            } else {
                m.clone()
            }
        })
        .collect();
    for column in &columns {
        for stat in ["mean", "min", "max"] {
            header.push(format!("{column}_{stat}"));
        }
    }
    let stats_at = header.len() - 3 * columns.len();
    header.splice(stats_at..stats_at, columns);
    let mut out = String::new();
    push_row(&mut out, &header);

    let prefix = |c: &Configuration, kind: &str| -> Vec<String> {
        let mut row = vec![kind.to_owned(), c.id.clone()];
        row.extend(
            grid.factors
                .iter()
                .zip(&c.levels)
                .map(|(f, &l)| f.levels[l].label.clone()),
        );
        row.push(c.robots.to_string());
        row
    };
    let run_fields = |row: &mut Vec<String>, r: &RunResult| {
        row.extend([
            r.ticks.to_string(),
            format!("{:.3}", r.wall_seconds),
            r.deaths.to_string(),
            r.commands_missing.to_string(),
        ]);
        row.extend(
            metrics
                .iter()
                .map(|m| r.metrics.get(m).map_or_else(String::new, |v| v.to_string())),
        );
    };
    for r in runs {
        let mut row = prefix(&configurations[r.configuration], "run");
        row.extend([r.seed.to_string(), String::new()]);
        run_fields(&mut row, r);
        row.extend(std::iter::repeat_n(String::new(), 3 * metrics.len()));
        push_row(&mut out, &row);
    }
    for result in results {
        let mut row = prefix(&configurations[result.configuration], "configuration");
        match result.median_run.map(|i| &runs[i]) {
            Some(median) => {
                row.extend([median.seed.to_string(), result.runs.len().to_string()]);
                run_fields(&mut row, median);
            }
            None => {
                row.extend([String::new(), result.runs.len().to_string()]);
                row.extend(std::iter::repeat_n(String::new(), 3 + metrics.len()));
            }
        }
        for m in &metrics {
            match result.stats.get(m) {
                Some(s) => row.extend([s.mean.to_string(), s.min.to_string(), s.max.to_string()]),
                None => row.extend(std::iter::repeat_n(String::new(), 3)),
            }
        }
        push_row(&mut out, &row);
    }
    out
}

fn push_row(out: &mut String, fields: &[String]) {
    for (i, field) in fields.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        if field.contains([',', '"', '\n']) {
            let _ = write!(out, "\"{}\"", field.replace('"', "\"\""));
        } else {
            out.push_str(field);
        }
    }
    out.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(configuration: usize, seed: u64, time: f64) -> RunResult {
        RunResult {
            configuration,
            seed,
            ticks: 100,
            wall_seconds: 1.0,
            deaths: 0,
            commands_missing: 0,
            metrics: BTreeMap::from([("TO".to_owned(), time), ("yield".to_owned(), seed as f64)]),
        }
    }

    #[test]
    fn median_run_of_five_repetitions_is_the_third_by_the_main_metric() {
        let runs: Vec<RunResult> = [(1, 50.0), (2, 10.0), (3, 40.0), (4, 20.0), (5, 30.0)]
            .into_iter()
            .map(|(seed, t)| run(0, seed, t))
            .collect();
        let results = select_medians(1, &runs, "TO");
        let median = results[0].median_run.map(|i| runs[i].seed);
        assert_eq!(
            median,
            Some(5),
            "the run with TO = 30 is the median of 10, 20, 30, 40, 50"
        );
        let stats = results[0].stats["TO"];
        assert_eq!((stats.mean, stats.min, stats.max), (30.0, 10.0, 50.0));
    }

    #[test]
    fn even_count_takes_the_lower_median_and_ties_the_smaller_seed() {
        let runs = vec![
            run(0, 7, 2.0),
            run(0, 3, 2.0),
            run(0, 1, 9.0),
            run(0, 2, 1.0),
        ];
        let results = select_medians(1, &runs, "TO");
        assert_eq!(results[0].median_run.map(|i| runs[i].seed), Some(3));
    }

    #[test]
    fn a_run_without_the_metric_ranks_after_every_run_with_it() {
        let mut censored = run(0, 2, 0.0);
        censored.metrics.remove("TO");
        let runs = vec![run(0, 1, 10.0), censored.clone(), run(0, 3, 20.0)];
        let results = select_medians(1, &runs, "TO");
        assert_eq!(results[0].median_run.map(|i| runs[i].seed), Some(3));
        let mut twice = censored;
        twice.seed = 4;
        let runs = vec![run(0, 1, 10.0), runs[1].clone(), twice];
        let results = select_medians(1, &runs, "TO");
        assert_eq!(
            results[0].median_run.map(|i| runs[i].seed),
            Some(2),
            "two of three runs never reached it: the median did not either"
        );
    }

    #[test]
    fn configuration_without_runs_has_no_median_run() {
        let runs = vec![run(1, 1, 5.0)];
        let results = select_medians(2, &runs, "TO");
        assert_eq!(results[0].median_run, None);
        assert!(results[0].runs.is_empty());
        assert_eq!(results[1].median_run, Some(0));
    }

    #[test]
    fn csv_has_a_row_per_run_and_per_configuration_and_renames_clashing_metrics() {
        let grid = Grid::parse(
            Path::new("g.toml"),
            "base = \"b.argos\"\nrepetitions = 2\nmedian_metric = \"TO\"\n[[factor]]\nname = \"E\"\nset = [\"noise\"]\nvalues = [0]\n",
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let configurations = vec![Configuration {
            id: "E-0".into(),
            levels: vec![0],
            robots: 4,
            text: String::new(),
        }];
        let mut runs = vec![run(0, 1, 3.0), run(0, 2, 5.0)];
        for r in &mut runs {
            r.metrics.insert("ticks".into(), 100.0);
        }
        let results = select_medians(1, &runs, "TO");
        let text = csv(&grid, &configurations, &runs, &results);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "kind,configuration,E,robots,seed,runs,ticks,wall_seconds,deaths,commands_missing,TO,metrics.ticks,yield,\
             TO_mean,TO_min,\
             TO_max,metrics.ticks_mean,metrics.ticks_min,metrics.ticks_max,yield_mean,yield_min,yield_max"
        );
        assert_eq!(lines[1], "run,E-0,0,4,1,,100,1.000,0,0,3,100,1,,,,,,,,,");
        assert_eq!(
            lines[3],
            "configuration,E-0,0,4,1,2,100,1.000,0,0,3,100,1,4,3,5,100,100,100,1.5,1,2"
        );
        assert_eq!(lines.len(), 4);
    }

    #[test]
    fn nested_metrics_get_dotted_names() {
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::write(
            dir.path().join("summary.json"),
            r#"{"ticks": 20, "wall_seconds": 1.5, "deaths": [{"robot": 1}],
                "metrics": {"collisions": 3, "energy": {"total": -2.5}, "label": "x"}}"#,
        )
        .expect("summary");
        let r = RunResult::read(dir.path(), 0, 1).expect("readable");
        assert_eq!(r.ticks, 20);
        assert_eq!(r.deaths, 1);
        assert_eq!(
            r.metrics,
            BTreeMap::from([
                ("collisions".to_owned(), 3.0),
                ("energy.total".to_owned(), -2.5)
            ])
        );
    }
}
