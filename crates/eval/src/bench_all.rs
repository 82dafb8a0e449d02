//! `shapecorr bench all`: the paper's evaluation (section 6) on every dataset present, written
//! to one results page with the paper's figures beside ours.
//!
//! Tables: region accuracy with the Reeb-graph baseline (paper Table 1), point-to-point map
//! errors (Table 2) with the cumulative error curves, the point-cloud protocol (section 6.3,
//! figure "pointclouds") and per-stage timing (Table 3). Every result is appended to a
//! JSON-lines log under the work folder as it finishes, so an interrupted run resumes where
//! it stopped; eigenbases are cached on disk ([`crate::bench_store::BasisCache`]). The logs'
//! names carry a hash of the parameters, so changed parameters start new logs. The timing
//! table is always measured fresh (no cache), end to end as a user's call runs.
//!
//! `quick` mode generates a small dataset of humanoid figures (two bodies, seven poses, one
//! vertex order, a mirror map) in the FAUST layout and runs everything on it: what CI runs.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::bench::{region_pair, PairResult};
use crate::bench_clouds::{cloud_figure, cloud_table, cloud_trials, CloudProtocol, CloudTrial};
use crate::bench_pointwise::{pointwise_pair, select_methods, write_curves, PairScores};
use crate::bench_store::{BasisCache, ProgressBar, ResultLog, ShapeStore};
use crate::datasets::{discover, Dataset, Pair};
use crate::reeb::{reeb_correspondence, ReebParams};
use shapecorr::maps::pointwise::{PointwiseParams, PointwiseTimings};
use shapecorr::pipeline::PointwiseCorrespondence;
use shapecorr::pipeline::{Correspondence, Params, Timings};
use shapecorr::progress::NoProgress;
use shapecorr::shape::Shape;
use shapecorr::spectral::eigen::EigenParams;
use shapecorr::spectral::eigen::ShapeBasis;
use shapecorr::ReadAs;
use shapecorr::{Error, Result};

/// What `bench all` runs and where it writes.
#[derive(Debug, Clone)]
pub struct AllParams {
    /// Dataset root (`pairs/NAME.txt` and `NAME/`); in quick mode, where the generated
    /// dataset is written.
    pub data: PathBuf,
    /// Where `results.md` and the figures (`images/`) go.
    pub out: PathBuf,
    /// Logs of finished results and the eigenbasis cache.
    pub work: PathBuf,
    /// Only these datasets (all found when None).
    pub datasets: Option<Vec<String>>,
    /// At most this many pairs per dataset and table, spread evenly over the pair list.
    pub limit: Option<usize>,
    /// Ground-truth pairs scored per shape pair for the pointwise errors (0 = all).
    pub p2p_samples: usize,
    /// Pairs of the point-cloud protocol (spread over FAUST's list, or the quick dataset's).
    pub cloud_pairs: usize,
    pub cloud_protocol: CloudProtocol,
    /// Pairs per size class of the timing table.
    pub timing_pairs: usize,
    /// Generated shapes only (CI).
    pub quick: bool,
    /// The command line, as typed, for the page.
    pub command: String,
    pub params: Params,
    pub pointwise: PointwiseParams,
    pub reeb: ReebParams,
}

impl AllParams {
    /// Defaults for a full run on `data`, writing to `out`.
    pub fn new(data: PathBuf, out: PathBuf, work: PathBuf, quick: bool) -> AllParams {
        AllParams {
            data,
            out,
            work,
            datasets: None,
            limit: None,
            p2p_samples: 1000,
            cloud_pairs: if quick { 2 } else { 6 },
            cloud_protocol: if quick {
                CloudProtocol {
                    densities: vec![1500, 500],
                    noise: vec![0.0, 0.02],
                    trials: 1,
                    ..CloudProtocol::default()
                }
            } else {
                CloudProtocol::default()
            },
            timing_pairs: if quick { 2 } else { 4 },
            quick,
            command: String::new(),
            params: Params::default(),
            pointwise: PointwiseParams::default(),
            reeb: ReebParams::default(),
        }
    }
}

/// One pair's fresh end-to-end timing.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TimingRecord {
    pub pair: Pair,
    pub n_vertices: (usize, usize),
    /// `Correspondence::compute` (its own eigenbases, regions), per stage.
    pub regions: Timings,
    /// `PointwiseCorrespondence::compute` (eigenbases with 100 pairs, regions, map): total.
    pub p2p_total: f64,
    pub p2p_stages: PointwiseTimings,
}

/// Everything one dataset produced.
#[derive(Debug, Default)]
struct DatasetResults {
    name: String,
    regions: Vec<PairResult>,
    reeb: Vec<PairResult>,
    p2p: Vec<PairScores>,
    clouds: Vec<CloudTrial>,
    timing: Vec<TimingRecord>,
    curves_png: Option<String>,
    clouds_png: Option<String>,
    /// Results computed by this invocation and read back from the logs of earlier ones.
    counts: Counts,
}

#[derive(Debug, Default, Clone, Copy)]
struct Counts {
    computed: usize,
    resumed: usize,
}

/// Runs every table on every dataset found and writes `out/results.md`. Returns its path.
pub fn run_all(p: &AllParams) -> Result<PathBuf> {
    let started = Instant::now();
    if p.quick {
        write_quick_dataset(&p.data)?;
    }
    let (mut datasets, skipped) = discover(&p.data)?;
    for s in &skipped {
        eprintln!("bench all: skipping {s}");
    }
    if let Some(only) = &p.datasets {
        if let Some(missing) = only
            .iter()
            .find(|n| !datasets.iter().any(|d| &d.name == *n))
        {
            return Err(Error::InvalidParameter {
                name: "datasets",
                reason: format!(
                    "{missing:?} was not found under {} (found: {})",
                    p.data.display(),
                    datasets
                        .iter()
                        .map(|d| d.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        }
        datasets.retain(|d| only.contains(&d.name));
    }
    if p.quick {
        datasets.retain(|d| d.name == QUICK);
    }
    if datasets.is_empty() {
        return Err(Error::file(
            &p.data,
            "no dataset found (a dataset NAME needs a folder NAME/ and a pair list pairs/NAME.txt)",
        ));
    }
    let images = p.out.join("images");
    std::fs::create_dir_all(&images).map_err(|e| Error::file(&images, e.to_string()))?;
    let mut all = Vec::new();
    for dataset in &datasets {
        all.push(run_dataset(p, dataset)?);
    }
    let page = results_page(p, &all, started.elapsed().as_secs_f64());
    let path = p.out.join("results.md");
    std::fs::write(&path, page).map_err(|e| Error::file(&path, e.to_string()))?;
    Ok(path)
}

/// The name of the generated dataset of quick mode.
pub const QUICK: &str = "quick";

/// Writes the quick dataset under `root`: `quick/bodyB_poseP.ply` for two bodies and the
/// seven humanoid poses (about 1,500 vertices, one vertex order), `quick/template_mirror.txt`
/// and `pairs/quick.txt` with FAUST's categories. Existing files are kept (they are
/// deterministic).
pub fn write_quick_dataset(root: &Path) -> Result<()> {
    use shapecorr::synth::{figure_poses, mirror_map, n_poses, FigureKind, Proportions};
    let folder = root.join(QUICK);
    let pairs_dir = root.join("pairs");
    for dir in [&folder, &pairs_dir] {
        std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, e.to_string()))?;
    }
    let poses: Vec<usize> = (0..n_poses(FigureKind::Humanoid)).collect();
    let bodies = [
        Proportions::default(),
        Proportions {
            limb_length: 1.15,
            limb_thickness: 0.8,
            ..Default::default()
        },
    ];
    let mut mirror = None;
    for (body, proportions) in bodies.iter().enumerate() {
        let meshes = figure_poses(FigureKind::Humanoid, 1500, *proportions, &poses)?;
        if body == 0 {
            mirror = Some(mirror_map(&meshes[0]));
        }
        for (pose, mesh) in meshes.iter().enumerate() {
            let path = folder.join(format!("body{body}_pose{pose}.ply"));
            if !path.exists() {
                shapecorr::shape::io::write_ply(&path, &mesh.vertices, &mesh.triangles, None)?;
            }
        }
    }
    let mirror: Vec<String> = mirror
        .expect("body 0 made")
        .iter()
        .map(|v| v.to_string())
        .collect();
    let mirror_path = folder.join("template_mirror.txt");
    std::fs::write(&mirror_path, mirror.join("\n") + "\n")
        .map_err(|e| Error::file(&mirror_path, e.to_string()))?;
    let pairs = [
        ("body0_pose0", "body0_pose3", "same_person"),
        ("body0_pose1", "body0_pose5", "same_person"),
        ("body1_pose2", "body1_pose6", "same_person"),
        ("body1_pose4", "body1_pose0", "same_person"),
        ("body0_pose2", "body1_pose2", "diff_person_same_pose"),
        ("body1_pose5", "body0_pose5", "diff_person_same_pose"),
        ("body0_pose0", "body1_pose6", "diff_person_diff_pose"),
        ("body1_pose3", "body0_pose1", "diff_person_diff_pose"),
    ];
    let mut text =
        String::from("# source\ttarget\tcategory (generated by shapecorr bench all --quick)\n");
    for (s, t, c) in pairs {
        let _ = writeln!(text, "{s}\t{t}\t{c}");
    }
    let list = pairs_dir.join(format!("{QUICK}.txt"));
    std::fs::write(&list, text).map_err(|e| Error::file(&list, e.to_string()))
}

/// Up to `n` pairs spread evenly over `pairs` (all when `n` is None or large enough).
fn spread(pairs: &[Pair], n: Option<usize>) -> Vec<Pair> {
    match n {
        Some(n) if n < pairs.len() => (0..n).map(|i| pairs[i * pairs.len() / n].clone()).collect(),
        _ => pairs.to_vec(),
    }
}

/// A short hash of anything's debug text: the parameter part of the log names.
fn fingerprint(value: &impl std::fmt::Debug) -> String {
    let digest = Sha256::digest(format!("{value:?}").as_bytes());
    digest.iter().take(6).map(|b| format!("{b:02x}")).collect()
}

/// Runs `work` for every pair not yet in the log `path` (results of type `T`, keyed by
/// `key`), appending as it goes; returns all results in pair order.
fn resumable<T: Serialize + serde::de::DeserializeOwned + Clone>(
    counts: &mut Counts,
    path: &Path,
    label: &str,
    pairs: &[Pair],
    key: &dyn Fn(&T) -> (String, String),
    work: &mut dyn FnMut(&Pair) -> Result<T>,
) -> Result<Vec<T>> {
    let (mut log, done) = ResultLog::open::<T>(path)?;
    let mut by_pair: BTreeMap<(String, String), T> =
        done.into_iter().map(|r| (key(&r), r)).collect();
    let already = pairs
        .iter()
        .filter(|p| by_pair.contains_key(&(p.source.clone(), p.target.clone())))
        .count();
    counts.resumed += already;
    let mut bar = ProgressBar::new(label, pairs.len(), already);
    for pair in pairs {
        let k = (pair.source.clone(), pair.target.clone());
        if by_pair.contains_key(&k) {
            continue;
        }
        let result = work(pair)?;
        counts.computed += 1;
        log.append(&result)?;
        by_pair.insert(k, result);
        bar.step(&format!("{} -> {}", pair.source, pair.target));
    }
    bar.finish();
    Ok(pairs
        .iter()
        .filter_map(|p| by_pair.get(&(p.source.clone(), p.target.clone())).cloned())
        .collect())
}

fn pair_key(r: &PairResult) -> (String, String) {
    (r.pair.source.clone(), r.pair.target.clone())
}

fn run_dataset(p: &AllParams, dataset: &Dataset) -> Result<DatasetResults> {
    let name = dataset.name.as_str();
    let pairs = spread(&dataset.pairs(&p.data)?, p.limit);
    let logs = p.work.join("logs");
    let eigen = EigenParams {
        n_eigenpairs: p.pointwise.n_eigenpairs.max(p.params.eigen.n_eigenpairs),
        ..p.params.eigen.clone()
    };
    let cache = BasisCache {
        dir: Some(p.work.join("eigenbases")),
    };
    let mut store = ShapeStore::new(dataset.clone(), eigen, cache);
    let mut out = DatasetResults {
        name: name.to_string(),
        ..Default::default()
    };

    let params = &p.params;
    out.regions = resumable(
        &mut out.counts,
        &logs.join(format!("regions-{name}-{}.jsonl", fingerprint(params))),
        &format!("{name} regions"),
        &pairs,
        &pair_key,
        &mut |pair| {
            region_pair(&mut store, pair, params, &|a, ba, b, bb, pp| {
                Correspondence::from_bases(
                    ShapeBasis::new(a, ba),
                    ShapeBasis::new(b, bb),
                    pp,
                    &mut NoProgress,
                )
            })
        },
    )?;
    let reeb = &p.reeb;
    out.reeb = resumable(
        &mut out.counts,
        &logs.join(format!(
            "reeb-{name}-{}.jsonl",
            fingerprint(&(params, reeb))
        )),
        &format!("{name} Reeb"),
        &pairs,
        &pair_key,
        &mut |pair| {
            region_pair(&mut store, pair, params, &|a, ba, b, bb, pp| {
                reeb_correspondence(a, ba, b, bb, reeb, pp)
            })
        },
    )?;
    let methods = select_methods(&p.pointwise, params, None)?;
    // Each shape keeps its eigenbasis and geodesic solver until its last pair, then is
    // released (the solvers are the largest items): nothing is made twice.
    let last_use: BTreeMap<&str, usize> = pairs
        .iter()
        .enumerate()
        .flat_map(|(i, q)| [(q.source.as_str(), i), (q.target.as_str(), i)])
        .collect();
    out.p2p = resumable(
        &mut out.counts,
        &logs.join(format!(
            "p2p-{name}-{}.jsonl",
            fingerprint(&(params, &p.pointwise, p.p2p_samples))
        )),
        &format!("{name} p2p"),
        &pairs,
        &|r: &PairScores| (r.source.clone(), r.target.clone()),
        &mut |pair| {
            let scores = pointwise_pair(&mut store, pair, params, &methods, p.p2p_samples);
            let index = pairs
                .iter()
                .position(|q| q == pair)
                .expect("a pair of the list");
            let needed: Vec<&str> = last_use
                .iter()
                .filter(|&(_, &last)| last > index)
                .map(|(&name, _)| name)
                .collect();
            store.retain(&needed);
            scores
        },
    )?;
    if !out.p2p.is_empty() {
        let file = format!("{name}_p2p_curves.csv");
        write_curves(&p.out.join("images").join(&file), name, &out.p2p)?;
        out.curves_png = Some(format!("images/{name}_p2p_curves.png"));
    }
    drop(store);

    if name == "faust" || name == QUICK {
        out.clouds = run_clouds(p, dataset, &pairs, &mut out.counts)?;
        if !out.clouds.is_empty() {
            let mesh = mesh_accuracy(&out.regions, &out.clouds);
            let file = format!("images/{name}_pointclouds.png");
            cloud_figure(&p.out.join(&file), &out.clouds, mesh)?;
            out.clouds_png = Some(file);
        }
    }
    out.timing = run_timing(p, dataset, &pairs, &mut out.counts)?;
    Ok(out)
}

/// The mean symmetric accuracy of the mesh-to-mesh run on the pairs of the cloud protocol.
fn mesh_accuracy(regions: &[PairResult], clouds: &[CloudTrial]) -> Option<f64> {
    let chosen: Vec<f64> = regions
        .iter()
        .filter(|r| {
            clouds
                .iter()
                .any(|c| c.source == r.pair.source && c.target == r.pair.target)
        })
        .map(|r| r.scores.symmetric)
        .collect();
    (!chosen.is_empty()).then(|| chosen.iter().sum::<f64>() / chosen.len() as f64)
}

fn run_clouds(
    p: &AllParams,
    dataset: &Dataset,
    pairs: &[Pair],
    counts: &mut Counts,
) -> Result<Vec<CloudTrial>> {
    let name = &dataset.name;
    let chosen = spread(pairs, Some(p.cloud_pairs));
    let path = p.work.join("logs").join(format!(
        "clouds-{name}-{}.jsonl",
        fingerprint(&(&p.params, &p.cloud_protocol))
    ));
    let (mut log, done) = ResultLog::open::<CloudTrial>(&path)?;
    let per_pair = 2
        * p.cloud_protocol.densities.len()
        * p.cloud_protocol.noise.len()
        * p.cloud_protocol.trials;
    let mut results: Vec<CloudTrial> = done
        .into_iter()
        .filter(|t| {
            chosen
                .iter()
                .any(|c| c.source == t.source && c.target == t.target)
        })
        .collect();
    counts.resumed += results.len();
    let mut bar = ProgressBar::new(
        &format!("{name} point clouds"),
        chosen.len() * per_pair,
        results.len(),
    );
    for pair in &chosen {
        let a = Shape::read(&dataset.shape_path(&pair.source)?, ReadAs::Auto)?;
        let b = Shape::read(&dataset.shape_path(&pair.target)?, ReadAs::Auto)?;
        let (truth, flipped) =
            dataset.ground_truth(&pair.source, &pair.target, a.n_vertices(), b.n_vertices())?;
        let finished: Vec<(String, usize, u64, usize)> = results
            .iter()
            .filter(|t| t.source == pair.source && t.target == pair.target)
            .map(|t| (t.mode.clone(), t.density, t.noise.to_bits(), t.trial))
            .collect();
        let skip = |mode: &str, density: usize, noise: f64, trial: usize| {
            finished.contains(&(mode.to_string(), density, noise.to_bits(), trial))
        };
        let mut failure = None;
        cloud_trials(
            pair,
            &a,
            &b,
            &truth,
            flipped.as_deref(),
            &p.cloud_protocol,
            &p.params,
            &skip,
            &mut |trial: &CloudTrial| {
                if let Err(e) = log.append(trial) {
                    failure.get_or_insert(e);
                }
                bar.step(&format!(
                    "{} -> {} {} {} points, noise {}",
                    trial.source, trial.target, trial.mode, trial.density, trial.noise
                ));
                results.push(trial.clone());
                counts.computed += 1;
            },
        )?;
        if let Some(e) = failure {
            return Err(e);
        }
    }
    bar.finish();
    Ok(results)
}

/// Fresh end-to-end timings (no cache): FAUST-like datasets on spread pairs, TOSCA on its
/// largest class (david, 52K vertices), the quick dataset on its first pairs.
fn run_timing(
    p: &AllParams,
    dataset: &Dataset,
    pairs: &[Pair],
    counts: &mut Counts,
) -> Result<Vec<TimingRecord>> {
    let chosen: Vec<Pair> = match dataset.name.as_str() {
        "tosca" => spread(
            &pairs
                .iter()
                .filter(|q| q.category == "david")
                .cloned()
                .collect::<Vec<_>>(),
            Some(p.timing_pairs),
        ),
        "faust" | QUICK => spread(pairs, Some(p.timing_pairs)),
        _ => return Ok(Vec::new()),
    };
    let name = &dataset.name;
    let path = p.work.join("logs").join(format!(
        "timing-{name}-{}.jsonl",
        fingerprint(&(&p.params, &p.pointwise))
    ));
    resumable(
        counts,
        &path,
        &format!("{name} timing"),
        &chosen,
        &|r: &TimingRecord| (r.pair.source.clone(), r.pair.target.clone()),
        &mut |pair| {
            let a = Shape::read(&dataset.shape_path(&pair.source)?, ReadAs::Auto)?;
            let b = Shape::read(&dataset.shape_path(&pair.target)?, ReadAs::Auto)?;
            let regions = Correspondence::compute(&a, &b, &p.params, &mut NoProgress)?;
            let pointwise =
                PointwiseCorrespondence::compute(&a, &b, &p.params, &p.pointwise, &mut NoProgress)?;
            Ok(TimingRecord {
                pair: pair.clone(),
                n_vertices: (a.n_vertices(), b.n_vertices()),
                regions: regions.timings,
                p2p_total: pointwise.total,
                p2p_stages: pointwise.map.timings,
            })
        },
    )
}

// ---------------------------------------------------------------------------------------
// The results page.

/// The paper's Table 1 (symmetric region accuracy): (dataset, row, ours, Reeb).
const PAPER_TABLE1: &[(&str, &str, f64, f64)] = &[
    ("tosca", "cat", 0.8146, 0.1101),
    ("tosca", "centaur", 0.8719, 0.2372),
    ("tosca", "david", 0.9483, 0.0177),
    ("tosca", "dog", 0.9155, 0.0920),
    ("tosca", "horse", 0.8959, 0.1106),
    ("scape", "all", 0.8704, 0.1790),
    ("faust", "same_person", 0.9223, 0.1700),
    ("faust", "diff_person", 0.8473, 0.1213),
    ("faust", "diff_person_same_pose", 0.8975, 0.1545),
    ("faust", "diff_person_diff_pose", 0.8384, 0.1154),
    ("faust", "all", 0.8814, 0.1434),
];
/// The paper's average segment counts: (dataset, ours, Reeb).
const PAPER_SEGMENTS: &[(&str, f64, f64)] = &[
    ("tosca", 19.22, 20.68),
    ("scape", 17.32, 6.24),
    ("faust", 16.88, 25.89),
];
/// The paper's Table 2 (mean geodesic error): dataset, then WKS, HKS, WKS + SEGS, SEGS, SYM.
const PAPER_TABLE2: &[(&str, [f64; 5])] = &[
    ("tosca", [0.0480, 0.0613, 0.0266, 0.0266, 0.0391]),
    ("scape", [0.1624, 0.2569, 0.0604, 0.0605, 0.0958]),
    ("faust", [0.0670, 0.1184, 0.0306, 0.0305, 0.0481]),
];
/// Our methods beside the paper's Table 2 column they compare with (index into
/// [`PAPER_TABLE2`]). The paper's maps come from the framework of Ovsjanikov et al. 2012,
/// which ends with its spectral ICP, so its WKS and SEGS columns sit beside both our raw
/// conversion and the ICP-refined map.
const TABLE2_COLUMNS: [(&str, usize); 7] = [
    ("wks", 0),
    ("wks+icp", 0),
    ("hks", 1),
    ("regions+wks", 2),
    ("regions", 3),
    ("regions+icp", 3),
    ("symmetric", 4),
];

/// The paper's Table 2 figure that our `method` compares with on `dataset`, if any.
fn paper_table2(dataset: &str, method: &str) -> Option<f64> {
    let row = PAPER_TABLE2.iter().find(|(d, _)| *d == dataset)?.1;
    TABLE2_COLUMNS
        .iter()
        .find(|(name, _)| *name == method)
        .map(|&(_, i)| row[i])
}

fn paper_table1(dataset: &str, row: &str) -> Option<(f64, f64)> {
    PAPER_TABLE1
        .iter()
        .find(|(d, r, _, _)| *d == dataset && *r == row)
        .map(|&(_, _, o, r)| (o, r))
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}

fn fmt_paper(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

/// Rows of Table 1 for one dataset: per category, FAUST's combined `diff_person`, and all.
fn table1_rows(r: &DatasetResults) -> Vec<(String, Vec<usize>)> {
    let mut rows: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (i, x) in r.regions.iter().enumerate() {
        rows.entry(x.pair.category.clone()).or_default().push(i);
        if x.pair.category.starts_with("diff_person") {
            rows.entry("diff_person".into()).or_default().push(i);
        }
    }
    let mut out: Vec<(String, Vec<usize>)> = rows.into_iter().collect();
    if out.len() > 1 || out.first().is_some_and(|(c, _)| c != "all") {
        out.push(("all".into(), (0..r.regions.len()).collect()));
    }
    out
}

fn results_page(p: &AllParams, all: &[DatasetResults], wall: f64) -> String {
    let mut s = String::new();
    page_header(&mut s, p, all, wall);
    page_region_accuracy(&mut s, all);
    page_point_to_point(&mut s, p, all);
    page_point_clouds(&mut s, p, all);
    page_timing(&mut s, all);
    s
}

/// The page's title and the run: command, version, machine, this invocation, data, paper.
fn page_header(s: &mut String, p: &AllParams, all: &[DatasetResults], wall: f64) {
    let _ = writeln!(s, "# Results\n");
    let _ = writeln!(
        s,
        "Made by one command: `{}`{}. Everything on this page was measured by that command \
         (an interrupted run resumes from its logs; the timing table is measured without the \
         eigenbasis cache). Every pair of every list, judged by its tails (median, worst pair, \
         failed pairs, the confidence's flags), is in [tails.md](tails.md) (`shapecorr bench tails`); \
         time, memory and accuracy against size, 5K to 1M vertices, with pyFM beside, in \
         [scale.md](scale.md) (`shapecorr bench scale`).\n",
        p.command,
        if p.quick {
            " on generated humanoid figures only (CI's quick mode: the figures say nothing about the benchmarks)"
        } else {
            ""
        }
    );
    let _ = writeln!(
        s,
        "- shapecorr {} ({}), {}",
        env!("CARGO_PKG_VERSION"),
        git_commit(),
        today()
    );
    let _ = writeln!(s, "- machine: {}", machine());
    let (computed, resumed) = all.iter().fold((0, 0), |(c, r), d| {
        (c + d.counts.computed, r + d.counts.resumed)
    });
    let _ = writeln!(
        s,
        "- this invocation: {wall:.0} s wall, {computed} results computed, {resumed} read back from the logs of earlier invocations (their own times are in the tables)"
    );
    let _ = writeln!(
        s,
        "- data: `{}` ({})",
        p.data.display(),
        all.iter()
            .map(|r| format!("{}: {} pairs", r.name, r.regions.len()))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        s,
        "- paper: Kleiman and Ovsjanikov, *Robust Structure-based Shape Correspondence*; its figures are on the full benchmarks, ours on the pair lists above (see `../shared/data/README.md`).\n"
    );
}

/// Region accuracy (paper Table 1) and the paper's segment counts.
fn page_region_accuracy(s: &mut String, all: &[DatasetResults]) {
    let _ = writeln!(s, "## Region accuracy (paper Table 1)\n");
    let _ = writeln!(
        s,
        "Symmetric matching accuracy: the area-weighted fraction of ground-truth vertex pairs whose \
         regions are matched (paper section 6.2). One-to-one accuracy allows a global left/right flip \
         where a mirror map exists. Reeb: a Reeb graph of one HKS (t = 0.1) matched by the same \
         graph matcher (`crates/eval/src/reeb.rs`). Each shape's eigenbasis is computed once with 100 \
         eigenpairs (the pointwise maps need them) and cut to the first 50 for the regions; seconds \
         per pair count both eigenbases as if computed for the pair.\n"
    );
    let _ = writeln!(
        s,
        "| dataset | category | pairs | ours | paper | Reeb (ours) | Reeb (paper) | one-to-one (flip ok) | regions A/B | Reeb nodes A/B | s/pair |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
    for r in all {
        for (row, idx) in table1_rows(r) {
            let pick = |v: &[PairResult], f: &dyn Fn(&PairResult) -> f64| {
                mean(idx.iter().filter_map(|&i| v.get(i)).map(f))
            };
            let paper = paper_table1(&r.name, &row);
            let flip = pick(&r.regions, &|x| {
                x.scores.one_to_one_flip.unwrap_or(x.scores.one_to_one)
            });
            let _ = writeln!(
                s,
                "| {} | {row} | {} | {:.3} | {} | {:.3} | {} | {flip:.3} | {:.1}/{:.1} | {:.1}/{:.1} | {:.2} |",
                r.name,
                idx.len(),
                pick(&r.regions, &|x| x.scores.symmetric),
                fmt_paper(paper.map(|x| x.0), 3),
                pick(&r.reeb, &|x| x.scores.symmetric),
                fmt_paper(paper.map(|x| x.1), 3),
                pick(&r.regions, &|x| x.scores.n_regions_a as f64),
                pick(&r.regions, &|x| x.scores.n_regions_b as f64),
                pick(&r.reeb, &|x| x.scores.n_regions_a as f64),
                pick(&r.reeb, &|x| x.scores.n_regions_b as f64),
                pick(&r.regions, &|x| x.seconds),
            );
        }
    }
    let segs: Vec<String> = PAPER_SEGMENTS
        .iter()
        .filter(|(d, _, _)| all.iter().any(|r| r.name == *d))
        .map(|(d, o, r)| format!("{d} {o} (Reeb {r})"))
        .collect();
    if !segs.is_empty() {
        let _ = writeln!(
            s,
            "\nThe paper's average segment counts: {}.",
            segs.join(", ")
        );
    }
}

/// Point-to-point maps (paper Table 2) and the error curves.
fn page_point_to_point(s: &mut String, p: &AllParams, all: &[DatasetResults]) {
    let _ = writeln!(s, "\n## Point-to-point maps (paper Table 2)\n");
    let _ = writeln!(
        s,
        "Mean geodesic error divided by sqrt(area) on {} sampled ground-truth pairs per shape pair \
         (the same sample for every method); \"flip ok\" takes the better of the ground truth and \
         its mirror image where a mirror map exists. The paper's columns: WKS, HKS, WKS + SEGS, \
         SEGS, SYM. The paper computes its maps with the framework of Ovsjanikov et al. 2012, \
         which ends with a spectral ICP; wks+icp and regions+icp are WKS and SEGS refined by \
         that ICP (on 2000-vertex samples), and the paper's WKS and SEGS figures are shown \
         beside both the raw and the refined maps. Beyond the paper: regions+zoomout (target \
         0.020). \
         Every map with regions uses the orientation-preserving term and, on orientable meshes, \
         the choice between the one-to-one answer and its mirror image.\n",
        if p.p2p_samples == 0 {
            "all".to_string()
        } else {
            p.p2p_samples.to_string()
        }
    );
    let _ = writeln!(
        s,
        "| dataset | method | pairs | error | error (flip ok) | paper | mirrored answers | within 0.05 | within 0.10 | s/pair |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for r in all.iter().filter(|r| !r.p2p.is_empty()) {
        for (m, score) in r.p2p[0].scores.iter().enumerate() {
            let scores: Vec<_> = r.p2p.iter().map(|x| &x.scores[m]).collect();
            let paper_value = paper_table2(&r.name, &score.method);
            let mirrored = if scores.iter().all(|x| x.error_mirrored.is_some()) {
                scores.iter().filter(|x| x.flipped()).count().to_string()
            } else {
                "n/a".into()
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.4} | {:.4} | {} | {mirrored} | {:.3} | {:.3} | {:.2} |",
                r.name,
                score.method,
                scores.len(),
                mean(scores.iter().map(|x| x.error.mean)),
                mean(scores.iter().map(|x| x.best_mean())),
                fmt_paper(paper_value, 4),
                mean(scores.iter().map(|x| x.error.within_005)),
                mean(scores.iter().map(|x| x.error.within_010)),
                mean(scores.iter().map(|x| x.seconds)),
            );
        }
    }
    for r in all {
        if let Some(png) = &r.curves_png {
            let _ = writeln!(
                s,
                "\n{} cumulative error curves (data: `{}`):\n\n![{} error curves]({png})",
                r.name,
                png.replace(".png", ".csv"),
                r.name
            );
        }
    }
}

/// Point clouds (paper section 6.3), one section per dataset that has them.
fn page_point_clouds(s: &mut String, p: &AllParams, all: &[DatasetResults]) {
    for r in all.iter().filter(|r| !r.clouds.is_empty()) {
        let mesh = mesh_accuracy(&r.regions, &r.clouds);
        let pairs: std::collections::BTreeSet<(&str, &str)> = r
            .clouds
            .iter()
            .map(|t| (t.source.as_str(), t.target.as_str()))
            .collect();
        let _ = writeln!(s, "\n## Point clouds, {} (paper section 6.3)\n", r.name);
        let _ = writeln!(
            s,
            "{} pairs ({}), each mesh sampled uniformly on its surface at {:?} points, every point \
             shifted by up to {:?} of the shape's width, {} trial(s) each, seeded; accuracy after \
             transferring each cloud's regions to its mesh (vertices no point maps to are left out). \
             Mesh-to-cloud: A stays a mesh. The paper gives this experiment as a figure only, with no \
             numbers in its text, so there is no paper column; the mesh-to-mesh accuracy of the same \
             pairs is {}.\n",
            pairs.len(),
            pairs
                .iter()
                .map(|(a, b)| format!("{a}-{b}"))
                .collect::<Vec<_>>()
                .join(", "),
            p.cloud_protocol.densities,
            p.cloud_protocol.noise,
            p.cloud_protocol.trials,
            mesh.map_or("n/a".into(), |m| format!("{m:.3}"))
        );
        s.push_str(&cloud_table(&r.clouds, mesh));
        if let Some(png) = &r.clouds_png {
            let _ = writeln!(s, "\n![{} point clouds]({png})", r.name);
        }
    }
}

/// Timing (paper Table 3), when any dataset was timed.
fn page_timing(s: &mut String, all: &[DatasetResults]) {
    let timed: Vec<&DatasetResults> = all.iter().filter(|r| !r.timing.is_empty()).collect();
    if !timed.is_empty() {
        let _ = writeln!(s, "\n## Timing (paper Table 3)\n");
        let _ = writeln!(
            s,
            "Seconds per pair, measured fresh (no cache) end to end as `Correspondence::compute` and \
             `PointwiseCorrespondence::compute` run, on this machine with all its cores. The paper's \
             machine: Intel Xeon 3 GHz, 64 GB; its \"symmetric matching\" is everything up to the \
             symmetric matches, \"post-processing\" the one-to-one step.\n"
        );
        let mut header = String::from("| stage |");
        let mut rule = String::from("|---|");
        for r in &timed {
            let n = mean(
                r.timing
                    .iter()
                    .map(|t| (t.n_vertices.0 + t.n_vertices.1) as f64 / 2.0),
            );
            let _ = write!(
                header,
                " {} ({} pairs, {:.0}K vertices) |",
                r.name,
                r.timing.len(),
                n / 1000.0
            );
            rule.push_str("---|");
        }
        header.push_str(" paper 7K | paper 52K |");
        rule.push_str("---|---|");
        let _ = writeln!(s, "{header}\n{rule}");
        type Stage<'a> = (&'a str, &'a dyn Fn(&TimingRecord) -> f64, &'a str, &'a str);
        let stages: [Stage; 9] = [
            (
                "eigenbases (50 pairs, both shapes)",
                &|t| t.regions.eigenbasis_a + t.regions.eigenbasis_b,
                "",
                "",
            ),
            ("descriptors", &|t| t.regions.descriptors, "", ""),
            (
                "joint segmentation and graphs",
                &|t| t.regions.segmentation,
                "",
                "",
            ),
            ("graph matching", &|t| t.regions.matching, "", ""),
            (
                "**symmetric matching** (all of the above)",
                &|t| {
                    t.regions.eigenbasis_a
                        + t.regions.eigenbasis_b
                        + t.regions.descriptors
                        + t.regions.segmentation
                        + t.regions.matching
                },
                "11.35",
                "63.11",
            ),
            (
                "**post-processing** (one-to-one)",
                &|t| t.regions.one_to_one,
                "4.90",
                "99.94",
            ),
            (
                "**total, regions**",
                &|t| t.regions.total,
                "16.25",
                "163.06",
            ),
            (
                "point-to-point map: fmap + ZoomOut",
                &|t| t.p2p_stages.fmap + t.p2p_stages.refinement,
                "",
                "",
            ),
            (
                "**total, regions + map** (100 eigenpairs)",
                &|t| t.p2p_total,
                "",
                "",
            ),
        ];
        for (label, f, p7, p52) in stages {
            let mut row = format!("| {label} |");
            for r in &timed {
                let _ = write!(row, " {:.2} |", mean(r.timing.iter().map(f)));
            }
            let _ = write!(
                row,
                " {} | {} |",
                if p7.is_empty() { "-" } else { p7 },
                if p52.is_empty() { "-" } else { p52 }
            );
            let _ = writeln!(s, "{row}");
        }
    }
}

fn git_commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| format!("commit {}", String::from_utf8_lossy(&o.stdout).trim()))
        .unwrap_or_else(|| "commit unknown".into())
}

fn today() -> String {
    std::process::Command::new("date")
        .args(["-u", "+%Y-%m-%d"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default()
}

/// CPU model, core count and memory, from /proc where it exists.
fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let memory = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("MemTotal"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<f64>().ok())
        })
        .map_or(String::new(), |kb| {
            format!(", {:.0} GiB", kb / 1024.0 / 1024.0)
        });
    format!("{cpu}, {cores} cores{memory}, {}", std::env::consts::OS)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every method named beside a paper column is one that `bench p2p` runs (a renamed
    /// method would silently lose its paper figure), and the refined maps share the raw
    /// maps' column.
    #[test]
    fn paper_columns_name_methods_that_exist() {
        let methods: Vec<String> =
            crate::bench_pointwise::methods(&PointwiseParams::default(), &Params::default())
                .into_iter()
                .map(|(name, _)| name)
                .collect();
        for (name, _) in TABLE2_COLUMNS {
            assert!(methods.iter().any(|m| m == name), "{name} is not a method");
        }
        assert_eq!(paper_table2("tosca", "wks+icp"), Some(0.0480));
        assert_eq!(paper_table2("faust", "regions+icp"), Some(0.0305));
        assert_eq!(paper_table2("faust", "regions+zoomout"), None);
        assert_eq!(paper_table2("quick", "wks"), None);
    }
}
