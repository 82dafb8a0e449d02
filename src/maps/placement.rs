//! Where the shapes stand (docs/placement.md): the rigid turn each verified hypothesis
//! implies between the two shapes' frames, whether that frame is informative, and a
//! hypothesis made from the frame itself (each vertex of B sent to the nearest point of A
//! after both are centred and scaled to unit area, as Smooth Shells starts from the
//! product of spectral and spatial coordinates).
//!
//! A human body is nearly symmetric under a half-turn (front and back swapped together with
//! left and right): no intrinsic energy separates the two maps, but the two shapes' frames
//! usually do. Shapes turned at random must give the intrinsic answer, so the frame is used
//! only when one competitive hypothesis implies almost no turn and every other answer a
//! large one ([`Placement::Auto`]).

use nalgebra::{Matrix3, Vector3};

use crate::shape::neighbors::PointTree;
use crate::shape::Shape;

/// How the two shapes' placement in space is used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Placement {
    /// Used when it is informative (one competitive answer implies at most
    /// [`NEAR_TURN`] degrees of turn and every other answer at least [`FAR_TURN`]);
    /// otherwise ignored.
    #[default]
    Auto,
    /// Never used: the answer depends on the shapes' intrinsic geometry only.
    Ignore,
    /// The shapes stand alike (one scene, one scanner rig): the competitive answer that
    /// implies the least turn is taken.
    Trust,
}

/// What the user knows beyond the shapes' geometry: how to use where they stand, landmark
/// pairs (vertices of the shapes a function is given, A's then B's), and whether one shape
/// is a part of the other.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Guidance {
    /// How the shapes' placement is used.
    pub placement: Placement,
    /// Landmark pairs ([`crate::maps::landmarks`]).
    pub landmarks: Vec<crate::maps::landmarks::Landmark>,
    /// When one shape is a part of the other, B's area over A's: the maps are then refined
    /// on the slanted diagonal of that slope ([`crate::maps::fmap::zoomout_sloped`]; with
    /// ZoomOut only). None for two whole shapes.
    pub part_slope: Option<f64>,
}

/// The names of [`Placement`]'s values, by value (0, 1, 2).
pub const PLACEMENT_NAMES: [&str; 3] = ["auto", "ignore", "trust"];

impl Placement {
    /// Every value, in the order of [`PLACEMENT_NAMES`].
    pub const ALL: [Placement; 3] = [Placement::Auto, Placement::Ignore, Placement::Trust];

    /// `auto`, `ignore` or `trust`.
    pub fn name(self) -> &'static str {
        PLACEMENT_NAMES[self as usize]
    }
}

/// A turn of at most this many degrees is "no turn" for [`Placement::Auto`]. On FAUST_r
/// (docs/placement.md) the true maps of 102 of 126 pairs imply 1-23 degrees; the other 24
/// (pose 8, a person turning round) 75-141. A uniformly random turn is within 30 degrees of
/// none with probability 0.75%.
pub const NEAR_TURN: f64 = 30.0;

/// Every answer giving another map must imply at least this many degrees, or at most
/// [`NEAR_TURN`], for the frame to be informative: an answer between the two leaves it
/// undecided. The half-turned answers measured imply 131-180 degrees (docs/placement.md);
/// at 150 the generated rig's pose 3 (the wrong answer at 144) stayed swapped.
pub const FAR_TURN: f64 = 100.0;

/// The hypothesis the frame picks must cost at most this many times the cheapest one: the
/// frame settles what the intrinsic energies leave nearly open, it does not overrule a clear
/// answer. Measured (docs/placement.md, "Choosing the rule"): the true answers the frame
/// must pick cost 1.03-1.26 times the cheapest (FAUST_r tr_reg_013 -> tr_reg_045, the
/// generated rig), the half-turned answers of a person turning round 1.49-1.66 times (three
/// FAUST_r pairs, all wrong at a ratio of 1.5 or more).
pub const PLACEMENT_COST_RATIO: f64 = 1.35;

/// When every region answer implies at least [`FAR_TURN`] and the frame's own map at most
/// [`NEAR_TURN`], [`Placement::Auto`] takes the frame's map if it costs at most this many
/// times the cheapest answer: the region stage has half-turned every answer (seen on
/// figures modelled in pieces, where the frame's map cost 2.0-2.9 times the cheapest and was
/// right, docs/decisions.md, "Shapes in pieces"). On the development pairs in their own
/// frames this happened once, at 7.9 times, with a right region answer; with B turned at
/// random it cost 22-98 times (20 FAUST_r pairs, docs/placement.md).
pub const FRAME_ONLY_COST_RATIO: f64 = 3.5;

/// The proper rotation `R` that best sends `from` onto `to` (`to[i] ~ R from[i] + t`, least
/// squares; Kabsch's method), as rows.
pub fn best_rotation(from: &[[f64; 3]], to: &[[f64; 3]]) -> [[f64; 3]; 3] {
    let n = from.len().min(to.len()).max(1) as f64;
    let centroid = |p: &[[f64; 3]]| {
        p.iter()
            .fold(Vector3::zeros(), |s, x| s + Vector3::from(*x))
            / n
    };
    let (cf, ct) = (centroid(from), centroid(to));
    let mut h = Matrix3::<f64>::zeros();
    for (p, q) in from.iter().zip(to) {
        h += (Vector3::from(*q) - ct) * (Vector3::from(*p) - cf).transpose();
    }
    let svd = h.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    };
    let d = (u * v_t).determinant().signum();
    let r =
        u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, if d == 0.0 { 1.0 } else { d })) * v_t;
    std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)]))
}

/// The angle of a rotation, in degrees (0 to 180).
pub fn turn_degrees(r: &[[f64; 3]; 3]) -> f64 {
    let trace = r[0][0] + r[1][1] + r[2][2];
    ((trace - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees()
}

/// The rotation a map implies: B's points `vertices_b` (rows `samples_b`) onto their images
/// `p2p` (vertices of A).
pub fn implied_rotation(
    vertices_a: &[[f64; 3]],
    vertices_b: &[[f64; 3]],
    samples_b: &[u32],
    p2p: &[u32],
) -> [[f64; 3]; 3] {
    let from: Vec<[f64; 3]> = samples_b.iter().map(|&v| vertices_b[v as usize]).collect();
    let to: Vec<[f64; 3]> = p2p.iter().map(|&x| vertices_a[x as usize]).collect();
    best_rotation(&from, &to)
}

/// The hypotheses as the frame sees them: each one's turn (degrees) and cost, which may be
/// picked (`eligible`: definite hypotheses), which one was made from the frame itself
/// (`from_frame`: its turn is no evidence), and whether two give different maps.
pub struct FrameView<'a> {
    /// The turn each hypothesis implies.
    pub turns: &'a [f64],
    /// Each hypothesis's cost.
    pub costs: &'a [f64],
    /// Whether a hypothesis may be picked.
    pub eligible: &'a dyn Fn(usize) -> bool,
    /// Whether a hypothesis was made from the frame ([`nearest_in_frame`]).
    pub from_frame: &'a dyn Fn(usize) -> bool,
    /// Whether two hypotheses give different maps.
    pub different: &'a dyn Fn(usize, usize) -> bool,
}

/// The hypothesis the frame picks. `Auto`: among the eligible hypotheses within
/// [`NEAR_TURN`] that cost at most [`PLACEMENT_COST_RATIO`] times the cheapest of all, the
/// cheapest region hypothesis (the frame's own only when no region hypothesis is there: on
/// FAUST its refined map was up to 0.026 less accurate than the region answer of the same
/// turn, docs/placement.md), provided every other hypothesis whose map differs implies at
/// most [`NEAR_TURN`] or at least [`FAR_TURN`]; with none within [`NEAR_TURN`], the frame's
/// own map as [`FRAME_ONLY_COST_RATIO`] says. `Trust`: among the eligible hypotheses
/// within the cost ratio, the cheapest within [`NEAR_TURN`] of the least turn. `Ignore`:
/// none.
pub fn frame_pick(mode: Placement, view: &FrameView<'_>) -> Option<usize> {
    let FrameView {
        turns,
        costs,
        eligible,
        from_frame,
        different,
    } = *view;
    let cheapest = costs.iter().copied().fold(f64::INFINITY, f64::min);
    let competitive = |h: usize| eligible(h) && costs[h] <= PLACEMENT_COST_RATIO * cheapest;
    let n = turns.len();
    let cheapest_of = |among: &dyn Fn(usize) -> bool| {
        (0..n)
            .filter(|&h| among(h))
            .min_by(|&x, &y| costs[x].total_cmp(&costs[y]).then(x.cmp(&y)))
    };
    match mode {
        Placement::Ignore => None,
        Placement::Trust => {
            // The least turn, and among the answers within NEAR_TURN of it the cheapest.
            let least = (0..n)
                .filter(|&h| competitive(h))
                .map(|h| turns[h])
                .fold(f64::INFINITY, f64::min);
            cheapest_of(&|h| competitive(h) && turns[h] <= least + NEAR_TURN)
        }
        Placement::Auto => {
            let near = |h: usize| competitive(h) && turns[h] <= NEAR_TURN;
            let Some(pick) =
                cheapest_of(&|h| near(h) && !from_frame(h)).or_else(|| cheapest_of(&near))
            else {
                // Every region answer half-turned, the frame's map not: the frame's map.
                let own = (0..n).find(|&h| eligible(h) && from_frame(h))?;
                let region_far = (0..n)
                    .filter(|&h| eligible(h) && !from_frame(h))
                    .all(|h| turns[h] >= FAR_TURN);
                let affordable = costs[own] <= FRAME_ONLY_COST_RATIO * cheapest;
                return (region_far && turns[own] <= NEAR_TURN && affordable).then_some(own);
            };
            let undecided = (0..n).any(|h| {
                !from_frame(h) && different(h, pick) && turns[h] > NEAR_TURN && turns[h] < FAR_TURN
            });
            (!undecided).then_some(pick)
        }
    }
}

/// The map the frame gives: every vertex of B to the nearest active vertex of A, both
/// centred on their area-weighted centroid and scaled to unit area (`mass_*`: the vertex
/// masses; `area_*`: the shapes' areas).
pub fn nearest_in_frame(
    (a, mass_a, area_a): (&Shape, &[f64], f64),
    (b, mass_b, area_b): (&Shape, &[f64], f64),
) -> Vec<u32> {
    let normalised = |shape: &Shape, mass: &[f64], area: f64| -> Vec<[f64; 3]> {
        let total: f64 = mass.iter().sum::<f64>().max(1e-300);
        let mut c = [0.0; 3];
        for (p, m) in shape.vertices().iter().zip(mass) {
            for k in 0..3 {
                c[k] += p[k] * m / total;
            }
        }
        let s = 1.0 / area.max(1e-300).sqrt();
        shape
            .vertices()
            .iter()
            .map(|p| std::array::from_fn(|k| (p[k] - c[k]) * s))
            .collect()
    };
    let (va, vb) = (normalised(a, mass_a, area_a), normalised(b, mass_b, area_b));
    let active = a.active_vertices();
    let tree = PointTree::new(&active.iter().map(|&v| va[v as usize]).collect::<Vec<_>>());
    vb.iter().map(|p| active[tree.nearest(p)]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rotation_z(degrees: f64) -> [[f64; 3]; 3] {
        let (s, c) = degrees.to_radians().sin_cos();
        [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    }

    fn apply(r: &[[f64; 3]; 3], p: &[f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| (0..3).map(|j| r[i][j] * p[j]).sum())
    }

    #[test]
    fn the_best_rotation_recovers_a_turn() {
        let points: Vec<[f64; 3]> = (0..50)
            .map(|i| {
                let t = i as f64;
                [
                    t.sin() * 2.0,
                    (t * 0.7).cos(),
                    (t * 0.3).sin() * 0.5 + t * 0.01,
                ]
            })
            .collect();
        for degrees in [0.0, 20.0, 90.0, 179.0] {
            let r = rotation_z(degrees);
            let turned: Vec<[f64; 3]> = points
                .iter()
                .map(|p| {
                    let q = apply(&r, p);
                    [q[0] + 5.0, q[1] - 1.0, q[2]]
                })
                .collect();
            let found = best_rotation(&points, &turned);
            assert!((turn_degrees(&found) - degrees).abs() < 1e-6, "{degrees}");
        }
    }

    #[test]
    fn auto_takes_a_region_answer_before_the_frames_own_map() {
        let (yes, differ) = (|_: usize| true, |h: usize, g: usize| h != g);
        let own = |h: usize| h == 2;
        let view = |turns: &'static [f64]| FrameView {
            turns,
            costs: &[1.0, 1.2, 0.9],
            eligible: &yes,
            from_frame: &own,
            different: &differ,
        };
        // The frame's own map is cheaper, but a region answer stands near it.
        assert_eq!(
            frame_pick(Placement::Auto, &view(&[170.0, 10.0, 5.0])),
            Some(1)
        );
        // No region answer near no turn: the frame's own map.
        assert_eq!(
            frame_pick(Placement::Auto, &view(&[170.0, 175.0, 5.0])),
            Some(2)
        );
    }

    #[test]
    fn auto_uses_the_frame_only_when_it_separates_the_answers() {
        let yes = |_: usize| true;
        let no = |_: usize| false;
        let differ = |h: usize, g: usize| h != g;
        let pick = |mode, turns: &[f64], costs: &[f64]| {
            frame_pick(
                mode,
                &FrameView {
                    turns,
                    costs,
                    eligible: &yes,
                    from_frame: &no,
                    different: &differ,
                },
            )
        };
        let costs = [1.0, 1.1, 1.2];
        // The cheapest answer is half-turned, a near-identity rival within the cost ratio.
        assert_eq!(pick(Placement::Auto, &[178.0, 5.0, 160.0], &costs), Some(1));
        // An answer between the two thresholds: undecided.
        assert_eq!(pick(Placement::Auto, &[60.0, 5.0, 160.0], &costs), None);
        // No answer near no turn (shapes turned at random): nothing.
        assert_eq!(pick(Placement::Auto, &[120.0, 140.0, 160.0], &costs), None);
        // Too costly to be picked.
        assert_eq!(pick(Placement::Auto, &[178.0, 5.0], &[1.0, 3.5]), None);
        assert_eq!(
            pick(Placement::Trust, &[120.0, 60.0, 160.0], &costs),
            Some(1)
        );
        // Trust: two answers of about the same least turn, the cheaper one.
        assert_eq!(pick(Placement::Trust, &[9.0, 8.0, 160.0], &costs), Some(0));
        assert_eq!(pick(Placement::Ignore, &[178.0, 5.0, 160.0], &costs), None);
    }
}
