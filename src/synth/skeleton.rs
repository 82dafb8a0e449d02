//! Skeletons of the figure kinds (bones made of tapered capsules, on a parent tree) and
//! their poses (joint rotations).
//!
//! Coordinates: y is up, the figures face +z, and the humanoid and quadruped are mirror
//! symmetric across the plane x = 0 (their left side is at +x). The humanoid is about
//! 1.76 units tall, the quadruped about 1.2 long, the star about 2.5 across.

use super::field::RoundCone;
use super::geom::{cross, normalize, scale, sub, V3};
use super::FigureKind;

/// One bone: the capsules that make its body, the joint (pivot) where it hangs from its
/// parent, and for limb bones the unit axis along which body proportions stretch it.
#[derive(Debug, Clone)]
pub(crate) struct Bone {
    pub name: String,
    pub parent: Option<usize>,
    pub pivot: V3,
    pub shapes: Vec<RoundCone>,
    pub limb_axis: Option<V3>,
}

/// Bones in parent-before-child order, with the blend width of the smooth union.
#[derive(Debug, Clone)]
pub(crate) struct Skeleton {
    pub bones: Vec<Bone>,
    pub blend: f64,
}

impl Skeleton {
    fn new(blend: f64) -> Skeleton {
        Skeleton {
            bones: Vec::new(),
            blend,
        }
    }

    /// Adds a bone hanging from `parent` at `pivot`; a limb bone's axis runs from the pivot
    /// to the end of its first capsule.
    fn add(
        &mut self,
        name: &str,
        parent: Option<&str>,
        pivot: V3,
        shapes: Vec<RoundCone>,
        limb: bool,
    ) {
        let parent = parent.map(|p| self.index(p));
        let limb_axis = limb.then(|| normalize(sub(shapes[0].b, pivot)));
        self.bones.push(Bone {
            name: name.to_string(),
            parent,
            pivot,
            shapes,
            limb_axis,
        });
    }

    /// Index of the bone called `name` (the names are fixed by this module).
    pub fn index(&self, name: &str) -> usize {
        self.bones
            .iter()
            .position(|b| b.name == name)
            .unwrap_or_else(|| panic!("no bone {name}"))
    }

    /// The axis segments of every capsule, each bone's joined to its pivot (all inside the
    /// figure, and together connected).
    pub fn axes(&self) -> Vec<(V3, V3)> {
        let mut axes = Vec::new();
        for b in &self.bones {
            for s in &b.shapes {
                axes.push((b.pivot, s.a));
                axes.push((s.a, s.b));
            }
        }
        axes
    }

    /// Every capsule of every bone, in bone order.
    pub fn shapes(&self) -> Vec<RoundCone> {
        self.bones
            .iter()
            .flat_map(|b| b.shapes.iter().copied())
            .collect()
    }
}

/// One joint rotation of a pose: `bone` turns by `degrees` about `axis` (a direction in
/// rest-pose coordinates) around its pivot, carrying its descendants along.
#[derive(Debug, Clone, Copy)]
pub(crate) struct JointRotation {
    pub bone: usize,
    pub axis: V3,
    pub degrees: f64,
}

/// A pose: joint rotations, applied per bone in the order listed.
pub(crate) type Pose = Vec<JointRotation>;

/// The skeleton of `kind` (limb counts must already be valid).
pub(crate) fn skeleton(kind: FigureKind) -> Skeleton {
    match kind {
        FigureKind::Humanoid => humanoid(),
        FigureKind::Quadruped => quadruped(),
        FigureKind::Star { limbs } => star(limbs),
    }
}

/// Number of poses of `kind`, the rest pose included.
pub(crate) fn n_poses(kind: FigureKind) -> usize {
    match kind {
        FigureKind::Humanoid => 7,
        FigureKind::Quadruped => 6,
        FigureKind::Star { .. } => 6,
    }
}

/// Pose number `index` (0 = rest) of `kind`; `index < n_poses(kind)`.
pub(crate) fn pose(kind: FigureKind, skel: &Skeleton, index: usize) -> Pose {
    let mut p = PoseBuilder {
        skel,
        rotations: Vec::new(),
    };
    if index > 0 {
        match kind {
            FigureKind::Humanoid => humanoid_pose(&mut p, index),
            FigureKind::Quadruped => quadruped_pose(&mut p, index),
            FigureKind::Star { limbs } => star_pose(&mut p, limbs, index),
        }
    }
    p.rotations
}

struct PoseBuilder<'a> {
    skel: &'a Skeleton,
    rotations: Pose,
}

impl PoseBuilder<'_> {
    fn rot(&mut self, bone: &str, axis: V3, degrees: f64) {
        self.rotations.push(JointRotation {
            bone: self.skel.index(bone),
            axis: normalize(axis),
            degrees,
        });
    }

    /// Axis that bends bone `bone` (whose first capsule points along `d`) towards `towards`.
    fn bend_axis(&self, bone: &str, towards: V3) -> V3 {
        let b = &self.skel.bones[self.skel.index(bone)];
        let d = normalize(sub(b.shapes[0].b, b.shapes[0].a));
        normalize(cross(d, towards))
    }

    /// Bends `bone` by `degrees` towards direction `towards` (perpendicular-ish to it).
    fn bend(&mut self, bone: &str, towards: V3, degrees: f64) {
        let axis = self.bend_axis(bone, towards);
        self.rot(bone, axis, degrees);
    }
}

const X: V3 = [1.0, 0.0, 0.0];
const Y: V3 = [0.0, 1.0, 0.0];
const Z: V3 = [0.0, 0.0, 1.0];

fn cone(a: V3, b: V3, ra: f64, rb: f64) -> RoundCone {
    RoundCone::new(a, b, ra, rb)
}

/// `p` on side `s` (+1 = the figure's left, at +x; -1 = its right).
fn side(s: f64, p: V3) -> V3 {
    [s * p[0], p[1], p[2]]
}

fn sides() -> [(&'static str, f64); 2] {
    [("l", 1.0), ("r", -1.0)]
}

/// A mannequin-like humanoid in an A-pose: pelvis, abdomen, chest, neck, head, arms with
/// mitten hands, legs with feet.
fn humanoid() -> Skeleton {
    let mut s = Skeleton::new(0.035);
    s.add(
        "pelvis",
        None,
        [0.0, 0.95, 0.0],
        vec![cone([-0.075, 0.93, 0.0], [0.075, 0.93, 0.0], 0.115, 0.115)],
        false,
    );
    s.add(
        "abdomen",
        Some("pelvis"),
        [0.0, 1.0, 0.0],
        vec![cone([0.0, 0.95, 0.0], [0.0, 1.2, 0.0], 0.112, 0.12)],
        false,
    );
    s.add(
        "chest",
        Some("abdomen"),
        [0.0, 1.18, 0.0],
        vec![
            cone([0.055, 1.2, 0.0], [0.1, 1.37, 0.0], 0.11, 0.115),
            cone([-0.055, 1.2, 0.0], [-0.1, 1.37, 0.0], 0.11, 0.115),
        ],
        false,
    );
    s.add(
        "neck",
        Some("chest"),
        [0.0, 1.44, 0.0],
        vec![cone([0.0, 1.42, 0.0], [0.0, 1.57, 0.01], 0.056, 0.05)],
        false,
    );
    s.add(
        "head",
        Some("neck"),
        [0.0, 1.56, 0.01],
        vec![cone([0.0, 1.635, 0.012], [0.0, 1.67, 0.02], 0.1, 0.092)],
        false,
    );
    // Arms hang 32 degrees out from the vertical.
    let (sa, ca) = 32f64.to_radians().sin_cos();
    let arm = |t: f64| -> V3 { [0.2 + t * sa, 1.38 - t * ca, 0.0] };
    for (n, sd) in sides() {
        s.add(
            &format!("{n}_upper_arm"),
            Some("chest"),
            side(sd, arm(0.0)),
            vec![cone(side(sd, arm(0.0)), side(sd, arm(0.29)), 0.056, 0.045)],
            true,
        );
        s.add(
            &format!("{n}_forearm"),
            Some(&format!("{n}_upper_arm")),
            side(sd, arm(0.29)),
            vec![cone(side(sd, arm(0.29)), side(sd, arm(0.55)), 0.045, 0.036)],
            true,
        );
        s.add(
            &format!("{n}_hand"),
            Some(&format!("{n}_forearm")),
            side(sd, arm(0.55)),
            vec![cone(side(sd, arm(0.57)), side(sd, arm(0.68)), 0.04, 0.036)],
            true,
        );
    }
    for (n, sd) in sides() {
        s.add(
            &format!("{n}_thigh"),
            Some("pelvis"),
            side(sd, [0.1, 0.9, 0.0]),
            vec![cone(
                side(sd, [0.1, 0.9, 0.0]),
                side(sd, [0.14, 0.5, 0.0]),
                0.085,
                0.06,
            )],
            true,
        );
        s.add(
            &format!("{n}_shin"),
            Some(&format!("{n}_thigh")),
            side(sd, [0.14, 0.5, 0.0]),
            vec![cone(
                side(sd, [0.14, 0.5, 0.0]),
                side(sd, [0.16, 0.1, 0.0]),
                0.06,
                0.042,
            )],
            true,
        );
        s.add(
            &format!("{n}_foot"),
            Some(&format!("{n}_shin")),
            side(sd, [0.16, 0.1, 0.0]),
            vec![cone(
                side(sd, [0.16, 0.075, 0.0]),
                side(sd, [0.17, 0.048, 0.15]),
                0.045,
                0.04,
            )],
            true,
        );
    }
    s
}

/// A dog-like quadruped: two-part body, neck, head with snout, four legs with paws, a
/// two-part tail.
fn quadruped() -> Skeleton {
    let mut s = Skeleton::new(0.04);
    s.add(
        "hindquarters",
        None,
        [0.0, 0.58, -0.02],
        vec![cone([0.0, 0.57, -0.34], [0.0, 0.58, -0.02], 0.15, 0.155)],
        false,
    );
    s.add(
        "forequarters",
        Some("hindquarters"),
        [0.0, 0.58, -0.02],
        vec![cone([0.0, 0.58, -0.02], [0.0, 0.61, 0.22], 0.155, 0.17)],
        false,
    );
    s.add(
        "neck",
        Some("forequarters"),
        [0.0, 0.66, 0.26],
        vec![cone([0.0, 0.64, 0.26], [0.0, 0.82, 0.42], 0.085, 0.07)],
        false,
    );
    s.add(
        "head",
        Some("neck"),
        [0.0, 0.82, 0.42],
        vec![cone([0.0, 0.86, 0.45], [0.0, 0.82, 0.63], 0.095, 0.05)],
        false,
    );
    for (n, sd) in sides() {
        let p = |v: V3| side(sd, v);
        s.add(
            &format!("{n}_front_upper"),
            Some("forequarters"),
            p([0.1, 0.52, 0.2]),
            vec![cone(
                p([0.1, 0.52, 0.2]),
                p([0.11, 0.29, 0.22]),
                0.062,
                0.048,
            )],
            true,
        );
        s.add(
            &format!("{n}_front_lower"),
            Some(&format!("{n}_front_upper")),
            p([0.11, 0.29, 0.22]),
            vec![cone(
                p([0.11, 0.29, 0.22]),
                p([0.11, 0.07, 0.2]),
                0.048,
                0.04,
            )],
            true,
        );
        s.add(
            &format!("{n}_front_paw"),
            Some(&format!("{n}_front_lower")),
            p([0.11, 0.07, 0.2]),
            vec![cone(
                p([0.11, 0.055, 0.2]),
                p([0.11, 0.045, 0.27]),
                0.042,
                0.036,
            )],
            true,
        );
        s.add(
            &format!("{n}_hind_upper"),
            Some("hindquarters"),
            p([0.1, 0.52, -0.3]),
            vec![cone(
                p([0.1, 0.52, -0.3]),
                p([0.11, 0.3, -0.22]),
                0.072,
                0.05,
            )],
            true,
        );
        s.add(
            &format!("{n}_hind_lower"),
            Some(&format!("{n}_hind_upper")),
            p([0.11, 0.3, -0.22]),
            vec![cone(
                p([0.11, 0.3, -0.22]),
                p([0.11, 0.16, -0.33]),
                0.05,
                0.04,
            )],
            true,
        );
        s.add(
            &format!("{n}_hind_foot"),
            Some(&format!("{n}_hind_lower")),
            p([0.11, 0.16, -0.33]),
            vec![cone(
                p([0.11, 0.16, -0.33]),
                p([0.11, 0.065, -0.31]),
                0.04,
                0.038,
            )],
            true,
        );
        s.add(
            &format!("{n}_hind_paw"),
            Some(&format!("{n}_hind_foot")),
            p([0.11, 0.065, -0.31]),
            vec![cone(
                p([0.11, 0.055, -0.31]),
                p([0.11, 0.045, -0.24]),
                0.042,
                0.036,
            )],
            true,
        );
    }
    s.add(
        "tail_base",
        Some("hindquarters"),
        [0.0, 0.62, -0.44],
        vec![cone([0.0, 0.62, -0.44], [0.0, 0.67, -0.6], 0.05, 0.04)],
        false,
    );
    s.add(
        "tail_tip",
        Some("tail_base"),
        [0.0, 0.67, -0.6],
        vec![cone([0.0, 0.67, -0.6], [0.0, 0.75, -0.76], 0.04, 0.03)],
        false,
    );
    s
}

/// Unit direction of limb `k` of `n` in the horizontal plane.
fn star_dir(k: usize, n: usize) -> V3 {
    let t = std::f64::consts::TAU * k as f64 / n as f64;
    [t.cos(), 0.0, t.sin()]
}

/// A round central body with `n` identical three-segment limbs in the horizontal plane.
fn star(n: usize) -> Skeleton {
    let mut s = Skeleton::new(0.04);
    s.add(
        "body",
        None,
        [0.0; 3],
        vec![cone([0.0, -0.06, 0.0], [0.0, 0.06, 0.0], 0.3, 0.3)],
        false,
    );
    for k in 0..n {
        let d = star_dir(k, n);
        let at = |t: f64| scale(d, t);
        s.add(
            &format!("limb{k}_0"),
            Some("body"),
            at(0.3),
            vec![cone(at(0.25), at(0.62), 0.105, 0.085)],
            true,
        );
        s.add(
            &format!("limb{k}_1"),
            Some(&format!("limb{k}_0")),
            at(0.62),
            vec![cone(at(0.62), at(0.95), 0.085, 0.062)],
            true,
        );
        s.add(
            &format!("limb{k}_2"),
            Some(&format!("limb{k}_1")),
            at(0.95),
            vec![cone(at(0.95), at(1.22), 0.062, 0.04)],
            true,
        );
    }
    s
}

/// Humanoid poses 1..=6: arms raised, walking stride, knee and elbow bent, crouch, twisted
/// torso, side lean with a raised arm and a leg out.
fn humanoid_pose(p: &mut PoseBuilder, index: usize) {
    // Directions: forward flexion of a hanging limb turns about -x; a knee bends about +x;
    // raising a limb sideways turns about s * z; the spine bends forward about +x.
    let forward = scale(X, -1.0);
    let elbow = |p: &mut PoseBuilder, n: &str, deg: f64| {
        p.bend(&format!("{n}_forearm"), Z, deg);
    };
    match index {
        1 => {
            for (n, s) in sides() {
                p.rot(&format!("{n}_upper_arm"), scale(Z, s), 90.0);
                elbow(p, n, 20.0);
            }
            p.rot("head", forward, -10.0);
        }
        2 => {
            p.rot("l_thigh", forward, 30.0);
            p.rot("l_shin", X, 15.0);
            p.rot("l_foot", forward, 10.0);
            p.rot("r_thigh", forward, -20.0);
            p.rot("r_shin", X, 40.0);
            p.rot("r_foot", forward, -15.0);
            p.rot("l_upper_arm", forward, -25.0);
            p.rot("r_upper_arm", forward, 25.0);
            elbow(p, "l", 15.0);
            elbow(p, "r", 30.0);
            p.rot("abdomen", Y, -6.0);
            p.rot("chest", Y, -6.0);
        }
        3 => {
            p.rot("r_thigh", forward, 80.0);
            p.rot("r_shin", X, 95.0);
            p.rot("l_upper_arm", forward, 20.0);
            elbow(p, "l", 100.0);
            p.rot("head", Y, 20.0);
        }
        4 => {
            for (n, _) in sides() {
                p.rot(&format!("{n}_thigh"), forward, 60.0);
                p.rot(&format!("{n}_shin"), X, 90.0);
                p.rot(&format!("{n}_foot"), forward, 30.0);
                p.rot(&format!("{n}_upper_arm"), forward, 45.0);
                elbow(p, n, 30.0);
            }
            p.rot("abdomen", X, 15.0);
            p.rot("chest", X, 10.0);
            p.rot("head", forward, 15.0);
        }
        5 => {
            p.rot("abdomen", Y, 20.0);
            p.rot("chest", Y, 20.0);
            p.rot("neck", Y, -15.0);
            p.rot("head", Y, -15.0);
            for (n, s) in sides() {
                p.rot(&format!("{n}_upper_arm"), scale(Z, s), 30.0);
                elbow(p, n, 30.0);
            }
            p.rot("l_thigh", forward, 10.0);
        }
        6 => {
            p.rot("chest", Z, 15.0);
            p.rot("abdomen", Z, 5.0);
            p.rot("l_upper_arm", Z, 110.0);
            elbow(p, "l", 25.0);
            p.rot("r_upper_arm", forward, 60.0);
            p.rot("r_thigh", scale(Z, -1.0), 25.0);
            p.rot("r_foot", forward, -20.0);
            p.rot("head", Z, 12.0);
        }
        _ => unreachable!("pose index checked by the caller"),
    }
}

/// Quadruped poses 1..=5: walking, sitting, tail raised, head lowered, paw raised while
/// looking aside.
fn quadruped_pose(p: &mut PoseBuilder, index: usize) {
    let forward = scale(X, -1.0);
    match index {
        1 => {
            // A trot: diagonal leg pairs swing together.
            p.rot("l_front_upper", forward, 25.0);
            p.rot("l_front_lower", X, 25.0);
            p.rot("r_front_upper", forward, -14.0);
            p.rot("r_hind_upper", forward, 14.0);
            p.rot("r_hind_lower", X, 10.0);
            p.rot("l_hind_upper", forward, -20.0);
            p.rot("tail_base", Y, 15.0);
            p.rot("tail_tip", Y, 15.0);
            p.rot("neck", X, 10.0);
        }
        2 => {
            // Sitting: the whole body pitches up about the hips, the hind legs fold under it
            // and the front legs turn back to the vertical.
            p.rot("hindquarters", forward, 30.0);
            for (n, _) in sides() {
                p.rot(&format!("{n}_hind_lower"), X, 40.0);
                p.rot(&format!("{n}_hind_foot"), forward, 35.0);
                p.rot(&format!("{n}_front_upper"), X, 30.0);
            }
            p.rot("neck", X, 20.0);
            p.rot("tail_base", X, 20.0);
        }
        3 => {
            p.rot("tail_base", X, 45.0);
            p.rot("tail_tip", X, 30.0);
            p.rot("neck", forward, 20.0);
            p.rot("head", forward, 15.0);
            p.rot("r_front_upper", forward, 15.0);
        }
        4 => {
            p.rot("neck", X, 55.0);
            p.rot("head", X, 20.0);
            p.rot("l_front_upper", Z, 10.0);
            p.rot("r_front_upper", Z, -10.0);
            p.rot("tail_base", X, -15.0);
        }
        5 => {
            p.rot("l_front_upper", forward, 40.0);
            p.rot("l_front_lower", X, 80.0);
            p.rot("neck", Y, 30.0);
            p.rot("head", Y, 15.0);
            p.rot("tail_base", Y, -30.0);
            p.rot("tail_tip", Y, -20.0);
        }
        _ => unreachable!("pose index checked by the caller"),
    }
}

/// Star poses 1..=5: limbs curled up, alternating up and down, per-limb bends, a pinwheel
/// (in-plane) bend, one limb raised high.
fn star_pose(p: &mut PoseBuilder, n: usize, index: usize) {
    for k in 0..n {
        let seg = |j: usize| format!("limb{k}_{j}");
        // The up-bend of a limb lifts it towards +y.
        let up = |p: &mut PoseBuilder, j: usize, deg: f64| p.bend(&seg(j), Y, deg);
        match index {
            1 => {
                for j in 0..3 {
                    up(p, j, 22.0);
                }
            }
            2 => {
                let s = if k % 2 == 0 { 1.0 } else { -1.0 };
                up(p, 0, 28.0 * s);
                up(p, 1, 20.0 * s);
                up(p, 2, 10.0 * s);
            }
            3 => {
                up(p, 0, 12.0 * (k % 4) as f64);
                up(p, 1, 20.0 * ((k + 1) % 3) as f64);
                up(p, 2, -15.0 * ((k + 2) % 3) as f64);
            }
            4 => {
                for j in 0..3 {
                    p.rot(&seg(j), Y, 15.0 + 5.0 * j as f64);
                }
            }
            5 => match k {
                0 => {
                    up(p, 0, 60.0);
                    up(p, 1, 40.0);
                    up(p, 2, 20.0);
                }
                _ if k == n / 2 => {
                    up(p, 0, -30.0);
                    up(p, 1, -15.0);
                }
                _ => up(p, 1, 10.0),
            },
            _ => unreachable!("pose index checked by the caller"),
        }
    }
}
