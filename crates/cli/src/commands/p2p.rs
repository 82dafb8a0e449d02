//! `shapecorr p2p`: the point-to-point map from B to A (regions, functional map, ZoomOut).

use crate::output::outln;
use std::path::PathBuf;

use serde_json::json;
use shapecorr::pipeline::PairJob;
use shapecorr::Error;
use shapecorr::PointwiseCorrespondence;

use crate::input::ShapePairArgs;
use crate::options::PointwiseOptions;
use crate::output::{
    budget_json, confidence_summary, correspondence_json, create_out_dir, end_progress_line,
    options_json, print_warning, set_verdict_json, write_colored, write_json, write_map,
    write_map_colors, TerminalProgress,
};

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
        let out = &self.out;
        let names = [
            "map_b_to_a.txt",
            "result.json",
            "a_regions.ply",
            "b_regions.ply",
            "a_colors.ply",
            "b_mapped.ply",
        ];
        create_out_dir(out, &names, &[&self.pair.a, &self.pair.b])?;
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
        let map = &result.map.p2p_ba;
        write_map(&out.join("map_b_to_a.txt"), map)?;
        let mut value = correspondence_json(&shape_a, &shape_b, &result.regions);
        value["timings_s"] = json!({
            "eigenbasis_a": result.eigenbasis_a,
            "eigenbasis_b": result.eigenbasis_b,
            "regions": result.regions.timings,
            "pointwise": result.map.timings,
            "total": result.total,
        });
        value["fmap_size"] = json!(result.map.fmap_ab.nrows());
        value["options"] = options_json(&options, true);
        value["region_times"] = json!(pointwise.region_times);
        value["budget"] = budget_json(&result.estimate);
        // The answer's verdict: the map's own when it verified hypotheses, else the regions'.
        set_verdict_json(&mut value, result.verdict());
        write_json(&out.join("result.json"), &value)?;
        write_colored(out, &shape_a, &shape_b, &result.regions)?;
        write_map_colors(out, &shape_a, &shape_b, map)?;
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
        print_warning(result.verdict());
        Ok(())
    }
}
