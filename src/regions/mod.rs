//! The region correspondence (paper, sections 4-5): joint segmentation of the two shapes
//! into shape graphs ([`segmentation`], [`graph`]), spectral matching of the graphs
//! ([`matching`]) and the one-to-one answer that breaks their symmetries ([`symmetry`]).

pub mod graph;
pub mod matching;
pub mod segmentation;
pub mod symmetry;

/// A region correspondence as the map stages read it (docs/design.md, steps 11-13): the
/// region of every vertex and the number of regions of each shape, the symmetric matches and
/// the one-to-one answer. The pipeline's [`crate::Correspondence::matches_view`] gives one.
#[derive(Debug, Clone, Copy)]
pub struct RegionMatches<'a> {
    /// The region of every vertex of A.
    pub labels_a: &'a [u32],
    /// Regions of A.
    pub n_regions_a: usize,
    /// The region of every vertex of B.
    pub labels_b: &'a [u32],
    /// Regions of B.
    pub n_regions_b: usize,
    /// Symmetric (many-to-many) matches `(region of A, region of B)`.
    pub matches: &'a [(u32, u32)],
    /// One-to-one matches, a subset of `matches`.
    pub one_to_one: &'a [(u32, u32)],
    /// Whether the one-to-one answer was verified at the map level already (then it is the
    /// only hypothesis a map is built from).
    pub verified: bool,
}
