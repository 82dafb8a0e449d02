//! Figures modelled in pieces against the same figures in one piece (docs/decisions.md,
//! "Shapes in pieces"): generated humanoids and quadrupeds at `N` vertices (default 3,000),
//! A in the rest pose, B in every other pose cut by skinning bone into pieces
//! (`synth::cut_into_pieces`: 1 or 3 slabs per bone, pieces touching or 2% apart), with
//! the map's mean geodesic error (truth by vertex copy) and the skin weights' mean
//! absolute error per vertex and bone, the connected B beside them, and the time per pair.
//!
//!     cargo run --release -p shapecorr-eval --example pieces -- [N]

use std::time::Instant;

use shapecorr::evaluation::pointwise_errors;
use shapecorr::geodesic::HeatGeodesics;
use shapecorr::maps::surface::SurfaceMap;
use shapecorr::synth::{self, FigureKind, Proportions, Rig};
use shapecorr::transfer::TransferMode;
use shapecorr::{NoProgress, Params, PointwiseCorrespondence, PointwiseParams, Shape};

/// Map error, weights error and seconds of B (vertex `v` copies the figure's
/// `original[v]`) matched to the rest figure `a`.
fn measure(rig: &Rig, a: &Shape, b: &Shape, original: &[u32]) -> shapecorr::Result<[f64; 3]> {
    let start = Instant::now();
    let result = PointwiseCorrespondence::compute(
        a,
        b,
        &Params::default(),
        &PointwiseParams::default(),
        &mut NoProgress,
    )?;
    let seconds = start.elapsed().as_secs_f64();
    if let Some(v) = result.verdict() {
        let scores: Vec<String> = v
            .scores
            .iter()
            .map(|h| {
                format!(
                    "{} {:.3} turn {:.0}",
                    h.kind.name(),
                    h.energy.cost(),
                    h.turn_degrees
                )
            })
            .collect();
        eprintln!(
            "  chosen {} by {} (confidence {:.2}); {scores:?}",
            v.chosen().kind.name(),
            v.decided_by.name(),
            v.confidence
        );
    }
    let p2p_ba = &result.map.p2p_ba;
    let truth: Vec<(u32, u32)> = original
        .iter()
        .enumerate()
        .map(|(v, &x)| (x, v as u32))
        .collect();
    let heat = HeatGeodesics::new(a)?;
    let errors = pointwise_errors(&heat, a.mesh_area(), &truth, &[p2p_ba])?;
    let map = errors[0].iter().sum::<f64>() / truth.len() as f64;
    let surface = SurfaceMap::from_vertex_map(a, b, p2p_ba, &mut NoProgress)?;
    let n = rig.n_bones;
    let carried = surface.transfer(&rig.weights, n, TransferMode::Weights { max_influences: 0 })?;
    let mut sum = 0.0;
    for (v, &x) in original.iter().enumerate() {
        for k in 0..n {
            sum += (carried[v * n + k] - rig.weights[x as usize * n + k]).abs();
        }
    }
    Ok([map, sum / (original.len() * n) as f64, seconds])
}

fn summary(name: &str, rows: &[[f64; 3]]) {
    let mut maps: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    maps.sort_by(f64::total_cmp);
    let n = maps.len();
    let mean = |k: usize| rows.iter().map(|r| r[k]).sum::<f64>() / n as f64;
    println!(
        "| {name} | {n} | {:.4} | {:.4} | {:.4} | {} | {:.4} | {:.2} |",
        mean(0),
        maps[n / 2],
        maps[n - 1],
        maps.iter().filter(|&&e| e > 0.05).count(),
        mean(1),
        mean(2)
    );
}

fn main() -> shapecorr::Result<()> {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(3000);
    let cuts = [
        ("one piece", 0, 0.0),
        ("per bone, touching", 1, 0.005),
        ("per bone, 2% apart", 1, 0.02),
        ("3 slabs per bone, touching", 3, 0.005),
        ("3 slabs per bone, 2% apart", 3, 0.02),
    ];
    let mut rows: Vec<Vec<[f64; 3]>> = vec![Vec::new(); cuts.len()];
    let mut pieces: Vec<Vec<usize>> = vec![Vec::new(); cuts.len()];
    for kind in [FigureKind::Humanoid, FigureKind::Quadruped] {
        let rig = synth::rig(kind, n)?;
        let a = Shape::mesh(rig.rest.vertices.clone(), &rig.rest.triangles)?;
        for pose in 1..synth::n_poses(kind) {
            let posed = rig.deform(&rig.weights, Proportions::default(), pose)?;
            for (c, &(name, slabs, gap)) in cuts.iter().enumerate() {
                let (b, original, count) = if slabs == 0 {
                    let identity: Vec<u32> = (0..posed.len() as u32).collect();
                    (
                        Shape::mesh(posed.clone(), &rig.rest.triangles)?,
                        identity,
                        1,
                    )
                } else {
                    let cut = synth::cut_into_pieces(&rig, &posed, slabs, gap)?;
                    (
                        Shape::mesh(cut.vertices, &cut.triangles)?,
                        cut.original,
                        cut.n_pieces,
                    )
                };
                let row = measure(&rig, &a, &b, &original)?;
                eprintln!("{kind:?} pose {pose}, {name} ({count} pieces): map {:.4}, weights {:.4}, {:.2} s", row[0], row[1], row[2]);
                rows[c].push(row);
                pieces[c].push(count);
            }
        }
    }
    println!("| B | pairs | mean | median | worst | failed (> 0.05) | weights MAE | seconds |");
    println!("|---|---|---|---|---|---|---|---|");
    for (c, &(name, _, _)) in cuts.iter().enumerate() {
        let (lo, hi) = (
            pieces[c].iter().min().unwrap_or(&0),
            pieces[c].iter().max().unwrap_or(&0),
        );
        summary(&format!("{name} ({lo}-{hi} pieces)"), &rows[c]);
    }
    Ok(())
}
