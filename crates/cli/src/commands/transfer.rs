//! `shapecorr transfer`: values on A's vertices carried to B's through the pointwise map and
//! the surface map (docs/transfer.md).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use shapecorr::maps::surface::SurfaceMap;
use shapecorr::transfer::TransferMode;
use shapecorr::Error;
use shapecorr::PointwiseCorrespondence;

use crate::input::ShapePairArgs;
use crate::options::PointwiseOptions;
use crate::output::{confidence_summary, end_progress_line, print_warning, TerminalProgress};

/// How the values are carried (the library's `TransferMode`).
#[derive(Clone, Copy, clap::ValueEnum)]
enum Mode {
    /// Weighted mean on A's surface: continuous data (colours, positions, any smooth value).
    Interpolate,
    /// The nearest vertex's value: labels, ids, integers.
    Nearest,
    /// Skin weights: interpolated, the largest `--max-influences` kept, each row summing to 1.
    Weights,
}

#[derive(clap::Args)]
pub struct TransferArgs {
    #[command(flatten)]
    pair: ShapePairArgs,
    /// Values on A: a text file with one row per vertex of A, in A's vertex order, numbers
    /// separated by spaces, tabs or commas (every row the same count); `#` starts a comment.
    #[arg(long)]
    values: PathBuf,
    /// Where B's values are written: one row per vertex of B, in the same layout.
    #[arg(long)]
    out: PathBuf,
    #[arg(long, value_enum, default_value = "interpolate")]
    mode: Mode,
    /// With `--mode weights`: the most non-zero weights a vertex keeps (0: all).
    #[arg(long, default_value_t = 4)]
    max_influences: usize,
    /// Also write where every vertex of B lands on A: a row per vertex of B with three
    /// vertices of A and their three weights (`a0 a1 a2 w0 w1 w2`).
    #[arg(long)]
    surface_map: Option<PathBuf>,
    #[command(flatten)]
    options: PointwiseOptions,
}

impl TransferArgs {
    pub fn run(&self) -> Result<(), Error> {
        let (options, pointwise) = self.options.pointwise()?;
        let (shape_a, shape_b) = self.pair.read()?;
        let (values, channels) = read_values(&self.values, shape_a.n_vertices())?;
        let mut progress = TerminalProgress::new();
        let result = PointwiseCorrespondence::compute(
            &shape_a,
            &shape_b,
            &options.params,
            &pointwise,
            &mut progress,
        )
        .and_then(|result| {
            let onto =
                SurfaceMap::from_vertex_map(&shape_a, &shape_b, &result.map.p2p_ba, &mut progress)?;
            Ok((result, onto))
        });
        end_progress_line();
        let (result, onto) = result.map_err(|e| self.pair.naming(e))?;
        let mode = match self.mode {
            Mode::Interpolate => TransferMode::Interpolate,
            Mode::Nearest => TransferMode::Nearest,
            Mode::Weights => TransferMode::Weights {
                max_influences: self.max_influences,
            },
        };
        let carried = onto
            .transfer(&values, channels, mode)
            .map_err(|e| Error::file(&self.values, e.to_string()))?;
        write_rows(&self.out, &carried, channels)?;
        if let Some(path) = &self.surface_map {
            write_surface_map(path, &onto)?;
        }
        println!(
            "{} values a vertex carried to {} vertices of B ({}); {:.2} s -> {}",
            channels,
            shape_b.n_vertices(),
            confidence_summary(result.verdict()),
            result.total,
            self.out.display()
        );
        print_warning(result.verdict());
        Ok(())
    }
}

/// A text matrix of `rows` rows: the values row-major and the column count.
fn read_values(path: &Path, rows: usize) -> Result<(Vec<f64>, usize), Error> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::file(path, e.to_string()))?;
    let mut values = Vec::new();
    let mut columns = None;
    let mut count = 0;
    for (number, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let before = values.len();
        for word in line.split(|c: char| c.is_whitespace() || c == ',') {
            if word.is_empty() {
                continue;
            }
            let value: f64 = word.parse().map_err(|_| {
                Error::file(
                    path,
                    format!("line {}: `{word}` is not a number", number + 1),
                )
            })?;
            values.push(value);
        }
        let width = values.len() - before;
        match columns {
            None => columns = Some(width),
            Some(c) if c != width => {
                return Err(Error::file(
                    path,
                    format!("line {} has {width} values, the first row {c}", number + 1),
                ))
            }
            _ => {}
        }
        count += 1;
    }
    if count != rows {
        return Err(Error::file(
            path,
            format!("{count} rows of values, but shape A has {rows} vertices (one row each)"),
        ));
    }
    Ok((values, columns.unwrap_or(0)))
}

fn write_rows(path: &Path, values: &[f64], channels: usize) -> Result<(), Error> {
    let mut text = String::with_capacity(values.len() * 10);
    for row in values.chunks(channels.max(1)) {
        for (i, x) in row.iter().enumerate() {
            let _ = write!(text, "{}{x}", if i == 0 { "" } else { " " });
        }
        text.push('\n');
    }
    std::fs::write(path, text).map_err(|e| Error::file(path, e.to_string()))
}

fn write_surface_map(path: &Path, onto: &SurfaceMap) -> Result<(), Error> {
    let mut text = String::with_capacity(onto.points.len() * 48);
    for point in &onto.points {
        let [v0, v1, v2] = point.vertices;
        let [w0, w1, w2] = point.weights;
        let _ = writeln!(text, "{v0} {v1} {v2} {w0} {w1} {w2}");
    }
    std::fs::write(path, text).map_err(|e| Error::file(path, e.to_string()))
}
