//! `shapecorr info`: counts, area, pieces and warnings of a shape file.

use crate::input::read_shape;
use crate::output::outln;
use std::path::PathBuf;

use serde_json::json;
use shapecorr::spectral::laplacian::Laplacian;
use shapecorr::{Error, ShapeKind};

#[derive(clap::Args)]
pub struct InfoArgs {
    file: PathBuf,
    /// Treat the file as a point cloud even if it has faces.
    #[arg(long)]
    points: bool,
    /// Use the shapes as given: no welding of coincident vertices, no leaving out of small
    /// loose pieces, far vertices or isolated points (each repair made is printed on stderr).
    #[arg(long)]
    no_repair: bool,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

impl InfoArgs {
    pub fn run(&self) -> Result<(), Error> {
        let file = &self.file;
        let shape = read_shape(file, self.points, self.no_repair)?;
        let laplacian = Laplacian::new(&shape)?;
        let warnings: Vec<String> = shape.warnings().iter().map(|w| w.to_string()).collect();
        let kind = match shape.kind() {
            ShapeKind::Mesh => "mesh",
            ShapeKind::PointCloud => "point cloud",
        };
        if self.json {
            let value = json!({
                "file": file.to_string_lossy(),
                "kind": shape.kind(),
                "n_vertices": shape.n_vertices(),
                "n_faces": shape.triangles().len(),
                "n_used_vertices": shape.active_vertices().len(),
                "area": laplacian.input_area,
                "width": shape.width(),
                "n_pieces": shape.n_pieces(),
                "warnings": warnings,
            });
            outln!(
                "{}",
                serde_json::to_string_pretty(&value).unwrap_or_default()
            )?;
        } else {
            outln!("file:        {}", file.display())?;
            outln!("kind:        {kind}")?;
            outln!("vertices:    {}", shape.n_vertices())?;
            outln!("faces:       {}", shape.triangles().len())?;
            outln!("area:        {:.6e}", laplacian.input_area)?;
            outln!("width:       {:.6e}", shape.width())?;
            outln!("pieces:      {}", shape.n_pieces())?;
            for w in warnings {
                outln!("warning:     {w}")?;
            }
        }
        Ok(())
    }
}
