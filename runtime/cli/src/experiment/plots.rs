//! PNG figures of a batch, as the thesis draws them: each metric against the robot count, one figure per
//! configuration family (the configurations that share every factor level except the robot factor and the line
//! factor), one line per level of the line factor, each point the configuration's median run. Each point also
//! shows the spread over its seeds: a thin bar from the smallest to the largest run, a thick one over the middle
//! half (first to third quartile), so a median that hides a wide spread is seen as such.
//!
//! Text is drawn with the TrueType font of [`swarm_contract::fonts`] (`SWARM_FONT`, else a common system font),
//! read once at run time, so the build needs no font library; without a font the batch still writes its table and
//! report and says why the figures are missing.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::prelude::*;
use swarm_contract::fonts::{self, NoFont};

use super::grid::Grid;
use super::plan::{Configuration, file_safe};
use super::results::{ConfigResult, RunResult};

/// The font family name the figures use.
const FAMILY: &str = "sans-serif";
/// Figure size in pixels.
const SIZE: (u32, u32) = (900, 560);

/// One point of a line: a configuration's median run and the spread of its runs over the seeds.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Point {
    robots: f64,
    median: f64,
    min: f64,
    lower_quartile: f64,
    upper_quartile: f64,
    max: f64,
}

/// The points of one line.
type Points = Vec<Point>;

/// The value at quantile `q` of sorted `values` (linear between neighbours).
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let at = (sorted.len() - 1) as f64 * q;
    let (low, high) = (at.floor() as usize, at.ceil() as usize);
    sorted[low] + (sorted[high] - sorted[low]) * (at - low as f64)
}
/// A family's fixed levels -> the line factor's level -> the line's points.
type Families = BTreeMap<Vec<usize>, BTreeMap<usize, Points>>;

/// One written figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// The metric drawn.
    pub metric: String,
    /// The factor drawn as lines (`None`: one line).
    pub line_factor: Option<String>,
    /// The fixed levels of the family, e.g. `No = 5, RE = true` (empty for a single family).
    pub family: String,
    /// The PNG, relative to the batch folder.
    pub path: PathBuf,
}

/// Why figures could not be drawn.
#[derive(Debug, Clone, thiserror::Error)]
pub enum PlotError {
    /// No usable font.
    #[error("cannot draw figures: {0}")]
    NoFont(NoFont),
    /// Drawing or writing a figure failed.
    #[error("{path}: {reason}")]
    Draw {
        /// The figure.
        path: String,
        /// What failed.
        reason: String,
    },
}

/// Registers the figures' font once per process.
fn font() -> Result<(), PlotError> {
    static FONT: OnceLock<Result<(), PlotError>> = OnceLock::new();
    FONT.get_or_init(|| {
        let font = fonts::font().map_err(|no_font| PlotError::NoFont(no_font.clone()))?;
        plotters::style::register_font(FAMILY, FontStyle::Normal, &font.bytes).map_err(|_| {
            PlotError::NoFont(NoFont {
                tried: format!("{} (not a font plotters can read)", font.path.display()),
            })
        })
    })
    .clone()
}

/// Draws every figure of the batch under `<batch>/plots/`; returns them in drawing order.
pub fn draw(
    batch: &Path,
    grid: &Grid,
    configurations: &[Configuration],
    runs: &[RunResult],
    results: &[ConfigResult],
    metrics: &[String],
) -> Result<Vec<Figure>, PlotError> {
    font()?;
    let mut figures = Vec::new();
    let line_factors: Vec<Option<usize>> = if grid.line_factors.is_empty() {
        vec![None]
    } else {
        grid.line_factors.iter().copied().map(Some).collect()
    };
    for metric in metrics {
        for &line in &line_factors {
            // family levels -> line level -> (robots, value) points
            let mut families: Families = BTreeMap::new();
            for result in results {
                let Some(median) = result
                    .median_run
                    .and_then(|i| runs[i].metrics.get(metric).copied())
                else {
                    continue;
                };
                let mut values: Vec<f64> = result
                    .runs
                    .iter()
                    .filter_map(|&i| runs[i].metrics.get(metric).copied())
                    .filter(|v| v.is_finite())
                    .collect();
                values.sort_by(f64::total_cmp);
                if values.is_empty() {
                    values.push(median);
                }
                let c = &configurations[result.configuration];
                let family: Vec<usize> = (0..grid.factors.len())
                    .filter(|&f| Some(f) != grid.x_factor && Some(f) != line)
                    .map(|f| c.levels[f])
                    .collect();
                let line_level = line.map_or(0, |f| c.levels[f]);
                families
                    .entry(family)
                    .or_default()
                    .entry(line_level)
                    .or_default()
                    .push(Point {
                        robots: f64::from(c.robots),
                        median,
                        min: values[0],
                        lower_quartile: quantile(&values, 0.25),
                        upper_quartile: quantile(&values, 0.75),
                        max: values[values.len() - 1],
                    });
            }
            let family_factors: Vec<usize> = (0..grid.factors.len())
                .filter(|&f| Some(f) != grid.x_factor && Some(f) != line)
                .collect();
            for (family, lines) in families {
                let named: Vec<(String, String)> = family_factors
                    .iter()
                    .zip(&family)
                    .map(|(&f, &l)| {
                        (
                            grid.factors[f].name.clone(),
                            grid.factors[f].levels[l].label.clone(),
                        )
                    })
                    .collect();
                let family_text = named
                    .iter()
                    .map(|(n, l)| format!("{n} = {l}"))
                    .collect::<Vec<_>>()
                    .join(", ");
                let file = if named.is_empty() {
                    "all".to_owned()
                } else {
                    named
                        .iter()
                        .map(|(n, l)| format!("{n}-{}", file_safe(l)))
                        .collect::<Vec<_>>()
                        .join("_")
                };
                let line_name = line.map(|f| grid.factors[f].name.clone());
                let relative = Path::new("plots")
                    .join(file_safe(metric))
                    .join(line_name.as_deref().unwrap_or("single"))
                    .join(format!("{file}.png"));
                let series: Vec<(String, Points)> = lines
                    .into_iter()
                    .map(|(level, mut points)| {
                        points.sort_by(|a, b| a.robots.total_cmp(&b.robots));
                        let label = match line {
                            Some(f) => format!(
                                "{} = {}",
                                grid.factors[f].name, grid.factors[f].levels[level].label
                            ),
                            None => metric.clone(),
                        };
                        (label, points)
                    })
                    .collect();
                let title = if family_text.is_empty() {
                    format!("{metric}: median run, bars over seeds")
                } else {
                    format!("{metric}: median run, bars over seeds; {family_text}")
                };
                draw_figure(&batch.join(&relative), &title, metric, &series)?;
                figures.push(Figure {
                    metric: metric.clone(),
                    line_factor: line_name,
                    family: family_text,
                    path: relative,
                });
            }
        }
    }
    Ok(figures)
}

/// A range around `values` with a margin, never empty.
fn padded(values: impl Iterator<Item = f64> + Clone) -> std::ops::Range<f64> {
    let min = values.clone().fold(f64::INFINITY, f64::min);
    let max = values.fold(f64::NEG_INFINITY, f64::max);
    if !min.is_finite() || !max.is_finite() {
        return 0.0..1.0;
    }
    let span = if max > min {
        max - min
    } else {
        min.abs().max(1.0)
    };
    (min - 0.08 * span)..(max + 0.08 * span)
}

fn draw_figure(
    path: &Path,
    title: &str,
    metric: &str,
    series: &[(String, Points)],
) -> Result<(), PlotError> {
    let fail = |reason: String| PlotError::Draw {
        path: path.display().to_string(),
        reason,
    };
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|e| fail(e.to_string()))?;
    }
    let points = series.iter().flat_map(|(_, p)| p.iter());
    let x_range = padded(points.clone().map(|p| p.robots));
    let y_range = padded(points.flat_map(|p| [p.min, p.max]));
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, (FAMILY, 20))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(x_range, y_range)
        .map_err(|e| fail(e.to_string()))?;
    chart
        .configure_mesh()
        .x_desc("robots")
        .y_desc(metric)
        .label_style((FAMILY, 14))
        .draw()
        .map_err(|e| fail(e.to_string()))?;
    for (i, (label, points)) in series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        // Bars first, so the line and its points stay on top.
        chart
            .draw_series(points.iter().map(|p| {
                PathElement::new(
                    vec![(p.robots, p.min), (p.robots, p.max)],
                    color.stroke_width(1),
                )
            }))
            .map_err(|e| fail(e.to_string()))?;
        chart
            .draw_series(points.iter().map(|p| {
                PathElement::new(
                    vec![(p.robots, p.lower_quartile), (p.robots, p.upper_quartile)],
                    color.mix(0.5).stroke_width(7),
                )
            }))
            .map_err(|e| fail(e.to_string()))?;
        chart
            .draw_series(LineSeries::new(
                points.iter().map(|p| (p.robots, p.median)),
                color.stroke_width(2),
            ))
            .map_err(|e| fail(e.to_string()))?
            .label(label.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        chart
            .draw_series(
                points
                    .iter()
                    .map(|p| Circle::new((p.robots, p.median), 4, color.filled())),
            )
            .map_err(|e| fail(e.to_string()))?;
    }
    chart
        .configure_series_labels()
        .label_font((FAMILY, 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| fail(e.to_string()))?;
    root.present().map_err(|e| fail(e.to_string()))
}

#[cfg(test)]
mod tests {
    #[test]
    fn quantiles_interpolate_between_sorted_values() {
        let values = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(super::quantile(&values, 0.0), 1.0);
        assert_eq!(super::quantile(&values, 0.25), 2.0);
        assert_eq!(super::quantile(&values, 0.5), 3.0);
        assert_eq!(super::quantile(&[1.0, 2.0], 0.5), 1.5);
        assert_eq!(super::quantile(&[7.0], 0.75), 7.0);
    }
}
