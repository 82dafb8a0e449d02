//! The one error type of the crate. Every variant maps to one stable status code of the
//! C API (added with the C API), so variants are only ever added, never renumbered.

use std::path::PathBuf;

/// Everything that can go wrong in shapecorr, with what was received and how to fix it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate {value} (NaN or infinity); remove or repair it")]
    NonFiniteCoordinate {
        /// Index of the offending input vertex (0-based).
        vertex: usize,
        /// The first non-finite coordinate of that vertex.
        value: f64,
    },
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {index}, but the shape has only {n_vertices} vertices (indices are 0-based)")]
    FaceIndexOutOfRange {
        /// Index of the offending face in the input face list (0-based).
        face: usize,
        /// The out-of-range vertex index the face refers to (0-based).
        index: u64,
        /// Number of vertices the shape has.
        n_vertices: usize,
    },
    /// A face with fewer than three corners.
    #[error("face {face} has {corners} corners; a face needs at least 3")]
    FaceTooSmall {
        /// Index of the offending face in the input face list (0-based).
        face: usize,
        /// Number of corners the face has (fewer than 3).
        corners: usize,
    },
    /// Not enough (referenced) vertices for the pipeline.
    #[error("the shape has {received} usable vertices; at least {required} are needed")]
    TooFewVertices {
        /// Usable vertices received: all input vertices, or those used by a face for a mesh.
        received: usize,
        /// Fewest usable vertices accepted ([`crate::shape::MIN_VERTICES`]).
        required: usize,
    },
    /// The surface has no area (all faces degenerate, or all points coincide).
    #[error("the shape has zero total area ({detail}); it cannot be normalised")]
    ZeroArea {
        /// Why the area is zero (no faces, all faces degenerate, or all points coincide).
        detail: String,
    },
    /// A parameter is out of its valid range.
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// Name of the parameter or argument, e.g. `segmentation.k_max` or `colors`.
        name: &'static str,
        /// What is wrong with the value.
        reason: String,
    },
    /// A file could not be read or parsed.
    #[error("{path}: {reason}")]
    File {
        /// The file (for in-memory parsing, the name the caller gave it).
        path: PathBuf,
        /// What went wrong reading, parsing or writing it.
        reason: String,
    },
    /// A numerical method failed (factorisation or eigensolver), with the detail.
    #[error("numerical failure in {stage}: {reason}")]
    Numerical {
        /// The pipeline stage that failed, e.g. `eigensolver` or `functional map`.
        stage: &'static str,
        /// The detail reported by the failing method.
        reason: String,
    },
    /// The caller asked to stop through the progress callback.
    #[error("cancelled by the caller")]
    Cancelled,
    /// An error about one shape of a pair: `side` says which (`'A'` or `'B'`). The C status
    /// is the inner error's.
    #[error("shape {side}: {source}")]
    InShape {
        /// `'A'` or `'B'`.
        side: char,
        /// What is wrong with that shape.
        source: Box<Error>,
    },
    /// An option name that does not exist (see [`crate::options::OPTIONS`]).
    #[error("unknown option `{name}`; the options are: {known}")]
    UnknownOption {
        /// The option name that was asked for.
        name: String,
        /// Comma-separated list of the option names that exist.
        known: String,
    },
    /// A job too big for a limit: refused before any work by its estimate, or stopped when
    /// it ran past the limit. Not a bad value: the job may run with a higher limit, on
    /// simpler shapes or on a larger machine (docs/design.md, "Errors and status codes").
    #[error("resource limit `{limit}`: {reason}")]
    ResourceLimit {
        /// The limit: the option that sets it (`memory_limit_mib`, `time_limit_s`,
        /// `max_vertices`), `available_memory` for the memory the system can give, or
        /// `address_space` for the process's address-space limit (`ulimit -v`).
        limit: &'static str,
        /// What the job needs (the estimate) or did, against the limit, and what to do.
        reason: String,
    },
}

/// The limits of a whole job rather than of one shape ([`Error::in_shape`]).
const JOB_LIMITS: [&str; 3] = ["memory_limit_mib", "time_limit_s", "address_space"];

/// Result with the crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// This error as one about shape `side` (`'A'` or `'B'`) of a pair. A cancel, a file
    /// error (it names the file), a parameter error and the limits of the whole job
    /// (`memory_limit_mib`, `time_limit_s`) are not about a shape and stay as they are.
    pub fn in_shape(self, side: char) -> Error {
        match self {
            Error::Cancelled | Error::File { .. } | Error::InShape { .. } => self,
            Error::InvalidParameter { .. } => self,
            Error::ResourceLimit { limit, .. } if JOB_LIMITS.contains(&limit) => self,
            _ => Error::InShape {
                side,
                source: Box::new(self),
            },
        }
    }

    /// The error itself, without the shape it is about ([`Error::InShape`]).
    pub fn innermost(&self) -> &Error {
        match self {
            Error::InShape { source, .. } => source.innermost(),
            _ => self,
        }
    }

    /// A file error naming the file and the problem.
    pub fn file(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        Error::File {
            path: path.into(),
            reason: reason.into(),
        }
    }
}
