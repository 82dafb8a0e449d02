//! What assembles the stages into jobs (docs/design.md, "Code layout"): the method's
//! parameters ([`params`]), the pair job written once ([`pair`]) with the region job
//! ([`correspondence`]), the pointwise job ([`pointwise`]) and symmetry detection
//! ([`symmetry`]) over it, the budget of a job ([`budget`]) and the multiresolution path of
//! dense shapes ([`multiresolution`]). The stages (`shape`, `spectral`, `regions`, `maps`)
//! take plain inputs and never import this module (checked by `tests/layout/check.py`).

pub mod budget;
pub mod correspondence;
pub mod multiresolution;
pub mod pair;
pub mod params;
pub mod pointwise;
pub mod symmetry;

pub use correspondence::{correspond, one_to_one_matches, Correspondence, Timings};
pub use pair::{run_pair, PairJob, PairResult, PairShapes, ReadyShape};
pub use params::{HksFallback, Params, REGION_EIGENPAIRS};
pub use pointwise::PointwiseCorrespondence;
pub use symmetry::Symmetry;
