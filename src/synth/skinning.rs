//! Deforming the rest mesh: smooth skinning weights from the distances to the bones, body
//! proportions as per-bone affine maps blended linearly, and poses as per-bone rigid motions
//! blended by dual quaternion skinning (which keeps twisted and bent joints from
//! collapsing).

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use super::field::Cone;
use super::geom::V3;
use super::skeleton::{Pose, Skeleton};
use super::Proportions;

/// Width of the weight falloff, as a fraction of each bone's mean radius.
const SIGMA_PER_RADIUS: f64 = 0.55;
/// Normalised weights below this are dropped (subtracted, so weights stay continuous).
const WEIGHT_FLOOR: f64 = 0.02;

/// An affine map `p -> m p + t`.
type Affine = (Matrix3<f64>, Vector3<f64>);
/// A rigid motion `p -> q p + t`.
type Rigid = (UnitQuaternion<f64>, Vector3<f64>);

/// Per-vertex bone weights in compressed rows: vertex `v` has bones
/// `bone[start[v]..start[v + 1]]` with weights `weight[..]` summing to 1.
#[derive(Debug, Clone)]
pub(crate) struct Weights {
    start: Vec<usize>,
    bone: Vec<u16>,
    weight: Vec<f64>,
}

impl Weights {
    /// Weights from dense rows (`n_bones` per vertex, row-major): the non-zero ones.
    pub fn from_rows(rows: &[f64], n_bones: usize) -> Weights {
        let mut out = Weights {
            start: vec![0],
            bone: Vec::new(),
            weight: Vec::new(),
        };
        for row in rows.chunks_exact(n_bones) {
            for (c, &w) in row.iter().enumerate() {
                if w > 0.0 {
                    out.bone.push(c as u16);
                    out.weight.push(w);
                }
            }
            out.start.push(out.bone.len());
        }
        out
    }

    /// Dense rows, `n_bones` per vertex, row-major.
    pub fn to_rows(&self, n_bones: usize) -> Vec<f64> {
        let n = self.start.len() - 1;
        let mut rows = vec![0.0; n * n_bones];
        for v in 0..n {
            for (c, w) in self.of(v) {
                rows[v * n_bones + c] = w;
            }
        }
        rows
    }

    /// `(bone, weight)` pairs of vertex `v`.
    pub fn of(&self, v: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.start[v]..self.start[v + 1];
        self.bone[r.clone()]
            .iter()
            .zip(&self.weight[r])
            .map(|(&b, &w)| (b as usize, w))
    }
}

/// Skinning weights of `vertices` (rest pose): bone `c` gets
/// `exp(-((s_c - s_min) / sigma_c)^2 / 2)`, where `s_c` is the signed distance from the
/// vertex to the bone's capsules, so a vertex follows the bones whose surface it lies on and
/// blends smoothly across joints, while parts separated by a gap do not pull on each other.
pub(crate) fn weights(skel: &Skeleton, vertices: &[V3]) -> Weights {
    let cones: Vec<Vec<Cone>> = skel
        .bones
        .iter()
        .map(|b| b.shapes.iter().map(|s| s.prepare()).collect())
        .collect();
    let sigma: Vec<f64> = skel
        .bones
        .iter()
        .map(|b| {
            let r: f64 = b.shapes.iter().map(|s| 0.5 * (s.ra + s.rb)).sum();
            SIGMA_PER_RADIUS * r / b.shapes.len() as f64
        })
        .collect();
    let nb = skel.bones.len();
    let mut out = Weights {
        start: vec![0],
        bone: Vec::new(),
        weight: Vec::new(),
    };
    let mut s = vec![0.0; nb];
    let mut w = vec![0.0; nb];
    for &p in vertices {
        for (c, cs) in cones.iter().enumerate() {
            s[c] = cs.iter().map(|k| k.sdf(p)).fold(f64::INFINITY, f64::min);
        }
        let s_min = s.iter().copied().fold(f64::INFINITY, f64::min);
        for c in 0..nb {
            let z = (s[c] - s_min) / sigma[c];
            w[c] = (-0.5 * z * z).exp();
        }
        let total: f64 = w.iter().sum();
        for x in w.iter_mut() {
            *x = (*x / total - WEIGHT_FLOOR).max(0.0);
        }
        let total: f64 = w.iter().sum();
        for (c, &x) in w.iter().enumerate() {
            if x > 0.0 {
                out.bone.push(c as u16);
                out.weight.push(x / total);
            }
        }
        out.start.push(out.bone.len());
    }
    out
}

/// Per-bone affine maps `p -> m p + t` that stretch limb bones by the proportions, and the
/// moved pivots. A limb bone scales by `limb_length` along its axis and `limb_thickness`
/// across it, about its pivot; every bone's pivot follows its parent's map.
fn proportion_maps(skel: &Skeleton, prop: &Proportions) -> (Vec<Affine>, Vec<V3>) {
    let mut maps: Vec<Affine> = Vec::with_capacity(skel.bones.len());
    let mut pivots = Vec::with_capacity(skel.bones.len());
    for bone in &skel.bones {
        let j = Vector3::from(bone.pivot);
        let j_new = match bone.parent {
            Some(pi) => maps[pi].0 * j + maps[pi].1,
            None => j,
        };
        let m = match bone.limb_axis {
            Some(u) => {
                let u = Vector3::from(u);
                let uu = u * u.transpose();
                uu * prop.limb_length + (Matrix3::identity() - uu) * prop.limb_thickness
            }
            None => Matrix3::identity(),
        };
        maps.push((m, j_new - m * j));
        pivots.push([j_new.x, j_new.y, j_new.z]);
    }
    (maps, pivots)
}

/// Rigid motion of every bone for `pose`, around the given (proportioned) pivots: each bone
/// turns about its pivot and is carried by its parent.
fn bone_motions(skel: &Skeleton, pivots: &[V3], pose: &Pose) -> Vec<Rigid> {
    let mut local = vec![UnitQuaternion::identity(); skel.bones.len()];
    for r in pose {
        let q = UnitQuaternion::from_axis_angle(
            &nalgebra::Unit::new_normalize(Vector3::from(r.axis)),
            r.degrees.to_radians(),
        );
        local[r.bone] = q * local[r.bone];
    }
    let mut motions: Vec<Rigid> = Vec::with_capacity(skel.bones.len());
    for (c, bone) in skel.bones.iter().enumerate() {
        let j = Vector3::from(pivots[c]);
        let (rp, tp) = match bone.parent {
            Some(pi) => motions[pi],
            None => (UnitQuaternion::identity(), Vector3::zeros()),
        };
        let r = local[c];
        // M_c = M_parent o (p -> j + R (p - j)).
        motions.push((rp * r, rp * (j - r * j) + tp));
    }
    motions
}

/// Unit dual quaternion `(real, dual)` of the rigid motion `p -> q p + t`.
fn dual_quaternion(
    q: &UnitQuaternion<f64>,
    t: &Vector3<f64>,
) -> (Quaternion<f64>, Quaternion<f64>) {
    let real = *q.quaternion();
    let dual = Quaternion::from_imag(*t) * real * 0.5;
    (real, dual)
}

/// The rest mesh `rest` moved to `pose` with body proportions `prop`, vertex for vertex.
pub(crate) fn deform(
    skel: &Skeleton,
    weights: &Weights,
    rest: &[V3],
    prop: &Proportions,
    pose: &Pose,
) -> Vec<V3> {
    let (maps, pivots) = proportion_maps(skel, prop);
    let dqs: Vec<_> = bone_motions(skel, &pivots, pose)
        .iter()
        .map(|(q, t)| dual_quaternion(q, t))
        .collect();
    rest.iter()
        .enumerate()
        .map(|(v, &p)| {
            let p = Vector3::from(p);
            // Proportions: linear blend of the affine maps.
            let mut q = Vector3::zeros();
            for (c, w) in weights.of(v) {
                q += (maps[c].0 * p + maps[c].1) * w;
            }
            // Pose: dual quaternion blend, every quaternion in the hemisphere of the heaviest.
            let heaviest = weights
                .of(v)
                .fold(
                    (0, -1.0),
                    |best, (c, w)| if w > best.1 { (c, w) } else { best },
                )
                .0;
            let pivot = dqs[heaviest].0;
            let mut real = Quaternion::new(0.0, 0.0, 0.0, 0.0);
            let mut dual = Quaternion::new(0.0, 0.0, 0.0, 0.0);
            for (c, w) in weights.of(v) {
                let w = if dqs[c].0.dot(&pivot) < 0.0 { -w } else { w };
                real += dqs[c].0 * w;
                dual += dqs[c].1 * w;
            }
            let n = real.norm();
            let real = real / n;
            let dual = dual / n;
            let t = (dual * real.conjugate()).imag() * 2.0;
            let r = UnitQuaternion::new_unchecked(real);
            let out = r * q + t;
            [out.x, out.y, out.z]
        })
        .collect()
}

/// The blended rotation of every vertex in `pose` (for checks of face orientation).
#[cfg(test)]
pub(crate) fn vertex_rotations(
    skel: &Skeleton,
    weights: &Weights,
    n: usize,
    pose: &Pose,
) -> Vec<UnitQuaternion<f64>> {
    let pivots: Vec<V3> = skel.bones.iter().map(|b| b.pivot).collect();
    let motions = bone_motions(skel, &pivots, pose);
    (0..n)
        .map(|v| {
            let pivot = weights
                .of(v)
                .fold((0, -1.0), |b, (c, w)| if w > b.1 { (c, w) } else { b })
                .0;
            let mut q = Quaternion::new(0.0, 0.0, 0.0, 0.0);
            for (c, w) in weights.of(v) {
                let qc = *motions[c].0.quaternion();
                let s = if qc.dot(motions[pivot].0.quaternion()) < 0.0 {
                    -w
                } else {
                    w
                };
                q += qc * s;
            }
            UnitQuaternion::new_normalize(q)
        })
        .collect()
}
