//! `shapecorr p2p`: the point-to-point map from B to A (regions, functional map, ZoomOut),
//! and the runner-up hypothesis's map in `OUT/other/` (nothing recomputed).

use crate::output::outln;
use std::path::{Path, PathBuf};

use serde_json::json;
use shapecorr::pipeline::PairJob;
use shapecorr::PointwiseCorrespondence;
use shapecorr::{Error, Params, PointwiseParams, Shape};

use crate::input::ShapePairArgs;
use crate::options::PointwiseOptions;
use crate::output::{
    budget_json, choice_summary, clear_other, confidence_summary, correspondence_json, create_dir,
    create_out_dir, end_progress_line, options_json, other_names, print_doubtful,
    print_pair_warnings, set_guidance_json, set_verdict_json, write_colored, write_json, write_map,
    write_map_colors, TerminalProgress, OTHER_DIR,
};

/// The files `p2p` writes into its folder, and into its `other/` folder for the runner-up.
pub const P2P_FILES: [&str; 6] = [
    "map_b_to_a.txt",
    "result.json",
    "a_regions.ply",
    "b_regions.ply",
    "a_colors.ply",
    "b_mapped.ply",
];

#[derive(clap::Args)]
pub struct P2pArgs {
    #[command(flatten)]
    pair: ShapePairArgs,
    /// Output folder (created if missing).
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    options: PointwiseOptions,
}

impl P2pArgs {
    pub fn run(&self) -> Result<(), Error> {
        let (mut options, pointwise) = self.options.pointwise()?;
        options.params.landmarks = self.pair.landmarks()?;
        let out = &self.out;
        let mut names: Vec<String> = P2P_FILES.iter().map(|n| n.to_string()).collect();
        names.extend(other_names(&P2P_FILES));
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        create_out_dir(out, &names, &self.pair.inputs())?;
        let mut progress = TerminalProgress::new();
        let mut budget = options.params.budget.clone();
        let job = PairJob {
            params: &options.params,
            map: Some(&pointwise),
        };
        let read = self.pair.read_in_budget(
            &mut budget,
            |files| job.check_files(files).map(|_| ()),
            &mut progress,
        );
        let (shape_a, shape_b) = read.inspect_err(|_| end_progress_line())?;
        options.params.budget = budget;
        let result = PointwiseCorrespondence::compute(
            &shape_a,
            &shape_b,
            &options.params,
            &pointwise,
            &mut progress,
        );
        end_progress_line();
        let result = result.map_err(|e| self.pair.naming(e))?;
        let other = result.other_answer();
        let answer = Answer {
            shapes: (&shape_a, &shape_b),
            options: &options,
            pointwise: &pointwise,
        };
        let mut value = answer.json(&result);
        value["other_answer"] = json!(other.as_ref().map(|_| OTHER_DIR));
        answer.write(out, &result, &value)?;
        let other_dir = out.join(OTHER_DIR);
        match &other {
            Some(other) => {
                create_dir(&other_dir)?;
                let mut value = answer.json(other);
                value["other_answer"] = serde_json::Value::Null;
                answer.write(&other_dir, other, &value)?;
            }
            None => clear_other(out, &P2P_FILES)?,
        }
        let map = &result.map.p2p_ba;
        outln!(
            "map of {} vertices of B onto A ({} one-to-one region matches, functional map {}x{}, {}); {:.2} s -> {}",
            map.len(),
            result.regions.matches_one_to_one.len(),
            result.map.fmap_ab.nrows(),
            result.map.fmap_ab.ncols(),
            confidence_summary(result.verdict()),
            result.total,
            out.display()
        )?;
        let params = &options.params;
        let where_other = format!("-> {}", other_dir.display());
        if let Some(line) = choice_summary(result.verdict(), params, &where_other) {
            outln!("{line}")?;
        }
        let look = format!(
            "look at {} (the runner-up's map, b_mapped.ply)",
            other_dir.display()
        );
        print_pair_warnings(&result.regions.working, [&self.pair.a, &self.pair.b]);
        print_doubtful(result.verdict(), params, &look);
        Ok(())
    }
}

/// What an answer's files are written from: the shapes, the options and the map's
/// parameters.
struct Answer<'a> {
    shapes: (&'a Shape, &'a Shape),
    options: &'a shapecorr::options::Options,
    pointwise: &'a PointwiseParams,
}

impl Answer<'_> {
    fn params(&self) -> &Params {
        &self.options.params
    }

    /// `result.json` of `result`.
    fn json(&self, result: &PointwiseCorrespondence) -> serde_json::Value {
        let (a, b) = self.shapes;
        let mut value = correspondence_json(a, b, &result.regions);
        value["timings_s"] = json!({
            "eigenbasis_a": result.eigenbasis_a,
            "eigenbasis_b": result.eigenbasis_b,
            "regions": result.regions.timings,
            "pointwise": result.map.timings,
            "total": result.total,
        });
        value["fmap_size"] = json!(result.map.fmap_ab.nrows());
        let partial = &result.map.partial;
        value["partial"] = json!({
            "taken_as": partial.partiality.name(),
            "given": partial.given,
            "covered_share": result.map.coverage.share_a,
            "open_boundary": partial.boundary,
            "area_share": partial.area_share,
            "covered_a": result.map.coverage.a.iter().filter(|&&c| c).count(),
            "covered_b": result.map.coverage.b.iter().filter(|&&c| c).count(),
        });
        value["options"] = options_json(self.options, true);
        value["region_times"] = json!(self.pointwise.region_times);
        value["budget"] = budget_json(&result.estimate);
        // The answer's verdict: the map's own when it verified hypotheses, else the regions'.
        set_verdict_json(&mut value, result.verdict());
        set_guidance_json(&mut value, self.params(), result.verdict());
        value
    }

    /// Writes the files of [`P2P_FILES`] of `result` into `dir`, `value` as `result.json`.
    fn write(
        &self,
        dir: &Path,
        result: &PointwiseCorrespondence,
        value: &serde_json::Value,
    ) -> Result<(), Error> {
        let (a, b) = self.shapes;
        write_map(&dir.join("map_b_to_a.txt"), &result.map.p2p_ba)?;
        write_json(&dir.join("result.json"), value)?;
        write_colored(dir, a, b, &result.regions)?;
        write_map_colors(dir, a, b, &result.map.p2p_ba)
    }
}
