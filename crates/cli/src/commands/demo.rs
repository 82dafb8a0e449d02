//! `shapecorr demo`: two generated humanoids in different poses, one a noisy point cloud,
//! matched (regions, then the point-to-point map) and scored against the known ground truth.

use crate::output::{errln, outln};
use std::path::PathBuf;
use std::time::Instant;

use shapecorr::evaluation::score_correspondence;
use shapecorr::maps::pointwise::{PointwiseMap, PointwiseParams};
use shapecorr::pipeline::pointwise::truncated;
use shapecorr::pipeline::{Correspondence, Params};
use shapecorr::synth::{self, FigureKind, FigureSpec, Proportions};
use shapecorr::{EigenParams, Eigenbasis, Error, NoProgress, Shape, ShapeBasis};

use crate::output::{
    correspondence_json, create_dir, end_progress_line, write_colored, write_json, write_map,
    write_map_colors, TerminalProgress,
};

#[derive(clap::Args)]
pub struct DemoArgs {
    /// Output folder.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
    /// Vertices of the mesh (and points of the cloud).
    #[arg(long, default_value_t = 8000)]
    vertices: usize,
}

impl DemoArgs {
    pub fn run(&self) -> Result<(), Error> {
        let (out, vertices) = (self.out.as_path(), self.vertices);
        create_dir(out)?;
        let spec = |pose| FigureSpec {
            kind: FigureKind::Humanoid,
            pose,
            target_vertices: vertices,
            proportions: Proportions::default(),
            ..Default::default()
        };
        let t = Instant::now();
        let mesh_a = synth::figure(&spec(0))?;
        let mesh_b = synth::figure(&spec(3))?;
        let cloud_b = synth::sample_points(&mesh_b, vertices, 0.005, 1)?;
        outln!(
            "A: humanoid, rest pose, mesh of {} vertices; B: humanoid, pose 3, point cloud of {} points with noise 0.5% of the width ({:.2} s)",
            mesh_a.vertices.len(),
            cloud_b.points.len(),
            t.elapsed().as_secs_f64()
        )?;
        let a = Shape::mesh(mesh_a.vertices.clone(), &mesh_a.triangles)?;
        let b = Shape::point_cloud(cloud_b.points.clone())?;
        let params = Params::default();
        let pointwise = PointwiseParams::default();
        // One eigenbasis per shape, large enough for the pointwise map; the regions use its
        // first `params.eigen.n_eigenpairs`.
        let eigen = EigenParams {
            n_eigenpairs: pointwise.n_eigenpairs,
            ..params.eigen.clone()
        };
        let full_a = Eigenbasis::compute(&a, &eigen, &mut NoProgress)?;
        let full_b = Eigenbasis::compute(&b, &eigen, &mut NoProgress)?;
        let basis_a = truncated(&full_a, params.eigen.n_eigenpairs);
        let basis_b = truncated(&full_b, params.eigen.n_eigenpairs);
        let result = Correspondence::from_bases(
            ShapeBasis::new(&a, &basis_a),
            ShapeBasis::new(&b, &basis_b),
            &params,
            &mut TerminalProgress::new(),
        );
        end_progress_line();
        let result = result?;
        errln!();
        write_json(
            &out.join("result.json"),
            &correspondence_json(&a, &b, &result),
        )?;
        write_colored(out, &a, &b, &result)?;
        // Ground truth: every point of B knows the vertex of the mesh it was sampled near,
        // and the two meshes share their vertex order.
        let truth: Vec<(u32, u32)> = cloud_b
            .source_vertex
            .iter()
            .enumerate()
            .map(|(p, &v)| (v, p as u32))
            .collect();
        // The rest pose is left/right symmetric: its mirror map gives the flip-tolerant score.
        let mirror = synth::mirror_map(&mesh_a);
        let flipped: Vec<(u32, u32)> = truth
            .iter()
            .map(|&(v, p)| (mirror[v as usize], p))
            .collect();
        let scores = score_correspondence(
            &result,
            &basis_a.mass,
            &basis_b.mass,
            &truth,
            Some(&flipped),
        );
        outln!(
            "k = {}: {} regions on A, {} on B; {} symmetric matches, {} one-to-one ({:.2} s after the eigenbases)",
            result.k,
            result.graph_a.n_nodes(),
            result.graph_b.n_nodes(),
            result.matches.len(),
            result.matches_one_to_one.len(),
            result.timings.total
        )?;
        outln!(
            "region accuracy against the ground truth: symmetric {:.3}, one-to-one {:.3}, one-to-one allowing a left/right flip {:.3} (coverage {:.3}, unmatched {:.3})",
            scores.symmetric,
            scores.one_to_one,
            scores.one_to_one_flip.unwrap_or(f64::NAN),
            scores.coverage,
            scores.unmatched
        )?;
        // Point-to-point map from the regions (functional map + ZoomOut).
        let map = PointwiseMap::from_bases(
            ShapeBasis::new(&a, &full_a),
            ShapeBasis::new(&b, &full_b),
            Some(result.matches_view()),
            &pointwise,
            &mut NoProgress,
        )?;
        write_map(&out.join("map_b_to_a.txt"), &map.p2p_ba)?;
        write_map_colors(out, &a, &b, &map.p2p_ba)?;
        report_map(&a, &full_a, &map, &truth, &flipped)?;
        outln!(
            "coloured shapes: {} and {}; the map: {} and {} (open them in MeshLab or Blender)",
            out.join("a_regions.ply").display(),
            out.join("b_regions.ply").display(),
            out.join("a_colors.ply").display(),
            out.join("b_mapped.ply").display()
        )?;
        Ok(())
    }
}

/// Prints the map's geodesic error on A (heat method) at 1000 of the cloud's points, the
/// better of the plain and the mirrored ground truth.
fn report_map(
    a: &Shape,
    basis_a: &Eigenbasis,
    map: &PointwiseMap,
    truth: &[(u32, u32)],
    flipped: &[(u32, u32)],
) -> Result<(), Error> {
    let heat = shapecorr::geodesic::HeatGeodesics::new(a)?;
    let step = (truth.len() / 1000).max(1);
    let sample = |t: &[(u32, u32)]| t.iter().copied().step_by(step).collect::<Vec<_>>();
    let errors = |t: &[(u32, u32)]| {
        shapecorr::evaluation::pointwise_errors(
            &heat,
            basis_a.input_area,
            &sample(t),
            &[&map.p2p_ba],
        )
        .map(|e| shapecorr::evaluation::ErrorSummary::of(&e[0]))
    };
    let (plain, mirrored) = (errors(truth)?, errors(flipped)?);
    let best = if mirrored.mean < plain.mean {
        mirrored
    } else {
        plain
    };
    outln!(
        "point-to-point map ({:.2} s): mean geodesic error {:.4} of sqrt(area) ({}), {:.1}% of the points within 0.05",
        map.timings.fmap + map.timings.refinement,
        best.mean,
        if mirrored.mean < plain.mean { "a left/right mirror image" } else { "not mirrored" },
        100.0 * best.within_005
    )?;
    Ok(())
}
