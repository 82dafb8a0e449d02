//! The one error type of the crate. Every variant maps to one stable status code of the
//! C API (added with the C API), so variants are only ever added, never renumbered.

use std::path::PathBuf;

/// Everything that can go wrong in shapecorr, with what was received and how to fix it.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate {value} (NaN or infinity); remove or repair it")]
    NonFiniteCoordinate { vertex: usize, value: f64 },
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {index}, but the shape has only {n_vertices} vertices (indices are 0-based)")]
    FaceIndexOutOfRange {
        face: usize,
        index: u64,
        n_vertices: usize,
    },
    /// A face with fewer than three corners.
    #[error("face {face} has {corners} corners; a face needs at least 3")]
    FaceTooSmall { face: usize, corners: usize },
    /// Not enough (referenced) vertices for the pipeline.
    #[error("the shape has {received} usable vertices; at least {required} are needed")]
    TooFewVertices { received: usize, required: usize },
    /// The surface has no area (all faces degenerate, or all points coincide).
    #[error("the shape has zero total area ({detail}); it cannot be normalised")]
    ZeroArea { detail: String },
    /// A parameter is out of its valid range.
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter { name: &'static str, reason: String },
    /// A file could not be read or parsed.
    #[error("{path}: {reason}")]
    File { path: PathBuf, reason: String },
    /// A numerical method failed (factorisation or eigensolver), with the detail.
    #[error("numerical failure in {stage}: {reason}")]
    Numerical { stage: &'static str, reason: String },
    /// The caller asked to stop through the progress callback.
    #[error("cancelled by the caller")]
    Cancelled,
    /// An option name that does not exist (see [`crate::options::OPTIONS`]).
    #[error("unknown option `{name}`; the options are: {known}")]
    UnknownOption { name: String, known: String },
}

/// Result with the crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// A file error naming the file and the problem.
    pub fn file(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        Error::File {
            path: path.into(),
            reason: reason.into(),
        }
    }
}
