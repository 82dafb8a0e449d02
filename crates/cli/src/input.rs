//! Reading the input shapes: the repairs (on unless `--no-repair`), errors naming the side
//! and the file, and the repairs made printed on stderr, one line each, naming the input.

use crate::output::errln;
use std::path::{Path, PathBuf};

use shapecorr::pipeline::budget::Budget;
use shapecorr::{Error, Progress, ReadAs, Repairs, Shape};

use crate::commands::naming_files;

/// Reads `path` as a shape (a point cloud when `points`), with the default repairs unless
/// `no_repair`.
pub fn read_shape(path: &Path, points: bool, no_repair: bool) -> Result<Shape, Error> {
    read_shape_watched(path, points, no_repair, &mut shapecorr::NoProgress)
}

/// [`read_shape`], reporting to `progress`, which may stop it ([`Shape::read_watched`]).
fn read_shape_watched(
    path: &Path,
    points: bool,
    no_repair: bool,
    progress: &mut dyn Progress,
) -> Result<Shape, Error> {
    let repairs = if no_repair {
        Repairs::none()
    } else {
        Repairs::default()
    };
    Shape::read_watched(path, ReadAs::point_cloud_when(points), &repairs, progress)
}

/// Reads shape `side` (`'A'` or `'B'`) of a pair as [`read_shape`]; an error names the side
/// and the file, and every repair made is printed on stderr as `shapecorr: repaired SIDE
/// (PATH): ...`.
pub fn read_input(side: char, path: &Path, points: bool, no_repair: bool) -> Result<Shape, Error> {
    read_input_watched(side, path, points, no_repair, &mut shapecorr::NoProgress)
}

/// [`read_input`], reporting to `progress`, which may stop it.
fn read_input_watched(
    side: char,
    path: &Path,
    points: bool,
    no_repair: bool,
    progress: &mut dyn Progress,
) -> Result<Shape, Error> {
    let shape = read_shape_watched(path, points, no_repair, progress).map_err(|e| match e {
        Error::File { path, reason } => Error::File {
            path,
            reason: format!("shape {side}: {reason}"),
        },
        e => naming_files(e.in_shape(side), path, path),
    })?;
    for warning in shape.warnings().iter().filter(|w| w.is_repair()) {
        errln!("shapecorr: repaired {side} ({}): {warning}", path.display());
    }
    Ok(shape)
}

/// The two shape files of a pair command (`match`, `p2p`, `transfer`) and how they are read.
#[derive(clap::Args)]
pub struct ShapePairArgs {
    /// Shape A (PLY, OFF or OBJ).
    pub a: PathBuf,
    /// Shape B.
    pub b: PathBuf,
    /// Treat both files as point clouds even if they have faces.
    #[arg(long)]
    pub points: bool,
    /// Use the shapes as given: no welding of coincident vertices, no leaving out of small
    /// loose pieces, far vertices or isolated points (each repair made is printed on stderr).
    #[arg(long)]
    pub no_repair: bool,
    /// Landmark pairs: a text file with a vertex of A, then the vertex of B that corresponds
    /// to it, on each line (0-based indices of the files' vertices, separated by spaces, tabs
    /// or one comma; `#` starts a comment). The answer is the one that carries them nearest
    /// their partners, and in a map (`p2p`, `transfer`) each landmark of B maps exactly to
    /// its partner; two pairs on one side of a body settle which side is which. See
    /// docs/placement.md.
    #[arg(long, value_name = "FILE")]
    pub landmarks: Option<PathBuf>,
}

impl ShapePairArgs {
    /// The landmark pairs of `--landmarks` (none without it), read as
    /// [`crate::landmarks::read_landmarks`]; the library checks them against the shapes.
    pub fn landmarks(&self) -> Result<Vec<shapecorr::maps::landmarks::Landmark>, Error> {
        self.landmarks
            .as_deref()
            .map_or(Ok(Vec::new()), crate::landmarks::read_landmarks)
    }

    /// The files the command reads: A, B and the landmarks file, which no output replaces.
    pub fn inputs(&self) -> Vec<&Path> {
        let mut inputs = vec![self.a.as_path(), &self.b];
        inputs.extend(self.landmarks.as_deref());
        inputs
    }

    /// Shapes A and B, read as [`read_input`].
    pub fn read(&self) -> Result<(Shape, Shape), Error> {
        Ok((
            read_input('A', &self.a, self.points, self.no_repair)?,
            read_input('B', &self.b, self.points, self.no_repair)?,
        ))
    }

    /// Shapes A and B, read as part of a job under `budget`: its time limit counts from now
    /// (`budget.started` is set), so reading is stopped when it runs past it, and the job's
    /// estimate, from the counts the files declare, is checked against the memory ceiling
    /// before anything is read (`job`).
    pub fn read_in_budget(
        &self,
        budget: &mut Budget,
        check: impl FnOnce([&Path; 2]) -> Result<(), Error>,
        progress: &mut dyn Progress,
    ) -> Result<(Shape, Shape), Error> {
        budget.started = Some(std::time::Instant::now());
        check([&self.a, &self.b]).map_err(|e| self.naming(e))?;
        budget.run(progress, |progress| {
            Ok((
                read_input_watched('A', &self.a, self.points, self.no_repair, progress)?,
                read_input_watched('B', &self.b, self.points, self.no_repair, progress)?,
            ))
        })
    }

    /// An error about shape A or B as one naming its file ([`naming_files`]), and one about
    /// the landmarks as one naming the landmarks file.
    pub fn naming(&self, e: Error) -> Error {
        match (e, &self.landmarks) {
            (
                e @ Error::InvalidParameter {
                    name: "landmarks", ..
                },
                Some(file),
            ) => Error::file(file, e.to_string()),
            (e, _) => naming_files(e, &self.a, &self.b),
        }
    }
}
