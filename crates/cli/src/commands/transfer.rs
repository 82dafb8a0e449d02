//! `shapecorr transfer`: values on A's vertices carried to B's through the pointwise map and
//! the surface map (docs/transfer.md).

use std::fmt::Write as _;
use std::path::PathBuf;

use shapecorr::maps::surface::SurfaceMap;
use shapecorr::transfer::{read_values, TransferMode};
use shapecorr::Error;
use shapecorr::PointwiseCorrespondence;

use crate::input::ShapePairArgs;
use crate::options::PointwiseOptions;
use crate::output::{
    check_output_file, choice_summary, confidence_summary, end_progress_line, outln,
    print_doubtful, refuse_inputs, write_files, TerminalProgress,
};

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
    /// separated by ASCII spaces, tabs or commas (every row the same count, no empty field);
    /// `#` starts a comment. Integers are exact to 64 bits (docs/transfer.md, "Values files").
    #[arg(long)]
    values: PathBuf,
    /// Where B's values are written: one row per vertex of B, in the same layout. Written
    /// only when the whole job succeeded; never one of the inputs.
    #[arg(long)]
    out: PathBuf,
    #[arg(long, value_enum, default_value = "interpolate")]
    mode: Mode,
    /// With `--mode weights`: the most non-zero weights a vertex keeps (0: all).
    #[arg(long, default_value = "4", allow_negative_numbers = true, value_parser = influences)]
    max_influences: usize,
    /// Also write where every vertex of B lands on A: a row per vertex of B with three
    /// vertices of A and their three weights (`a0 a1 a2 w0 w1 w2`).
    #[arg(long)]
    surface_map: Option<PathBuf>,
    /// Carry the values through the runner-up hypothesis's map instead of the chosen one:
    /// the other answer (`p2p` writes it in `OUT/other/`), for when the first transfer came
    /// out swapped or mirrored. Fails when no other hypothesis gives a different map.
    #[arg(long)]
    other_answer: bool,
    #[command(flatten)]
    options: PointwiseOptions,
}

/// `--max-influences`: a count, 0 for all; a negative number gets a message of its own
/// rather than clap's "unexpected argument".
fn influences(text: &str) -> Result<usize, String> {
    match text.parse::<i128>() {
        Ok(n) if n < 0 => Err(format!(
            "{n} is negative: give the most weights a vertex keeps, or 0 to keep all"
        )),
        Ok(n) => Ok(usize::try_from(n).unwrap_or(usize::MAX)),
        Err(_) => Err(format!(
            "`{text}` is not a count: give the most weights a vertex keeps, or 0 to keep all"
        )),
    }
}

impl TransferArgs {
    pub fn run(&self) -> Result<(), Error> {
        let (mut options, pointwise) = self.options.pointwise()?;
        options.params.landmarks = self.pair.landmarks()?;
        let mut outputs = vec![self.out.as_path()];
        outputs.extend(self.surface_map.as_deref());
        let mut inputs = self.pair.inputs();
        inputs.push(&self.values);
        refuse_inputs(&outputs, &inputs)?;
        for path in &outputs {
            check_output_file(path)?;
        }
        let (shape_a, shape_b) = self.pair.read()?;
        let values = read_values(&self.values, shape_a.n_vertices())?;
        let mut progress = TerminalProgress::new();
        let result = PointwiseCorrespondence::compute(
            &shape_a,
            &shape_b,
            &options.params,
            &pointwise,
            &mut progress,
        )
        .and_then(|result| {
            let result = if self.other_answer {
                result
                    .other_answer()
                    .ok_or_else(|| Error::InvalidParameter {
                        name: "other_answer",
                        reason:
                            "no other hypothesis gives a different map: the answer is the only \
                             one (see `shapecorr p2p`'s result.json, `runner_up`)"
                                .into(),
                    })?
            } else {
                result
            };
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
        let carried = values
            .transfer(&onto, mode)
            .map_err(|e| Error::file(&self.values, e.to_string()))?;
        let mut rows = Vec::new();
        let _ = carried.write_text(&mut rows);
        let map = self
            .surface_map
            .as_ref()
            .map(|path| (path, surface_map_text(&onto)));
        let mut files = vec![(self.out.as_path(), rows.as_slice())];
        files.extend(map.as_ref().map(|(p, t)| (p.as_path(), t.as_bytes())));
        write_files(&files)?;
        outln!(
            "{} values a vertex carried to {} vertices of B ({}); {:.2} s -> {}",
            values.channels(),
            shape_b.n_vertices(),
            confidence_summary(result.verdict()),
            result.total,
            self.out.display()
        )?;
        let uncovered = result.map.coverage.b.iter().filter(|&&c| !c).count();
        if uncovered > 0 {
            outln!(
                "A was taken as a part of B: {uncovered} of {} vertices of B have no \
                 counterpart on A; their rows come from the nearest part of A, not from a \
                 counterpart (docs/partial.md)",
                shape_b.n_vertices()
            )?;
        }
        let params = &options.params;
        let other = if self.other_answer {
            ""
        } else {
            "(--other-answer carries the values through its map)"
        };
        if let Some(line) = choice_summary(result.verdict(), params, other) {
            outln!("{line}")?;
        }
        let look = if self.other_answer {
            "run without --other-answer to go back to the first answer"
        } else {
            "carry the values through the runner-up's map with --other-answer"
        };
        print_doubtful(result.verdict(), params, look);
        Ok(())
    }
}

fn surface_map_text(onto: &SurfaceMap) -> String {
    let mut text = String::with_capacity(onto.points.len() * 48);
    for point in &onto.points {
        let [v0, v1, v2] = point.vertices;
        let [w0, w1, w2] = point.weights;
        let _ = writeln!(text, "{v0} {v1} {v2} {w0} {w1} {w2}");
    }
    text
}
