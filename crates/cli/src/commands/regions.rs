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
    budget_json, choice_summary, clear_other, confidence_summary, correspondence_json, create_dir,
    create_out_dir, end_progress_line, graph_json, options_json, other_names, print_doubtful,
    print_pair_warnings, set_guidance_json, write_colored, write_json, TerminalProgress, OTHER_DIR,
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
        options.params.landmarks = self.pair.landmarks()?;
        let out = &self.out;
        let mut names: Vec<String> = MATCH_FILES.iter().map(|n| n.to_string()).collect();
        names.extend(other_names(&MATCH_FILES));
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        create_out_dir(out, &names, &self.pair.inputs())?;
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
        let other = result.other_answer();
        let json = |result: &Correspondence, other: Option<&str>| {
            let mut value = correspondence_json(&shape_a, &shape_b, result);
            set_guidance_json(&mut value, &options.params, result.verdict.as_ref());
            value["other_answer"] = json!(other);
            value["options"] = options_json(&options, false);
            if let Some(estimate) = &result.estimate {
                value["budget"] = budget_json(estimate);
            }
            value
        };
        let value = json(&result, other.as_ref().map(|_| OTHER_DIR));
        write_json(&out.join("result.json"), &value)?;
        write_colored(out, &shape_a, &shape_b, &result)?;
        let other_dir = out.join(OTHER_DIR);
        match &other {
            Some(other) => {
                create_dir(&other_dir)?;
                write_json(&other_dir.join("result.json"), &json(other, None))?;
                write_colored(&other_dir, &shape_a, &shape_b, other)?;
            }
            None => clear_other(out, &MATCH_FILES)?,
        }
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
        let verdict = result.verdict.as_ref();
        let where_other = format!("-> {}", other_dir.display());
        if let Some(line) = choice_summary(verdict, &options.params, &where_other) {
            outln!("{line}")?;
        }
        let look = format!(
            "look at {} (the runner-up's one-to-one regions)",
            other_dir.display()
        );
        print_pair_warnings(&result.working, [&self.pair.a, &self.pair.b]);
        print_doubtful(verdict, &options.params, &look);
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
