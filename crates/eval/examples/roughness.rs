//! The noise test on every shape at hand (docs/scans.md, "Noisy meshes"): the median angle
//! between adjacent faces' normals ([`smoothing::roughness`]) of each mesh's working shape
//! (its simplified proxy when it is dense, as the pipeline runs it), for every file under the
//! folders given and for generated figures (humanoid and quadruped at 1K, 5K and 20K vertices
//! and decimated to 150 and 300), clean and with Gaussian vertex noise of 0.1%-1% of the
//! bounding-box diagonal. Prints one line per shape and, per group, the smallest and largest
//! roughness and how many would be smoothed ([`smoothing::NOISY_ROUGHNESS`]).
//!
//!     cargo run --release -p shapecorr-eval --example roughness -- [DIR ..]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use shapecorr::pipeline::multiresolution::{DEFAULT_PROXY_ABOVE, DEFAULT_PROXY_VERTICES};
use shapecorr::shape::proxy::Proxy;
use shapecorr::shape::smoothing::{roughness, NOISY_ROUGHNESS};
use shapecorr::synth::{self, FigureKind, FigureSpec};
use shapecorr::{ReadAs, Shape, ShapeKind};

fn main() -> shapecorr::Result<()> {
    let mut groups: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for dir in std::env::args().skip(1).map(PathBuf::from) {
        let mut files = Vec::new();
        walk(&dir, &mut files);
        files.sort();
        for file in files {
            let Ok(shape) = Shape::read(&file, ReadAs::Auto) else {
                continue;
            };
            if shape.kind() != ShapeKind::Mesh {
                continue;
            }
            let group = file
                .parent()
                .map_or(String::new(), |p| p.display().to_string());
            if let Some(r) = working_roughness(&shape)? {
                println!("{} {} {r:.3}", file.display(), shape.n_vertices());
                groups.entry(group).or_default().push(r);
            }
        }
    }
    for kind in [FigureKind::Humanoid, FigureKind::Quadruped] {
        for pose in [0, 2] {
            for size in [150, 300, 1_000, 5_000, 20_000] {
                let figure = synth::figure(&FigureSpec {
                    kind,
                    pose,
                    target_vertices: size.max(1_000),
                    ..Default::default()
                })?;
                let figure = if size < 1_000 {
                    synth::decimate(&figure, size)?.0
                } else {
                    figure
                };
                for level in [0.0, 0.001, 0.0025, 0.005, 0.01] {
                    let moved =
                        synth::with_noise(&figure.vertices, level, (size * 31 + pose) as u64);
                    let shape = Shape::mesh(moved, &figure.triangles)?;
                    if let Some(r) = working_roughness(&shape)? {
                        let group = format!("synth {kind:?} {size} noise {:.2}%", level * 100.0);
                        println!("{group} pose {pose}: {r:.3}");
                        groups.entry(group).or_default().push(r);
                    }
                }
            }
        }
    }
    println!("\ngroup: shapes, smallest, largest roughness, smoothed (> {NOISY_ROUGHNESS})");
    for (group, values) in groups {
        let low = values.iter().copied().fold(f64::MAX, f64::min);
        let high = values.iter().copied().fold(f64::MIN, f64::max);
        let smoothed = values.iter().filter(|&&r| r > NOISY_ROUGHNESS).count();
        println!(
            "{group}: {} shapes, {low:.3} - {high:.3}, {smoothed} smoothed",
            values.len()
        );
    }
    Ok(())
}

/// The roughness of the shape the pipeline runs on (a dense shape's proxy).
fn working_roughness(shape: &Shape) -> shapecorr::Result<Option<f64>> {
    if shape.active_vertices().len() > DEFAULT_PROXY_ABOVE {
        let proxy = Proxy::build(shape, DEFAULT_PROXY_VERTICES)?;
        Ok(roughness(&proxy.shape))
    } else {
        Ok(roughness(shape))
    }
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            walk(&path, out);
        } else if matches!(
            path.extension().and_then(|e| e.to_str()),
            Some("off" | "ply" | "obj" | "stl")
        ) {
            out.push(path);
        }
    }
}
