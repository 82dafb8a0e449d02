//! Generated articulated figures with ground truth.
//!
//! Tests, demos and benchmarks need shapes without outside data, so the crate makes its own:
//! a humanoid, a quadruped and n-limbed stars, in several poses and body proportions. All
//! poses and proportions of one kind and resolution are deformations of the same rest mesh,
//! so **vertex `i` is the same body point in all of them**: the identity is the ground-truth
//! correspondence.
//!
//! How a figure is made:
//! 1. `skeleton`: bones of tapered capsules on a parent tree, per kind, and the poses as
//!    joint rotations;
//! 2. `field`: the capsules' exact signed distances blended by a polynomial smooth union;
//! 3. `polygonize`: surface nets on a block-sparse grid whose spacing is tuned until the
//!    vertex count is within a few percent of the target;
//! 4. `surface`: projection onto the level set, tangential relaxation, quads split along
//!    the better diagonal, and a closed-manifold check (with a shifted grid on failure);
//! 5. `skinning`: smooth weights from the distances to the bones; proportions as
//!    per-bone affine maps, poses by dual quaternion skinning.
//!
//! Frame and size: y is up and the figures face +z. The humanoid is about 1.76 units tall
//! (A-pose), the quadruped about 1.2 long, a star about 2.5 across (limbs in the xz plane).
//! The humanoid and quadruped are mirror symmetric across x = 0 in the rest pose (the grid
//! is too, so the rest mesh is symmetric to rounding); a star is n-fold symmetric about the
//! y axis up to about an edge length (the grid is not).
//!
//! Poses (see [`n_poses`]): humanoid 1 arms raised, 2 walking stride, 3 knee and elbow
//! bent, 4 crouch, 5 twisted torso, 6 side lean with an arm up and a leg out; quadruped
//! 1 trot, 2 sitting, 3 tail and head up, 4 head lowered, 5 paw raised looking aside; star
//! 1 limbs curled up, 2 alternately up and down, 3 different bends per limb, 4 pinwheel
//! (bent in the plane), 5 one limb raised high. With the default proportions no pose
//! intersects itself (checked from 1,000 to 20,000 vertices); other proportions, short or
//! thick legs above all, can make limbs touch in the tighter poses (the sitting quadruped
//! first).
//!
//! [`sample_points`] turns a figure into a (noisy) point cloud that remembers the vertex of
//! every point.
//! [`cut_below`], [`cut_extremity`], [`with_holes`] and [`seen_from`] give parts of a figure
//! (a plane cut, holes, one camera's view) that remember the whole's vertex of each of theirs.
//!
//! ```
//! use shapecorr::synth::{figure, FigureKind, FigureSpec};
//! let spec = FigureSpec { kind: FigureKind::Star { limbs: 5 }, pose: 2, target_vertices: 1500, ..Default::default() };
//! let mesh = figure(&spec)?;
//! assert!(mesh.vertices.len() > 1000);
//! # Ok::<(), shapecorr::Error>(())
//! ```

mod field;
mod geom;
mod partial;
mod pieces;
mod polygonize;
mod props;
mod sampling;
mod skeleton;
mod skinning;
mod surface;

use std::fmt;

use crate::{Error, Result};
use geom::V3;

pub use partial::{cut_below, cut_by_plane, cut_extremity, seen_from, with_holes, Part};
pub use pieces::{cut_into_pieces, PiecesMesh};
pub use props::box_beside;
pub use sampling::{sample_points, with_noise, SampledCloud};

/// The kinds of figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FigureKind {
    /// Head, torso, two arms, two legs; left/right symmetric in the rest pose.
    Humanoid,
    /// Body, head on a neck, four legs, a tail (dog-like).
    Quadruped,
    /// A round body with `limbs` identical limbs (3..=8), n-fold symmetric in the rest pose.
    Star {
        /// Number of limbs (3..=8).
        limbs: usize,
    },
}

impl FigureKind {
    /// Parses `"humanoid"`, `"quadruped"`, `"star5"` or `"star:5"` (case-insensitive). The
    /// limb count is checked by [`figure`], not here.
    pub fn parse(s: &str) -> Option<FigureKind> {
        let s = s.trim().to_ascii_lowercase();
        match s.as_str() {
            "humanoid" => Some(FigureKind::Humanoid),
            "quadruped" => Some(FigureKind::Quadruped),
            _ => {
                let rest = s.strip_prefix("star")?;
                let digits = rest.strip_prefix(':').unwrap_or(rest);
                if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
                    return None;
                }
                digits.parse().ok().map(|limbs| FigureKind::Star { limbs })
            }
        }
    }
}

impl fmt::Display for FigureKind {
    /// The name [`FigureKind::parse`] reads back: `humanoid`, `quadruped`, `star5`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FigureKind::Humanoid => write!(f, "humanoid"),
            FigureKind::Quadruped => write!(f, "quadruped"),
            FigureKind::Star { limbs } => write!(f, "star{limbs}"),
        }
    }
}

/// Body proportions, applied as a deformation of the rest mesh (so the vertex order is the
/// ground truth between proportions too): limb bones are stretched by `limb_length` along
/// their axis and by `limb_thickness` across it. 1.0 is the default body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proportions {
    /// Scale factor of every limb bone along its axis (1.0 = default; finite, > 0).
    pub limb_length: f64,
    /// Scale factor of every limb bone across its axis (1.0 = default; finite, > 0).
    pub limb_thickness: f64,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for Proportions {
    fn default() -> Self {
        Proportions {
            limb_length: 1.0,
            limb_thickness: 1.0,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

/// What figure to make.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FigureSpec {
    /// Which figure to make.
    pub kind: FigureKind,
    /// 0 = rest pose; `1..n_poses(kind)` are the other poses.
    pub pose: usize,
    /// Wanted number of vertices (500..=200_000); the result is within 15% of it, usually
    /// within a few percent.
    pub target_vertices: usize,
    /// Body proportions, applied as a deformation of the rest mesh.
    pub proportions: Proportions,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for FigureSpec {
    fn default() -> Self {
        FigureSpec {
            kind: FigureKind::Humanoid,
            pose: 0,
            target_vertices: 5000,
            proportions: Proportions::default(),
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

/// A closed triangle mesh, outward oriented (counter-clockwise seen from outside).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FigureMesh {
    /// Vertex positions (y up, facing +z); vertex `i` is the same body point in every pose.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as 0-based indices into `vertices`, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl FigureMesh {
    /// The surface area: the sum of the triangles' areas.
    pub fn area(&self) -> f64 {
        (self.triangles.iter())
            .map(|t| {
                let [a, b, c] = t.map(|k| self.vertices[k as usize]);
                geom::triangle_area(a, b, c)
            })
            .sum()
    }
}

/// Smallest and largest accepted `target_vertices`.
const TARGET_RANGE: (usize, usize) = (500, 200_000);
/// Relaxation rounds after polygonisation.
const RELAX_ITERATIONS: usize = 4;
/// Grid placements tried before giving up on a manifold surface.
const GRID_ATTEMPTS: usize = 8;

/// Number of poses of `kind`, the rest pose (0) included: 7 for the humanoid, 6 for the
/// quadruped and the stars.
pub fn n_poses(kind: FigureKind) -> usize {
    skeleton::n_poses(kind)
}

/// Makes the figure described by `spec`.
///
/// Errors with [`Error::InvalidParameter`] for a star with limbs outside 3..=8,
/// `target_vertices` outside 500..=200_000, a pose `>= n_poses(kind)`, or proportions that
/// are not finite and positive.
pub fn figure(spec: &FigureSpec) -> Result<FigureMesh> {
    let mut meshes = figure_poses(
        spec.kind,
        spec.target_vertices,
        spec.proportions,
        &[spec.pose],
    )?;
    Ok(meshes.pop().expect("one pose asked"))
}

/// Makes several poses of one figure at once: the rest mesh is built once and deformed into
/// each pose of `poses` (with `proportions`), so this is cheaper than calling [`figure`] per
/// pose and gives the same meshes. Errors as [`figure`].
pub fn figure_poses(
    kind: FigureKind,
    target_vertices: usize,
    proportions: Proportions,
    poses: &[usize],
) -> Result<Vec<FigureMesh>> {
    validate(kind, target_vertices, &proportions, poses)?;
    let skel = skeleton::skeleton(kind);
    let rest = rest_mesh(&skel, target_vertices)?;
    // The rest pose with the default body is the rest mesh itself; everything else moves it.
    let moved = |p: usize| p != 0 || proportions != Proportions::default();
    let weights = poses
        .iter()
        .any(|&p| moved(p))
        .then(|| skinning::weights(&skel, &rest.vertices));
    Ok(poses
        .iter()
        .map(|&p| match &weights {
            Some(w) if moved(p) => FigureMesh {
                vertices: skinning::deform(
                    &skel,
                    w,
                    &rest.vertices,
                    &proportions,
                    &skeleton::pose(kind, &skel, p),
                ),
                triangles: rest.triangles.clone(),
            },
            _ => rest.clone(),
        })
        .collect())
}

/// A figure's rest mesh with its skinning weights: the ground truth of a transfer (issue
/// 21). Every pose and proportion of the figure at this resolution is this mesh moved by
/// these weights, so its weights are every such figure's.
#[derive(Debug, Clone)]
pub struct Rig {
    /// The figure.
    pub kind: FigureKind,
    /// The rest mesh (pose 0, default proportions).
    pub rest: FigureMesh,
    /// Number of bones.
    pub n_bones: usize,
    /// Every vertex's weight per bone (`n_bones` per vertex, row-major), each row summing
    /// to 1.
    pub weights: Vec<f64>,
}

/// The rig of a figure at a resolution (arguments as [`figure`]'s).
pub fn rig(kind: FigureKind, target_vertices: usize) -> Result<Rig> {
    validate(kind, target_vertices, &Proportions::default(), &[0])?;
    let skel = skeleton::skeleton(kind);
    let rest = rest_mesh(&skel, target_vertices)?;
    let weights = skinning::weights(&skel, &rest.vertices).to_rows(skel.bones.len());
    Ok(Rig {
        kind,
        rest,
        n_bones: skel.bones.len(),
        weights,
    })
}

impl Rig {
    /// The rest mesh's vertices moved to `pose` with `proportions` by `weights` (the rig's
    /// own give [`figure_poses`]' vertices; transferred ones show how well they pose).
    /// Errors unless `weights` has `n_bones` non-negative values per vertex summing to 1.
    pub fn deform(
        &self,
        weights: &[f64],
        proportions: Proportions,
        pose: usize,
    ) -> Result<Vec<[f64; 3]>> {
        validate(self.kind, TARGET_RANGE.0, &proportions, &[pose])?;
        if weights.len() != self.rest.vertices.len() * self.n_bones {
            return Err(invalid(
                "weights",
                format!(
                    "has {} values, the rig has {} vertices x {} bones",
                    weights.len(),
                    self.rest.vertices.len(),
                    self.n_bones
                ),
            ));
        }
        for (v, row) in weights.chunks_exact(self.n_bones).enumerate() {
            let total: f64 = row.iter().sum();
            if row.iter().any(|&w| !(w >= 0.0)) || (total - 1.0).abs() > 1e-6 {
                return Err(invalid(
                    "weights",
                    format!("vertex {v}: weights must be non-negative and sum to 1"),
                ));
            }
        }
        let skel = skeleton::skeleton(self.kind);
        let weights = skinning::Weights::from_rows(weights, self.n_bones);
        Ok(skinning::deform(
            &skel,
            &weights,
            &self.rest.vertices,
            &proportions,
            &skeleton::pose(self.kind, &skel, pose),
        ))
    }
}

fn invalid(name: &'static str, reason: String) -> Error {
    Error::InvalidParameter { name, reason }
}

fn validate(kind: FigureKind, target: usize, prop: &Proportions, poses: &[usize]) -> Result<()> {
    if let FigureKind::Star { limbs } = kind {
        if !(3..=8).contains(&limbs) {
            return Err(invalid(
                "limbs",
                format!("a star has 3 to 8 limbs, got {limbs}"),
            ));
        }
    }
    if !(TARGET_RANGE.0..=TARGET_RANGE.1).contains(&target) {
        return Err(invalid(
            "target_vertices",
            format!(
                "must be in {}..={}, got {target}",
                TARGET_RANGE.0, TARGET_RANGE.1
            ),
        ));
    }
    let n = n_poses(kind);
    if let Some(&p) = poses.iter().find(|&&p| p >= n) {
        return Err(invalid("pose", format!("{kind} has poses 0..{n}, got {p}")));
    }
    for (name, v) in [
        ("limb_length", prop.limb_length),
        ("limb_thickness", prop.limb_thickness),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(invalid(
                name,
                format!("must be finite and positive, got {v}"),
            ));
        }
    }
    Ok(())
}

/// The rest-pose surface of `skel` with about `target` vertices.
fn rest_mesh(skel: &skeleton::Skeleton, target: usize) -> Result<FigureMesh> {
    let field = field::Field::new(&skel.shapes(), skel.blend);
    let table = polygonize::CubeTable::new();
    let (lo, hi) = field.bounds();
    let axes = skel.axes();
    let h = tune_spacing(&field, &table, lo, hi, &axes, target);
    let mut last_problem = String::new();
    for attempt in 0..GRID_ATTEMPTS {
        // Shift the grid along y and z only, keeping it mirror symmetric across x = 0.
        let shift = if attempt == 0 {
            [0.0; 3]
        } else {
            let a = attempt as f64;
            [0.0, (0.618_034 * a).fract(), (0.414_214 * a + 0.5).fract()]
        };
        let grid = polygonize::Grid::around(lo, hi, h, shift);
        match polygonize::Sampled::new(&field, grid, &axes)
            .surface_nets(&table)
            .and_then(|(vertices, quads)| finish(&field, grid.spacing(), vertices, quads))
        {
            Ok(mesh) => return Ok(mesh),
            Err(problem) => last_problem = problem,
        }
    }
    Err(Error::Numerical {
        stage: "synth::figure",
        reason: format!(
            "no closed manifold surface after {GRID_ATTEMPTS} grid placements: {last_problem}"
        ),
    })
}

/// Grid spacing whose surface nets have about `target` vertices: the count scales as
/// `1 / h^2`, so a few rescaled trials converge.
fn tune_spacing(
    field: &field::Field,
    table: &polygonize::CubeTable,
    lo: V3,
    hi: V3,
    axes: &[(V3, V3)],
    target: usize,
) -> f64 {
    let mut h = (1.3 * field.rough_area() / target as f64).sqrt();
    let mut best = (f64::INFINITY, h);
    for _ in 0..5 {
        let grid = polygonize::Grid::around(lo, hi, h, [0.0; 3]);
        let n = polygonize::Sampled::new(field, grid, axes).vertex_count(table);
        let error = (n as f64 / target as f64 - 1.0).abs();
        if error < best.0 {
            best = (error, h);
        }
        if error < 0.02 || n == 0 {
            break;
        }
        h *= (n as f64 / target as f64).sqrt();
    }
    best.1
}

/// Surface nets output made into a checked triangle mesh on the surface.
fn finish(
    field: &field::Field,
    h: f64,
    mut vertices: Vec<V3>,
    quads: Vec<[u32; 4]>,
) -> std::result::Result<FigureMesh, String> {
    surface::project_all(field, &mut vertices, h);
    surface::relax(field, &mut vertices, &quads, h, RELAX_ITERATIONS);
    let triangles = surface::triangulate(&vertices, &quads);
    surface::check_closed_manifold(&vertices, &triangles)?;
    Ok(FigureMesh {
        vertices,
        triangles,
    })
}

#[cfg(test)]
mod tests;

/// Left/right mirror map of a figure that is symmetric about the plane x = 0 (the rest pose
/// of the humanoid and the quadruped): for every vertex, the vertex nearest to its
/// reflection. Poses share the rest pose's vertex order, so the map serves them all, e.g.
/// for flip-tolerant scores.
pub fn mirror_map(rest: &FigureMesh) -> Vec<u32> {
    let tree = crate::shape::neighbors::PointTree::new(&rest.vertices);
    rest.vertices
        .iter()
        .map(|p| tree.nearest(&[-p[0], p[1], p[2]]) as u32)
        .collect()
}

/// `mesh` simplified by meshoptimizer's edge collapse to about `target_vertices` vertices
/// (plain quadric error, no regularisation: long thin triangles as in low-poly assets), with
/// the index in `mesh` of every kept vertex (ascending): a decimated figure keeps its
/// ground truth by index. Errors with [`Error::InvalidParameter`] for fewer than 16 vertices.
pub fn decimate(mesh: &FigureMesh, target_vertices: usize) -> Result<(FigureMesh, Vec<u32>)> {
    if target_vertices < 16 {
        return Err(Error::InvalidParameter {
            name: "target_vertices",
            reason: format!("a decimated figure needs 16 or more vertices, got {target_vertices}"),
        });
    }
    let positions: Vec<[f32; 3]> = mesh.vertices.iter().map(|p| p.map(|x| x as f32)).collect();
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    // A closed surface has about two triangles per vertex; the error bound is left open.
    let kept = meshopt::simplify_decoder(
        &indices,
        &positions,
        6 * target_vertices,
        1.0,
        meshopt::SimplifyOptions::None,
        None,
    );
    let mut original: Vec<u32> = kept.clone();
    original.sort_unstable();
    original.dedup();
    let index = |v: u32| original.binary_search(&v).unwrap_or_default() as u32;
    Ok((
        FigureMesh {
            vertices: original
                .iter()
                .map(|&v| mesh.vertices[v as usize])
                .collect(),
            triangles: kept
                .chunks_exact(3)
                .map(|t| [index(t[0]), index(t[1]), index(t[2])])
                .collect(),
        },
        original,
    ))
}
