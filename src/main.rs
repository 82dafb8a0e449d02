//! `shapecorr`: the command-line front end. Every command exits non-zero with a one-line
//! reason on bad input.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand};
use serde_json::json;
use shapecorr::synth::{self, FigureKind, FigureSpec, Proportions};
use shapecorr::{hks, EigenParams, Eigenbasis, Error, HksParams, Laplacian, Shape, ShapeKind};

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
    /// The main job for now: two generated figures in different poses, their eigenbases
    /// and heat kernel signatures, coloured PLYs, and how well the descriptors agree at
    /// corresponding vertices.
    Demo {
        /// Output folder.
        #[arg(long, default_value = "out/demo")]
        out: PathBuf,
        #[arg(long, default_value_t = 8000)]
        vertices: usize,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
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
        shapecorr::eigen::eigenpairs(&laplacian, &params, &mut shapecorr::NoProgress)?;
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
            shapecorr::io::write_ply(out, &mesh.vertices, &mesh.triangles, None)?;
            println!(
                "{}: {} vertices, {} triangles",
                out.display(),
                mesh.vertices.len(),
                mesh.triangles.len()
            );
        }
        Some(n) => {
            let cloud = synth::sample_points(&mesh, n, noise, seed)?;
            shapecorr::io::write_ply(out, &cloud.points, &[], None)?;
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

fn demo(out: &Path, vertices: usize) -> Result<(), Error> {
    std::fs::create_dir_all(out).map_err(|e| Error::file(out, e.to_string()))?;
    let params = EigenParams::default();
    let hks_params = HksParams::default();
    let mut signatures = Vec::new();
    for (name, pose) in [("a", 0usize), ("b", 3usize)] {
        let t0 = Instant::now();
        let mesh = synth::figure(&FigureSpec {
            kind: FigureKind::Humanoid,
            pose,
            target_vertices: vertices,
            proportions: Proportions::default(),
        })?;
        let t_synth = t0.elapsed().as_secs_f64();
        let shape = Shape::mesh(mesh.vertices.clone(), &mesh.triangles)?;
        let t1 = Instant::now();
        let basis = Eigenbasis::compute(&shape, &params)?;
        let t_eigen = t1.elapsed().as_secs_f64();
        let h = hks(&basis, &hks_params)?;
        let column: Vec<f64> = (0..h.nrows()).map(|v| h[(v, 0)]).collect();
        let path = out.join(format!("{name}_hks.ply"));
        shapecorr::io::write_ply(&path, &mesh.vertices, &mesh.triangles, Some(&ramp(&column)))?;
        println!(
            "shape {name}: humanoid pose {pose}, {} vertices; made in {t_synth:.2} s, {} eigenpairs in {t_eigen:.2} s; HKS coloured -> {}",
            shape.n_vertices(),
            basis.len(),
            path.display()
        );
        signatures.push(h);
    }
    // Ground truth is the identity: compare the descriptors at the same vertex.
    let (a, b) = (&signatures[0], &signatures[1]);
    for t in [0, a.ncols() / 2, a.ncols() - 1] {
        let x: Vec<f64> = (0..a.nrows()).map(|v| a[(v, t)]).collect();
        let y: Vec<f64> = (0..b.nrows()).map(|v| b[(v, t)]).collect();
        println!(
            "HKS at time {:.3}: correlation between poses at corresponding vertices {:.4}",
            hks_params.times()[t],
            correlation(&x, &y)
        );
    }
    Ok(())
}

fn correlation(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    sxy / (sxx * syy).sqrt()
}

/// A blue-to-yellow colour ramp over the range of `values`.
fn ramp(values: &[f64]) -> Vec<[u8; 3]> {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let span = (hi - lo).max(f64::MIN_POSITIVE);
    values
        .iter()
        .map(|v| {
            let t = ((v - lo) / span).clamp(0.0, 1.0);
            [
                (255.0 * t) as u8,
                (60.0 + 160.0 * t) as u8,
                (200.0 * (1.0 - t) + 40.0) as u8,
            ]
        })
        .collect()
}
