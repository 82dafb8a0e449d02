//! Partial shapes on generated figures (docs/partial.md): A is a whole figure in its rest
//! pose; B is another pose of it, whole or with a part missing (`synth::cut_below` a third of
//! the height, `synth::cut_extremity` the outer 30% of the farthest limb, `synth::with_holes`
//! six holes of 6% of the height, `synth::seen_from` what a camera before a person or
//! beside an animal sees, as a cloud). Each B is mapped to A by the default pipeline (`p2p`) and scored on all of B's
//! vertices against the exact truth (mean geodesic error over sqrt(area) on A, a pair fails
//! above 0.1; the flip allowed for clouds). Prints a line per pair (error, the share of the
//! whole's area B keeps, confidence) and a summary per variant: mean, median, worst, failed.
//!
//! With `--part-as-a`, the other way round: A is the rest pose cut (the lower third, or six
//! holes) and B another pose whole, with `partial = a_in_b`; B's vertices that A holds are
//! scored on A, and B's coverage mask against the truth.
//!
//!     cargo run --release -p shapecorr-eval --example partial -- [--vertices N] [--partial auto|off|b_in_a] [--part-as-a]

use shapecorr::evaluation::pointwise_errors;
use shapecorr::geodesic::HeatGeodesics;
use shapecorr::maps::partial::Partiality;
use shapecorr::synth::{self, FigureKind, Part};
use shapecorr::{NoProgress, PointwiseCorrespondence, Shape};

/// A pair fails above this mean error (as the partial-shapes issue's targets).
const FAILED: f64 = 0.1;
/// The variants, in the order they run.
const VARIANTS: [&str; 5] = [
    "whole",
    "lower third cut",
    "limb cut",
    "holes",
    "one view cloud",
];

fn main() -> shapecorr::Result<()> {
    let mut args = std::env::args().skip(1);
    let mut vertices = 5_000usize;
    let mut params = shapecorr::Params::default();
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--vertices" => vertices = args.next().and_then(|s| s.parse().ok()).unwrap_or(5_000),
            "--partial" => {
                let value = shapecorr::options::parse_option_value(
                    "partial",
                    &args.next().unwrap_or_default(),
                )?;
                params.set_option("partial", value)?;
            }
            "--part-as-a" => return part_as_a(vertices),
            other => panic!("unknown argument {other}"),
        }
    }
    let mut errors: Vec<Vec<f64>> = vec![Vec::new(); VARIANTS.len()];
    let mut mask_right: Vec<Vec<f64>> = vec![Vec::new(); VARIANTS.len()];
    let mut calls = [0usize; VARIANTS.len()];
    // Seconds of each pair's whole call (`PointwiseCorrespondence::total`).
    let mut seconds: Vec<Vec<f64>> = vec![Vec::new(); VARIANTS.len()];
    for kind in [FigureKind::Humanoid, FigureKind::Quadruped] {
        let poses: Vec<usize> = (0..synth::n_poses(kind)).collect();
        let meshes = synth::figure_poses(kind, vertices, Default::default(), &poses)?;
        let a = Shape::mesh(meshes[0].vertices.clone(), &meshes[0].triangles)?;
        let heat = HeatGeodesics::new(&a)?;
        let area_a = a.mesh_area();
        let mirror = synth::mirror_map(&meshes[0]);
        for (pose, whole) in meshes.iter().enumerate().skip(1) {
            for (v, variant) in VARIANTS.iter().enumerate() {
                let seed = (pose * 31 + v) as u64;
                let part = match *variant {
                    "whole" => Part {
                        mesh: whole.clone(),
                        whole_vertex: (0..whole.vertices.len() as u32).collect(),
                    },
                    "lower third cut" => synth::cut_below(whole, 1.0 / 3.0),
                    "limb cut" => synth::cut_extremity(whole, 0.3),
                    "holes" => synth::with_holes(whole, 6, 0.06, seed),
                    "one view cloud" => synth::seen_from(whole, view(kind), 256),
                    other => panic!("unknown variant {other}"),
                };
                let b = if variant.contains("cloud") {
                    Shape::point_cloud(part.mesh.vertices.clone())?
                } else {
                    Shape::mesh(part.mesh.vertices.clone(), &part.mesh.triangles)?
                };
                let kept = part.mesh.area() / whole.area();
                let line = match PointwiseCorrespondence::compute(
                    &a,
                    &b,
                    &params,
                    &Default::default(),
                    &mut NoProgress,
                ) {
                    Ok(result) => {
                        let truth: Vec<(u32, u32)> = (part.whole_vertex.iter().enumerate())
                            .map(|(i, &w)| (w, i as u32))
                            .collect();
                        let map = &result.map.p2p_ba;
                        let mut error = mean(&pointwise_errors(&heat, area_a, &truth, &[map])?[0]);
                        if variant.contains("cloud") {
                            let flipped: Vec<u32> =
                                map.iter().map(|&x| mirror[x as usize]).collect();
                            let e = mean(&pointwise_errors(&heat, area_a, &truth, &[&flipped])?[0]);
                            error = error.min(e);
                        }
                        errors[v].push(error);
                        let mut truly_covered = vec![false; a.n_vertices()];
                        for &w in &part.whole_vertex {
                            truly_covered[w as usize] = true;
                        }
                        let mask = &result.map.coverage.a;
                        let right = (mask.iter().zip(&truly_covered))
                            .filter(|(m, t)| m == t)
                            .count() as f64
                            / a.n_vertices() as f64;
                        mask_right[v].push(right);
                        let report = &result.map.partial;
                        calls[v] += usize::from(report.partiality != Partiality::Whole);
                        seconds[v].push(result.total);
                        format!(
                            "{error:.4} confidence {} taken as {} (covered {:.2}, boundary \
                             {:.2} {:.2}) mask right {right:.3}",
                            result
                                .confidence()
                                .map_or("-".into(), |c| format!("{c:.2}")),
                            report.partiality.name(),
                            result.map.coverage.share_a,
                            report.boundary[0],
                            report.boundary[1],
                        )
                    }
                    Err(e) => {
                        errors[v].push(f64::INFINITY);
                        format!("no answer: {e}")
                    }
                };
                println!("{kind} pose {pose} {variant} (keeps {kept:.2} of the area): {line}");
            }
        }
    }
    for (v, (variant, e)) in VARIANTS.iter().zip(&mut errors).enumerate() {
        e.sort_by(f64::total_cmp);
        let right = &mut mask_right[v];
        right.sort_by(f64::total_cmp);
        println!(
            "{variant:>15}: mean {:.4} median {:.4} worst {:.4} failed {}/{}; taken as a part \
             {}/{}; mask right mean {:.3} worst {:.3}; {:.2} s a pair",
            mean(e),
            e[e.len() / 2],
            e[e.len() - 1],
            e.iter().filter(|&&x| x > FAILED).count(),
            e.len(),
            calls[v],
            e.len(),
            mean(right),
            right.first().copied().unwrap_or(f64::NAN),
            mean(&seconds[v]),
        );
    }
    Ok(())
}

/// A part of the rest pose as A, another pose whole as B (`partial = a_in_b`): the error of
/// B's vertices that A holds, and the share of B's vertices its mask gets right.
fn part_as_a(vertices: usize) -> shapecorr::Result<()> {
    let params = shapecorr::Params {
        partial: shapecorr::maps::partial::PartialOption::AInB,
        ..Default::default()
    };
    for variant in ["lower third cut", "holes"] {
        let (mut errors, mut rights, mut seconds) = (Vec::new(), Vec::new(), Vec::new());
        for kind in [FigureKind::Humanoid, FigureKind::Quadruped] {
            let poses: Vec<usize> = (0..synth::n_poses(kind)).collect();
            let meshes = synth::figure_poses(kind, vertices, Default::default(), &poses)?;
            let part = match variant {
                "holes" => synth::with_holes(&meshes[0], 6, 0.06, 7),
                _ => synth::cut_below(&meshes[0], 1.0 / 3.0),
            };
            let a = Shape::mesh(part.mesh.vertices.clone(), &part.mesh.triangles)?;
            let heat = HeatGeodesics::new(&a)?;
            let truth: Vec<(u32, u32)> = (part.whole_vertex.iter().enumerate())
                .map(|(i, &w)| (i as u32, w))
                .collect();
            for (pose, whole) in meshes.iter().enumerate().skip(1) {
                let b = Shape::mesh(whole.vertices.clone(), &whole.triangles)?;
                let result = PointwiseCorrespondence::compute(
                    &a,
                    &b,
                    &params,
                    &Default::default(),
                    &mut NoProgress,
                )?;
                let map = &result.map.p2p_ba;
                let error = mean(&pointwise_errors(&heat, a.mesh_area(), &truth, &[map])?[0]);
                let mut truly = vec![false; b.n_vertices()];
                for &w in &part.whole_vertex {
                    truly[w as usize] = true;
                }
                let mask = &result.map.coverage.b;
                let right = (mask.iter().zip(&truly)).filter(|(m, t)| m == t).count() as f64
                    / b.n_vertices() as f64;
                println!("{kind} pose {pose} {variant} as A: {error:.4} B's mask right {right:.3}");
                errors.push(error);
                rights.push(right);
                seconds.push(result.total);
            }
        }
        errors.sort_by(f64::total_cmp);
        rights.sort_by(f64::total_cmp);
        println!(
            "{variant} as A: mean {:.4} median {:.4} worst {:.4} failed {}/{}; B's mask right \
             mean {:.3} worst {:.3}; {:.2} s a pair",
            mean(&errors),
            errors[errors.len() / 2],
            errors[errors.len() - 1],
            errors.iter().filter(|&&x| x > FAILED).count(),
            errors.len(),
            mean(&rights),
            rights[0],
            mean(&seconds),
        );
    }
    Ok(())
}

/// Where a single-view scan's camera stands: before a person, beside an animal.
fn view(kind: FigureKind) -> [f64; 3] {
    match kind {
        FigureKind::Quadruped => [1.0, 0.0, 0.0],
        _ => [0.0, 0.0, 1.0],
    }
}

fn mean(e: &[f64]) -> f64 {
    e.iter().sum::<f64>() / e.len().max(1) as f64
}
