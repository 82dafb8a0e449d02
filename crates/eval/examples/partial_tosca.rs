//! Partial shapes on TOSCA (docs/partial.md, "The TOSCA development set"): A is the first
//! shape of a class; B is another shape of the class with the lowest 30% along its longest
//! axis cut away by a plane (`synth::cut_by_plane`) or with six holes
//! (`synth::with_holes`), matched by the default pipeline (`p2p`). The truth is the vertex
//! index (a class shares its vertex order); the error is scored on every 20th of B's
//! vertices (mean geodesic error over sqrt(area) on A, the left/right flip allowed through
//! the class's mirror map, a pair fails above 0.1). Research data: read from
//! `../shared/data/tosca` (or the first argument), never copied into the repository.
//!
//!     cargo run --release -p shapecorr-eval --example partial_tosca -- [DIR] [--per-class N] [--partial auto|off]

use std::path::PathBuf;

use shapecorr::evaluation::pointwise_errors;
use shapecorr::geodesic::HeatGeodesics;
use shapecorr::maps::partial::Partiality;
use shapecorr::synth::{self, FigureMesh, Part};
use shapecorr::{NoProgress, PointwiseCorrespondence, ReadAs, Shape};

const CLASSES: [(&str, &[usize]); 5] = [
    ("cat", &[0, 1, 2, 3]),
    ("centaur", &[0, 1, 2, 5]),
    ("david", &[0, 1, 6, 10]),
    ("dog", &[0, 1, 2, 3]),
    ("horse", &[0, 5, 7, 10]),
];
const VARIANTS: [&str; 3] = ["whole", "plane cut", "holes"];
const FAILED: f64 = 0.1;
/// Every how many of B's vertices the error is scored on.
const SCORE_STEP: usize = 20;

fn main() -> shapecorr::Result<()> {
    let mut dir = PathBuf::from("../shared/data/tosca");
    let mut per_class = 3usize;
    let mut params = shapecorr::Params::default();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--per-class" => per_class = args.next().and_then(|s| s.parse().ok()).unwrap_or(3),
            "--partial" => {
                let text = args.next().unwrap_or_default();
                let value = shapecorr::options::parse_option_value("partial", &text)?;
                params.set_option("partial", value)?;
            }
            other => dir = PathBuf::from(other),
        }
    }
    if !dir.is_dir() {
        println!("no TOSCA folder at {}: skipped", dir.display());
        return Ok(());
    }
    let mut errors: Vec<Vec<f64>> = vec![Vec::new(); VARIANTS.len()];
    let mut calls = [0usize; VARIANTS.len()];
    for (class, indices) in CLASSES {
        let read = |i: usize| Shape::read(&dir.join(format!("{class}{i}.ply")), ReadAs::Auto);
        let a = read(indices[0])?;
        let heat = HeatGeodesics::new(&a)?;
        let area_a = a.mesh_area();
        let mirror: Vec<u32> = std::fs::read_to_string(dir.join(format!("{class}_mirror.txt")))
            .unwrap_or_default()
            .lines()
            .filter_map(|l| l.trim().parse().ok())
            .collect();
        for &i in indices.iter().skip(1).take(per_class) {
            let shape = read(i)?;
            let whole = FigureMesh {
                vertices: shape.vertices().to_vec(),
                triangles: shape.triangles().to_vec(),
            };
            for (v, variant) in VARIANTS.iter().enumerate() {
                let part = match *variant {
                    "whole" => Part {
                        mesh: whole.clone(),
                        whole_vertex: (0..whole.vertices.len() as u32).collect(),
                    },
                    "plane cut" => {
                        let axis = longest_axis(&whole.vertices);
                        let along = |p: &[f64; 3]| p[axis];
                        let lo = whole.vertices.iter().map(along).fold(f64::MAX, f64::min);
                        let hi = whole.vertices.iter().map(along).fold(f64::MIN, f64::max);
                        let mut normal = [0.0; 3];
                        normal[axis] = 1.0;
                        synth::cut_by_plane(&whole, normal, lo + 0.3 * (hi - lo))
                    }
                    _ => synth::with_holes(&whole, 6, 0.06, i as u64),
                };
                let b = Shape::mesh(part.mesh.vertices.clone(), &part.mesh.triangles)?;
                let kept = part.mesh.area() / whole.area();
                let result = PointwiseCorrespondence::compute(
                    &a,
                    &b,
                    &params,
                    &Default::default(),
                    &mut NoProgress,
                );
                let line = match result {
                    Ok(result) => {
                        let truth: Vec<(u32, u32)> = (part.whole_vertex.iter().enumerate())
                            .step_by(SCORE_STEP)
                            .map(|(j, &w)| (w, j as u32))
                            .collect();
                        let map = &result.map.p2p_ba;
                        let flipped: Vec<u32> = map
                            .iter()
                            .map(|&x| mirror.get(x as usize).copied().unwrap_or(x))
                            .collect();
                        let e = pointwise_errors(&heat, area_a, &truth, &[map, &flipped])?;
                        let error = mean(&e[0]).min(mean(&e[1]));
                        errors[v].push(error);
                        let report = &result.map.partial;
                        calls[v] += usize::from(report.partiality != Partiality::Whole);
                        format!(
                            "{error:.4} confidence {} taken as {} (boundary {:.2} {:.2}, area \
                             share {:.2}); {:.1} s",
                            result
                                .confidence()
                                .map_or("-".into(), |c| format!("{c:.2}")),
                            report.partiality.name(),
                            report.boundary[0],
                            report.boundary[1],
                            report.area_share,
                            result.total,
                        )
                    }
                    Err(e) => {
                        errors[v].push(f64::INFINITY);
                        format!("no answer: {e}")
                    }
                };
                println!(
                    "{class}{} -> {class}{i} {variant} (keeps {kept:.2}): {line}",
                    indices[0]
                );
            }
        }
    }
    for (v, (variant, e)) in VARIANTS.iter().zip(&mut errors).enumerate() {
        e.sort_by(f64::total_cmp);
        println!(
            "{variant:>9}: mean {:.4} median {:.4} worst {:.4} failed {}/{}; taken as a part {}/{}",
            mean(e),
            e[e.len() / 2],
            e[e.len() - 1],
            e.iter().filter(|&&x| x > FAILED).count(),
            e.len(),
            calls[v],
            e.len()
        );
    }
    Ok(())
}

/// The axis (0, 1, 2) along which the points reach farthest.
fn longest_axis(points: &[[f64; 3]]) -> usize {
    (0..3)
        .max_by(|&i, &j| extent(points, i).total_cmp(&extent(points, j)))
        .unwrap_or(1)
}

fn extent(points: &[[f64; 3]], axis: usize) -> f64 {
    let values = points.iter().map(|p| p[axis]);
    values.clone().fold(f64::MIN, f64::max) - values.fold(f64::MAX, f64::min)
}

fn mean(e: &[f64]) -> f64 {
    e.iter().sum::<f64>() / e.len().max(1) as f64
}
