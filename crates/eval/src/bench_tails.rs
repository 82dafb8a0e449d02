//! Every pair of every dataset, judged by its tails (`shapecorr bench tails`; docs/tails.md): the
//! default pipeline (regions verified at the map level, then the map) on each pair, with the
//! region accuracies, the map's mean geodesic error (no flip: every input here is a mesh,
//! whose orientation is known), the confidence and the seconds. The page lists per dataset
//! the mean, median, worst pair and failed-pair counts, every failed pair by name, and how
//! well the confidence flags the failed pairs.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::bench_pointwise::score_maps;
use crate::bench_store::{BasisCache, ResultLog, ShapeStore};
use crate::datasets::{discover, Pair};
use crate::tails::{error_tails_table, Tails, FAILED_ERRORS};
use shapecorr::evaluation::score_correspondence;
use shapecorr::maps::placement::Placement;
use shapecorr::maps::pointwise::PointwiseParams;
use shapecorr::pipeline::pointwise::regions_and_map;
use shapecorr::pipeline::Params;
use shapecorr::pipeline::PointwiseCorrespondence;
use shapecorr::progress::NoProgress;
use shapecorr::spectral::eigen::EigenParams;
use shapecorr::spectral::eigen::ShapeBasis;
use shapecorr::Result;

/// One pair of the tails run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TailRecord {
    pub dataset: String,
    pub pair: Pair,
    pub symmetric: f64,
    /// One-to-one accuracy (flip allowed where a mirror map exists).
    pub one_to_one: f64,
    /// Mean geodesic error of the map (unit-area A), against the ground truth.
    pub error: f64,
    /// The same with the flip allowed, where a mirror map exists.
    pub error_flip_ok: Option<f64>,
    /// The answer's confidence (None when nothing was verified).
    pub confidence: Option<f64>,
    /// The chosen hypothesis.
    pub hypothesis: Option<String>,
    /// What settled the choice (`cost`, `close call`, `placement`, `landmarks`).
    #[serde(default)]
    pub decided_by: Option<String>,
    /// The turn (degrees) the chosen map implies between B's frame and A's.
    #[serde(default)]
    pub turn_degrees: Option<f64>,
    /// Seconds of the regions and the map (eigenbases not counted: cached).
    pub seconds: f64,
}

/// Runs every pair of every dataset under `root` (or of `only`), resuming from
/// `work/tails.jsonl`; returns the records. Dense shapes run on proxies as the library's
/// default does, unless `full_resolution`; the shapes' placement is used as `placement` says.
pub fn run_tails(
    root: &Path,
    work: &Path,
    only: Option<&[String]>,
    samples: usize,
    (full_resolution, placement): (bool, Placement),
) -> Result<Vec<TailRecord>> {
    let (mut datasets, _) = discover(root)?;
    if let Some(only) = only {
        datasets.retain(|d| only.contains(&d.name));
    }
    std::fs::create_dir_all(work).map_err(|e| shapecorr::Error::file(work, e.to_string()))?;
    let (mut log, mut records) = ResultLog::open::<TailRecord>(&work.join("tails.jsonl"))?;
    let mut params = Params {
        placement,
        ..Params::default()
    };
    if full_resolution {
        params.multiresolution.above = 0;
    }
    let pointwise = PointwiseParams::default();
    for dataset in datasets {
        let pairs = dataset.pairs(root)?;
        let eigen = EigenParams {
            n_eigenpairs: pointwise.n_eigenpairs,
            ..params.eigen.clone()
        };
        let cache = BasisCache {
            dir: Some(work.join("eigenbases")),
        };
        let name = dataset.name.clone();
        let mut store = ShapeStore::new(dataset, eigen, cache);
        for (i, pair) in pairs.iter().enumerate() {
            if records
                .iter()
                .any(|r: &TailRecord| r.dataset == name && r.pair == *pair)
            {
                continue;
            }
            let record = tail_pair(&mut store, &name, pair, &params, &pointwise, samples)?;
            eprintln!(
                "[{name} {}/{}] {} -> {}: symmetric {:.3}, one-to-one {:.3}, error {:.4}, confidence {}, {:.2} s",
                i + 1,
                pairs.len(),
                pair.source,
                pair.target,
                record.symmetric,
                record.one_to_one,
                record.error,
                record.confidence.map_or("-".into(), |c| format!("{c:.2}")),
                record.seconds
            );
            log.append(&record)?;
            records.push(record);
        }
        store.retain(&[]);
    }
    Ok(records)
}

fn tail_pair(
    store: &mut ShapeStore,
    name: &str,
    pair: &Pair,
    params: &Params,
    pointwise: &PointwiseParams,
    samples: usize,
) -> Result<TailRecord> {
    store.load(&pair.source, true, false)?;
    store.load(&pair.target, true, false)?;
    let (a, b) = (
        &store.get(&pair.source).shape,
        &store.get(&pair.target).shape,
    );
    let (basis_a, basis_b) = (
        &store.basis(&pair.source).basis,
        &store.basis(&pair.target).basis,
    );
    let t = Instant::now();
    // Dense shapes run as the library runs them, on proxies (their eigenbases are computed
    // here, not cached, and counted in the seconds); the full-resolution bases above give
    // the vertex masses the regions are scored with.
    let dense = [a, b].iter().any(|s| params.multiresolution.applies_to(s));
    let (regions, map) = if dense {
        let result = PointwiseCorrespondence::compute(a, b, params, pointwise, &mut NoProgress)?;
        (result.regions, result.map)
    } else {
        regions_and_map(
            ShapeBasis::new(a, basis_a),
            ShapeBasis::new(b, basis_b),
            params,
            pointwise,
            &mut NoProgress,
        )?
    };
    let seconds = t.elapsed().as_secs_f64();
    let (truth, flipped) =
        store
            .dataset
            .ground_truth(&pair.source, &pair.target, a.n_vertices(), b.n_vertices())?;
    let region_scores = score_correspondence(
        &regions,
        &basis_a.mass,
        &basis_b.mass,
        &truth,
        flipped.as_deref(),
    );
    let verdict = map.verdict.as_ref().or(regions.verdict.as_ref());
    let confidence = verdict.map(|v| v.confidence);
    let hypothesis = verdict.map(|v| v.chosen().kind.name());
    let decided_by = verdict.map(|v| v.decided_by.name().to_string());
    let turn_degrees = verdict.map(|v| v.chosen().turn_degrees);
    let scores = score_maps(store, pair, &[("map".into(), map.p2p_ba, 0.0)], samples)?;
    Ok(TailRecord {
        dataset: name.to_string(),
        pair: pair.clone(),
        symmetric: region_scores.symmetric,
        one_to_one: region_scores
            .one_to_one_flip
            .unwrap_or(region_scores.one_to_one),
        error: scores[0].error.mean,
        error_flip_ok: scores[0].error_mirrored.map(|_| scores[0].best_mean()),
        confidence,
        hypothesis,
        decided_by,
        turn_degrees,
        seconds,
    })
}

/// The page: per dataset the tails of the map error and of the region accuracies, the failed
/// pairs by name, and the confidence's flags.
pub fn tails_page(records: &[TailRecord], command: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Tails: every pair of every dataset\n");
    let _ = writeln!(
        s,
        "Made by `{command}` (docs/decisions.md, \"Hypotheses verified at the map level\"). The default pipeline on every pair of every list: regions verified \
         at the map level, then the map. Error: mean geodesic error / sqrt(area) on 1000 sampled \
         ground-truth pairs, no flip allowed (every input is a mesh). Failed: above {} and above {}. \
         Shapes above the default `proxy_above` (12K vertices: TOSCA's) run on proxies as the \
         library runs them (docs/design.md, step 16; `--full-resolution` turns that off).\n",
        FAILED_ERRORS[0], FAILED_ERRORS[1]
    );
    let datasets: Vec<&str> = {
        let mut d: Vec<&str> = records.iter().map(|r| r.dataset.as_str()).collect();
        d.dedup();
        d
    };
    let name = |r: &TailRecord| format!("{} -> {}", r.pair.source, r.pair.target);
    let rows: Vec<(String, Vec<(f64, String)>)> = datasets
        .iter()
        .map(|d| {
            let v = records
                .iter()
                .filter(|r| r.dataset == *d)
                .map(|r| (r.error, name(r)))
                .collect();
            (d.to_string(), v)
        })
        .collect();
    let _ = writeln!(s, "## Map error\n\n{}", error_tails_table(&rows));
    let _ = writeln!(s, "## Regions\n");
    let _ = writeln!(
        s,
        "| dataset | pairs | symmetric mean | median | worst pair | one-to-one mean | median | worst pair | largest gap | pairs with gap > 0.02 |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for d in &datasets {
        let of = |f: &dyn Fn(&TailRecord) -> f64| -> Vec<(f64, String)> {
            records
                .iter()
                .filter(|r| r.dataset == *d)
                .map(|r| (f(r), name(r)))
                .collect()
        };
        let (sym, one, gap) = (
            of(&|r| r.symmetric),
            of(&|r| r.one_to_one),
            of(&|r| r.symmetric - r.one_to_one),
        );
        if let (Some(ts), Some(to), Some(tg)) = (
            Tails::of(&sym, false),
            Tails::of(&one, false),
            Tails::of(&gap, true),
        ) {
            let _ = writeln!(
                s,
                "| {d} | {} | {:.3} | {:.3} | {:.3} ({}) | {:.3} | {:.3} | {:.3} ({}) | {:.3} ({}) | {} |",
                ts.pairs,
                ts.mean,
                ts.median,
                ts.worst.0,
                ts.worst.1,
                to.mean,
                to.median,
                to.worst.0,
                to.worst.1,
                tg.worst.0,
                tg.worst.1,
                Tails::count_above(&gap, 0.02)
            );
        }
    }
    let failed: Vec<&TailRecord> = records
        .iter()
        .filter(|r| r.error > FAILED_ERRORS[0])
        .collect();
    let _ = writeln!(s, "\n## Failed pairs (error above {})\n", FAILED_ERRORS[0]);
    if failed.is_empty() {
        let _ = writeln!(s, "None.");
    } else {
        let _ = writeln!(
            s,
            "| dataset | pair | error | symmetric | one-to-one | hypothesis | decided by | turn | confidence |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
        for r in failed {
            let _ = writeln!(
                s,
                "| {} | {} | {:.4} | {:.3} | {:.3} | {} | {} | {} | {} |",
                r.dataset,
                name(r),
                r.error,
                r.symmetric,
                r.one_to_one,
                r.hypothesis.as_deref().unwrap_or("-"),
                r.decided_by.as_deref().unwrap_or("-"),
                r.turn_degrees.map_or("-".into(), |t| format!("{t:.0}")),
                r.confidence.map_or("-".into(), |c| format!("{c:.2}"))
            );
        }
    }
    confidence_section(&mut s, records);
    let seconds: Vec<f64> = records.iter().map(|r| r.seconds).collect();
    let _ = writeln!(
        s,
        "\n{} pairs; regions and map {:.2} s per pair on average (eigenbases cached).",
        records.len(),
        seconds.iter().sum::<f64>() / seconds.len().max(1) as f64
    );
    s
}

/// How many failed and good pairs the confidence flags at each threshold.
fn confidence_section(s: &mut String, records: &[TailRecord]) {
    let _ = writeln!(s, "\n## Confidence\n");
    let _ = writeln!(
        s,
        "Flagged: confidence below the threshold. A good confidence flags the failed pairs \
         (error above {}) and not the good ones.\n",
        FAILED_ERRORS[0]
    );
    let _ = writeln!(
        s,
        "| threshold | failed pairs flagged | good pairs flagged |"
    );
    let _ = writeln!(s, "|---|---|---|");
    let bad: Vec<f64> = records
        .iter()
        .filter(|r| r.error > FAILED_ERRORS[0])
        .map(|r| r.confidence.unwrap_or(1.0))
        .collect();
    let good: Vec<f64> = records
        .iter()
        .filter(|r| r.error <= FAILED_ERRORS[0])
        .map(|r| r.confidence.unwrap_or(1.0))
        .collect();
    for threshold in [0.1, 0.2, 0.3, 0.4, 0.45, 0.5, 0.6, 0.7] {
        let frac = |v: &[f64]| {
            if v.is_empty() {
                "-".to_string()
            } else {
                let n = v.iter().filter(|&&c| c < threshold).count();
                format!(
                    "{n}/{} ({:.0}%)",
                    v.len(),
                    100.0 * n as f64 / v.len() as f64
                )
            }
        };
        let marker = if (threshold - shapecorr::maps::hypotheses::DOUBTFUL_BELOW).abs() < 1e-9 {
            " (default)"
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "| {threshold}{marker} | {} | {} |",
            frac(&bad),
            frac(&good)
        );
    }
}
