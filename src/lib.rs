//! # shapecorr
//!
//! Region-level correspondences between 3D shapes (triangle meshes and point clouds), after
//! Kleiman and Ovsjanikov, "Robust Structure-based Shape Correspondence".
//!
//! The modules follow the data flow: [`io`] (files) -> [`shape`] (validated shape) ->
//! [`laplacian`] -> [`eigen`] (eigenbasis) -> [`descriptors`] (HKS, WKS) ->
//! [`segmentation`] (joint clusters, [`graph`] shape graphs) -> [`matching`] (symmetric
//! region matches) -> [`symmetry`] (one-to-one, with [`geodesic`] region distances).
//! [`correspondence`] runs the whole job; [`evaluation`], [`datasets`] and [`bench`](mod@bench) score
//! it; [`synth`] makes articulated test figures with known ground truth; [`progress`]
//! carries progress reports and cancellation.
//!
//! ```no_run
//! use shapecorr::correspondence::{Correspondence, Params};
//! use shapecorr::{NoProgress, Shape};
//!
//! # fn main() -> shapecorr::Result<()> {
//! let a = Shape::read("a.ply".as_ref(), false)?; // validated, input order kept
//! let b = Shape::read("b.off".as_ref(), false)?;
//! let result = Correspondence::compute(&a, &b, &Params::default(), &mut NoProgress)?;
//! println!("k = {}, matches {:?}", result.k, result.matches_one_to_one);
//! let region_of_vertex_7_of_a = result.regions_a()[7];
//! # let _ = region_of_vertex_7_of_a;
//! # Ok(())
//! # }
//! ```
//!
//! Every per-vertex output is indexed by the caller's input vertices. Direction lives in the
//! name: `p2p_21[i]` is the vertex of shape 1 matched to vertex `i` of shape 2; `fmap_12`
//! maps functions on shape 1 to functions on shape 2.

// `!(x > 0.0)` is the NaN-rejecting comparison this numerical code means; clippy's rewrite
// with `partial_cmp` would hide that.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod correspondence;
pub mod descriptors;
pub mod eigen;
pub mod error;
pub mod evaluation;
pub mod ffi;
pub mod fmap;
pub mod geodesic;
pub mod graph;
pub mod io;
pub mod laplacian;
pub mod matching;
pub mod neighbors;
pub mod options;
pub mod pointwise;
pub mod progress;
pub mod segmentation;
pub mod shape;
mod sparse;
pub mod symmetry;
pub mod synth;

pub use descriptors::{hks, wks, HksParams, WksParams};
pub use eigen::{EigenParams, Eigenbasis};
pub use error::{Error, Result};
pub use laplacian::Laplacian;
pub use progress::{NoProgress, Progress, Stage};
pub use shape::{Shape, ShapeKind, Warning};
