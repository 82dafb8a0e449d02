//! Which map energy tells a right region hypothesis from a wrong one
//! (docs/decisions.md, "Hypotheses verified at the map level"): for every
//! pair of the datasets given, every hypothesis the default pipeline verifies, with its
//! energies, its cost, whether it was chosen, and its full-resolution map's mean geodesic
//! error against the ground truth (and with the flip allowed, where a mirror map exists), and
//! the mean distance between its full-resolution map and every other hypothesis's (`dist`,
//! on the unit-area A). One JSON line per hypothesis on stdout; a summary per pair on
//! stderr. `crates/eval/scripts/hypothesis_rules.py` replays selection rules on these lines.
//!
//!     cargo run --release -p shapecorr-eval --example hypotheses -- \
//!         [--data DIR] [--limit N] [--cache DIR] [--reverse] DATASET ...
//!
//! `--reverse` also runs every pair the other way (B to A), for the direction test;
//! `--region-basis` verifies on the regions' basis (50 eigenpairs, ZoomOut to 50);
//! `--placement auto|ignore|trust` sets how the shapes' placement is used (default auto);
//! `--rotate SEED` turns B by a random rotation (seeded per pair) before matching;
//! `--landmarks N` gives N landmark pairs from the ground truth: B's vertices spread by
//! farthest-point sampling from the truth's vertex farthest from B's centroid, with their
//! true partners. Each line also has the hypothesis's implied turn (degrees) and rotation,
//! its landmark error and what decided the choice.

use std::path::PathBuf;

use shapecorr::maps::fmap::fmap_to_p2p;
use shapecorr::maps::pointwise::PointwiseParams;
use shapecorr::pipeline::pointwise::truncated;
use shapecorr::pipeline::Params;
use shapecorr::progress::Cancel;
use shapecorr::progress::NoProgress;
use shapecorr::spectral::eigen::{EigenParams, ShapeBasis};
use shapecorr_eval::bench_pointwise::score_maps;
use shapecorr_eval::bench_store::{BasisCache, ShapeStore};
use shapecorr_eval::datasets::{default_data_root, pair_list, Pair};
use shapecorr_eval::seeded::{fnv, random_rotation, turned};

fn main() -> shapecorr::Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut data, mut limit, mut cache, mut reverse) = (default_data_root(), None, None, false);
    let mut region_basis = false;
    let mut placement = shapecorr::maps::placement::Placement::Auto;
    let (mut rotate, mut n_landmarks) = (None::<u64>, 0usize);
    let mut datasets = Vec::new();
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--data" => data = PathBuf::from(args.next().expect("--data DIR")),
            "--limit" => limit = args.next().and_then(|n| n.parse().ok()),
            "--cache" => cache = args.next().map(PathBuf::from),
            "--reverse" => reverse = true,
            "--region-basis" => region_basis = true,
            "--placement" => {
                let name = args.next().expect("--placement auto|ignore|trust");
                placement = shapecorr::maps::placement::Placement::ALL
                    .into_iter()
                    .find(|p| p.name() == name)
                    .expect("--placement auto|ignore|trust");
            }
            "--rotate" => rotate = args.next().and_then(|n| n.parse().ok()),
            "--landmarks" => n_landmarks = args.next().and_then(|n| n.parse().ok()).unwrap_or(0),
            name => datasets.push(name.to_string()),
        }
    }
    let params = Params {
        placement,
        ..Params::default()
    };
    let mut pointwise = PointwiseParams::default();
    if region_basis {
        // The verification on the regions' own basis (50 eigenpairs, ZoomOut to 50).
        pointwise.n_eigenpairs = params.eigen.n_eigenpairs;
        pointwise.refinement =
            shapecorr::maps::pointwise::Refinement::ZoomOut(shapecorr::maps::fmap::ZoomOutParams {
                k_end: params.eigen.n_eigenpairs,
                ..Default::default()
            });
    }
    for name in datasets {
        let list = data.join("pairs").join(format!("{name}.txt"));
        let spec = if list.is_file() {
            list
        } else {
            PathBuf::from(&name)
        };
        let (dataset, pairs) = pair_list(&data, &spec, None)?;
        let pairs = spread(&pairs, limit);
        let eigen = EigenParams {
            n_eigenpairs: PointwiseParams::default().n_eigenpairs,
            ..params.eigen.clone()
        };
        let mut store = ShapeStore::new(dataset, eigen, BasisCache { dir: cache.clone() });
        for pair in &pairs {
            let mut runs = vec![pair.clone()];
            if reverse {
                runs.push(Pair {
                    source: pair.target.clone(),
                    target: pair.source.clone(),
                    category: pair.category.clone(),
                });
            }
            for run in runs {
                if let Err(e) = one_pair(
                    &mut store,
                    &name,
                    &run,
                    (&params, &pointwise),
                    (rotate, n_landmarks),
                ) {
                    eprintln!("{name} {} -> {}: {e}", run.source, run.target);
                }
            }
        }
    }
    Ok(())
}

fn one_pair(
    store: &mut ShapeStore,
    name: &str,
    pair: &Pair,
    (params, pointwise): (&Params, &PointwiseParams),
    (rotate, n_landmarks): (Option<u64>, usize),
) -> shapecorr::Result<()> {
    store.load(&pair.source, true, true)?;
    store.load(&pair.target, true, false)?;
    let (b, params) = &turned_and_landmarks(store, pair, params, (rotate, n_landmarks))?;
    let a = &store.get(&pair.source).shape;
    let (basis_a, basis_b) = (
        &store.basis(&pair.source).basis,
        &store.basis(&pair.target).basis,
    );
    let t = std::time::Instant::now();
    // The pipeline's path (`p2p`): unverified regions, hypotheses verified by the map.
    let (_, map) = shapecorr::pipeline::pointwise::regions_and_map(
        ShapeBasis::new(a, basis_a),
        ShapeBasis::new(b, basis_b),
        params,
        pointwise,
        &mut NoProgress,
    )?;
    let seconds = t.elapsed().as_secs_f64();
    let (basis_a, basis_b) = (
        &truncated(basis_a, pointwise.n_eigenpairs),
        &truncated(basis_b, pointwise.n_eigenpairs),
    );
    let Some(verdict) = map.verdict.as_ref() else {
        eprintln!("{name} {} -> {}: one hypothesis", pair.source, pair.target);
        return Ok(());
    };
    let maps: Vec<(String, Vec<u32>, f64)> = verdict
        .scores
        .iter()
        .map(|h| -> shapecorr::Result<_> {
            let p2p = fmap_to_p2p(
                h.fmap_ab.as_ref(),
                basis_a.vectors.as_ref(),
                basis_b.vectors.as_ref(),
                &Cancel::default(),
            )?;
            Ok((h.kind.name(), p2p, 0.0))
        })
        .collect::<shapecorr::Result<_>>()?;
    let mut maps = maps;
    // Full-resolution orientation kept and coverage of A's vertices (the close call's
    // `full_consistency` is their product).
    let extra: Vec<(Option<f64>, f64)> = maps
        .iter()
        .map(|(_, p2p, _)| {
            let mut hit = vec![false; a.n_vertices()];
            for &x in p2p {
                hit[x as usize] = true;
            }
            let covered = hit.iter().filter(|&&h| h).count() as f64 / a.n_vertices() as f64;
            (
                shapecorr::maps::hypotheses::orientation_score(a, b, p2p),
                covered,
            )
        })
        .collect();
    // Full-resolution mean image distance between every two hypotheses' maps (unit-area A).
    let scale = 1.0 / basis_a.input_area.sqrt();
    let va = a.vertices();
    let dist: Vec<Vec<f64>> = maps
        .iter()
        .map(|(_, p, _)| {
            maps.iter()
                .map(|(_, q, _)| shapecorr::maps::hypotheses::mean_image_distance(p, q, va) * scale)
                .collect()
        })
        .collect();
    maps.push(("final".into(), map.p2p_ba.clone(), 0.0));
    if let Some(other) = &map.other_p2p_ba {
        maps.push(("other".into(), other.clone(), 0.0));
    }
    for &[la, lb] in &params.landmarks {
        if map.p2p_ba[lb as usize] != la {
            eprintln!(
                "landmark ({la}, {lb}) not kept: {}",
                map.p2p_ba[lb as usize]
            );
        }
    }
    let scores = score_maps(store, pair, &maps, 1000)?;
    let n_h = verdict.scores.len();
    let final_error = scores.get(n_h).map_or(f64::NAN, |s| s.error.mean);
    let other_error = scores.get(n_h + 1).map(|s| s.error.mean);
    let mut summary = String::new();
    for (i, (h, s)) in verdict.scores.iter().zip(&scores).enumerate() {
        let e = &h.energy;
        println!(
            "{{\"dataset\":\"{name}\",\"source\":\"{}\",\"target\":\"{}\",\"hypothesis\":\"{}\",\"chosen\":{},\"turn\":{:.2},\"rotation\":{:?},\"landmark_error\":{},\"decided_by\":\"{}\",\"ruled_out\":{},\"runner_up\":{},\"other_error\":{},\"distortion\":{:.6},\"coverage\":{:.5},\"orientation\":{},\"cost\":{:.6},\"residual\":{:.6},\"error\":{:.5},\"error_flip\":{:.5},\"confidence\":{:.4},\"final_error\":{final_error:.5},\"distance_to_chosen\":{:.4},\"orient_full\":{:.4},\"cover_full\":{:.4},\"dist\":{:?},\"seconds\":{seconds:.3}}}",
            pair.source,
            pair.target,
            h.kind.name(),
            i == verdict.chosen,
            h.turn_degrees,
            h.rotation,
            h.landmark_error.map_or("null".to_string(), |x| format!("{x:.4}")),
            verdict.decided_by.name(),
            verdict.ruled_out[i],
            verdict.runner_up() == Some(i),
            other_error.map_or("null".to_string(), |x| format!("{x:.5}")),
            e.distortion,
            e.coverage,
            e.orientation.map_or("null".to_string(), |o| format!("{o:.5}")),
            e.cost(),
            e.residual,
            s.error.mean,
            s.best_mean(),
            verdict.confidence,
            h.distance_to_chosen,
            extra[i].0.unwrap_or(f64::NAN),
            extra[i].1,
            dist[i].iter().map(|d| (d * 1e4).round() / 1e4).collect::<Vec<_>>(),
        );
        summary.push_str(&format!(
            " {}{}={:.3}/{:.4}",
            if i == verdict.chosen { "*" } else { "" },
            h.kind.name(),
            s.error.mean,
            e.cost()
        ));
    }
    eprintln!(
        "{name} {} -> {} final {final_error:.3} conf {:.2} {seconds:.2}s:{summary}",
        pair.source, pair.target, verdict.confidence
    );
    Ok(())
}

/// At most `n` pairs spread over the list.
fn spread(pairs: &[Pair], n: Option<usize>) -> Vec<Pair> {
    match n {
        Some(n) if n < pairs.len() => (0..n).map(|i| pairs[i * pairs.len() / n].clone()).collect(),
        _ => pairs.to_vec(),
    }
}

/// B, turned at random when `rotate` gives a seed, and the parameters with `n_landmarks`
/// landmarks from the ground truth.
fn turned_and_landmarks(
    store: &mut ShapeStore,
    pair: &Pair,
    params: &Params,
    (rotate, n_landmarks): (Option<u64>, usize),
) -> shapecorr::Result<(shapecorr::Shape, Params)> {
    let n_a = store.get(&pair.source).shape.n_vertices();
    let b_given = store.get(&pair.target).shape.clone();
    let b = match rotate {
        Some(seed) => {
            let r = random_rotation(seed ^ fnv(&format!("{}>{}", pair.source, pair.target)));
            b_given.with_vertices(turned(b_given.vertices(), &r))?
        }
        None => b_given,
    };
    let mut params = params.clone();
    if n_landmarks > 0 {
        let (truth, _) =
            store
                .dataset
                .ground_truth(&pair.source, &pair.target, n_a, b.n_vertices())?;
        params.landmarks = landmarks_from_truth(b.vertices(), &truth, n_landmarks);
    }
    Ok((b, params))
}

/// `n` landmark pairs from the ground truth `truth` ((A vertex, B vertex) pairs): B's
/// vertices spread by farthest-point sampling (Euclidean), starting from the one farthest
/// from B's centroid.
fn landmarks_from_truth(vertices_b: &[[f64; 3]], truth: &[(u32, u32)], n: usize) -> Vec<[u32; 2]> {
    let mut seen = std::collections::HashSet::new();
    let pairs: Vec<(u32, u32)> = truth.iter().copied().filter(|p| seen.insert(p.1)).collect();
    if pairs.is_empty() {
        return Vec::new();
    }
    let at = |p: &(u32, u32)| vertices_b[p.1 as usize];
    let c: [f64; 3] =
        std::array::from_fn(|k| pairs.iter().map(|p| at(p)[k]).sum::<f64>() / pairs.len() as f64);
    let d2 = |x: [f64; 3], y: [f64; 3]| (0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>();
    let far = |from: &dyn Fn(usize) -> f64| {
        (0..pairs.len()).fold(0, |best, i| if from(i) > from(best) { i } else { best })
    };
    let mut chosen = vec![far(&|i| d2(at(&pairs[i]), c))];
    let mut nearest: Vec<f64> = pairs
        .iter()
        .map(|p| d2(at(p), at(&pairs[chosen[0]])))
        .collect();
    while chosen.len() < n.min(pairs.len()) {
        let next = far(&|i| nearest[i]);
        chosen.push(next);
        for (i, p) in pairs.iter().enumerate() {
            nearest[i] = nearest[i].min(d2(at(p), at(&pairs[next])));
        }
    }
    let mut used_a = std::collections::HashSet::new();
    chosen
        .into_iter()
        .map(|i| [pairs[i].0, pairs[i].1])
        .filter(|l| used_a.insert(l[0]))
        .collect()
}
