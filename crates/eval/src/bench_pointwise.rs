//! Pointwise-map benchmark over a pair list (`shapecorr bench p2p`, the paper's Table 2 and
//! FAUST error curves), and the scoring of maps computed elsewhere (`shapecorr bench maps`,
//! for comparisons with other tools on the same geodesic error).
//!
//! Error: for a sample of the ground-truth pairs `(x on A, y on B)` (seeded, the same for
//! every method), the geodesic distance on A between `x` and the map's image of `y`,
//! divided by `sqrt(area of A)`; geodesics by the heat method (within 2% of exact on a
//! sphere and a grid). Where a mirror map exists, the error against the mirrored ground
//! truth is computed too, and the better of the two is reported beside the plain one.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::bench_store::{BasisCache, ShapeStore};
use crate::datasets::{pair_list, Pair};
use shapecorr::evaluation::{pointwise_errors, ErrorSummary};
use shapecorr::maps::pointwise::{PointwiseMap, PointwiseParams, Refinement, RegionConstraints};
use shapecorr::pipeline::pointwise::truncated;
use shapecorr::pipeline::{Correspondence, Params};
use shapecorr::progress::NoProgress;
use shapecorr::shape::Shape;
use shapecorr::spectral::descriptors::WksParams;
use shapecorr::spectral::eigen::EigenParams;
use shapecorr::spectral::eigen::ShapeBasis;
use shapecorr::{Error, Result};

/// Seed of the ground-truth sample.
const SAMPLE_SEED: u64 = 0x9e0d;

/// Number of points of the stored error curves: thresholds 0, 0.0025, ..., 0.25.
pub const CURVE_POINTS: usize = 101;
/// Step between the thresholds of the error curves.
pub const CURVE_STEP: f64 = 0.0025;

/// The thresholds of the error curves.
pub fn curve_thresholds() -> Vec<f64> {
    (0..CURVE_POINTS).map(|i| i as f64 * CURVE_STEP).collect()
}

/// The methods of the paper's Table 2 plus the refined one: name and parameters, all
/// derived from `base` (the default pipeline, regions + ZoomOut).
pub fn methods(base: &PointwiseParams, region_params: &Params) -> Vec<(String, PointwiseParams)> {
    let plain = PointwiseParams {
        refinement: Refinement::None,
        ..base.clone()
    };
    let descriptors_only = PointwiseParams {
        regions: RegionConstraints::None,
        ..plain.clone()
    };
    let wks_only = PointwiseParams {
        wks: Some(WksParams::default()),
        ..descriptors_only.clone()
    };
    // Ovsjanikov et al. 2012's refinement, the last step of the framework the paper uses.
    let icp = Refinement::Icp(shapecorr::options::ICP_ITERATIONS);
    vec![
        ("wks".into(), wks_only.clone()),
        (
            "hks".into(),
            PointwiseParams {
                hks: Some(region_params.hks.clone()),
                descriptor_step: 1,
                ..descriptors_only.clone()
            },
        ),
        (
            "wks+icp".into(),
            PointwiseParams {
                refinement: icp.clone(),
                ..wks_only
            },
        ),
        ("regions".into(), plain.clone()),
        (
            "regions+wks".into(),
            PointwiseParams {
                wks: Some(WksParams::default()),
                ..plain.clone()
            },
        ),
        (
            "symmetric".into(),
            PointwiseParams {
                regions: RegionConstraints::Symmetric,
                ..plain.clone()
            },
        ),
        (
            "regions+icp".into(),
            PointwiseParams {
                refinement: icp,
                ..plain.clone()
            },
        ),
        ("regions+zoomout".into(), base.clone()),
    ]
}

/// One method's scores on one pair.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MapScore {
    pub method: String,
    /// Against the ground truth.
    pub error: ErrorSummary,
    /// Against the mirrored ground truth, where a mirror map exists.
    pub error_mirrored: Option<ErrorSummary>,
    /// Seconds for the pair as if run alone (both eigenbases, the regions where used, the
    /// map); 0 for maps scored from files.
    pub seconds: f64,
    /// Fraction of the sampled errors (plain, or mirrored where that mean is lower) within
    /// each of [`curve_thresholds`], for the cumulative curves.
    pub curve: Vec<f64>,
    /// Number of ground-truth pairs scored (the weight of `curve` when pairs are pooled).
    pub n_scored: usize,
}

impl MapScore {
    /// The better of the plain and the mirrored mean error.
    pub fn best_mean(&self) -> f64 {
        self.error_mirrored
            .map_or(self.error.mean, |m| m.mean.min(self.error.mean))
    }

    /// True when the mirrored ground truth fits better.
    pub fn flipped(&self) -> bool {
        self.error_mirrored
            .is_some_and(|m| m.mean < self.error.mean)
    }
}

/// The scores of every method on one pair.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PairScores {
    pub source: String,
    pub target: String,
    pub category: String,
    pub scores: Vec<MapScore>,
}

/// Scores maps `p2p_ba` (name, map, seconds) of one pair against its ground truth (a seeded sample of at most
/// `samples` pairs; 0 = all).
pub fn score_maps(
    store: &mut ShapeStore,
    pair: &Pair,
    maps: &[(String, Vec<u32>, f64)],
    samples: usize,
) -> Result<Vec<MapScore>> {
    let n_a = store.load(&pair.source, false, true)?.shape.n_vertices();
    let n_b = store.load(&pair.target, false, false)?.shape.n_vertices();
    for (name, map, _) in maps {
        if map.len() != n_b {
            return Err(Error::InvalidParameter {
                name: "map",
                reason: format!(
                    "{name}: {} entries for the {n_b} vertices of {}",
                    map.len(),
                    pair.target
                ),
            });
        }
        if let Some(v) = map.iter().find(|&&v| v as usize >= n_a) {
            return Err(Error::InvalidParameter {
                name: "map",
                reason: format!(
                    "{name}: vertex {v} is out of range for {} ({n_a} vertices)",
                    pair.source
                ),
            });
        }
    }
    let (truth, mirrored) = store
        .dataset
        .ground_truth(&pair.source, &pair.target, n_a, n_b)?;
    let mut chosen: Vec<usize> = (0..truth.len()).collect();
    if samples > 0 && samples < truth.len() {
        chosen.shuffle(&mut ChaCha8Rng::seed_from_u64(SAMPLE_SEED));
        chosen.truncate(samples);
        chosen.sort_unstable();
    }
    let pick = |t: &[(u32, u32)]| chosen.iter().map(|&i| t[i]).collect::<Vec<_>>();
    let entry = store.get(&pair.source);
    let heat = entry.heat.as_ref().expect("loaded above");
    let area_a = shape_area(&entry.shape)?;
    let map_refs: Vec<&[u32]> = maps.iter().map(|(_, m, _)| m.as_slice()).collect();
    let plain = pointwise_errors(heat, area_a, &pick(&truth), &map_refs)?;
    let flipped = match &mirrored {
        Some(m) => Some(pointwise_errors(heat, area_a, &pick(m), &map_refs)?),
        None => None,
    };
    Ok(maps
        .iter()
        .enumerate()
        .map(|(i, (name, _, seconds))| {
            let error = ErrorSummary::of(&plain[i]);
            let error_mirrored = flipped.as_ref().map(|f| ErrorSummary::of(&f[i]));
            let best_errors = match (&flipped, error_mirrored) {
                (Some(f), Some(m)) if m.mean < error.mean => &f[i],
                _ => &plain[i],
            };
            MapScore {
                method: name.clone(),
                error,
                error_mirrored,
                seconds: *seconds,
                curve: shapecorr::evaluation::error_curve(best_errors, &curve_thresholds()),
                n_scored: best_errors.len(),
            }
        })
        .collect())
}

/// The area of a shape in its own units (the unit-area scale of the errors).
fn shape_area(shape: &Shape) -> Result<f64> {
    Ok(shapecorr::spectral::laplacian::Laplacian::new(shape)?.input_area)
}

#[allow(clippy::too_many_arguments)]
/// Runs every method of [`methods`] on the pairs of `pairs_file` (layout from its name).
/// `samples` ground-truth pairs per shape pair are scored (0 = all); eigenbases come from and
/// go to `cache`. `report` is called after every pair.
pub fn bench_pointwise(
    root: &Path,
    pairs_file: &Path,
    params: &Params,
    pointwise: &PointwiseParams,
    samples: usize,
    only: Option<&[String]>,
    limit: Option<usize>,
    cache: BasisCache,
    report: &mut dyn FnMut(usize, usize, &PairScores),
) -> Result<Vec<PairScores>> {
    let (dataset, pairs) = pair_list(root, pairs_file, limit)?;
    let methods = select_methods(pointwise, params, only)?;
    let eigen = EigenParams {
        n_eigenpairs: pointwise.n_eigenpairs.max(params.eigen.n_eigenpairs),
        ..params.eigen.clone()
    };
    let mut store = ShapeStore::new(dataset, eigen, cache);
    let mut results = Vec::with_capacity(pairs.len());
    for (index, pair) in pairs.iter().enumerate() {
        let outcome = pointwise_pair(&mut store, pair, params, &methods, samples)?;
        report(index, pairs.len(), &outcome);
        results.push(outcome);
    }
    Ok(results)
}

/// The methods of [`methods`] named in `only` (all when None); an unknown name is an error.
pub fn select_methods(
    base: &PointwiseParams,
    region_params: &Params,
    only: Option<&[String]>,
) -> Result<Vec<(String, PointwiseParams)>> {
    let mut methods = methods(base, region_params);
    if let Some(only) = only {
        if let Some(unknown) = only.iter().find(|o| !methods.iter().any(|(m, _)| m == *o)) {
            return Err(Error::InvalidParameter {
                name: "methods",
                reason: format!(
                    "unknown method {unknown:?}; known: {}",
                    methods
                        .iter()
                        .map(|(m, _)| m.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        }
        methods.retain(|(m, _)| only.contains(m));
    }
    Ok(methods)
}

/// One pair of `store`'s dataset: the regions (on eigenbases cut to
/// `params.eigen.n_eigenpairs`), then every method's map, scored on `samples` ground-truth
/// pairs (0 = all). The store's eigenbases need at least the methods' `n_eigenpairs`.
pub fn pointwise_pair(
    store: &mut ShapeStore,
    pair: &Pair,
    params: &Params,
    methods: &[(String, PointwiseParams)],
    samples: usize,
) -> Result<PairScores> {
    store.load(&pair.source, true, false)?;
    store.load(&pair.target, true, false)?;
    let (a, b) = (
        &store.get(&pair.source).shape,
        &store.get(&pair.target).shape,
    );
    let (basis_a, basis_b) = (store.basis(&pair.source), store.basis(&pair.target));
    let eigen_seconds = basis_a.seconds + basis_b.seconds;
    let t = Instant::now();
    // The maps verify the hypotheses themselves, on their larger basis
    // (shapecorr::pipeline::pointwise::regions_and_map).
    let unverified = Params {
        verify_hypotheses: false,
        ..params.clone()
    };
    let k = params.eigen.n_eigenpairs;
    let (truncated_a, truncated_b) = (truncated(&basis_a.basis, k), truncated(&basis_b.basis, k));
    let regions = Correspondence::from_bases(
        ShapeBasis::new(a, &truncated_a),
        ShapeBasis::new(b, &truncated_b),
        &unverified,
        &mut NoProgress,
    )?;
    let region_seconds = t.elapsed().as_secs_f64();
    let mut maps = Vec::with_capacity(methods.len());
    for (name, method) in methods {
        let t = Instant::now();
        let map = PointwiseMap::from_bases(
            ShapeBasis::new(a, &basis_a.basis),
            ShapeBasis::new(b, &basis_b.basis),
            Some(regions.matches_view()),
            method,
            &mut NoProgress,
        )?;
        let uses_regions = method.regions != RegionConstraints::None;
        let seconds = t.elapsed().as_secs_f64()
            + eigen_seconds
            + if uses_regions { region_seconds } else { 0.0 };
        maps.push((name.clone(), map.p2p_ba, seconds));
    }
    let scores = score_maps(store, pair, &maps, samples)?;
    Ok(PairScores {
        source: pair.source.clone(),
        target: pair.target.clone(),
        category: pair.category.clone(),
        scores,
    })
}

/// Scores maps stored as files `maps_dir/{source}__{target}.txt` (one 0-based vertex of A
/// per line, for every vertex of B) on the pairs of `pairs_file`.
pub fn bench_map_files(
    root: &Path,
    pairs_file: &Path,
    maps_dir: &Path,
    samples: usize,
    limit: Option<usize>,
    report: &mut dyn FnMut(usize, usize, &PairScores),
) -> Result<Vec<PairScores>> {
    let (dataset, pairs) = pair_list(root, pairs_file, limit)?;
    let mut store = ShapeStore::new(dataset, EigenParams::default(), BasisCache::default());
    let name = maps_dir
        .file_name()
        .map_or("map".to_string(), |n| n.to_string_lossy().into_owned());
    let mut results = Vec::with_capacity(pairs.len());
    for (index, pair) in pairs.iter().enumerate() {
        let path = maps_dir.join(format!("{}__{}.txt", pair.source, pair.target));
        let map = read_map(&path)?;
        let scores = score_maps(&mut store, pair, &[(name.clone(), map, 0.0)], samples)?;
        let outcome = PairScores {
            source: pair.source.clone(),
            target: pair.target.clone(),
            category: pair.category.clone(),
            scores,
        };
        report(index, pairs.len(), &outcome);
        results.push(outcome);
    }
    Ok(results)
}

/// Reads a map file: one 0-based vertex index per line.
pub fn read_map(path: &Path) -> Result<Vec<u32>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::file(path, e.to_string()))?;
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(n, l)| {
            l.trim().parse::<u32>().map_err(|_| {
                Error::file(
                    path,
                    format!("line {}: expected a vertex index, got {l:?}", n + 1),
                )
            })
        })
        .collect()
}

/// Per category and method: mean error, the better of plain and mirrored (with how many
/// pairs the mirror won), the fractions within 0.05 and 0.10, and seconds per pair.
pub fn pointwise_table(results: &[PairScores]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| category | method | pairs | mean error | mean error (flip ok) | flipped pairs | within 0.05 | within 0.10 | s/pair |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|");
    let mut categories: BTreeMap<&str, Vec<&PairScores>> = BTreeMap::new();
    for r in results {
        categories.entry(r.category.as_str()).or_default().push(r);
    }
    let all: Vec<&PairScores> = results.iter().collect();
    let methods: Vec<String> = results
        .first()
        .map(|r| r.scores.iter().map(|s| s.method.clone()).collect())
        .unwrap_or_default();
    let rows = categories
        .iter()
        .map(|(c, v)| (c.to_string(), v.clone()))
        .chain(std::iter::once(("all".to_string(), all)));
    for (category, rows) in rows {
        for (m, method) in methods.iter().enumerate() {
            let scores: Vec<&MapScore> = rows.iter().map(|r| &r.scores[m]).collect();
            let n = scores.len() as f64;
            let mean = |f: &dyn Fn(&MapScore) -> f64| scores.iter().map(|s| f(s)).sum::<f64>() / n;
            let has_mirror = scores.iter().all(|s| s.error_mirrored.is_some());
            let (flip, flipped) = if has_mirror {
                (
                    format!("{:.4}", mean(&|s| s.best_mean())),
                    format!("{}", scores.iter().filter(|s| s.flipped()).count()),
                )
            } else {
                ("n/a".into(), "n/a".into())
            };
            let _ = writeln!(
                out,
                "| {category} | {method} | {} | {:.4} | {flip} | {flipped} | {:.3} | {:.3} | {:.2} |",
                scores.len(),
                mean(&|s| s.error.mean),
                mean(&|s| s.error.within_005),
                mean(&|s| s.error.within_010),
                mean(&|s| s.seconds),
            );
        }
    }
    out
}

/// Per method: the mean, median and worst pair of the mean error against the ground truth
/// (no flip: the inputs are meshes, whose orientation is known) and the count of failed
/// pairs ([`crate::tails::FAILED_ERRORS`]).
pub fn pointwise_tails_table(results: &[PairScores]) -> String {
    let methods: Vec<String> = results
        .first()
        .map(|r| r.scores.iter().map(|s| s.method.clone()).collect())
        .unwrap_or_default();
    let rows: Vec<(String, Vec<(f64, String)>)> = methods
        .iter()
        .enumerate()
        .map(|(m, method)| {
            let values = results
                .iter()
                .map(|r| {
                    (
                        r.scores[m].error.mean,
                        format!("{} -> {}", r.source, r.target),
                    )
                })
                .collect();
            (method.clone(), values)
        })
        .collect();
    crate::tails::error_tails_table(&rows)
}

/// Cumulative error curves over all pairs (flip allowed where a mirror map exists): one
/// column per method at [`curve_thresholds`] (0 to 0.25), every scored ground-truth pair
/// weighted alike. Returns the methods, their curves and the CSV text.
pub fn curves_csv(results: &[PairScores]) -> (Vec<String>, Vec<Vec<f64>>, String) {
    let thresholds = curve_thresholds();
    let methods: Vec<String> = results
        .first()
        .map(|r| r.scores.iter().map(|s| s.method.clone()).collect())
        .unwrap_or_default();
    let curves: Vec<Vec<f64>> = (0..methods.len())
        .map(|m| {
            let total: usize = results.iter().map(|r| r.scores[m].n_scored).sum();
            (0..thresholds.len())
                .map(|i| {
                    let within: f64 = results
                        .iter()
                        .map(|r| r.scores[m].curve[i] * r.scores[m].n_scored as f64)
                        .sum();
                    within / total.max(1) as f64
                })
                .collect()
        })
        .collect();
    let mut csv = format!("threshold,{}\n", methods.join(","));
    for (i, t) in thresholds.iter().enumerate() {
        let _ = write!(csv, "{t:.4}");
        for c in &curves {
            let _ = write!(csv, ",{:.5}", c[i]);
        }
        csv.push('\n');
    }
    (methods, curves, csv)
}

/// Writes the cumulative error curves of `results` as CSV to `csv_path` and as a PNG beside
/// it (same name, `.png`), titled with `name`. Returns whether a font was found for the
/// PNG's text.
pub fn write_curves(csv_path: &Path, name: &str, results: &[PairScores]) -> Result<bool> {
    let (methods, curves, csv) = curves_csv(results);
    std::fs::write(csv_path, csv).map_err(|e| Error::file(csv_path, e.to_string()))?;
    let thresholds = curve_thresholds();
    let series: Vec<crate::plot::Series> = methods
        .iter()
        .zip(&curves)
        .map(|(m, c)| crate::plot::Series {
            label: m.clone(),
            points: thresholds.iter().copied().zip(c.iter().copied()).collect(),
        })
        .collect();
    let title = format!(
        "{name} ({} pairs): fraction of vertices within a geodesic error",
        results.len()
    );
    let rendered = crate::plot::line_chart_png(
        &csv_path.with_extension("png"),
        &crate::plot::Chart {
            title: &title,
            x_label: "geodesic error / sqrt(area) (flip allowed where a mirror map exists)",
            y_label: "fraction of vertices",
            x_range: (0.0, 0.25),
            y_range: (0.0, 1.0),
        },
        &series,
    )?;
    Ok(rendered.font.is_some())
}
