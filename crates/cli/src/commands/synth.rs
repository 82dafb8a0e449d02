//! `shapecorr synth`: an articulated test figure, as a mesh or a sampled point cloud.

use crate::output::outln;
use std::path::PathBuf;

use shapecorr::synth::{self, FigureKind, FigureSpec, Proportions};
use shapecorr::Error;

#[derive(clap::Args)]
pub struct SynthArgs {
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
}

impl SynthArgs {
    pub fn run(&self) -> Result<(), Error> {
        let kind = FigureKind::parse(&self.kind).ok_or_else(|| Error::InvalidParameter {
            name: "kind",
            reason: format!(
                "unknown figure kind `{}` (use humanoid, quadruped or star3..star8)",
                self.kind
            ),
        })?;
        let mesh = synth::figure(&FigureSpec {
            kind,
            pose: self.pose,
            target_vertices: self.vertices,
            proportions: Proportions {
                limb_length: self.limb_length,
                limb_thickness: self.limb_thickness,
                ..Default::default()
            },
            ..Default::default()
        })?;
        let out = &self.out;
        match self.points {
            None => {
                shapecorr::shape::io::write_ply(out, &mesh.vertices, &mesh.triangles, None)?;
                outln!(
                    "{}: {} vertices, {} triangles",
                    out.display(),
                    mesh.vertices.len(),
                    mesh.triangles.len()
                )?;
            }
            Some(n) => {
                let cloud = synth::sample_points(&mesh, n, self.noise, self.seed)?;
                shapecorr::shape::io::write_ply(out, &cloud.points, &[], None)?;
                let gt_path = out.with_extension("gt.txt");
                let text: String = cloud
                    .source_vertex
                    .iter()
                    .map(|v| format!("{v}\n"))
                    .collect();
                std::fs::write(&gt_path, text).map_err(|e| Error::file(&gt_path, e.to_string()))?;
                outln!(
                    "{}: {} points (ground-truth mesh vertex of every point in {})",
                    out.display(),
                    cloud.points.len(),
                    gt_path.display()
                )?;
            }
        }
        Ok(())
    }
}
