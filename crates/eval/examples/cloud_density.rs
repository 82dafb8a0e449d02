//! Point clouds sampled on generated figures (docs/scans.md, "Point clouds"): A is a whole
//! figure in its rest pose (about 5,000 vertices), B another pose as a cloud sampled on its
//! surface (`synth::sample_points`): uniform, of uneven density (the side a single scanner
//! faces, before a person or beside an animal, four times as dense as the far side), and
//! with noise (each point moved up to 0.5% or 1% of the bounding-box diagonal). Each B is
//! mapped to A by the default pipeline (`p2p`) and scored on every point against the vertex
//! it was sampled nearest (mean geodesic error over sqrt(area) on A, the left/right flip
//! allowed; a pair fails above 0.1, a confidence below 0.45 flags it). Prints a line per
//! pair and a summary per variant: mean, median, worst, failed, and pairs above 0.05 that
//! are not flagged.
//!
//!     cargo run --release -p shapecorr-eval --example cloud_density

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shapecorr::evaluation::pointwise_errors;
use shapecorr::geodesic::HeatGeodesics;
use shapecorr::synth::{self, FigureKind};
use shapecorr::{NoProgress, PointwiseCorrespondence, Shape};

/// A pair fails above this mean error (as the scans issue's table).
const FAILED: f64 = 0.1;
/// A confidence below this flags the answer as doubtful (docs/tails.md).
const FLAGGED: f64 = 0.45;
/// The variants: name, whether the density is uneven, noise as a share of the diagonal.
const VARIANTS: [(&str, bool, f64); 4] = [
    ("uniform", false, 0.0),
    ("uneven 4x", true, 0.0),
    ("uneven 4x, noise 0.5%", true, 0.005),
    ("uniform, noise 1%", false, 0.01),
];
/// Points of a cloud (the uneven ones sample 8,000 and keep a quarter of the far side's).
const POINTS: usize = 5_000;

fn main() -> shapecorr::Result<()> {
    let mut results: Vec<Vec<(f64, f64)>> = vec![Vec::new(); VARIANTS.len()];
    for kind in [FigureKind::Humanoid, FigureKind::Quadruped] {
        let poses: Vec<usize> = (0..synth::n_poses(kind)).collect();
        let meshes = synth::figure_poses(kind, POINTS, Default::default(), &poses)?;
        let a = Shape::mesh(meshes[0].vertices.clone(), &meshes[0].triangles)?;
        let heat = HeatGeodesics::new(&a)?;
        let mirror = synth::mirror_map(&meshes[0]);
        // The axis the scanner looks along: z before a person, x beside an animal.
        let axis = if kind == FigureKind::Quadruped { 0 } else { 2 };
        for (pose, whole) in meshes.iter().enumerate().skip(1) {
            for (v, &(variant, uneven, noise)) in VARIANTS.iter().enumerate() {
                let seed = (pose * 17 + v) as u64;
                let n = if uneven { 8 * POINTS / 5 } else { POINTS };
                let sampled = synth::sample_points(whole, n, noise, seed)?;
                let n_vertices = whole.vertices.len() as f64;
                let centre = whole.vertices.iter().map(|p| p[axis]).sum::<f64>() / n_vertices;
                let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5ca7);
                let kept: Vec<usize> = (0..sampled.points.len())
                    .filter(|&i| {
                        !uneven || sampled.points[i][axis] >= centre || rng.random::<f64>() < 0.25
                    })
                    .collect();
                let b = Shape::point_cloud(kept.iter().map(|&i| sampled.points[i]).collect())?;
                let result = PointwiseCorrespondence::compute(
                    &a,
                    &b,
                    &Default::default(),
                    &Default::default(),
                    &mut NoProgress,
                )?;
                let truth: Vec<(u32, u32)> = (kept.iter().enumerate())
                    .map(|(j, &i)| (sampled.source_vertex[i], j as u32))
                    .collect();
                let map = &result.map.p2p_ba;
                let flipped: Vec<u32> = map.iter().map(|&x| mirror[x as usize]).collect();
                let errors = pointwise_errors(&heat, a.mesh_area(), &truth, &[map, &flipped])?;
                let mean_of = |e: &[f64]| e.iter().sum::<f64>() / e.len().max(1) as f64;
                let error = mean_of(&errors[0]).min(mean_of(&errors[1]));
                let confidence = result.confidence().unwrap_or(0.0);
                println!(
                    "{kind} pose {pose} {variant} ({} points): {error:.4} confidence {confidence:.2}",
                    kept.len()
                );
                results[v].push((error, confidence));
            }
        }
    }
    for ((variant, _, _), r) in VARIANTS.iter().zip(&mut results) {
        r.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mean = r.iter().map(|x| x.0).sum::<f64>() / r.len() as f64;
        let failed = r.iter().filter(|x| x.0 > FAILED).count();
        let unflagged = r.iter().filter(|x| x.0 > 0.05 && x.1 >= FLAGGED).count();
        println!(
            "{variant:>22}: mean {mean:.4} median {:.4} worst {:.4} failed {failed}/{} above 0.05 not flagged {unflagged}",
            r[r.len() / 2].0,
            r[r.len() - 1].0,
            r.len()
        );
    }
    Ok(())
}
