//! `shapecorr eigen`: Laplacian eigenvalues of a shape, with time and peak memory.

use crate::input::read_shape;
use crate::output::outln;
use crate::output::peak_memory_mib;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde_json::json;
use shapecorr::spectral::laplacian::Laplacian;
use shapecorr::{EigenParams, Error};

#[derive(clap::Args)]
pub struct EigenArgs {
    file: PathBuf,
    /// Number of eigenpairs.
    #[arg(long, default_value_t = EigenParams::default().n_eigenpairs)]
    k: usize,
    #[arg(long)]
    points: bool,
    /// Use the shapes as given: no welding of coincident vertices, no leaving out of small
    /// loose pieces, far vertices or isolated points (each repair made is printed on stderr).
    #[arg(long)]
    no_repair: bool,
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
}

impl EigenArgs {
    pub fn run(&self) -> Result<(), Error> {
        let file = &self.file;
        let t0 = Instant::now();
        let shape = read_shape(file, self.points, self.no_repair)?;
        let t_read = t0.elapsed().as_secs_f64();
        let params = EigenParams {
            n_eigenpairs: self.k,
            threads: self.threads,
            ..Default::default()
        };
        let t1 = Instant::now();
        let laplacian = Laplacian::new(&shape)?;
        let t_laplacian = t1.elapsed().as_secs_f64();
        let t2 = Instant::now();
        let (values, vectors) = shapecorr::spectral::eigen::eigenpairs(
            &laplacian,
            &params,
            &mut shapecorr::NoProgress,
        )?;
        let t_eigen = t2.elapsed().as_secs_f64();
        let peak = peak_memory_mib();
        if let Some(dir) = &self.export {
            export_problem(dir, &laplacian, &values, &vectors)?;
        }
        if self.json {
            let value = json!({
                "file": file.to_string_lossy(),
                "n_vertices": shape.n_vertices(),
                "k": values.len(),
                "eigenvalues": values,
                "input_area": laplacian.input_area,
                "timings_s": {"read": t_read, "laplacian": t_laplacian, "eigensolve": t_eigen},
                "peak_memory_mib": peak,
            });
            outln!(
                "{}",
                serde_json::to_string_pretty(&value).unwrap_or_default()
            )?;
        } else {
            outln!(
                "{}: {} vertices, {} eigenpairs (unit-area shape)",
                file.display(),
                shape.n_vertices(),
                values.len()
            )?;
            outln!(
                "time: read {t_read:.3} s, laplacian {t_laplacian:.3} s, eigensolve {t_eigen:.3} s; peak memory {}",
                peak.map_or("unknown".to_string(), |p| format!("{p:.1} MiB"))
            )?;
            for (i, v) in values.iter().enumerate() {
                outln!("{i:4} {v:.12e}")?;
            }
        }
        Ok(())
    }
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
