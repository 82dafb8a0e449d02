//! `shapecorr`: the command-line front end. Every command exits non-zero with a one-line
//! reason on bad input.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand};
use serde_json::json;
use shapecorr::colors::{coordinate_colors, region_colors};
use shapecorr::correspondence::{Correspondence, Params, Symmetry};
use shapecorr::evaluation::score_correspondence;
use shapecorr::maps::fmap::ZoomOutParams;
use shapecorr::maps::pointwise::{
    truncated, PointwiseCorrespondence, PointwiseMap, PointwiseParams, Refinement,
    RegionConstraints,
};
use shapecorr::progress::{Progress, Stage};
use shapecorr::regions::graph::ShapeGraph;
use shapecorr::spectral::laplacian::Laplacian;
use shapecorr::synth::{self, FigureKind, FigureSpec, Proportions};
use shapecorr::{EigenParams, Eigenbasis, Error, Shape, ShapeKind};
use shapecorr_eval::bench_pointwise::PairScores;

#[derive(Parser)]
#[command(
    name = "shapecorr",
    version,
    about = "Region correspondences between 3D shapes"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Counts, area, connected pieces and warnings of a shape file.
    Info {
        file: PathBuf,
        /// Treat the file as a point cloud even if it has faces.
        #[arg(long)]
        points: bool,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Laplacian eigenvalues of a shape (unit-area normalised), with time and peak memory.
    Eigen {
        file: PathBuf,
        /// Number of eigenpairs.
        #[arg(long, default_value_t = EigenParams::default().n_eigenpairs)]
        k: usize,
        #[arg(long)]
        points: bool,
        #[arg(long)]
        json: bool,
        /// Threads for dense products (0 = all); the result does not depend on it.
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Also write the stiffness `L.mtx`, the mass `M.mtx` (Matrix Market), the
        /// eigenvalues `eigenvalues.txt` and the eigenvectors `eigenvectors.f64` (raw
        /// little-endian, one vector after another) into this folder, to compare solvers.
        #[arg(long)]
        export: Option<PathBuf>,
    },
    /// Make an articulated test figure (ground truth: the vertex order is shared by every
    /// pose and proportion of a kind and resolution).
    Synth {
        /// humanoid, quadruped, or starN (N = 3..8 limbs)
        #[arg(long, default_value = "humanoid")]
        kind: String,
        /// Pose number (0 = rest pose).
        #[arg(long, default_value_t = 0)]
        pose: usize,
        /// Approximate number of vertices.
        #[arg(long, default_value_t = 5000)]
        vertices: usize,
        /// Limb length factor (1 = default body).
        #[arg(long, default_value_t = 1.0)]
        limb_length: f64,
        /// Limb thickness factor (1 = default body).
        #[arg(long, default_value_t = 1.0)]
        limb_thickness: f64,
        /// Sample this many points on the surface and write a point cloud instead.
        #[arg(long)]
        points: Option<usize>,
        /// Shift each sampled point by up to this fraction of the shape's width.
        #[arg(long, default_value_t = 0.0)]
        noise: f64,
        /// Seed of the point sampling.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Output PLY file.
        #[arg(long)]
        out: PathBuf,
    },
    /// Region correspondence between two shapes: writes DIR/result.json and
    /// DIR/a_regions.ply, DIR/b_regions.ply (matched regions share a colour, unmatched ones
    /// are dark grey).
    Match {
        a: PathBuf,
        b: PathBuf,
        #[arg(long)]
        out: PathBuf,
        /// Treat both files as point clouds even if they have faces.
        #[arg(long)]
        points: bool,
        #[command(flatten)]
        method: MethodArgs,
    },
    /// Symmetric regions of one shape (the shape matched to itself): DIR/result.json and a
    /// PLY coloured by symmetry group.
    Symmetry {
        a: PathBuf,
        #[arg(long)]
        out: PathBuf,
        #[arg(long)]
        points: bool,
        #[command(flatten)]
        method: MethodArgs,
    },
    /// Point-to-point map from B to A (regions, functional map, ZoomOut): writes
    /// DIR/map_b_to_a.txt (for every vertex of B, the 0-based index of its vertex on A),
    /// DIR/result.json (the regions as `match`, plus timings), DIR/a_colors.ply (A coloured
    /// by its normalised coordinates) and DIR/b_mapped.ply (B with A's colours carried over
    /// by the map).
    P2p {
        a: PathBuf,
        b: PathBuf,
        #[arg(long)]
        out: PathBuf,
        #[arg(long)]
        points: bool,
        #[command(flatten)]
        method: MethodArgs,
        #[command(flatten)]
        pointwise: PointwiseArgs,
    },
    /// Benchmarks on the research datasets.
    Bench {
        #[command(subcommand)]
        which: BenchCommand,
    },
    /// The main job: two generated humanoids in different poses, one of them a noisy point
    /// cloud, matched; coloured PLYs and the region accuracy against the known ground truth.
    Demo {
        /// Output folder.
        #[arg(long, default_value = "out/demo")]
        out: PathBuf,
        /// Vertices of the mesh (and points of the cloud).
        #[arg(long, default_value_t = 8000)]
        vertices: usize,
    },
}

// Parsed once per run: the size difference between variants does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum BenchCommand {
    /// Region accuracy over a pair list (like the paper's Table 1).
    Regions {
        /// Dataset root (default: $SHAPECORR_DATA or ../shared/data).
        #[arg(long)]
        data: Option<PathBuf>,
        /// Pair list DATA/pairs/NAME.txt of the dataset in DATA/NAME (its layout from the
        /// name or the folder's contents: see src/datasets.rs).
        #[arg(long)]
        pairs: PathBuf,
        /// Only the first N pairs.
        #[arg(long)]
        limit: Option<usize>,
        #[command(flatten)]
        method: MethodArgs,
    },
    /// Pointwise maps over a pair list (like the paper's Table 2 and FAUST curves): WKS, HKS,
    /// WKS + ICP, regions, regions + WKS, symmetric regions, regions + ICP, regions + ZoomOut.
    P2p {
        /// Dataset root (default: $SHAPECORR_DATA or ../shared/data).
        #[arg(long)]
        data: Option<PathBuf>,
        /// Pair list DATA/pairs/NAME.txt of the dataset in DATA/NAME (its layout from the
        /// name or the folder's contents: see src/datasets.rs).
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
        method: MethodArgs,
        #[command(flatten)]
        pointwise: PointwiseArgs,
    },
    /// The paper's whole evaluation on every dataset found under the data root (a dataset
    /// NAME = a folder NAME/ and a pair list pairs/NAME.txt): region accuracy with the Reeb
    /// baseline, point-to-point errors and curves, the point-cloud protocol, timing. Writes
    /// OUT/results.md and OUT/images/. Resumable: finished results are kept in WORK/logs and
    /// eigenbases in WORK/eigenbases.
    All {
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
    },
    /// Scores maps computed elsewhere, stored as MAPS/{source}__{target}.txt (for every
    /// vertex of the target, the 0-based index of its vertex on the source), with the same
    /// geodesic error as `bench p2p`.
    Maps {
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
    },
}

/// Parameters of the pointwise map; defaults come from `PointwiseParams::default()`.
#[derive(clap::Args, Clone, Default)]
struct PointwiseArgs {
    /// Size of the first functional map.
    #[arg(long)]
    fmap_size: Option<usize>,
    /// Final basis size of ZoomOut.
    #[arg(long)]
    zoomout_end: Option<usize>,
    /// Eigenfunctions added per ZoomOut iteration.
    #[arg(long)]
    zoomout_step: Option<usize>,
    /// Vertices per shape on which ZoomOut iterates (0 = all).
    #[arg(long)]
    zoomout_sample: Option<usize>,
    /// Weight of the Laplacian commutativity term.
    #[arg(long)]
    laplacian_weight: Option<f64>,
    /// Weight of the descriptor commutativity term (0 = off).
    #[arg(long)]
    descriptor_commutativity: Option<f64>,
    /// Weight of the orientation-preserving term (0 = off).
    #[arg(long)]
    orientation_term: Option<f64>,
    /// Diffusion times of the region indicators, comma separated.
    #[arg(long, value_delimiter = ',')]
    region_times: Option<Vec<f64>>,
    /// Refinement: zoomout, icp or none.
    #[arg(long)]
    refine: Option<String>,
    /// Region constraints: one-to-one, symmetric or none.
    #[arg(long)]
    regions: Option<String>,
    /// Add WKS descriptors.
    #[arg(long)]
    wks: bool,
    /// Leave out the region distance functions.
    #[arg(long)]
    no_region_distances: bool,
    /// Keep a mirror-image (orientation-reversing) answer as it is.
    #[arg(long)]
    no_orientation: bool,
}

impl PointwiseArgs {
    fn params(&self) -> Result<PointwiseParams, Error> {
        let mut p = PointwiseParams::default();
        if let Some(v) = self.fmap_size {
            p.fmap_size = v;
        }
        let mut zoom = match &p.refinement {
            Refinement::ZoomOut(z) => z.clone(),
            _ => ZoomOutParams::default(),
        };
        if let Some(v) = self.zoomout_end {
            zoom.k_end = v;
        }
        if let Some(v) = self.zoomout_step {
            zoom.step = v;
        }
        if let Some(v) = self.zoomout_sample {
            zoom.sample_size = v;
        }
        p.refinement = match self.refine.as_deref() {
            None | Some("zoomout") => Refinement::ZoomOut(zoom),
            Some("icp") => Refinement::Icp(shapecorr::options::ICP_ITERATIONS),
            Some("none") => Refinement::None,
            Some(other) => {
                return Err(Error::InvalidParameter {
                    name: "refine",
                    reason: format!("expected zoomout, icp or none, got {other:?}"),
                })
            }
        };
        p.regions = match self.regions.as_deref() {
            None | Some("one-to-one") => RegionConstraints::OneToOne,
            Some("symmetric") => RegionConstraints::Symmetric,
            Some("none") => RegionConstraints::None,
            Some(other) => {
                return Err(Error::InvalidParameter {
                    name: "regions",
                    reason: format!("expected one-to-one, symmetric or none, got {other:?}"),
                })
            }
        };
        if let Some(v) = self.laplacian_weight {
            p.laplacian_weight = v;
        }
        if let Some(v) = self.descriptor_commutativity {
            p.descriptor_commutativity = v;
        }
        if let Some(v) = self.orientation_term {
            p.orientation_term = v;
        }
        if let Some(v) = &self.region_times {
            p.region_times = v.clone();
        }
        if self.wks {
            p.wks = Some(Default::default());
        }
        if self.no_region_distances {
            p.region_distances = false;
        }
        if self.no_orientation {
            p.orientation = false;
        }
        p.validate()?;
        Ok(p)
    }
}

/// The main parameters of the method; defaults come from `Params::default()`.
#[derive(clap::Args, Clone, Default)]
struct MethodArgs {
    /// Smallest number of joint clusters tried.
    #[arg(long)]
    k_min: Option<usize>,
    /// Largest number of joint clusters tried.
    #[arg(long)]
    k_max: Option<usize>,
    /// Number of HKS times.
    #[arg(long)]
    hks_times: Option<usize>,
    /// Smallest HKS time (unit-area shape).
    #[arg(long)]
    hks_t_min: Option<f64>,
    /// Largest HKS time (unit-area shape).
    #[arg(long)]
    hks_t_max: Option<f64>,
    /// Gap ratio of the discretisation (a score below ratio x previous ends the matches).
    #[arg(long)]
    gap: Option<f64>,
    /// Largest symmetry order (matches per region).
    #[arg(long)]
    max_order: Option<usize>,
    /// Skip the one-to-one step.
    #[arg(long)]
    no_one_to_one: bool,
    /// Number of eigenpairs.
    #[arg(long)]
    eigenpairs: Option<usize>,
}

impl MethodArgs {
    fn params(&self) -> Params {
        let mut p = Params::default();
        if let Some(v) = self.k_min {
            p.segmentation.k_min = v;
        }
        if let Some(v) = self.k_max {
            p.segmentation.k_max = v;
        }
        if let Some(v) = self.hks_times {
            p.hks.n_times = v;
        }
        if let Some(v) = self.hks_t_min {
            p.hks.t_min = v;
        }
        if let Some(v) = self.hks_t_max {
            p.hks.t_max = v;
        }
        if let Some(v) = self.gap {
            p.matching.gap_ratio = v;
        }
        if let Some(v) = self.max_order {
            p.matching.max_symmetry_order = v;
        }
        if let Some(v) = self.eigenpairs {
            p.eigen.n_eigenpairs = v;
        }
        p.skip_one_to_one = self.no_one_to_one;
        p
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // The whole command runs on a worker of one rayon pool: parallel loops called from
    // inside it start without handing work over from a foreign thread, which with many
    // small loops (k-means, Lanczos) cost measurable time in thread wake-ups. Threads come
    // from RAYON_NUM_THREADS or the CPU count, as before; results do not depend on them.
    match rayon::ThreadPoolBuilder::new().build() {
        Ok(pool) => pool.install(|| run(cli)),
        Err(_) => run(cli),
    }
}

fn run(cli: Cli) -> ExitCode {
    let result = match cli.command {
        Command::Info { file, points, json } => info(&file, points, json),
        Command::Eigen {
            file,
            k,
            points,
            json,
            threads,
            export,
        } => eigen(&file, k, points, json, threads, export.as_deref()),
        Command::Synth {
            kind,
            pose,
            vertices,
            limb_length,
            limb_thickness,
            points,
            noise,
            seed,
            out,
        } => synth_command(
            &kind,
            pose,
            vertices,
            Proportions {
                limb_length,
                limb_thickness,
            },
            points,
            noise,
            seed,
            &out,
        ),
        Command::Match {
            a,
            b,
            out,
            points,
            method,
        } => match_command(&a, &b, &out, points, &method.params()),
        Command::Symmetry {
            a,
            out,
            points,
            method,
        } => symmetry_command(&a, &out, points, &method.params()),
        Command::P2p {
            a,
            b,
            out,
            points,
            method,
            pointwise,
        } => pointwise
            .params()
            .and_then(|p| p2p_command(&a, &b, &out, points, &method.params(), &p)),
        Command::Bench {
            which:
                BenchCommand::Regions {
                    data,
                    pairs,
                    limit,
                    method,
                },
        } => bench_regions_command(data, &pairs, limit, &method.params()),
        Command::Bench {
            which:
                BenchCommand::P2p {
                    data,
                    pairs,
                    limit,
                    samples,
                    curves,
                    json,
                    methods,
                    basis_cache,
                    method,
                    pointwise,
                },
        } => pointwise.params().and_then(|p| {
            bench_p2p_command(
                data,
                &pairs,
                limit,
                samples,
                methods.as_deref(),
                basis_cache,
                curves.as_deref(),
                json.as_deref(),
                &method.params(),
                &p,
            )
        }),
        Command::Bench {
            which:
                BenchCommand::Maps {
                    data,
                    pairs,
                    maps,
                    limit,
                    samples,
                    json,
                },
        } => bench_maps_command(data, &pairs, &maps, limit, samples, json.as_deref()),
        Command::Bench {
            which:
                BenchCommand::All {
                    data,
                    out,
                    work,
                    quick,
                    datasets,
                    limit,
                    samples,
                    cloud_pairs,
                    timing_pairs,
                    fresh,
                },
        } => {
            let work = work.unwrap_or_else(|| {
                PathBuf::from(if quick {
                    "target/bench-quick"
                } else {
                    "target/bench-all"
                })
            });
            let data = data.unwrap_or_else(|| {
                if quick {
                    work.join("data")
                } else {
                    shapecorr_eval::datasets::default_data_root()
                }
            });
            let out = out.unwrap_or_else(|| {
                if quick {
                    work.clone()
                } else {
                    PathBuf::from("docs")
                }
            });
            let mut p = shapecorr_eval::bench_all::AllParams::new(data, out, work, quick);
            p.datasets = datasets;
            p.limit = limit;
            p.p2p_samples = samples;
            p.cloud_pairs = cloud_pairs.unwrap_or(p.cloud_pairs);
            p.timing_pairs = timing_pairs.unwrap_or(p.timing_pairs);
            p.command = std::iter::once("shapecorr".to_string())
                .chain(std::env::args().skip(1))
                .collect::<Vec<_>>()
                .join(" ");
            bench_all_command(&p, fresh)
        }
        Command::Demo { out, vertices } => demo(&out, vertices),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("shapecorr: {e}");
            ExitCode::FAILURE
        }
    }
}

fn info(file: &Path, points: bool, as_json: bool) -> Result<(), Error> {
    let shape = Shape::read(file, points)?;
    let laplacian = Laplacian::new(&shape)?;
    let warnings: Vec<String> = shape.warnings().iter().map(|w| w.to_string()).collect();
    let kind = match shape.kind() {
        ShapeKind::Mesh => "mesh",
        ShapeKind::PointCloud => "point cloud",
    };
    if as_json {
        let value = json!({
            "file": file,
            "kind": shape.kind(),
            "n_vertices": shape.n_vertices(),
            "n_faces": shape.triangles().len(),
            "n_used_vertices": shape.active_vertices().len(),
            "area": laplacian.input_area,
            "width": shape.width(),
            "n_pieces": shape.n_pieces(),
            "warnings": warnings,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&value).unwrap_or_default()
        );
    } else {
        println!("file:        {}", file.display());
        println!("kind:        {kind}");
        println!("vertices:    {}", shape.n_vertices());
        println!("faces:       {}", shape.triangles().len());
        println!("area:        {:.6}", laplacian.input_area);
        println!("width:       {:.6}", shape.width());
        println!("pieces:      {}", shape.n_pieces());
        for w in warnings {
            println!("warning:     {w}");
        }
    }
    Ok(())
}

fn eigen(
    file: &Path,
    k: usize,
    points: bool,
    as_json: bool,
    threads: usize,
    export: Option<&Path>,
) -> Result<(), Error> {
    let t0 = Instant::now();
    let shape = Shape::read(file, points)?;
    let t_read = t0.elapsed().as_secs_f64();
    let params = EigenParams {
        n_eigenpairs: k,
        threads,
        ..Default::default()
    };
    let t1 = Instant::now();
    let laplacian = Laplacian::new(&shape)?;
    let t_laplacian = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let (values, vectors) =
        shapecorr::spectral::eigen::eigenpairs(&laplacian, &params, &mut shapecorr::NoProgress)?;
    let t_eigen = t2.elapsed().as_secs_f64();
    let peak = peak_memory_mib();
    if let Some(dir) = export {
        export_problem(dir, &laplacian, &values, &vectors)?;
    }
    if as_json {
        let value = json!({
            "file": file,
            "n_vertices": shape.n_vertices(),
            "k": values.len(),
            "eigenvalues": values,
            "input_area": laplacian.input_area,
            "timings_s": {"read": t_read, "laplacian": t_laplacian, "eigensolve": t_eigen},
            "peak_memory_mib": peak,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&value).unwrap_or_default()
        );
    } else {
        println!(
            "{}: {} vertices, {} eigenpairs (unit-area shape)",
            file.display(),
            shape.n_vertices(),
            values.len()
        );
        println!(
            "time: read {t_read:.3} s, laplacian {t_laplacian:.3} s, eigensolve {t_eigen:.3} s; peak memory {}",
            peak.map_or("unknown".to_string(), |p| format!("{p:.1} MiB"))
        );
        for (i, v) in values.iter().enumerate() {
            println!("{i:4} {v:.12e}");
        }
    }
    Ok(())
}

fn export_problem(
    dir: &Path,
    laplacian: &Laplacian,
    values: &[f64],
    vectors: &faer::Mat<f64>,
) -> Result<(), Error> {
    let io_error = |path: &Path, e: std::io::Error| Error::file(path, e.to_string());
    std::fs::create_dir_all(dir).map_err(|e| io_error(dir, e))?;
    let l_path = dir.join("L.mtx");
    sprs::io::write_matrix_market(&l_path, &laplacian.stiffness)
        .map_err(|e| io_error(&l_path, e))?;
    let n = laplacian.len();
    let mut mass = sprs::TriMat::new((n, n));
    for (i, &m) in laplacian.mass.iter().enumerate() {
        mass.add_triplet(i, i, m);
    }
    let m_path = dir.join("M.mtx");
    sprs::io::write_matrix_market(&m_path, &mass.to_csc::<usize>())
        .map_err(|e| io_error(&m_path, e))?;
    let v_path = dir.join("eigenvalues.txt");
    let text: String = values.iter().map(|v| format!("{v:.17e}\n")).collect();
    std::fs::write(&v_path, text).map_err(|e| io_error(&v_path, e))?;
    // Eigenvectors as raw little-endian f64, one eigenvector after another.
    let mut bytes = Vec::with_capacity(8 * vectors.nrows() * vectors.ncols());
    for j in 0..vectors.ncols() {
        for i in 0..vectors.nrows() {
            bytes.extend_from_slice(&vectors[(i, j)].to_le_bytes());
        }
    }
    let x_path = dir.join("eigenvectors.f64");
    std::fs::write(&x_path, bytes).map_err(|e| io_error(&x_path, e))?;
    Ok(())
}

/// Peak resident memory of this process (Linux `VmHWM`), in MiB.
fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

#[allow(clippy::too_many_arguments)]
fn synth_command(
    kind: &str,
    pose: usize,
    vertices: usize,
    proportions: Proportions,
    points: Option<usize>,
    noise: f64,
    seed: u64,
    out: &Path,
) -> Result<(), Error> {
    let kind = FigureKind::parse(kind).ok_or_else(|| Error::InvalidParameter {
        name: "kind",
        reason: format!("unknown figure kind `{kind}` (use humanoid, quadruped or star3..star8)"),
    })?;
    let mesh = synth::figure(&FigureSpec {
        kind,
        pose,
        target_vertices: vertices,
        proportions,
    })?;
    match points {
        None => {
            shapecorr::shape::io::write_ply(out, &mesh.vertices, &mesh.triangles, None)?;
            println!(
                "{}: {} vertices, {} triangles",
                out.display(),
                mesh.vertices.len(),
                mesh.triangles.len()
            );
        }
        Some(n) => {
            let cloud = synth::sample_points(&mesh, n, noise, seed)?;
            shapecorr::shape::io::write_ply(out, &cloud.points, &[], None)?;
            let gt_path = out.with_extension("gt.txt");
            let text: String = cloud
                .source_vertex
                .iter()
                .map(|v| format!("{v}\n"))
                .collect();
            std::fs::write(&gt_path, text).map_err(|e| Error::file(&gt_path, e.to_string()))?;
            println!(
                "{}: {} points (ground-truth mesh vertex of every point in {})",
                out.display(),
                cloud.points.len(),
                gt_path.display()
            );
        }
    }
    Ok(())
}

/// Prints stage progress on one line of the terminal (nothing when stderr is not one).
struct TerminalProgress;

impl Progress for TerminalProgress {
    fn report(&mut self, stage: Stage, fraction: f32) -> bool {
        use std::io::{IsTerminal, Write};
        let mut stderr = std::io::stderr();
        if stderr.is_terminal() {
            let _ = write!(
                stderr,
                "\r{:<16} {:>3.0}%",
                format!("{stage:?}"),
                100.0 * fraction
            );
            let _ = stderr.flush();
        }
        true
    }
}

/// Ends the progress line, if one was drawn.
fn end_progress_line() {
    use std::io::IsTerminal;
    if std::io::stderr().is_terminal() {
        eprintln!();
    }
}

fn write_json(path: &Path, value: &serde_json::Value) -> Result<(), Error> {
    let text = serde_json::to_string_pretty(value).unwrap_or_default();
    std::fs::write(path, text).map_err(|e| Error::file(path, e.to_string()))
}

fn graph_json(graph: &ShapeGraph) -> serde_json::Value {
    json!({
        "n_nodes": graph.n_nodes(),
        "node_area": graph.node_area,
        "node_cluster": graph.node_cluster,
        "node_descriptor": graph.node_descriptor,
        "edges": graph.edges,
    })
}

fn correspondence_json(a: &Shape, b: &Shape, result: &Correspondence) -> serde_json::Value {
    json!({
        "version": env!("CARGO_PKG_VERSION"),
        "n_vertices_a": a.n_vertices(),
        "n_vertices_b": b.n_vertices(),
        "kind_a": a.kind(),
        "kind_b": b.kind(),
        "k": result.k,
        "regions_a": result.regions_a(),
        "regions_b": result.regions_b(),
        "matches": result.matches,
        "matches_one_to_one": result.matches_one_to_one,
        "graph_a": graph_json(&result.graph_a),
        "graph_b": graph_json(&result.graph_b),
        "timings_s": result.timings,
        "warnings_a": a.warnings().iter().map(|w| w.to_string()).collect::<Vec<_>>(),
        "warnings_b": b.warnings().iter().map(|w| w.to_string()).collect::<Vec<_>>(),
    })
}

/// Writes the coloured PLYs of a correspondence; colours by the one-to-one matches when
/// there are any, else by the symmetric groups.
fn write_colored(out: &Path, a: &Shape, b: &Shape, result: &Correspondence) -> Result<(), Error> {
    let pairs = if result.matches_one_to_one.is_empty() {
        &result.matches
    } else {
        &result.matches_one_to_one
    };
    let (colors_a, colors_b) = region_colors(
        result.regions_a(),
        result.graph_a.n_nodes(),
        result.regions_b(),
        result.graph_b.n_nodes(),
        pairs,
    );
    shapecorr::shape::io::write_ply(
        &out.join("a_regions.ply"),
        a.vertices(),
        a.triangles(),
        Some(&colors_a),
    )?;
    shapecorr::shape::io::write_ply(
        &out.join("b_regions.ply"),
        b.vertices(),
        b.triangles(),
        Some(&colors_b),
    )
}

fn match_command(
    a: &Path,
    b: &Path,
    out: &Path,
    points: bool,
    params: &Params,
) -> Result<(), Error> {
    let shape_a = Shape::read(a, points)?;
    let shape_b = Shape::read(b, points)?;
    std::fs::create_dir_all(out).map_err(|e| Error::file(out, e.to_string()))?;
    let result = Correspondence::compute(&shape_a, &shape_b, params, &mut TerminalProgress);
    end_progress_line();
    let result = result?;
    write_json(
        &out.join("result.json"),
        &correspondence_json(&shape_a, &shape_b, &result),
    )?;
    write_colored(out, &shape_a, &shape_b, &result)?;
    println!(
        "k = {}: {} regions on A, {} on B; {} symmetric matches, {} one-to-one; {:.2} s -> {}",
        result.k,
        result.graph_a.n_nodes(),
        result.graph_b.n_nodes(),
        result.matches.len(),
        result.matches_one_to_one.len(),
        result.timings.total,
        out.display()
    );
    Ok(())
}

fn symmetry_command(a: &Path, out: &Path, points: bool, params: &Params) -> Result<(), Error> {
    let shape = Shape::read(a, points)?;
    std::fs::create_dir_all(out).map_err(|e| Error::file(out, e.to_string()))?;
    let symmetry = Symmetry::detect(&shape, params, &mut TerminalProgress);
    end_progress_line();
    let symmetry = symmetry?;
    let colors = symmetry.vertex_colors();
    shapecorr::shape::io::write_ply(
        &out.join("a_symmetry.ply"),
        shape.vertices(),
        shape.triangles(),
        Some(&colors),
    )?;
    write_json(
        &out.join("result.json"),
        &json!({
            "version": env!("CARGO_PKG_VERSION"),
            "n_vertices_a": shape.n_vertices(),
            "regions_a": symmetry.graph.labels,
            "groups": symmetry.groups,
            "matches": symmetry.matches,
            "graph_a": graph_json(&symmetry.graph),
        }),
    )?;
    let symmetric_groups = symmetry.groups.iter().filter(|g| g.len() > 1).count();
    println!(
        "{} regions, {} groups of symmetric regions -> {}",
        symmetry.graph.n_nodes(),
        symmetric_groups,
        out.display()
    );
    Ok(())
}

fn bench_regions_command(
    data: Option<PathBuf>,
    pairs: &Path,
    limit: Option<usize>,
    params: &Params,
) -> Result<(), Error> {
    let root = data.unwrap_or_else(shapecorr_eval::datasets::default_data_root);
    let started = Instant::now();
    let results = shapecorr_eval::bench::bench_regions(
        &root,
        pairs,
        params,
        limit,
        &mut |i, n, r| {
            eprintln!(
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
    println!(
        "shapecorr {} bench regions --pairs {} ({} pairs, {:.0} s wall)",
        env!("CARGO_PKG_VERSION"),
        pairs.display(),
        results.len(),
        started.elapsed().as_secs_f64()
    );
    print!("{}", shapecorr_eval::bench::summary_table(&results));
    Ok(())
}

fn p2p_command(
    a: &Path,
    b: &Path,
    out: &Path,
    points: bool,
    params: &Params,
    pointwise: &PointwiseParams,
) -> Result<(), Error> {
    let shape_a = Shape::read(a, points)?;
    let shape_b = Shape::read(b, points)?;
    std::fs::create_dir_all(out).map_err(|e| Error::file(out, e.to_string()))?;
    let result = PointwiseCorrespondence::compute(
        &shape_a,
        &shape_b,
        params,
        pointwise,
        &mut TerminalProgress,
    );
    end_progress_line();
    let result = result?;
    let map = &result.map.p2p_ba;
    write_map(&out.join("map_b_to_a.txt"), map)?;
    let mut value = correspondence_json(&shape_a, &shape_b, &result.regions);
    value["timings_s"] = json!({
        "eigenbasis_a": result.eigenbasis_a,
        "eigenbasis_b": result.eigenbasis_b,
        "regions": result.regions.timings,
        "pointwise": result.map.timings,
        "total": result.total,
    });
    value["fmap_size"] = json!(result.map.fmap_ab.nrows());
    write_json(&out.join("result.json"), &value)?;
    write_colored(out, &shape_a, &shape_b, &result.regions)?;
    write_map_colors(out, &shape_a, &shape_b, map)?;
    println!(
        "map of {} vertices of B onto A ({} one-to-one region matches, functional map {}x{}); {:.2} s -> {}",
        map.len(),
        result.regions.matches_one_to_one.len(),
        result.map.fmap_ab.nrows(),
        result.map.fmap_ab.ncols(),
        result.total,
        out.display()
    );
    Ok(())
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
    eprintln!(
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

#[allow(clippy::too_many_arguments)]
fn bench_p2p_command(
    data: Option<PathBuf>,
    pairs: &Path,
    limit: Option<usize>,
    samples: usize,
    only: Option<&[String]>,
    basis_cache: Option<PathBuf>,
    curves: Option<&Path>,
    json_path: Option<&Path>,
    params: &Params,
    pointwise: &PointwiseParams,
) -> Result<(), Error> {
    let root = data.unwrap_or_else(shapecorr_eval::datasets::default_data_root);
    let started = Instant::now();
    let results = shapecorr_eval::bench_pointwise::bench_pointwise(
        &root,
        pairs,
        params,
        pointwise,
        samples,
        only,
        limit,
        shapecorr_eval::bench_store::BasisCache { dir: basis_cache },
        &mut print_pair_scores,
    )?;
    println!(
        "shapecorr {} bench p2p --pairs {} ({} pairs, {} samples per pair, {:.0} s wall)",
        env!("CARGO_PKG_VERSION"),
        pairs.display(),
        results.len(),
        samples,
        started.elapsed().as_secs_f64()
    );
    print!(
        "{}",
        shapecorr_eval::bench_pointwise::pointwise_table(&results)
    );
    if let Some(path) = json_path {
        write_scores_json(path, &results)?;
    }
    if let Some(path) = curves {
        let name = pairs
            .file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into_owned());
        if !shapecorr_eval::bench_pointwise::write_curves(path, &name, &results)? {
            eprintln!(
                "shapecorr: no font found, {} has no text (set SHAPECORR_FONT)",
                path.with_extension("png").display()
            );
        }
    }
    Ok(())
}

fn bench_all_command(p: &shapecorr_eval::bench_all::AllParams, fresh: bool) -> Result<(), Error> {
    let logs = p.work.join("logs");
    if fresh && logs.exists() {
        std::fs::remove_dir_all(&logs).map_err(|e| Error::file(&logs, e.to_string()))?;
    }
    let started = Instant::now();
    let page = shapecorr_eval::bench_all::run_all(p)?;
    println!(
        "{} written ({:.0} s); logs and eigenbasis cache in {}",
        page.display(),
        started.elapsed().as_secs_f64(),
        p.work.display()
    );
    Ok(())
}

fn bench_maps_command(
    data: Option<PathBuf>,
    pairs: &Path,
    maps: &Path,
    limit: Option<usize>,
    samples: usize,
    json_path: Option<&Path>,
) -> Result<(), Error> {
    let root = data.unwrap_or_else(shapecorr_eval::datasets::default_data_root);
    let results = shapecorr_eval::bench_pointwise::bench_map_files(
        &root,
        pairs,
        maps,
        samples,
        limit,
        &mut print_pair_scores,
    )?;
    print!(
        "{}",
        shapecorr_eval::bench_pointwise::pointwise_table(&results)
    );
    if let Some(path) = json_path {
        write_scores_json(path, &results)?;
    }
    Ok(())
}

fn demo(out: &Path, vertices: usize) -> Result<(), Error> {
    std::fs::create_dir_all(out).map_err(|e| Error::file(out, e.to_string()))?;
    let spec = |pose| FigureSpec {
        kind: FigureKind::Humanoid,
        pose,
        target_vertices: vertices,
        proportions: Proportions::default(),
    };
    let t = Instant::now();
    let mesh_a = synth::figure(&spec(0))?;
    let mesh_b = synth::figure(&spec(3))?;
    let cloud_b = synth::sample_points(&mesh_b, vertices, 0.005, 1)?;
    println!(
        "A: humanoid, rest pose, mesh of {} vertices; B: humanoid, pose 3, point cloud of {} points with noise 0.5% of the width ({:.2} s)",
        mesh_a.vertices.len(),
        cloud_b.points.len(),
        t.elapsed().as_secs_f64()
    );
    let a = Shape::mesh(mesh_a.vertices.clone(), &mesh_a.triangles)?;
    let b = Shape::point_cloud(cloud_b.points.clone())?;
    let params = Params::default();
    let pointwise = PointwiseParams::default();
    // One eigenbasis per shape, large enough for the pointwise map; the regions use its
    // first `params.eigen.n_eigenpairs`.
    let eigen = EigenParams {
        n_eigenpairs: pointwise.n_eigenpairs,
        ..params.eigen.clone()
    };
    let full_a = Eigenbasis::compute(&a, &eigen)?;
    let full_b = Eigenbasis::compute(&b, &eigen)?;
    let basis_a = truncated(&full_a, params.eigen.n_eigenpairs);
    let basis_b = truncated(&full_b, params.eigen.n_eigenpairs);
    let result =
        Correspondence::from_bases(&a, &basis_a, &b, &basis_b, &params, &mut TerminalProgress);
    end_progress_line();
    let result = result?;
    eprintln!();
    write_json(
        &out.join("result.json"),
        &correspondence_json(&a, &b, &result),
    )?;
    write_colored(out, &a, &b, &result)?;
    // Ground truth: every point of B knows the vertex of the mesh it was sampled near, and
    // the two meshes share their vertex order.
    let truth: Vec<(u32, u32)> = cloud_b
        .source_vertex
        .iter()
        .enumerate()
        .map(|(p, &v)| (v, p as u32))
        .collect();
    // The rest pose is left/right symmetric: its mirror map gives the flip-tolerant score.
    let mirror = synth::mirror_map(&mesh_a);
    let flipped: Vec<(u32, u32)> = truth
        .iter()
        .map(|&(v, p)| (mirror[v as usize], p))
        .collect();
    let scores = score_correspondence(
        &result,
        &basis_a.mass,
        &basis_b.mass,
        &truth,
        Some(&flipped),
    );
    println!(
        "k = {}: {} regions on A, {} on B; {} symmetric matches, {} one-to-one ({:.2} s after the eigenbases)",
        result.k,
        result.graph_a.n_nodes(),
        result.graph_b.n_nodes(),
        result.matches.len(),
        result.matches_one_to_one.len(),
        result.timings.total
    );
    println!(
        "region accuracy against the ground truth: symmetric {:.3}, one-to-one {:.3}, one-to-one allowing a left/right flip {:.3} (coverage {:.3}, unmatched {:.3})",
        scores.symmetric,
        scores.one_to_one,
        scores.one_to_one_flip.unwrap_or(f64::NAN),
        scores.coverage,
        scores.unmatched
    );
    // Point-to-point map from the regions (functional map + ZoomOut), scored by the
    // geodesic error on A (heat method) at 1000 of the cloud's points.
    let map = PointwiseMap::from_bases(&a, &full_a, &b, &full_b, Some(&result), &pointwise)?;
    write_map(&out.join("map_b_to_a.txt"), &map.p2p_ba)?;
    write_map_colors(out, &a, &b, &map.p2p_ba)?;
    let heat = shapecorr::geodesic::HeatGeodesics::new(&a)?;
    let step = (truth.len() / 1000).max(1);
    let sample = |t: &[(u32, u32)]| t.iter().copied().step_by(step).collect::<Vec<_>>();
    let errors = |t: &[(u32, u32)]| {
        shapecorr::evaluation::pointwise_errors(
            &heat,
            full_a.input_area,
            &sample(t),
            &[&map.p2p_ba],
        )
        .map(|e| shapecorr::evaluation::ErrorSummary::of(&e[0]))
    };
    let (plain, mirrored) = (errors(&truth)?, errors(&flipped)?);
    let best = if mirrored.mean < plain.mean {
        mirrored
    } else {
        plain
    };
    println!(
        "point-to-point map ({:.2} s): mean geodesic error {:.4} of sqrt(area) ({}), {:.1}% of the points within 0.05",
        map.timings.fmap + map.timings.refinement,
        best.mean,
        if mirrored.mean < plain.mean { "a left/right mirror image" } else { "not mirrored" },
        100.0 * best.within_005
    );
    println!(
        "coloured shapes: {} and {}; the map: {} and {} (open them in MeshLab or Blender)",
        out.join("a_regions.ply").display(),
        out.join("b_regions.ply").display(),
        out.join("a_colors.ply").display(),
        out.join("b_mapped.ply").display()
    );
    Ok(())
}

/// Writes `a_colors.ply` (A coloured by its normalised coordinates) and `b_mapped.ply` (B
/// with A's colours carried over by the map), to look at a map.
fn write_map_colors(out: &Path, a: &Shape, b: &Shape, p2p_ba: &[u32]) -> Result<(), Error> {
    let colors_a = coordinate_colors(a.vertices());
    let colors_b: Vec<[u8; 3]> = p2p_ba.iter().map(|&v| colors_a[v as usize]).collect();
    shapecorr::shape::io::write_ply(
        &out.join("a_colors.ply"),
        a.vertices(),
        a.triangles(),
        Some(&colors_a),
    )?;
    shapecorr::shape::io::write_ply(
        &out.join("b_mapped.ply"),
        b.vertices(),
        b.triangles(),
        Some(&colors_b),
    )
}

/// Writes a map file: one 0-based vertex index per line.
fn write_map(path: &Path, map: &[u32]) -> Result<(), Error> {
    let mut text = String::with_capacity(map.len() * 6);
    for v in map {
        text.push_str(&v.to_string());
        text.push('\n');
    }
    std::fs::write(path, text).map_err(|e| Error::file(path, e.to_string()))
}
