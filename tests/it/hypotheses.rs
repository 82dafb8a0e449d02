//! Region hypotheses verified at the map level (docs/design.md, 12.1) on generated figures, whose ground
//! truth is exact (one vertex order across poses and proportions): a mirrored one-to-one
//! answer never becomes a mixed map, hard pairs keep their parts, both directions agree,
//! and every verified answer carries a confidence.

use shapecorr::evaluation::{pointwise_errors, ErrorSummary};
use shapecorr::geodesic::HeatGeodesics;
use shapecorr::maps::hypotheses::HypothesisKind;
use shapecorr::maps::placement::{Guidance, Placement};
use shapecorr::maps::pointwise::{PointwiseMap, PointwiseParams};
use shapecorr::pipeline::{Correspondence, Params};
use shapecorr::synth::{self, FigureKind, FigureMesh, Proportions};
use shapecorr::ShapeBasis;
use shapecorr::{EigenParams, Eigenbasis, NoProgress, Shape};

fn meshes(
    kind: FigureKind,
    vertices: usize,
    body: Proportions,
    poses: &[usize],
) -> Vec<FigureMesh> {
    synth::figure_poses(kind, vertices, body, poses).unwrap()
}

fn shape(mesh: &FigureMesh) -> Shape {
    Shape::mesh(mesh.vertices.clone(), &mesh.triangles).unwrap()
}

fn basis(shape: &Shape) -> Eigenbasis {
    Eigenbasis::compute(
        shape,
        &EigenParams {
            n_eigenpairs: PointwiseParams::default().n_eigenpairs,
            ..Default::default()
        },
        &mut NoProgress,
    )
    .unwrap()
}

/// The pipeline's regions and map ([`shapecorr::pipeline::pointwise::regions_and_map`]).
fn regions_and_map(
    (a, basis_a): (&Shape, &Eigenbasis),
    (b, basis_b): (&Shape, &Eigenbasis),
    params: &Params,
) -> (Correspondence, PointwiseMap) {
    shapecorr::pipeline::pointwise::regions_and_map(
        ShapeBasis::new(a, basis_a),
        ShapeBasis::new(b, basis_b),
        params,
        &PointwiseParams::default(),
        &mut NoProgress,
    )
    .unwrap()
}

fn map_of(
    a: &Shape,
    ba: &Eigenbasis,
    b: &Shape,
    bb: &Eigenbasis,
    r: &Correspondence,
) -> PointwiseMap {
    guided_map((a, ba), (b, bb), r, &Guidance::default())
}

/// The map on the regions `r` with what the user knows (`guidance`).
fn guided_map(
    (a, ba): (&Shape, &Eigenbasis),
    (b, bb): (&Shape, &Eigenbasis),
    r: &Correspondence,
    guidance: &Guidance,
) -> PointwiseMap {
    PointwiseMap::guided(
        ShapeBasis::new(a, ba),
        ShapeBasis::new(b, bb),
        Some(r.matches_view()),
        &PointwiseParams::default(),
        guidance,
        &mut NoProgress,
    )
    .unwrap()
}

/// Mean geodesic error (unit-area A) of `p2p_ba` against the truth `(truth(v), v)` on every
/// third vertex of B.
fn error(a: &Shape, area_a: f64, n_b: usize, p2p_ba: &[u32], truth: &dyn Fn(u32) -> u32) -> f64 {
    let heat = HeatGeodesics::new(a).unwrap();
    let pairs: Vec<(u32, u32)> = (0..n_b as u32).step_by(3).map(|v| (truth(v), v)).collect();
    ErrorSummary::of(&pointwise_errors(&heat, area_a, &pairs, &[p2p_ba]).unwrap()[0]).mean
}

/// The generated humanoid at rest (A) and in pose 3 (B), 3,000 vertices each, one vertex
/// order (so `(v, v)` is the truth), with the pipeline's regions and map.
struct HumanoidPair {
    poses: Vec<FigureMesh>,
    /// A's vertex mirror images ([`synth::mirror_map`]).
    mirror: Vec<u32>,
    a: Shape,
    b: Shape,
    basis_a: Eigenbasis,
    basis_b: Eigenbasis,
    regions: Correspondence,
    map: PointwiseMap,
}

impl HumanoidPair {
    fn rest_and_pose_3() -> HumanoidPair {
        let poses = meshes(FigureKind::Humanoid, 3000, Proportions::default(), &[0, 3]);
        let mirror = synth::mirror_map(&poses[0]);
        let (a, b) = (shape(&poses[0]), shape(&poses[1]));
        let (basis_a, basis_b) = (basis(&a), basis(&b));
        let (regions, map) = regions_and_map((&a, &basis_a), (&b, &basis_b), &Params::default());
        HumanoidPair {
            poses,
            mirror,
            a,
            b,
            basis_a,
            basis_b,
            regions,
            map,
        }
    }
}

/// The one-to-one matches with A's side replaced by its mirror image: region `i` of A
/// becomes the region most of `i`'s mirrored vertices fall in.
fn mirrored_answer(regions: &Correspondence, mirror: &[u32]) -> Vec<(u32, u32)> {
    let labels = regions.regions_a();
    let n = regions.graph_a.n_nodes();
    let mut votes = vec![vec![0usize; n]; n];
    for (v, &m) in mirror.iter().enumerate() {
        votes[labels[v] as usize][labels[m as usize] as usize] += 1;
    }
    let image = |i: u32| {
        (0..n)
            .max_by_key(|&j| votes[i as usize][j])
            .unwrap_or(i as usize) as u32
    };
    let mut pairs: Vec<(u32, u32)> = regions
        .matches_one_to_one
        .iter()
        .map(|&(i, j)| (image(i), j))
        .collect();
    pairs.sort_unstable();
    pairs
}

/// A point cloud's cost tells an answer from its mirror image only as far as its normals
/// can be trusted; where the shapes stand alike, the placement can. B's pose as a cloud,
/// the answer forced to its mirror image: the mirror of that (the truth) is verified beside
/// it and taken, with no left/right flip left in the map.
#[test]
fn a_clouds_mirror_image_answer_is_undone_where_the_shapes_stand_alike() {
    let poses = meshes(FigureKind::Humanoid, 3000, Proportions::default(), &[0, 3]);
    let mirror = synth::mirror_map(&poses[0]);
    let a = shape(&poses[0]);
    let b = Shape::point_cloud(poses[1].vertices.clone()).unwrap();
    let (basis_a, basis_b) = (basis(&a), basis(&b));
    let (regions, _) = regions_and_map((&a, &basis_a), (&b, &basis_b), &Params::default());
    let mut forced = regions.clone();
    forced.matches_one_to_one = mirrored_answer(&regions, &mirror);
    forced.verdict = None;
    assert_ne!(forced.matches_one_to_one, regions.matches_one_to_one);
    let guidance = Guidance {
        placement: Placement::Trust,
        ..Default::default()
    };
    let map = guided_map((&a, &basis_a), (&b, &basis_b), &forced, &guidance);
    let verdict = map.verdict.as_ref().unwrap();
    let kinds: Vec<&HypothesisKind> = verdict.scores.iter().map(|s| &s.kind).collect();
    assert!(
        kinds.contains(&&HypothesisKind::Mirror),
        "verified: {kinds:?}"
    );
    let err = error(&a, basis_a.input_area, b.n_vertices(), &map.p2p_ba, &|v| v);
    println!(
        "humanoid 0 -> cloud 3, forced mirror image: {err:.4}, chose {:?}",
        verdict.chosen().kind
    );
    assert!(err < 0.05, "error without the flip {err}");
}

/// Where every region answer is wrong (as on TOSCA_r david10 -> david6, docs/placement.md,
/// "Landmarks"), two landmarks still give the right map: their own hypothesis, free of the
/// region answer. The regions of B are garbled (each match moved to the next region of B),
/// so the answer and every hypothesis built from it are wrong.
#[test]
fn two_landmarks_give_the_right_map_when_every_region_answer_is_wrong() {
    let HumanoidPair {
        poses,
        mirror,
        a,
        b,
        basis_a,
        basis_b,
        regions,
        ..
    } = HumanoidPair::rest_and_pose_3();
    let n_b = regions.graph_b.n_nodes() as u32;
    let garbled = |matches: &[(u32, u32)]| {
        let mut moved: Vec<(u32, u32)> = matches.iter().map(|&(i, j)| (i, (j + 1) % n_b)).collect();
        moved.sort_unstable();
        moved
    };
    let mut forced = regions.clone();
    forced.matches = garbled(&regions.matches);
    forced.matches_one_to_one = garbled(&regions.matches_one_to_one);
    forced.verdict = None;
    // Two vertices away from the plane of symmetry (one vertex order across poses: (v, v)
    // are true pairs): the one farthest from its mirror image, then the one farthest from
    // it and its mirror image.
    let p = &poses[0].vertices;
    let apart = |u: usize, v: usize| -> f64 { (0..3).map(|c| (p[u][c] - p[v][c]).powi(2)).sum() };
    let first = (0..p.len())
        .max_by(|&u, &v| apart(u, mirror[u] as usize).total_cmp(&apart(v, mirror[v] as usize)))
        .unwrap();
    let second = (0..p.len())
        .max_by(|&u, &v| {
            let far = |w| apart(w, first).min(apart(w, mirror[first] as usize));
            far(u).total_cmp(&far(v))
        })
        .unwrap();
    let landmarks = vec![[first as u32; 2], [second as u32; 2]];
    let map_with = |landmarks: Vec<[u32; 2]>| {
        let guidance = Guidance {
            placement: Placement::Ignore,
            landmarks,
            ..Default::default()
        };
        guided_map((&a, &basis_a), (&b, &basis_b), &forced, &guidance)
    };
    let err =
        |map: &PointwiseMap| error(&a, basis_a.input_area, b.n_vertices(), &map.p2p_ba, &|v| v);
    let (without, with) = (map_with(Vec::new()), map_with(landmarks.clone()));
    let verdict = with.verdict.as_ref().unwrap();
    println!(
        "humanoid 0 -> 3, garbled regions: without landmarks {:.4}, with two {:.4} ({:?})",
        err(&without),
        err(&with),
        verdict.chosen().kind
    );
    assert!(
        err(&without) > 0.1,
        "the garbled regions were not wrong: {}",
        err(&without)
    );
    assert_eq!(verdict.chosen().kind, HypothesisKind::Landmarks);
    assert!(err(&with) < 0.05, "error with two landmarks {}", err(&with));
    for [la, lb] in landmarks {
        assert_eq!(with.p2p_ba[lb as usize], la, "landmark {lb} not pinned");
    }
}

#[test]
fn a_forced_mirror_image_answer_gives_the_same_map() {
    let HumanoidPair {
        mirror,
        a,
        b,
        basis_a,
        basis_b,
        regions,
        map,
        ..
    } = HumanoidPair::rest_and_pose_3();
    let unforced = error(&a, basis_a.input_area, b.n_vertices(), &map.p2p_ba, &|v| v);
    // The same regions with the one-to-one answer forced to its mirror image: the map
    // verifies it as it verifies any answer.
    let mut forced = regions.clone();
    forced.matches_one_to_one = mirrored_answer(&regions, &mirror);
    forced.verdict = None;
    assert_ne!(forced.matches_one_to_one, regions.matches_one_to_one);
    let forced_map = map_of(&a, &basis_a, &b, &basis_b, &forced);
    let after = error(
        &a,
        basis_a.input_area,
        b.n_vertices(),
        &forced_map.p2p_ba,
        &|v| v,
    );
    println!("humanoid 0 -> 3: unforced {unforced:.4}, forced mirror image {after:.4}");
    assert!(unforced < 0.03, "unforced map error {unforced}");
    assert!(
        (after - unforced).abs() <= 0.1 * unforced,
        "forced {after} vs unforced {unforced}"
    );
    let confidence = regions.confidence().expect("the answer was verified");
    assert!((0.0..=1.0).contains(&confidence), "{confidence}");
}

/// A pose and a body.
type Side = (usize, Proportions);

/// Hard pairs with known truth: each must stay under the error bound, so a swapped part
/// (about 0.2 for a limb) fails.
#[test]
fn hard_generated_pairs_keep_their_parts() {
    let longer = Proportions {
        limb_length: 1.25,
        limb_thickness: 0.9,
        ..Default::default()
    };
    let cases: [(&str, FigureKind, Side, Side); 3] = [
        // Walking: front and back legs apart, of one length.
        (
            "quadruped walk -> paw raised",
            FigureKind::Quadruped,
            (1, Proportions::default()),
            (5, Proportions::default()),
        ),
        (
            "quadruped rest -> walk, longer legs",
            FigureKind::Quadruped,
            (0, Proportions::default()),
            (1, longer),
        ),
        (
            "humanoid stride -> twisted, longer limbs",
            FigureKind::Humanoid,
            (2, Proportions::default()),
            (6, longer),
        ),
    ];
    let mut failures = Vec::new();
    for (name, kind, (pose_a, body_a), (pose_b, body_b)) in cases {
        let a = shape(&meshes(kind, 3000, body_a, &[pose_a])[0]);
        let b = shape(&meshes(kind, 3000, body_b, &[pose_b])[0]);
        let (basis_a, basis_b) = (basis(&a), basis(&b));
        let (regions, map) = regions_and_map((&a, &basis_a), (&b, &basis_b), &Params::default());
        let e = error(&a, basis_a.input_area, b.n_vertices(), &map.p2p_ba, &|v| v);
        let confidence = regions.confidence();
        println!("{name}: mean error {e:.4}, confidence {confidence:?}");
        if e >= 0.05 {
            failures.push(format!("{name}: {e:.4}"));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

#[test]
fn a_noisy_point_cloud_is_mapped_or_cleanly_mirrored() {
    let poses = meshes(FigureKind::Humanoid, 3000, Proportions::default(), &[0, 4]);
    let mirror = synth::mirror_map(&poses[0]);
    let a = shape(&poses[0]);
    let cloud = synth::sample_points(&poses[1], 3000, 0.005, 7).unwrap();
    let b = Shape::point_cloud(cloud.points.clone()).unwrap();
    let (basis_a, basis_b) = (basis(&a), basis(&b));
    let (_, map) = regions_and_map((&a, &basis_a), (&b, &basis_b), &Params::default());
    let source = |v: u32| cloud.source_vertex[v as usize];
    let direct = error(&a, basis_a.input_area, b.n_vertices(), &map.p2p_ba, &source);
    let flipped = error(&a, basis_a.input_area, b.n_vertices(), &map.p2p_ba, &|v| {
        mirror[source(v) as usize]
    });
    println!("mesh -> noisy cloud: {direct:.4}, against the mirrored truth {flipped:.4}");
    // Orientation cannot be known on a cloud: one of the two is small, never both large.
    assert!(direct.min(flipped) < 0.06, "{direct} {flipped}");
}

#[test]
fn both_directions_give_inverse_maps() {
    let poses = meshes(FigureKind::Quadruped, 3000, Proportions::default(), &[0, 2]);
    let (a, b) = (shape(&poses[0]), shape(&poses[1]));
    let (basis_a, basis_b) = (basis(&a), basis(&b));
    let (_, ab) = regions_and_map((&a, &basis_a), (&b, &basis_b), &Params::default());
    let (_, ba) = regions_and_map((&b, &basis_b), (&a, &basis_a), &Params::default());
    // ab.p2p_ba: B -> A; ba.p2p_ba: A -> B. Both against the truth, and the round trip
    // B -> A -> B against the identity on B.
    let e_ab = error(&a, basis_a.input_area, b.n_vertices(), &ab.p2p_ba, &|v| v);
    let e_ba = error(&b, basis_b.input_area, a.n_vertices(), &ba.p2p_ba, &|v| v);
    let round_trip: Vec<u32> = (0..b.n_vertices())
        .map(|v| ba.p2p_ba[ab.p2p_ba[v] as usize])
        .collect();
    let e_round = error(&b, basis_b.input_area, b.n_vertices(), &round_trip, &|v| v);
    println!("A -> B {e_ab:.4}, B -> A {e_ba:.4}, round trip on B {e_round:.4}");
    assert!(e_ab < 0.05 && e_ba < 0.05, "{e_ab} {e_ba}");
    assert!(e_round <= e_ab + e_ba + 0.01, "round trip {e_round}");
}
