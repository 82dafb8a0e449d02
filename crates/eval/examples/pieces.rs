//! Figures modelled in pieces against the same figures in one piece (docs/decisions.md,
//! "Shapes in pieces"): generated humanoids and quadrupeds at `N` vertices (default 3,000),
//! A in the rest pose, B in every other pose cut by skinning bone into pieces
//! (`synth::cut_into_pieces`: 1 or 3 slabs per bone, pieces touching or 2% apart), with
//! the map's mean geodesic error (truth by vertex copy) and the skin weights' mean
//! absolute error per vertex and bone, the connected B beside them, and the time per pair.
//!
//! With `--one-part`, B is instead the figure in pose 1 with a single bone's faces a piece
//! of their own touching the rest (a modelled character's separate head, hand or foot), for
//! every bone: a part of the figure must never be left out as an object touching it
//! ([`Shape::without_touching_objects`]).
//!
//!     cargo run --release -p shapecorr-eval --example pieces -- [N] [--one-part]

use std::time::Instant;

use shapecorr::evaluation::pointwise_errors;
use shapecorr::geodesic::HeatGeodesics;
use shapecorr::maps::surface::SurfaceMap;
use shapecorr::synth::{self, FigureKind, Proportions, Rig};
use shapecorr::transfer::TransferMode;
use shapecorr::{NoProgress, Params, PointwiseCorrespondence, PointwiseParams, Shape};

/// Map error, weights error and seconds of B (vertex `v` copies the figure's
/// `original[v]`) matched to the rest figure `a`, with the vertices of B left out as objects
/// touching the figure.
fn measure(
    rig: &Rig,
    a: &Shape,
    b: &Shape,
    original: &[u32],
) -> shapecorr::Result<([f64; 3], usize)> {
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
    let objects = result.regions.working[1].objects_left_out.vertices;
    Ok(([map, sum / (original.len() * n) as f64, seconds], objects))
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

/// The figure `posed` with the faces whose heaviest bone is `bone` made a piece of their
/// own, shrunk by 0.5% about its centroid (touching the rest); with the vertex each copies.
fn one_part_apart(
    rig: &Rig,
    posed: &[[f64; 3]],
    bone: usize,
) -> (Vec<[f64; 3]>, Vec<[u32; 3]>, Vec<u32>) {
    let n = rig.n_bones;
    let heaviest = |t: &[u32; 3]| {
        (0..n)
            .max_by(|&x, &y| {
                let w = |b: usize| {
                    t.iter()
                        .map(|&v| rig.weights[v as usize * n + b])
                        .sum::<f64>()
                };
                w(x).total_cmp(&w(y)).then(y.cmp(&x))
            })
            .unwrap_or(0)
    };
    let mut vertices = posed.to_vec();
    let mut original: Vec<u32> = (0..posed.len() as u32).collect();
    let mut copy: std::collections::BTreeMap<u32, u32> = Default::default();
    let mut triangles = Vec::new();
    for t in &rig.rest.triangles {
        if heaviest(t) != bone {
            triangles.push(*t);
            continue;
        }
        triangles.push(t.map(|v| {
            *copy.entry(v).or_insert_with(|| {
                vertices.push(posed[v as usize]);
                original.push(v);
                (vertices.len() - 1) as u32
            })
        }));
    }
    let first = posed.len();
    let part = &mut vertices[first..];
    let count = part.len().max(1) as f64;
    let centre: [f64; 3] = std::array::from_fn(|c| part.iter().map(|p| p[c]).sum::<f64>() / count);
    for p in part.iter_mut() {
        *p = std::array::from_fn(|c| centre[c] + 0.995 * (p[c] - centre[c]));
    }
    (vertices, triangles, original)
}

/// `--one-part`: every bone's faces apart in turn, pose 1 of both figures.
fn one_part(n: usize) -> shapecorr::Result<()> {
    let mut rows = Vec::new();
    let mut left_out = 0;
    for kind in [FigureKind::Humanoid, FigureKind::Quadruped] {
        let rig = synth::rig(kind, n)?;
        let a = Shape::mesh(rig.rest.vertices.clone(), &rig.rest.triangles)?;
        let posed = rig.deform(&rig.weights, Proportions::default(), 1)?;
        let whole = Shape::mesh(posed.clone(), &rig.rest.triangles)?;
        let identity: Vec<u32> = (0..posed.len() as u32).collect();
        let baseline = measure(&rig, &a, &whole, &identity)?;
        eprintln!("{kind:?} pose 1, one piece: map {:.4}", baseline.0[0]);
        for bone in 0..rig.n_bones {
            let (vertices, triangles, original) = one_part_apart(&rig, &posed, bone);
            if vertices.len() == posed.len() {
                continue;
            }
            let b = Shape::mesh(vertices, &triangles)?;
            let (row, objects) = measure(&rig, &a, &b, &original)?;
            eprintln!(
                "{kind:?} bone {bone} apart ({} vertices): map {:.4} (one piece {:.4}), {} s, left out {objects}",
                original.len() - posed.len(),
                row[0],
                baseline.0[0],
                row[2]
            );
            left_out += usize::from(objects > 0);
            rows.push(row);
        }
    }
    println!("| B | pairs | mean | median | worst | failed (> 0.05) | weights MAE | seconds |");
    println!("|---|---|---|---|---|---|---|---|");
    summary("one bone's faces apart, touching", &rows);
    println!(
        "parts left out as touching objects: {left_out} of {}",
        rows.len()
    );
    Ok(())
}

fn main() -> shapecorr::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.iter().find_map(|s| s.parse().ok()).unwrap_or(3000);
    if args.iter().any(|a| a == "--one-part") {
        return one_part(n);
    }
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
                let (row, _) = measure(&rig, &a, &b, &original)?;
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
