//! `shapecorr match` (region correspondence of two shapes) and `shapecorr symmetry` (the
//! symmetric regions of one shape).

use crate::output::outln;
use std::path::PathBuf;

use serde_json::json;
use shapecorr::pipeline::{Correspondence, PairJob, Symmetry};
use shapecorr::Error;

use crate::input::{read_input, ShapePairArgs};
use crate::options::RegionOptions;
use crate::output::{
    budget_json, confidence_summary, correspondence_json, create_out_dir, end_progress_line,
    graph_json, options_json, print_warning, write_colored, write_json, TerminalProgress,
};

/// The files `match` writes into its folder.
pub const MATCH_FILES: [&str; 3] = ["result.json", "a_regions.ply", "b_regions.ply"];

#[derive(clap::Args)]
pub struct MatchArgs {
    #[command(flatten)]
    pair: ShapePairArgs,
    /// Output folder (created if missing).
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    options: RegionOptions,
}

impl MatchArgs {
    pub fn run(&self) -> Result<(), Error> {
        let mut options = self.options.options()?;
        let out = &self.out;
        create_out_dir(out, &MATCH_FILES, &[&self.pair.a, &self.pair.b])?;
        let mut progress = TerminalProgress::new();
        let mut budget = options.params.budget.clone();
        let job = PairJob {
            params: &options.params,
            map: None,
        };
        let read = self.pair.read_in_budget(
            &mut budget,
            |files| job.check_files(files).map(|_| ()),
            &mut progress,
        );
        let (shape_a, shape_b) = read.inspect_err(|_| end_progress_line())?;
        options.params.budget = budget;
        let result = Correspondence::compute(&shape_a, &shape_b, &options.params, &mut progress);
        end_progress_line();
        let result = result.map_err(|e| self.pair.naming(e))?;
        let mut value = correspondence_json(&shape_a, &shape_b, &result);
        value["options"] = options_json(&options, false);
        if let Some(estimate) = &result.estimate {
            value["budget"] = budget_json(estimate);
        }
        write_json(&out.join("result.json"), &value)?;
        write_colored(out, &shape_a, &shape_b, &result)?;
        outln!(
            "k = {}: {} regions on A, {} on B; {} symmetric matches, {} one-to-one ({}); {:.2} s -> {}",
            result.k,
            result.graph_a.n_nodes(),
            result.graph_b.n_nodes(),
            result.matches.len(),
            result.matches_one_to_one.len(),
            confidence_summary(result.verdict.as_ref()),
            result.timings.total,
            out.display()
        )?;
        print_warning(result.verdict.as_ref());
        Ok(())
    }
}

#[derive(clap::Args)]
pub struct SymmetryArgs {
    a: PathBuf,
    /// Output folder (created if missing).
    #[arg(long)]
    out: PathBuf,
    #[arg(long)]
    points: bool,
    /// Use the shapes as given: no welding of coincident vertices, no leaving out of small
    /// loose pieces, far vertices or isolated points (each repair made is printed on stderr).
    #[arg(long)]
    no_repair: bool,
    #[command(flatten)]
    options: RegionOptions,
}

impl SymmetryArgs {
    pub fn run(&self) -> Result<(), Error> {
        let options = self.options.options()?;
        let out = &self.out;
        create_out_dir(out, &["a_symmetry.ply", "result.json"], &[&self.a])?;
        let shape = read_input('A', &self.a, self.points, self.no_repair)?;
        let symmetry = Symmetry::detect(&shape, &options.params, &mut TerminalProgress::new());
        end_progress_line();
        let symmetry = symmetry?;
        let colors = symmetry.vertex_colors();
        shapecorr::shape::io::write_ply(
            &out.join("a_symmetry.ply"),
            shape.vertices(),
            shape.triangles(),
            Some(&colors),
        )?;
        write_json(
            &out.join("result.json"),
            &json!({
                "version": env!("CARGO_PKG_VERSION"),
                "n_vertices_a": shape.n_vertices(),
                "regions_a": symmetry.graph.labels,
                "groups": symmetry.groups,
                "matches": symmetry.matches,
                "graph_a": graph_json(&symmetry.graph),
                "options": options_json(&options, false),
            }),
        )?;
        let symmetric_groups = symmetry.groups.iter().filter(|g| g.len() > 1).count();
        outln!(
            "{} regions, {} groups of symmetric regions -> {}",
            symmetry.graph.n_nodes(),
            symmetric_groups,
            out.display()
        )?;
        Ok(())
    }
}
