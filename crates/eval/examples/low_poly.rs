//! Low-poly meshes on a refined working mesh (docs/decisions.md, "Low-poly meshes: a
//! refined working mesh"): pairs of generated figures in two poses (humanoid and
//! quadruped, 5K vertices), each pose decimated on its own by meshoptimizer ([`synth::decimate`]) to 150, 300 and 1,000 vertices, mapped
//! with `refine_below` off and at each value given, and scored on the 5K figure by index
//! (mean geodesic error over sqrt(area), a left/right flip allowed, a pair failed above 0.05).
//! Prints per size and setting the mean, median and worst pair, the failed pairs and the
//! mean seconds per pair, and per size the floor: the mean error of the best vertex map
//! (every vertex of B to the vertex of A nearest its truth), which no map to A's vertices
//! beats. `--sizes 150,300` scores those sizes only (5000: the original).
//!
//!     cargo run --release -p shapecorr-eval --example low_poly -- [--sizes N,..] [N ...]
//!
//! (each N a `refine_below` to compare with 0; the default's when none is given)

use std::time::Instant;

use shapecorr::evaluation::pointwise_errors;
use shapecorr::geodesic::HeatGeodesics;
use shapecorr::pipeline::multiresolution::{Multiresolution, DEFAULT_REFINE_BELOW};
use shapecorr::pipeline::Params;
use shapecorr::shape::neighbors::PointTree;
use shapecorr::synth::{self, FigureKind, FigureMesh, Proportions};
use shapecorr::{NoProgress, PointwiseCorrespondence, PointwiseParams, Shape};

/// The figures' resolution before decimation.
const ORIGINAL: usize = 5_000;
/// The decimated sizes (the original is scored too).
const SIZES: [usize; 3] = [150, 300, 1_000];
/// The pose pairs of each kind (the humanoid has 7 poses, the quadruped 6).
const POSES: [(usize, usize); 3] = [(0, 3), (1, 4), (2, 5)];
/// Vertices of B scored per pair, at most.
const SCORED: usize = 300;
/// A pair fails above this mean error.
const FAILED: f64 = 0.05;

/// One pair's mean error, the floor's and seconds.
struct Scored {
    error: f64,
    floor: f64,
    seconds: f64,
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut sizes: Vec<usize> = SIZES.iter().copied().chain([ORIGINAL]).collect();
    if let Some(i) = args.iter().position(|a| a == "--sizes") {
        let list = args.get(i + 1).expect("--sizes N,N,...").clone();
        sizes = list
            .split(',')
            .map(|n| n.parse().expect("a size"))
            .collect();
        args.drain(i..i + 2);
    }
    let settings: Vec<usize> = match args {
        args if args.is_empty() => vec![0, DEFAULT_REFINE_BELOW],
        args => std::iter::once(0)
            .chain(
                args.iter()
                    .map(|a| a.parse().expect("REFINE_BELOW is a count")),
            )
            .collect(),
    };
    let mut figures = Vec::new();
    for kind in [FigureKind::Humanoid, FigureKind::Quadruped] {
        let poses: Vec<usize> = std::iter::once(0)
            .chain(POSES.iter().flat_map(|&(a, b)| [a, b]))
            .collect();
        let meshes = synth::figure_poses(kind, ORIGINAL, Proportions::default(), &poses).unwrap();
        let mirror = synth::mirror_map(&meshes[0]);
        for (i, &(pa, pb)) in POSES.iter().enumerate() {
            let (a, b) = (meshes[1 + 2 * i].clone(), meshes[2 + 2 * i].clone());
            figures.push((format!("{kind} {pa}-{pb}"), a, b, mirror.clone()));
        }
    }
    for size in sizes {
        for &refine_below in &settings {
            let params = Params {
                multiresolution: Multiresolution {
                    refine_below,
                    ..Default::default()
                },
                ..Params::default()
            };
            let scored: Vec<Scored> = figures
                .iter()
                .map(|(name, a, b, mirror)| {
                    let s = pair(a, b, mirror, size, &params);
                    eprintln!(
                        "  {size} refine_below {refine_below} {name}: {:.4} in {:.2} s",
                        s.error, s.seconds
                    );
                    s
                })
                .collect();
            let mut errors: Vec<f64> = scored.iter().map(|s| s.error).collect();
            errors.sort_by(f64::total_cmp);
            let n = errors.len() as f64;
            println!(
                "{size:>5} vertices, refine_below {refine_below:>5}: mean {:.4} median {:.4} worst {:.4} failed {}/{} ({:.2} s per pair; floor {:.4})",
                errors.iter().sum::<f64>() / n,
                errors[errors.len() / 2],
                errors[errors.len() - 1],
                errors.iter().filter(|&&e| e > FAILED).count(),
                errors.len(),
                scored.iter().map(|s| s.seconds).sum::<f64>() / n,
                scored.iter().map(|s| s.floor).sum::<f64>() / n,
            );
        }
    }
}

/// `a` and `b` decimated to `size` (as they are at [`ORIGINAL`]), B mapped to A with
/// `params`, scored on the original A by index.
fn pair(a: &FigureMesh, b: &FigureMesh, mirror: &[u32], size: usize, params: &Params) -> Scored {
    let low = |m: &FigureMesh| -> (FigureMesh, Vec<u32>) {
        if size >= ORIGINAL {
            (m.clone(), (0..m.vertices.len() as u32).collect())
        } else {
            synth::decimate(m, size).unwrap()
        }
    };
    let ((low_a, original_a), (low_b, original_b)) = (low(a), low(b));
    let shape = |m: &FigureMesh| Shape::mesh(m.vertices.clone(), &m.triangles).unwrap();
    let (shape_a, shape_b) = (shape(&low_a), shape(&low_b));
    let started = Instant::now();
    let result = PointwiseCorrespondence::compute(
        &shape_a,
        &shape_b,
        params,
        &PointwiseParams::default(),
        &mut NoProgress,
    )
    .unwrap();
    let seconds = started.elapsed().as_secs_f64();
    // The map on the original vertices of A, scored on the original A.
    let map: Vec<u32> = result
        .map
        .p2p_ba
        .iter()
        .map(|&w| original_a[w as usize])
        .collect();
    let full_a = shape(a);
    let heat = HeatGeodesics::new(&full_a).unwrap();
    let step = original_b.len().div_ceil(SCORED);
    let truth: Vec<(u32, u32)> = (0..original_b.len() as u32)
        .step_by(step)
        .map(|y| (original_b[y as usize], y))
        .collect();
    let flipped: Vec<(u32, u32)> = truth
        .iter()
        .map(|&(x, y)| (mirror[x as usize], y))
        .collect();
    let mean = |truth: &[(u32, u32)], map: &[u32]| {
        let errors = pointwise_errors(&heat, full_a.mesh_area(), truth, &[map]).unwrap();
        errors[0].iter().sum::<f64>() / errors[0].len() as f64
    };
    // The best vertex map: every vertex of B to the vertex of A nearest its truth.
    let tree = PointTree::new(&low_a.vertices);
    let best: Vec<u32> = original_b
        .iter()
        .map(|&o| original_a[tree.nearest(&a.vertices[o as usize])])
        .collect();
    Scored {
        error: mean(&truth, &map).min(mean(&flipped, &map)),
        floor: mean(&truth, &best),
        seconds,
    }
}
