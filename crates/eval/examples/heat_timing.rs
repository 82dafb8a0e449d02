//! Times the heat-method geodesics: setup (two sparse factorisations) and one distance
//! solve per source, on the shapes given (default: FAUST tr_reg_000 and TOSCA david0 from
//! ../shared/data, skipped when absent).
//!
//!     cargo run --release -p shapecorr-eval --example heat_timing [FILE ...]

use std::path::PathBuf;
use std::time::Instant;

use shapecorr::geodesic::HeatGeodesics;
use shapecorr::ReadAs;
use shapecorr::Shape;

fn main() -> shapecorr::Result<()> {
    let mut files: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if files.is_empty() {
        let data = shapecorr_eval::datasets::default_data_root();
        files = ["faust/tr_reg_000.ply", "tosca/david0.ply"]
            .iter()
            .map(|f| data.join(f))
            .filter(|p| p.exists())
            .collect();
    }
    const SOURCES: usize = 10;
    for file in files {
        let shape = Shape::read(&file, ReadAs::Auto)?;
        let t = Instant::now();
        let solver = HeatGeodesics::new(&shape)?;
        let setup = t.elapsed().as_secs_f64();
        let step = (shape.n_vertices() / SOURCES).max(1);
        let t = Instant::now();
        for i in 0..SOURCES {
            solver.distances(&[((i * step) % shape.n_vertices()) as u32])?;
        }
        let per_source = t.elapsed().as_secs_f64() / SOURCES as f64;
        println!(
            "{}: {} vertices, setup {setup:.3} s, {:.4} s per source",
            file.display(),
            shape.n_vertices(),
            per_source
        );
    }
    Ok(())
}
