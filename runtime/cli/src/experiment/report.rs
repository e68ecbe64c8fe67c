//! `report.md`: a batch in Markdown: what was run, the per-configuration table (median runs) and the figures.

use std::fmt::Write as _;

use super::grid::Grid;
use super::plan::Configuration;
use super::plots::Figure;
use super::results::{ConfigResult, RunResult};

/// What the report says about the batch besides the results.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportFacts {
    /// Runs the grid asks for.
    pub runs_planned: usize,
    /// Runs finished (now or by earlier invocations).
    pub runs_finished: usize,
    /// Why figures are missing, if they are.
    pub plots_missing: Option<String>,
}

/// Renders `report.md`.
pub fn markdown(
    grid: &Grid,
    configurations: &[Configuration],
    runs: &[RunResult],
    results: &[ConfigResult],
    metrics: &[String],
    figures: &[Figure],
    facts: &ReportFacts,
) -> String {
    let mut out = String::new();
    let stem = grid
        .path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let _ = writeln!(out, "# Experiment `{stem}`\n");
    let _ = writeln!(out, "- grid: `{}`", grid.path.display());
    let _ = writeln!(out, "- base configuration: `{}`", grid.base.display());
    let seeds: Vec<String> = grid.seeds.iter().map(u64::to_string).collect();
    let _ = writeln!(out, "- seeds: {}", seeds.join(", "));
    if let Some(ticks) = grid.ticks {
        let _ = writeln!(out, "- ticks per run: {ticks}");
    }
    let _ = writeln!(
        out,
        "- configurations: {}; runs finished: {} of {}",
        configurations.len(),
        facts.runs_finished,
        facts.runs_planned
    );
    let _ = writeln!(
        out,
        "- each configuration is represented by its run with the median `{}` (the lower median for an even \
         count); `results.csv` has every run and each metric's mean, min and max\n",
        grid.median_metric
    );

    let _ = writeln!(out, "## Factors\n");
    let _ = writeln!(out, "| factor | sets | levels |\n|---|---|---|");
    for factor in &grid.factors {
        let sets: Vec<String> = factor.addresses.iter().map(|a| format!("`{a}`")).collect();
        let levels: Vec<&str> = factor.levels.iter().map(|l| l.label.as_str()).collect();
        let _ = writeln!(
            out,
            "| {} | {} | {} |",
            factor.name,
            sets.join("<br>"),
            levels.join(", ")
        );
    }

    let _ = writeln!(out, "\n## Configurations (median runs)\n");
    let mut header: Vec<String> = grid.factors.iter().map(|f| f.name.clone()).collect();
    header.extend(["robots".into(), "runs".into(), "median seed".into()]);
    header.extend(metrics.iter().cloned());
    let _ = writeln!(out, "| {} |", header.join(" | "));
    let _ = writeln!(out, "|{}", "---|".repeat(header.len()));
    for result in results {
        let c = &configurations[result.configuration];
        let mut row: Vec<String> = grid
            .factors
            .iter()
            .zip(&c.levels)
            .map(|(f, &l)| f.levels[l].label.clone())
            .collect();
        row.push(c.robots.to_string());
        row.push(format!("{}/{}", result.runs.len(), grid.seeds.len()));
        let median = result.median_run.map(|i| &runs[i]);
        row.push(median.map_or_else(|| "-".to_owned(), |r| r.seed.to_string()));
        row.extend(metrics.iter().map(|m| {
            median
                .and_then(|r| r.metrics.get(m))
                .map_or_else(|| "-".to_owned(), |v| format_value(*v))
        }));
        let _ = writeln!(out, "| {} |", row.join(" | "));
    }

    let _ = writeln!(out, "\n## Figures\n");
    if let Some(reason) = &facts.plots_missing {
        let _ = writeln!(out, "No figures: {reason}");
    }
    let mut current = None;
    for figure in figures {
        let heading = (&figure.metric, &figure.line_factor);
        if current != Some(heading) {
            current = Some(heading);
            let _ = match &figure.line_factor {
                Some(line) => writeln!(
                    out,
                    "### `{}` by robot count, one line per `{line}`\n",
                    figure.metric
                ),
                None => writeln!(out, "### `{}` by robot count\n", figure.metric),
            };
        }
        let alt = if figure.family.is_empty() {
            figure.metric.clone()
        } else {
            figure.family.clone()
        };
        let _ = writeln!(out, "![{alt}]({})\n", figure.path.display());
    }
    out
}

/// Up to four significant decimals, without trailing zeros.
fn format_value(value: f64) -> String {
    let text = format!("{value:.4}");
    let trimmed = text.trim_end_matches('0').trim_end_matches('.');
    if trimmed.is_empty() || trimmed == "-" {
        "0".to_owned()
    } else {
        trimmed.to_owned()
    }
}
