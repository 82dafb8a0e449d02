//! Point-to-point maps from the region correspondence (paper, section 6.4): functional
//! maps and their refinement ([`fmap`]), the region hypotheses verified at the map level
//! ([`hypotheses`]), what the shapes' placement and the user's landmarks say about them
//! ([`placement`], [`landmarks`]), the pointwise map from regions ([`pointwise`]), parts of
//! shapes ([`partial`]) and the map onto a surface ([`surface`]).

pub mod fmap;
pub mod hypotheses;
pub mod landmarks;
pub mod partial;
pub mod placement;
pub mod pointwise;
pub mod surface;
