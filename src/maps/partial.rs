//! Partial shapes (docs/partial.md): whether B is a part of A (or A of B), whose map is then
//! refined on the slanted diagonal of a partial functional map (Rodolà et al., "Partial
//! Functional Correspondence", CGF 2017; [`crate::maps::fmap::zoomout_sloped`]), and which
//! of A's vertices a map from B covers.

use faer::{Mat, MatRef};

use crate::geodesic::edge_graph_distances;
use crate::maps::fmap::{
    embedding_through, nearest_rows, p2p_to_fmap, sloped_sizes, zoomout_sloped, Sample,
    ZoomOutParams,
};
use crate::maps::hypotheses::{orientation_scores, DistortionProbe, MapEnergy};
use crate::progress::Cancel;
use crate::shape::neighbors::PointTree;
use crate::shape::{distance, Shape, ShapeKind};
use crate::spectral::eigen::ShapeBasis;
use crate::Result;

/// Whether one shape of the pair is a part of the other: measured, or given by the user
/// (the `partial` option).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum PartialOption {
    /// B is taken as a part of A when the measurement says so ([`detect`]).
    #[default]
    Auto,
    /// Both shapes are taken as whole.
    Off,
    /// B is a part of A (a scan of one side, a body with its feet cut off).
    BInA,
    /// A is a part of B.
    AInB,
}

/// The names of [`PartialOption`]'s values, by value (0 to 3).
pub const PARTIAL_NAMES: [&str; 4] = ["auto", "off", "b_in_a", "a_in_b"];

impl PartialOption {
    /// Every value, in the order of [`PARTIAL_NAMES`].
    pub const ALL: [PartialOption; 4] = [
        PartialOption::Auto,
        PartialOption::Off,
        PartialOption::BInA,
        PartialOption::AInB,
    ];
}

/// What the pair was taken to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Partiality {
    /// Two whole shapes.
    #[default]
    Whole,
    /// B is a part of A.
    BInA,
    /// A is a part of B.
    AInB,
}

impl Partiality {
    /// `"whole"`, `"b_in_a"` or `"a_in_b"`.
    pub fn name(self) -> &'static str {
        match self {
            Partiality::Whole => "whole",
            Partiality::BInA => "b_in_a",
            Partiality::AInB => "a_in_b",
        }
    }
}

/// How much more open boundary (length over the square root of the area) B must have than
/// A to be taken as a part of it. On the generated figures (docs/partial.md, "How
/// partiality is detected") a plane cut across the legs adds 0.63-1.87, six small holes
/// 1.7-2.2, cutting off the outer 30% of a limb 0.24 (that part is matched as well as a
/// whole).
pub const PART_EXTRA_BOUNDARY: f64 = 0.5;

/// The areas B may keep of A to be taken as a part of it (B's area over A's, the two in the
/// same units). Above the upper bound the slanted map loses more than it gains: on the
/// generated figures with six holes (81-97% of the area kept) it raised the mean error
/// from 0.041 to 0.048 and the failed pairs from 1 to 3, where it lowered the error of
/// the lower cuts (65-82% kept) from 0.186 to 0.154 (docs/partial.md). Below the lower
/// bound the two are more likely in other units than one a part of the other.
pub const PART_AREA_SHARE: (f64, f64) = (0.2, 0.8);

/// A vertex of A is covered when it lies within this many spacings of B's image (the
/// spacing of B's vertices spread over A's area, or A's mean edge when that is longer).
pub const COVERED_SPACINGS: f64 = 2.0;

/// What the pair's partiality check measured and decided.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PartialReport {
    /// What the pair was taken to be.
    pub partiality: Partiality,
    /// The `partial` option decided (not the measurement).
    pub given: bool,
    /// Open boundary length over the square root of the area, of A and of B (0 for a point
    /// cloud).
    pub boundary: [f64; 2],
    /// B's area over A's.
    pub area_share: f64,
}

/// For every vertex of `a`, whether it lies within [`COVERED_SPACINGS`] of B's image under
/// `p2p_ba` (edge-graph distance on `a`; `area_a` is `a`'s area, `n_b` B's vertex count).
pub fn covered(a: &Shape, area_a: f64, p2p_ba: &[u32], n_b: usize) -> Vec<bool> {
    let scale = 1.0 / area_a.max(f64::MIN_POSITIVE).sqrt();
    let mut images = p2p_ba.to_vec();
    images.sort_unstable();
    images.dedup();
    let spacing = (1.0 / n_b.max(1) as f64)
        .sqrt()
        .max(a.mean_edge_length() * scale);
    let radius = COVERED_SPACINGS * spacing;
    edge_graph_distances(a, &images, scale)
        .into_iter()
        .map(|d| d <= radius)
        .collect()
}

/// Which vertices of each shape have a counterpart on the other under one map.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Coverage {
    /// For every vertex of A, whether B's image covers it ([`covered`]).
    pub a: Vec<bool>,
    /// For every vertex of B, whether it has a counterpart on A: when A was taken as a part
    /// of B, whether A's image in B covers it; else every vertex does.
    pub b: Vec<bool>,
    /// The share of A's area that is covered ([`covered_share`]).
    pub share_a: f64,
}

/// The coverage of the map `p2p_ba`: A's side by [`covered`]. B's, when A is a part of B,
/// by [`covered`] of A's image in B, `p2p_ab` ([`part_into_whole`]); else every vertex of B
/// is covered.
pub fn coverage(
    a: ShapeBasis<'_>,
    b: ShapeBasis<'_>,
    p2p_ba: &[u32],
    p2p_ab: Option<&[u32]>,
) -> Coverage {
    let n_active = |s: &Shape| s.active_vertices().len();
    let covered_a = covered(a.shape, a.basis.input_area, p2p_ba, n_active(b.shape));
    let covered_b = match p2p_ab {
        Some(p2p_ab) => covered(b.shape, b.basis.input_area, p2p_ab, n_active(a.shape)),
        None => vec![true; b.shape.n_vertices()],
    };
    Coverage {
        share_a: covered_share(&a.basis.mass, &covered_a),
        a: covered_a,
        b: covered_b,
    }
}

/// For A a part of B, the map of the part into the whole, made the way round the slanted
/// diagonal suits best (the whole as the first shape, as for B a part of A, where the
/// generated lower cuts' error is 0.004 against 0.04 this way round): A's vertices sent to
/// B's nearest rows through `fmap_ab` (`k_b x k_a`), then grown by [`part_map`] with the
/// slope `k_a / k_b`. Returns `p2p_ab` (a vertex of B for every vertex of A) and the map of
/// B's vertices it gives: each goes to the vertex of A whose image lies nearest in space.
pub fn part_into_whole(
    (a, b): (ShapeBasis<'_>, ShapeBasis<'_>),
    fmap_ab: MatRef<'_, f64>,
    slope: f64,
    zoomout: &ZoomOutParams,
    cancel: &Cancel,
) -> Result<(Vec<u32>, Vec<u32>)> {
    let embedding_a = embedding_through(fmap_ab, a.basis.vectors.as_ref());
    let phi_b = b.basis.vectors.as_ref().subcols(0, fmap_ab.nrows());
    let first = nearest_rows(phi_b, embedding_a.as_ref(), cancel)?;
    let (_, p2p_ab) = part_map((b, a), &first, 1.0 / slope, zoomout, cancel)?;
    let active_a = a.shape.active_vertices();
    let pb = b.shape.vertices();
    let images: Vec<[f64; 3]> = (active_a.iter())
        .map(|&u| pb[p2p_ab[u as usize] as usize])
        .collect();
    let tree = PointTree::new(&images);
    let p2p_ba = (0..b.shape.n_vertices())
        .map(|v| active_a[tree.nearest(&pb[v])])
        .collect();
    Ok((p2p_ab, p2p_ba))
}

/// The share of the mass on covered vertices.
pub fn covered_share(mass: &[f64], covered: &[bool]) -> f64 {
    let total: f64 = mass.iter().sum();
    let on: f64 = mass
        .iter()
        .zip(covered)
        .filter(|(_, &c)| c)
        .map(|(m, _)| m)
        .sum();
    if total > 0.0 {
        on / total
    } else {
        1.0
    }
}

/// The length of a mesh's open boundary (edges of one triangle) over the square root of its
/// area; 0 for a point cloud or a closed mesh.
pub fn open_boundary(shape: &Shape) -> f64 {
    let p = shape.vertices();
    let length: f64 = (open_edges(shape).iter())
        .map(|&(i, j)| distance(&p[i as usize], &p[j as usize]))
        .sum();
    length / shape.mesh_area().max(f64::MIN_POSITIVE).sqrt()
}

/// A mesh's edges that belong to one triangle only (none for a point cloud).
fn open_edges(shape: &Shape) -> Vec<(u32, u32)> {
    if shape.kind() != ShapeKind::Mesh {
        return Vec::new();
    }
    let mut edges: Vec<(u32, u32)> = shape
        .triangles()
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(i, j)| (i.min(j), i.max(j)))
        .collect();
    edges.sort_unstable();
    (0..edges.len())
        .filter(|&i| (i == 0 || edges[i - 1] != edges[i]) && edges.get(i + 1) != Some(&edges[i]))
        .map(|i| edges[i])
        .collect()
}

/// What the pair is taken to be: the option when it is not `Auto`; else B is a part of A
/// when it has [`PART_EXTRA_BOUNDARY`] more open boundary than A (a cut or a hole leaves a
/// boundary) and keeps a share of A's area within [`PART_AREA_SHARE`]. How much of A the
/// first map covers does not tell: a map of a part smears it over 87-98% of the whole
/// (docs/partial.md). A part of B as A, and a point cloud as the part, are only taken when
/// asked for.
pub fn detect(option: PartialOption, boundary: [f64; 2], area_share: f64) -> PartialReport {
    let (low, high) = PART_AREA_SHARE;
    let looks_like_part =
        boundary[1] > boundary[0] + PART_EXTRA_BOUNDARY && (low..=high).contains(&area_share);
    let (partiality, given) = match option {
        PartialOption::Off => (Partiality::Whole, true),
        PartialOption::BInA => (Partiality::BInA, true),
        PartialOption::AInB => (Partiality::AInB, true),
        PartialOption::Auto if looks_like_part => (Partiality::BInA, false),
        PartialOption::Auto => (Partiality::Whole, false),
    };
    PartialReport {
        partiality,
        given,
        boundary,
        area_share,
    }
}

/// The map of a part refined on the slanted diagonal: from `p2p_ba`, the functional map of
/// the first eigenfunctions with B's basis `slope` times A's ([`zoomout_sloped`]), grown by
/// ZoomOut to `zoomout.k_end` on the larger side, once from each of [`PART_MAP_STARTS`]
/// eigenfunctions; the map with the least geodesic distortion on B's samples, over the square
/// of the share of B's triangles that keep their orientation, is kept.
/// `slope` is B's area over the area of A it covers (below 1 when B is a part of A).
/// Returns the functional map and the map on every vertex of B.
pub fn part_map(
    (a, b): (ShapeBasis<'_>, ShapeBasis<'_>),
    p2p_ba: &[u32],
    slope: f64,
    zoomout: &ZoomOutParams,
    cancel: &Cancel,
) -> Result<(Mat<f64>, Vec<u32>)> {
    let (basis_a, basis_b) = (a.basis, b.basis);
    let k_end = zoomout.k_end.min(basis_a.len()).min(basis_b.len());
    let (phi_a, phi_b) = (basis_a.vectors.as_ref(), basis_b.vectors.as_ref());
    let params = ZoomOutParams {
        k_end,
        ..zoomout.clone()
    };
    // Each start's map is the top-left block of the largest start's.
    let largest = sloped_sizes(
        PART_MAP_STARTS.iter().max().map_or(1, |&s| s.min(k_end)),
        slope,
    );
    let exact = p2p_to_fmap(p2p_ba, phi_a, phi_b, &basis_b.mass, largest.1, largest.0);
    let grow = |start: usize| {
        let (k_b, k_a) = sloped_sizes(start.min(k_end), slope);
        zoomout_sloped(
            exact.as_ref().submatrix(0, 0, k_b, k_a),
            (
                (phi_a, basis_a.mass.as_slice()),
                (phi_b, basis_b.mass.as_slice()),
            ),
            &params,
            slope,
            cancel,
        )
    };
    let mut grown = PART_MAP_STARTS
        .iter()
        .map(|&start| grow(start))
        .collect::<Result<Vec<_>>>()?;
    cancel.check()?;
    let samples_b = Sample::random(&basis_b.mass, PROBE_SAMPLES, PROBE_SEED).vertices;
    let probe = DistortionProbe::new(
        a.shape,
        1.0 / basis_a.input_area.sqrt(),
        b.shape,
        1.0 / basis_b.input_area.sqrt(),
        &samples_b,
    );
    // The hypotheses' cost with the coverage left at 1: a part does not reach all of A.
    let maps: Vec<&[u32]> = grown.iter().map(|(_, p2p)| p2p.as_slice()).collect();
    let kept = orientation_scores(a.shape, b.shape, &maps);
    let costs: Vec<f64> = (maps.iter().zip(kept))
        .map(|(p2p, orientation)| {
            let on_samples: Vec<u32> = samples_b.iter().map(|&v| p2p[v as usize]).collect();
            MapEnergy {
                distortion: probe.distortion(&on_samples),
                coverage: 1.0,
                orientation,
                residual: 0.0,
            }
            .cost()
        })
        .collect();
    let best = (0..grown.len())
        .min_by(|&i, &j| costs[i].total_cmp(&costs[j]))
        .unwrap_or(0);
    Ok(grown.swap_remove(best))
}

/// The sizes (on the larger side) from which [`part_map`] grows a part's map. From the
/// exact map of the generated humanoids' lower cuts, starting at 10 gave 0.04-0.12 and
/// starting at 20 0.006-0.054 (docs/partial.md); from the verified hypotheses of the
/// quadrupeds' cuts, 10 did better (0.005 against 0.029 on one pair). Both are grown and
/// the less distorted map kept.
pub const PART_MAP_STARTS: [usize; 2] = [10, 20];

/// B's samples on which [`part_map`] measures the distortion of its maps (as the
/// hypotheses' verification samples 2,000 vertices).
const PROBE_SAMPLES: usize = 2000;

/// Seed of those samples.
const PROBE_SEED: u64 = 0x9a47;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detection_needs_more_boundary_and_a_share_of_the_area() {
        let auto = |boundary, share| detect(PartialOption::Auto, boundary, share);
        assert_eq!(auto([0.0, 1.0], 0.7).partiality, Partiality::BInA);
        // Not enough extra boundary, too much area, too little (other units).
        assert_eq!(auto([0.6, 1.0], 0.7).partiality, Partiality::Whole);
        assert_eq!(auto([0.0, 1.0], 0.95).partiality, Partiality::Whole);
        assert_eq!(auto([0.0, 1.0], 0.01).partiality, Partiality::Whole);
        assert!(!auto([0.0, 1.0], 0.7).given);
        let told = detect(PartialOption::AInB, [0.0, 0.0], 1.0);
        assert_eq!((told.partiality, told.given), (Partiality::AInB, true));
        let off = detect(PartialOption::Off, [0.0, 1.0], 0.7);
        assert_eq!((off.partiality, off.given), (Partiality::Whole, true));
    }

    #[test]
    fn a_cut_mesh_has_an_open_boundary_and_a_closed_one_none() {
        let figure = crate::synth::figure_poses(
            crate::synth::FigureKind::Humanoid,
            1_500,
            Default::default(),
            &[0],
        )
        .unwrap()
        .remove(0);
        let whole = Shape::mesh(figure.vertices.clone(), &figure.triangles).unwrap();
        assert_eq!(open_boundary(&whole), 0.0);
        let cut = crate::synth::cut_below(&figure, 1.0 / 3.0).mesh;
        let cut = Shape::mesh(cut.vertices, &cut.triangles).unwrap();
        assert!(
            open_boundary(&cut) > PART_EXTRA_BOUNDARY,
            "{}",
            open_boundary(&cut)
        );
        // The identity map covers all of the whole; a map onto one vertex almost nothing.
        let n = whole.n_vertices();
        let identity: Vec<u32> = (0..n as u32).collect();
        let all = covered(&whole, whole.mesh_area(), &identity, n);
        assert!(all.iter().all(|&c| c));
        let one = covered(&whole, whole.mesh_area(), &vec![0; n], n);
        assert!(one.iter().filter(|&&c| c).count() < n / 50);
        let mass = vec![1.0; n];
        assert_eq!(covered_share(&mass, &all), 1.0);
    }
}
