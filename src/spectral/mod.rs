//! The spectrum of a shape: the Laplacian ([`laplacian`]), its smallest eigenpairs
//! ([`eigen`]) and the descriptors built on them ([`descriptors`]: HKS, WKS).

pub mod descriptors;
pub mod eigen;
pub mod laplacian;
pub(crate) mod sparse;
