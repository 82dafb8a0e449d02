//! The region correspondence (paper, sections 4-5): joint segmentation of the two shapes
//! into shape graphs ([`segmentation`], [`graph`]), spectral matching of the graphs
//! ([`matching`]) and the one-to-one answer that breaks their symmetries ([`symmetry`]).

pub mod graph;
pub mod matching;
pub mod segmentation;
pub mod symmetry;
