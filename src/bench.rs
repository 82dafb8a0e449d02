//! Region-correspondence benchmark over a pair list (`shapecorr bench regions`): the paper's
//! Table 1 with, per category, symmetric and one-to-one accuracy, the flip-tolerant one-to-one
//! accuracy, region counts, coverage, the unmatched fraction and seconds per pair.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use crate::correspondence::{Correspondence, Params};
use crate::datasets::{read_pairs, Layout, Pair};
use crate::eigen::Eigenbasis;
use crate::evaluation::{score_correspondence, RegionScores};
use crate::progress::NoProgress;
use crate::shape::Shape;
use crate::Result;

/// The outcome of one pair.
#[derive(Debug, Clone)]
pub struct PairResult {
    pub pair: Pair,
    pub k: usize,
    pub scores: RegionScores,
    /// Seconds for the pair as if run alone: both eigenbases plus the matching.
    pub seconds: f64,
}

/// Runs the pairs of `pairs_file` (layout from its name) on the shapes under `root`.
/// Each shape's eigenbasis is computed once and reused; the time of a pair counts both
/// eigenbases as if computed for it. `report` is called after every pair.
pub fn bench_regions(
    root: &Path,
    pairs_file: &Path,
    params: &Params,
    limit: Option<usize>,
    report: &mut dyn FnMut(usize, usize, &PairResult),
) -> Result<Vec<PairResult>> {
    let layout = Layout::from_pairs_file(pairs_file)?;
    let mut pairs = read_pairs(pairs_file)?;
    if let Some(limit) = limit {
        pairs.truncate(limit);
    }
    let mut cache: BTreeMap<String, (Shape, Eigenbasis, f64)> = BTreeMap::new();
    let mut results = Vec::with_capacity(pairs.len());
    for (index, pair) in pairs.iter().enumerate() {
        for name in [&pair.source, &pair.target] {
            if !cache.contains_key(name.as_str()) {
                let shape = Shape::read(&layout.shape_path(root, name), false)?;
                let t = Instant::now();
                let basis = Eigenbasis::compute(&shape, &params.eigen)?;
                cache.insert(name.clone(), (shape, basis, t.elapsed().as_secs_f64()));
            }
        }
        let (a, basis_a, t_a) = &cache[pair.source.as_str()];
        let (b, basis_b, t_b) = &cache[pair.target.as_str()];
        let t = Instant::now();
        let result = Correspondence::from_bases(a, basis_a, b, basis_b, params, &mut NoProgress)?;
        let seconds = t.elapsed().as_secs_f64() + t_a + t_b;
        let (truth, flipped) = layout.ground_truth(
            root,
            &pair.source,
            &pair.target,
            a.n_vertices(),
            b.n_vertices(),
        )?;
        let scores = score_correspondence(
            &result,
            &basis_a.mass,
            &basis_b.mass,
            &truth,
            flipped.as_deref(),
        );
        let outcome = PairResult {
            pair: pair.clone(),
            k: result.k,
            scores,
            seconds,
        };
        report(index, pairs.len(), &outcome);
        results.push(outcome);
    }
    Ok(results)
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
