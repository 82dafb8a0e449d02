//! `shapecorr bench`: region accuracy (`regions`), pointwise maps (`p2p`), maps made by
//! other tools (`maps`) and the paper's whole evaluation (`all`) on the research datasets.

use crate::output::{errln, out, outln};
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde_json::json;
use shapecorr::Error;
use shapecorr_eval::bench_pointwise::PairScores;

use crate::options::{PointwiseOptions, RegionOptions};
use crate::output::write_json;

// Parsed once per run: the size difference between variants does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(clap::Subcommand)]
pub enum BenchCommand {
    /// Region accuracy over a pair list (like the paper's Table 1).
    Regions(BenchRegionsArgs),
    /// Pointwise maps over a pair list (like the paper's Table 2 and FAUST curves): WKS, HKS,
    /// WKS + ICP, regions, regions + WKS, symmetric regions, regions + ICP, regions + ZoomOut.
    P2p(BenchP2pArgs),
    /// The paper's whole evaluation on every dataset found under the data root (a dataset
    /// NAME = a folder NAME/ and a pair list pairs/NAME.txt): region accuracy with the Reeb
    /// baseline, point-to-point errors and curves, the point-cloud protocol, timing. Writes
    /// OUT/results.md and OUT/images/. Resumable: finished results are kept in WORK/logs and
    /// eigenbases in WORK/eigenbases.
    All(BenchAllArgs),
    /// Scores maps computed elsewhere, stored as MAPS/{source}__{target}.txt (for every
    /// vertex of the target, the 0-based index of its vertex on the source), with the same
    /// geodesic error as `bench p2p`.
    Maps(BenchMapsArgs),
    /// Every pair of every dataset with the default pipeline, judged by its tails: per
    /// dataset the mean, median, worst pair and failed pairs of the map error and the region
    /// accuracies, and how well the confidence flags the failed pairs. Writes OUT (default
    /// docs/tails.md); resumable from WORK/tails.jsonl, eigenbases kept in WORK/eigenbases.
    Tails(BenchTailsArgs),
    /// Time, peak memory and accuracy of `match` and `p2p` against size, on generated pairs
    /// from 5K to 1M vertices, with the full-resolution path and pyFM as references. Writes
    /// OUT (default docs/scale.md) and a log-log PNG beside it; resumable from
    /// WORK/scale.jsonl.
    Scale(BenchScaleArgs),
}

impl BenchCommand {
    pub fn run(&self) -> Result<(), Error> {
        match self {
            BenchCommand::Regions(args) => args.run(),
            BenchCommand::P2p(args) => args.run(),
            BenchCommand::All(args) => args.run(),
            BenchCommand::Maps(args) => args.run(),
            BenchCommand::Tails(args) => args.run(),
            BenchCommand::Scale(args) => args.run(),
        }
    }
}

/// The dataset root: `--data`, else $SHAPECORR_DATA or ../shared/data.
fn data_root(data: &Option<PathBuf>) -> PathBuf {
    data.clone()
        .unwrap_or_else(shapecorr_eval::datasets::default_data_root)
}

#[derive(clap::Args)]
pub struct BenchRegionsArgs {
    /// Dataset root (default: $SHAPECORR_DATA or ../shared/data).
    #[arg(long)]
    data: Option<PathBuf>,
    /// Pair list DATA/pairs/NAME.txt of the dataset in DATA/NAME (its layout from the
    /// name or the folder's contents: see crates/eval/src/datasets.rs), or a dataset's
    /// name (camel_gallop and lion_cat, which have no pair list, take their map files' pairs).
    #[arg(long)]
    pairs: PathBuf,
    /// Only the first N pairs.
    #[arg(long)]
    limit: Option<usize>,
    /// Keep the eigenbases in this folder and read them back on the next run (the same
    /// cache as `bench p2p --basis-cache`: 100 eigenpairs, cut to the regions' own).
    #[arg(long)]
    basis_cache: Option<PathBuf>,
    #[command(flatten)]
    options: RegionOptions,
}

impl BenchRegionsArgs {
    pub fn run(&self) -> Result<(), Error> {
        let params = self.options.params()?;
        let started = Instant::now();
        let results = shapecorr_eval::bench::bench_regions(
            &data_root(&self.data),
            &self.pairs,
            &params,
            self.limit,
            shapecorr_eval::bench_store::BasisCache {
                dir: self.basis_cache.clone(),
            },
            &mut |i, n, r| {
                errln!(
                    "[{}/{}] {} -> {} ({}): symmetric {:.3}, one-to-one {:.3}{}, regions {}/{}, coverage {:.3}, k {}, {:.2} s",
                    i + 1,
                    n,
                    r.pair.source,
                    r.pair.target,
                    r.pair.category,
                    r.scores.symmetric,
                    r.scores.one_to_one,
                    r.scores
                        .one_to_one_flip
                        .map_or(String::new(), |f| format!(" (flip ok {f:.3})")),
                    r.scores.n_regions_a,
                    r.scores.n_regions_b,
                    r.scores.coverage,
                    r.k,
                    r.seconds
                );
            },
        )?;
        outln!(
            "shapecorr {} bench regions --pairs {} ({} pairs, {:.0} s wall)",
            env!("CARGO_PKG_VERSION"),
            self.pairs.display(),
            results.len(),
            started.elapsed().as_secs_f64()
        )?;
        out!("{}", shapecorr_eval::bench::summary_table(&results))?;
        outln!()?;
        out!("{}", shapecorr_eval::bench::region_tails_table(&results))?;
        Ok(())
    }
}

#[derive(clap::Args)]
pub struct BenchP2pArgs {
    /// Dataset root (default: $SHAPECORR_DATA or ../shared/data).
    #[arg(long)]
    data: Option<PathBuf>,
    /// Pair list DATA/pairs/NAME.txt of the dataset in DATA/NAME (its layout from the
    /// name or the folder's contents: see crates/eval/src/datasets.rs), or a dataset's
    /// name (camel_gallop and lion_cat, which have no pair list, take their map files' pairs).
    #[arg(long)]
    pairs: PathBuf,
    /// Only the first N pairs.
    #[arg(long)]
    limit: Option<usize>,
    /// Ground-truth pairs scored per shape pair (a seeded sample; 0 = all).
    #[arg(long, default_value_t = 1000)]
    samples: usize,
    /// Write the cumulative error curves here (CSV, plus a PNG beside it).
    #[arg(long)]
    curves: Option<PathBuf>,
    /// Write every pair's scores here (JSON).
    #[arg(long)]
    json: Option<PathBuf>,
    /// Only these methods (comma separated; default: all).
    #[arg(long, value_delimiter = ',')]
    methods: Option<Vec<String>>,
    /// Keep the eigenbases in this folder and read them back on the next run (keyed by
    /// the shape file's bytes and the eigensolver's parameters).
    #[arg(long)]
    basis_cache: Option<PathBuf>,
    #[command(flatten)]
    options: PointwiseOptions,
}

impl BenchP2pArgs {
    pub fn run(&self) -> Result<(), Error> {
        let (options, pointwise) = self.options.pointwise()?;
        let started = Instant::now();
        let results = shapecorr_eval::bench_pointwise::bench_pointwise(
            &data_root(&self.data),
            &self.pairs,
            &options.params,
            &pointwise,
            self.samples,
            self.methods.as_deref(),
            self.limit,
            shapecorr_eval::bench_store::BasisCache {
                dir: self.basis_cache.clone(),
            },
            &mut print_pair_scores,
        )?;
        outln!(
            "shapecorr {} bench p2p --pairs {} ({} pairs, {} samples per pair, {:.0} s wall)",
            env!("CARGO_PKG_VERSION"),
            self.pairs.display(),
            results.len(),
            self.samples,
            started.elapsed().as_secs_f64()
        )?;
        out!(
            "{}",
            shapecorr_eval::bench_pointwise::pointwise_table(&results)
        )?;
        outln!("\nTails (mean error per pair against the ground truth, no flip):\n")?;
        out!(
            "{}",
            shapecorr_eval::bench_pointwise::pointwise_tails_table(&results)
        )?;
        if let Some(path) = &self.json {
            write_scores_json(path, &results)?;
        }
        if let Some(path) = &self.curves {
            let name = self
                .pairs
                .file_stem()
                .map_or(String::new(), |s| s.to_string_lossy().into_owned());
            if !shapecorr_eval::bench_pointwise::write_curves(path, &name, &results)? {
                errln!(
                    "shapecorr: no font found, {} has no text (set SHAPECORR_FONT)",
                    path.with_extension("png").display()
                );
            }
        }
        Ok(())
    }
}

#[derive(clap::Args)]
pub struct BenchAllArgs {
    /// Dataset root (default: $SHAPECORR_DATA or ../shared/data; quick mode: WORK/data).
    #[arg(long)]
    data: Option<PathBuf>,
    /// Where results.md and images/ go (default: docs; quick mode: WORK).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Logs and eigenbasis cache (default: target/bench-all; quick mode: target/bench-quick).
    #[arg(long)]
    work: Option<PathBuf>,
    /// Generated shapes only, small protocol (what CI runs).
    #[arg(long)]
    quick: bool,
    /// Only these datasets (comma separated).
    #[arg(long, value_delimiter = ',')]
    datasets: Option<Vec<String>>,
    /// At most N pairs per dataset, spread over its pair list.
    #[arg(long)]
    limit: Option<usize>,
    /// Ground-truth pairs scored per shape pair for the pointwise errors (0 = all).
    #[arg(long, default_value_t = 1000)]
    samples: usize,
    /// Pairs of the point-cloud protocol (default 6; quick 2).
    #[arg(long)]
    cloud_pairs: Option<usize>,
    /// Pairs per dataset of the timing table (default 4; quick 2).
    #[arg(long)]
    timing_pairs: Option<usize>,
    /// Forget the logs of earlier runs (the eigenbasis cache is kept).
    #[arg(long)]
    fresh: bool,
}

impl BenchAllArgs {
    fn params(&self) -> shapecorr_eval::bench_all::AllParams {
        let quick = self.quick;
        let work = self.work.clone().unwrap_or_else(|| {
            PathBuf::from(if quick {
                "target/bench-quick"
            } else {
                "target/bench-all"
            })
        });
        let data = self.data.clone().unwrap_or_else(|| {
            if quick {
                work.join("data")
            } else {
                shapecorr_eval::datasets::default_data_root()
            }
        });
        let out = self.out.clone().unwrap_or_else(|| {
            if quick {
                work.clone()
            } else {
                PathBuf::from("docs")
            }
        });
        let mut p = shapecorr_eval::bench_all::AllParams::new(data, out, work, quick);
        p.datasets = self.datasets.clone();
        p.limit = self.limit;
        p.p2p_samples = self.samples;
        p.cloud_pairs = self.cloud_pairs.unwrap_or(p.cloud_pairs);
        p.timing_pairs = self.timing_pairs.unwrap_or(p.timing_pairs);
        p.command = std::iter::once("shapecorr".to_string())
            .chain(std::env::args().skip(1))
            .collect::<Vec<_>>()
            .join(" ");
        p
    }

    pub fn run(&self) -> Result<(), Error> {
        let p = self.params();
        let logs = p.work.join("logs");
        if self.fresh && logs.exists() {
            std::fs::remove_dir_all(&logs).map_err(|e| Error::file(&logs, e.to_string()))?;
        }
        let started = Instant::now();
        let page = shapecorr_eval::bench_all::run_all(&p)?;
        outln!(
            "{} written ({:.0} s); logs and eigenbasis cache in {}",
            page.display(),
            started.elapsed().as_secs_f64(),
            p.work.display()
        )?;
        Ok(())
    }
}

#[derive(clap::Args)]
pub struct BenchMapsArgs {
    #[arg(long)]
    data: Option<PathBuf>,
    #[arg(long)]
    pairs: PathBuf,
    #[arg(long)]
    maps: PathBuf,
    #[arg(long)]
    limit: Option<usize>,
    #[arg(long, default_value_t = 1000)]
    samples: usize,
    #[arg(long)]
    json: Option<PathBuf>,
}

impl BenchMapsArgs {
    pub fn run(&self) -> Result<(), Error> {
        let results = shapecorr_eval::bench_pointwise::bench_map_files(
            &data_root(&self.data),
            &self.pairs,
            &self.maps,
            self.samples,
            self.limit,
            &mut print_pair_scores,
        )?;
        out!(
            "{}",
            shapecorr_eval::bench_pointwise::pointwise_table(&results)
        )?;
        outln!("\nTails (mean error per pair against the ground truth, no flip):\n")?;
        out!(
            "{}",
            shapecorr_eval::bench_pointwise::pointwise_tails_table(&results)
        )?;
        if let Some(path) = &self.json {
            write_scores_json(path, &results)?;
        }
        Ok(())
    }
}

fn print_pair_scores(i: usize, n: usize, r: &PairScores) {
    let scores: Vec<String> = r
        .scores
        .iter()
        .map(|s| match s.error_mirrored {
            Some(m) => format!("{} {:.4} (flip {:.4})", s.method, s.error.mean, m.mean),
            None => format!("{} {:.4}", s.method, s.error.mean),
        })
        .collect();
    errln!(
        "[{}/{}] {} -> {} ({}): {}",
        i + 1,
        n,
        r.source,
        r.target,
        r.category,
        scores.join(", ")
    );
}

fn write_scores_json(path: &Path, results: &[PairScores]) -> Result<(), Error> {
    let pairs: Vec<serde_json::Value> = results
        .iter()
        .flat_map(|r| {
            r.scores.iter().map(move |s| {
                json!({
                    "source": r.source,
                    "target": r.target,
                    "category": r.category,
                    "method": s.method,
                    "mean_error": s.error.mean,
                    "mean_error_flip": s.error_mirrored.map(|_| s.best_mean()),
                    "flipped": s.flipped(),
                    "within_005": s.error.within_005,
                    "within_010": s.error.within_010,
                    "seconds": s.seconds,
                })
            })
        })
        .collect();
    write_json(
        path,
        &json!({ "version": env!("CARGO_PKG_VERSION"), "pairs": pairs }),
    )
}

#[derive(clap::Args)]
pub struct BenchTailsArgs {
    /// Dataset root (default: $SHAPECORR_DATA or ../shared/data).
    #[arg(long)]
    data: Option<PathBuf>,
    /// The page to write.
    #[arg(long, default_value = "docs/tails.md")]
    out: PathBuf,
    /// Log and eigenbasis cache.
    #[arg(long, default_value = "target/bench-tails")]
    work: PathBuf,
    /// Only these datasets (comma separated).
    #[arg(long, value_delimiter = ',')]
    datasets: Option<Vec<String>>,
    /// Ground-truth pairs scored per shape pair (a seeded sample; 0 = all).
    #[arg(long, default_value_t = 1000)]
    samples: usize,
    /// Every shape at full resolution (no proxies for dense shapes: the reference the
    /// multiresolution path is compared with).
    #[arg(long)]
    full_resolution: bool,
    /// How the shapes' placement is used: auto (the default), ignore (the intrinsic
    /// figures, comparable with the literature) or trust.
    #[arg(long, default_value = "auto")]
    placement: String,
}

impl BenchTailsArgs {
    pub fn run(&self) -> Result<(), Error> {
        let placement = shapecorr::maps::placement::Placement::ALL
            .into_iter()
            .find(|p| p.name() == self.placement)
            .ok_or_else(|| Error::InvalidParameter {
                name: "placement",
                reason: format!("expected auto, ignore or trust, got {}", self.placement),
            })?;
        let records = shapecorr_eval::bench_tails::run_tails(
            &data_root(&self.data),
            &self.work,
            self.datasets.as_deref(),
            self.samples,
            (self.full_resolution, placement),
        )?;
        let mut command = "shapecorr bench tails".to_string();
        if placement != shapecorr::maps::placement::Placement::Auto {
            command.push_str(&format!(" --placement {}", placement.name()));
        }
        if self.full_resolution {
            command.push_str(" --full-resolution");
        }
        if let Some(d) = &self.datasets {
            command.push_str(&format!(" --datasets {}", d.join(",")));
        }
        let page = shapecorr_eval::bench_tails::tails_page(&records, &command);
        std::fs::write(&self.out, &page).map_err(|e| Error::file(&self.out, e.to_string()))?;
        out!("{page}")?;
        Ok(())
    }
}

#[derive(clap::Args)]
pub struct BenchScaleArgs {
    /// Vertices per shape (comma separated).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "5000,12000,25000,50000,100000,250000,500000,1000000"
    )]
    sizes: Vec<usize>,
    /// The page to write (the PNG goes beside it, same name).
    #[arg(long, default_value = "docs/scale.md")]
    out: PathBuf,
    /// Generated pairs, outputs and the log.
    #[arg(long, default_value = "target/bench-scale")]
    work: PathBuf,
    /// Run the full-resolution path too up to this many vertices.
    #[arg(long, default_value_t = 100_000)]
    full_up_to: usize,
    /// A Python with pyFM (pyfmaps) installed, for the reference
    /// (tests/bench/scale_pyfm.sh makes one); none: no pyFM column.
    #[arg(long)]
    pyfm_python: Option<PathBuf>,
    /// pyFM runs at the next size only while it finished within this many seconds.
    #[arg(long, default_value_t = 600)]
    pyfm_limit_s: u64,
}

impl BenchScaleArgs {
    pub fn run(&self) -> Result<(), Error> {
        let exe = std::env::current_exe()
            .map_err(|e| Error::file(Path::new("shapecorr"), e.to_string()))?;
        let settings = shapecorr_eval::bench_scale::ScaleSettings {
            sizes: self.sizes.clone(),
            exe,
            work: self.work.clone(),
            full_up_to: self.full_up_to,
            pyfm_python: self.pyfm_python.clone(),
            pyfm_script: PathBuf::from("tests/bench/scale_pyfm.py"),
            pyfm_limit: std::time::Duration::from_secs(self.pyfm_limit_s),
        };
        let records = shapecorr_eval::bench_scale::run_scale(&settings)?;
        let sizes: Vec<String> = self.sizes.iter().map(|n| n.to_string()).collect();
        let command = format!(
            "shapecorr bench scale --sizes {} --full-up-to {}{}",
            sizes.join(","),
            self.full_up_to,
            if self.pyfm_python.is_some() {
                " --pyfm-python PY"
            } else {
                ""
            }
        );
        let png = self.out.with_extension("png");
        let page = shapecorr_eval::bench_scale::scale_page(&records, &command, &png)?;
        std::fs::write(&self.out, &page).map_err(|e| Error::file(&self.out, e.to_string()))?;
        out!("{page}")?;
        Ok(())
    }
}
