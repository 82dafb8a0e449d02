//! # shapecorr
//!
//! Region-level correspondences between 3D shapes (triangle meshes and point clouds), after
//! Kleiman and Ovsjanikov, "Robust Structure-based Shape Correspondence".
//!
//! The modules follow the data flow (the method: `docs/design.md`; why each default is what
//! it is: `docs/decisions.md`):
//!
//! | stage | module |
//! |---|---|
//! | shape in: files, validation, neighbours | [`shape`] ([`shape::io`], [`shape::neighbors`]) |
//! | Laplacian, eigenbasis, HKS/WKS | [`spectral`] ([`laplacian`](spectral::laplacian), [`eigen`](spectral::eigen), [`descriptors`](spectral::descriptors)) |
//! | joint segmentation, shape graphs, graph matching, one-to-one | [`regions`] ([`segmentation`](regions::segmentation), [`graph`](regions::graph), [`matching`](regions::matching), [`symmetry`](regions::symmetry)) |
//! | distances on the surface (edge graph, heat method) | [`geodesic`] |
//! | point-to-point maps | [`maps`] ([`fmap`](maps::fmap), [`pointwise`](maps::pointwise)) |
//! | the jobs that assemble the stages | [`pipeline`] ([`pipeline::run_pair`]: [`Correspondence`], [`PointwiseCorrespondence`], [`Symmetry`], the batch), with its [`budget`](pipeline::budget) and [`proxies`](pipeline::multiresolution) |
//! | scores against ground truth | [`evaluation`] |
//! | front ends | [`options`] (the one table of named options), [`ffi`] (the C API), [`colors`] |
//! | test figures with exact ground truth | [`synth`] |
//!
//! [`progress`] carries progress reports and cancellation, [`pipeline::budget`] the memory
//! ceiling and time limit of a job; [`Error`] is the one error type. The stages never
//! import [`pipeline`] (docs/design.md, "Code layout").
//! The benchmark harness is the workspace crate `shapecorr-eval` (`crates/eval`), the
//! command line `shapecorr-cli` (`crates/cli`).
//!
//! ```no_run
//! use shapecorr::{Correspondence, NoProgress, Params, ReadAs, Shape};
//!
//! # fn main() -> shapecorr::Result<()> {
//! let a = Shape::read("a.ply".as_ref(), ReadAs::Auto)?; // validated, input order kept
//! let b = Shape::read("b.off".as_ref(), ReadAs::Auto)?;
//! let result = Correspondence::compute(&a, &b, &Params::default(), &mut NoProgress)?;
//! println!("k = {}, matches {:?}", result.k, result.matches_one_to_one);
//! let region_of_vertex_7_of_a = result.regions_a()[7];
//! # let _ = region_of_vertex_7_of_a;
//! # Ok(())
//! # }
//! ```
//!
//! Every per-vertex output is indexed by the caller's input vertices. Direction lives in the
//! name: `p2p_ba[i]` is the vertex of shape A matched to vertex `i` of shape B; `fmap_ab`
//! maps functions on shape A to functions on shape B (the C API, Python and the command
//! line say the same in words: `map_b_to_a`).

// `!(x > 0.0)` is the NaN-rejecting comparison this numerical code means; clippy's rewrite
// with `partial_cmp` would hide that.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![warn(missing_docs)]

pub mod collection;
pub mod colors;
pub mod error;
pub mod evaluation;
pub mod ffi;
pub mod geodesic;
pub mod maps;
pub mod options;
pub mod pipeline;
pub mod progress;
pub mod regions;
pub mod shape;
pub mod spectral;
pub mod synth;
pub mod system;
pub mod transfer;

pub use error::{Error, Result};
pub use maps::pointwise::PointwiseParams;
pub use pipeline::{Correspondence, Params, PointwiseCorrespondence, Symmetry};
pub use progress::{NoProgress, Progress, Stage};
pub use shape::{ReadAs, Repairs, Shape, ShapeKind, Warning};
pub use spectral::eigen::{EigenParams, Eigenbasis, ShapeBasis};

/// The hidden last field of every params struct (faer's pattern): callers outside the crate
/// cannot name every field, so they write `Params { k_max: 8, ..Default::default() }` and a
/// new parameter never breaks them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NonExhaustive(pub(crate) ());
