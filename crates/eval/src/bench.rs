//! Region-correspondence benchmark over a pair list (`shapecorr bench regions`): the paper's
//! Table 1 with, per category, symmetric and one-to-one accuracy, the flip-tolerant one-to-one
//! accuracy, region counts, coverage, the unmatched fraction and seconds per pair.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::bench_store::{BasisCache, ShapeStore};
use crate::datasets::{pair_list, Pair};
use shapecorr::evaluation::{score_correspondence, RegionScores};
use shapecorr::pipeline::pointwise::truncated;
use shapecorr::pipeline::{Correspondence, Params, Timings};
use shapecorr::progress::NoProgress;
use shapecorr::spectral::eigen::ShapeBasis;
use shapecorr::Result;

/// The outcome of one pair.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PairResult {
    pub pair: Pair,
    /// The number of joint clusters (Reeb baseline: intervals of the function).
    pub k: usize,
    pub scores: RegionScores,
    /// Seconds for the pair as if run alone: both eigenbases plus the matching.
    pub seconds: f64,
    /// Seconds per stage (the eigenbases as measured when computed).
    pub timings: Timings,
}

/// Runs the pairs of `pairs_file` (the dataset `root/NAME` of `pairs/NAME.txt`, or a dataset
/// name) on the shapes under `root`. Each shape's eigenbasis is computed once and reused (and
/// kept in `cache`); the time of a pair counts both eigenbases as if computed for it.
/// `report` is called after every pair.
pub fn bench_regions(
    root: &Path,
    pairs_file: &Path,
    params: &Params,
    limit: Option<usize>,
    cache: BasisCache,
    report: &mut dyn FnMut(usize, usize, &PairResult),
) -> Result<Vec<PairResult>> {
    let (dataset, pairs) = pair_list(root, pairs_file, limit)?;
    // With a cache, the bases are those of the pointwise maps (100 eigenpairs, cut to the
    // regions' 50 for each pair), so that `bench p2p` and `bench regions` share them.
    let eigen = match cache.dir {
        Some(_) => shapecorr::EigenParams {
            n_eigenpairs: shapecorr::PointwiseParams::default()
                .n_eigenpairs
                .max(params.eigen.n_eigenpairs),
            ..params.eigen.clone()
        },
        None => params.eigen.clone(),
    };
    let mut store = ShapeStore::new(dataset, eigen, cache);
    let mut results = Vec::with_capacity(pairs.len());
    for (index, pair) in pairs.iter().enumerate() {
        let outcome = region_pair(&mut store, pair, params, &|a, ba, b, bb, p| {
            Correspondence::from_bases(
                ShapeBasis::new(a, ba),
                ShapeBasis::new(b, bb),
                p,
                &mut NoProgress,
            )
        })?;
        report(index, pairs.len(), &outcome);
        results.push(outcome);
    }
    Ok(results)
}

/// A region method run on two shapes with their eigenbases: the paper's pipeline
/// ([`Correspondence::from_bases`]) or a baseline.
pub type RegionMethod<'a> = dyn Fn(
        &shapecorr::Shape,
        &shapecorr::Eigenbasis,
        &shapecorr::Shape,
        &shapecorr::Eigenbasis,
        &Params,
    ) -> Result<Correspondence>
    + 'a;

/// One pair of `store`'s dataset: `method` on the two shapes (their eigenbases cut to
/// `params.eigen.n_eigenpairs` when the store holds more), scored against the ground truth.
pub fn region_pair(
    store: &mut ShapeStore,
    pair: &Pair,
    params: &Params,
    method: &RegionMethod,
) -> Result<PairResult> {
    store.load(&pair.source, true, false)?;
    store.load(&pair.target, true, false)?;
    let (a, b) = (store.get(&pair.source), store.get(&pair.target));
    let (basis_a, basis_b) = (store.basis(&pair.source), store.basis(&pair.target));
    let k = params.eigen.n_eigenpairs;
    let cut = |basis: &shapecorr::Eigenbasis| (basis.len() > k).then(|| truncated(basis, k));
    let (cut_a, cut_b) = (cut(&basis_a.basis), cut(&basis_b.basis));
    let t = Instant::now();
    let mut result = method(
        &a.shape,
        cut_a.as_ref().unwrap_or(&basis_a.basis),
        &b.shape,
        cut_b.as_ref().unwrap_or(&basis_b.basis),
        params,
    )?;
    let seconds = t.elapsed().as_secs_f64() + basis_a.seconds + basis_b.seconds;
    result.timings.eigenbasis_a = basis_a.seconds;
    result.timings.eigenbasis_b = basis_b.seconds;
    result.timings.total = seconds;
    let (truth, flipped) = store.dataset.ground_truth(
        &pair.source,
        &pair.target,
        a.shape.n_vertices(),
        b.shape.n_vertices(),
    )?;
    let scores = score_correspondence(
        &result,
        &basis_a.basis.mass,
        &basis_b.basis.mass,
        &truth,
        flipped.as_deref(),
    );
    Ok(PairResult {
        pair: pair.clone(),
        k: result.k,
        scores,
        seconds,
        timings: result.timings,
    })
}

/// The results as a table: one row per category and one for all pairs.
pub fn summary_table(results: &[PairResult]) -> String {
    let mut categories: BTreeMap<&str, Vec<&PairResult>> = BTreeMap::new();
    for r in results {
        categories
            .entry(r.pair.category.as_str())
            .or_default()
            .push(r);
    }
    let all: Vec<&PairResult> = results.iter().collect();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| category | pairs | symmetric | one-to-one | one-to-one (flip ok) | worst symmetric | regions A/B | coverage | unmatched | k | s/pair |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|");
    let rows = categories
        .iter()
        .map(|(c, v)| (c.to_string(), v.clone()))
        .chain(std::iter::once(("all".to_string(), all)));
    for (name, rows) in rows {
        let n = rows.len() as f64;
        let mean = |f: &dyn Fn(&PairResult) -> f64| rows.iter().map(|r| f(r)).sum::<f64>() / n;
        let flip = if rows.iter().all(|r| r.scores.one_to_one_flip.is_some()) {
            format!(
                "{:.3}",
                mean(&|r| r.scores.one_to_one_flip.unwrap_or(f64::NAN))
            )
        } else {
            "n/a".to_string()
        };
        let worst = rows
            .iter()
            .map(|r| r.scores.symmetric)
            .fold(f64::INFINITY, f64::min);
        let _ = writeln!(
            out,
            "| {name} | {} | {:.3} | {:.3} | {flip} | {worst:.3} | {:.1}/{:.1} | {:.3} | {:.3} | {:.2} | {:.2} |",
            rows.len(),
            mean(&|r| r.scores.symmetric),
            mean(&|r| r.scores.one_to_one),
            mean(&|r| r.scores.n_regions_a as f64),
            mean(&|r| r.scores.n_regions_b as f64),
            mean(&|r| r.scores.coverage),
            mean(&|r| r.scores.unmatched),
            mean(&|r| r.k as f64),
            mean(&|r| r.seconds),
        );
    }
    out
}

/// A score's label, its (value, pair) per pair, and whether higher is worse.
type ScoreRow<'a> = (&'a str, Vec<(f64, String)>, bool);

/// The accuracy below which a pair's regions count as failed (the symmetric accuracy of the
/// paper's method on FAUST is 0.88 on average).
pub const FAILED_ACCURACY: [f64; 2] = [0.9, 0.8];

/// The tails of the region scores: per score (symmetric, one-to-one with the flip allowed
/// where a mirror map exists, and the gap between them), the mean, median, worst pair and the
/// count of failed pairs (accuracy below each of [`FAILED_ACCURACY`]; gap above 0.02).
pub fn region_tails_table(results: &[PairResult]) -> String {
    use crate::tails::Tails;
    let name = |r: &PairResult| format!("{} -> {}", r.pair.source, r.pair.target);
    let one_to_one = |r: &PairResult| r.scores.one_to_one_flip.unwrap_or(r.scores.one_to_one);
    let rows: [ScoreRow; 3] = [
        (
            "symmetric",
            results
                .iter()
                .map(|r| (r.scores.symmetric, name(r)))
                .collect(),
            false,
        ),
        (
            "one-to-one",
            results.iter().map(|r| (one_to_one(r), name(r))).collect(),
            false,
        ),
        (
            "gap (symmetric - one-to-one)",
            results
                .iter()
                .map(|r| (r.scores.symmetric - one_to_one(r), name(r)))
                .collect(),
            true,
        ),
    ];
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| score | pairs | mean | median | worst pair | below 0.9 | below 0.8 | gap above 0.02 |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|");
    for (label, values, is_gap) in rows {
        let Some(t) = Tails::of(&values, is_gap) else {
            continue;
        };
        let below = |x: f64| values.iter().filter(|v| v.0 < x).count().to_string();
        let (b9, b8, gap) = if is_gap {
            (
                "-".into(),
                "-".into(),
                Tails::count_above(&values, 0.02).to_string(),
            )
        } else {
            (
                below(FAILED_ACCURACY[0]),
                below(FAILED_ACCURACY[1]),
                "-".into(),
            )
        };
        let _ = writeln!(
            out,
            "| {label} | {} | {:.3} | {:.3} | {:.3} ({}) | {b9} | {b8} | {gap} |",
            t.pairs, t.mean, t.median, t.worst.0, t.worst.1
        );
    }
    out
}
