//! The whole region-correspondence pipeline on generated figures with known ground truth.

use shapecorr::evaluation::{score_correspondence, RegionScores};
use shapecorr::pipeline::{Correspondence, Params, Symmetry};
use shapecorr::synth::{self, FigureKind, FigureMesh, FigureSpec, Proportions};
use shapecorr::ShapeBasis;
use shapecorr::{EigenParams, Eigenbasis, Error, NoProgress, Shape, Stage};

fn humanoid(pose: usize, vertices: usize, proportions: Proportions) -> FigureMesh {
    synth::figure(&FigureSpec {
        kind: FigureKind::Humanoid,
        pose,
        target_vertices: vertices,
        proportions,
        ..Default::default()
    })
    .unwrap()
}

/// Scores of A -> B with ground-truth pairs `(vertex of A, vertex of B)`; the flipped truth
/// mirrors A's side.
fn run(
    a: &Shape,
    b: &Shape,
    truth: &[(u32, u32)],
    mirror_a: &[u32],
) -> (Correspondence, RegionScores) {
    let params = Params::default();
    let basis_a = Eigenbasis::compute(a, &params.eigen, &mut NoProgress).unwrap();
    let basis_b = Eigenbasis::compute(b, &params.eigen, &mut NoProgress).unwrap();
    let result = Correspondence::from_bases(
        ShapeBasis::new(a, &basis_a),
        ShapeBasis::new(b, &basis_b),
        &params,
        &mut NoProgress,
    )
    .unwrap();
    let flipped: Vec<(u32, u32)> = truth
        .iter()
        .map(|&(x, y)| (mirror_a[x as usize], y))
        .collect();
    let scores = score_correspondence(&result, &basis_a.mass, &basis_b.mass, truth, Some(&flipped));
    println!("{scores:?}, k = {}", result.k);
    (result, scores)
}

fn identity(n: usize) -> Vec<(u32, u32)> {
    (0..n as u32).map(|v| (v, v)).collect()
}

#[test]
fn humanoids_in_different_poses_match_region_by_region() {
    let rest = humanoid(0, 5000, Proportions::default());
    let mirror = synth::mirror_map(&rest);
    let a = Shape::mesh(rest.vertices.clone(), &rest.triangles).unwrap();
    for pose in [2, 4] {
        let posed = humanoid(pose, 5000, Proportions::default());
        let b = Shape::mesh(posed.vertices, &posed.triangles).unwrap();
        let (result, s) = run(&a, &b, &identity(a.n_vertices()), &mirror);
        assert!(
            result.graph_a.n_nodes() >= 6,
            "too few regions to mean anything"
        );
        assert!(
            s.symmetric >= 0.95,
            "pose {pose}: symmetric accuracy {}",
            s.symmetric
        );
        let flip = s.one_to_one_flip.unwrap();
        assert!(flip >= 0.90, "pose {pose}: one-to-one (flip ok) {flip}");
    }
}

#[test]
fn other_proportions_and_a_noisy_point_cloud_still_match() {
    let rest = humanoid(0, 5000, Proportions::default());
    let mirror = synth::mirror_map(&rest);
    let a = Shape::mesh(rest.vertices.clone(), &rest.triangles).unwrap();
    // B: longer, thinner limbs in another pose, sampled as a noisy point cloud.
    let other = humanoid(
        3,
        5000,
        Proportions {
            limb_length: 1.15,
            limb_thickness: 0.85,
            ..Default::default()
        },
    );
    let cloud = synth::sample_points(&other, 5000, 0.005, 7).unwrap();
    let b = Shape::point_cloud(cloud.points).unwrap();
    let truth: Vec<(u32, u32)> = cloud
        .source_vertex
        .iter()
        .enumerate()
        .map(|(p, &v)| (v, p as u32))
        .collect();
    let (_, s) = run(&a, &b, &truth, &mirror);
    assert!(s.symmetric >= 0.85, "symmetric accuracy {}", s.symmetric);
    let flip = s.one_to_one_flip.unwrap();
    assert!(flip >= 0.85, "one-to-one (flip ok) {flip}");
}

#[test]
fn a_permuted_copy_gives_the_permuted_regions_and_swapping_transposes() {
    let rest = humanoid(0, 3000, Proportions::default());
    let posed = humanoid(2, 3000, Proportions::default());
    let a = Shape::mesh(rest.vertices.clone(), &rest.triangles).unwrap();
    let b = Shape::mesh(posed.vertices.clone(), &posed.triangles).unwrap();
    let params = Params::default();
    let ab = Correspondence::compute(&a, &b, &params, &mut NoProgress).unwrap();

    // Permute B's vertices: new vertex i is old vertex perm[i].
    let n = b.n_vertices();
    let perm: Vec<usize> = (0..n).map(|i| (i * 7919 + 13) % n).collect();
    assert!(
        !n.is_multiple_of(7919),
        "7919 is prime: coprime to n, so this is a permutation"
    );
    let mut inverse = vec![0u32; n];
    for (new, &old) in perm.iter().enumerate() {
        inverse[old] = new as u32;
    }
    let vertices: Vec<[f64; 3]> = perm.iter().map(|&old| posed.vertices[old]).collect();
    let triangles: Vec<[u32; 3]> = posed
        .triangles
        .iter()
        .map(|t| t.map(|v| inverse[v as usize]))
        .collect();
    let b_permuted = Shape::mesh(vertices, &triangles).unwrap();
    let ab2 = Correspondence::compute(&a, &b_permuted, &params, &mut NoProgress).unwrap();
    assert_eq!(ab.k, ab2.k);
    assert_eq!(ab.regions_a(), ab2.regions_a());
    // Regions of B compared up to relabelling: map old labels to new labels.
    let mut relabel = vec![u32::MAX; ab.graph_b.n_nodes()];
    for (new, &old) in perm.iter().enumerate() {
        let (l_old, l_new) = (ab.regions_b()[old], ab2.regions_b()[new]);
        if relabel[l_old as usize] == u32::MAX {
            relabel[l_old as usize] = l_new;
        }
        assert_eq!(
            relabel[l_old as usize], l_new,
            "regions differ beyond relabelling"
        );
    }
    let mut mapped: Vec<(u32, u32)> = ab
        .matches
        .iter()
        .map(|&(i, j)| (i, relabel[j as usize]))
        .collect();
    mapped.sort_unstable();
    assert_eq!(mapped, ab2.matches);

    // Swapping A and B transposes the symmetric matches.
    let ba = Correspondence::compute(&b, &a, &params, &mut NoProgress).unwrap();
    assert_eq!(ba.regions_a(), ab.regions_b());
    assert_eq!(ba.regions_b(), ab.regions_a());
    let mut transposed: Vec<(u32, u32)> = ab.matches.iter().map(|&(i, j)| (j, i)).collect();
    transposed.sort_unstable();
    assert_eq!(ba.matches, transposed);
}

#[test]
fn symmetry_detection_groups_the_limbs_of_a_star() {
    let star = synth::figure(&FigureSpec {
        kind: FigureKind::Star { limbs: 5 },
        target_vertices: 4000,
        ..Default::default()
    })
    .unwrap();
    let shape = Shape::mesh(star.vertices.clone(), &star.triangles).unwrap();
    let symmetry = Symmetry::detect(&shape, &Params::default(), &mut NoProgress).unwrap();
    // Limb tips: vertices farthest from the centre in each of the 5 directions.
    let centre = star
        .vertices
        .iter()
        .fold([0.0; 3], |c, p| [c[0] + p[0], c[1] + p[1], c[2] + p[2]]);
    let n = star.vertices.len() as f64;
    let centre = [centre[0] / n, centre[1] / n, centre[2] / n];
    let tip = star
        .vertices
        .iter()
        .enumerate()
        .max_by(|(_, p), (_, q)| {
            let d = |v: &[f64; 3]| {
                (v[0] - centre[0]).powi(2) + (v[1] - centre[1]).powi(2) + (v[2] - centre[2]).powi(2)
            };
            d(p).total_cmp(&d(q))
        })
        .unwrap()
        .0;
    let tip_region = symmetry.graph.labels[tip];
    let group = symmetry
        .groups
        .iter()
        .find(|g| g.contains(&tip_region))
        .unwrap();
    assert_eq!(
        group.len(),
        5,
        "the limb-tip regions form one group of 5: {:?}",
        symmetry.groups
    );
    // Regression (the symmetry command coloured only the first region of each group and
    // left the others dark grey): every region of the limb group has the group's colour.
    let colors = symmetry.vertex_colors();
    let group_colour = colors[tip];
    assert_ne!(group_colour, shapecorr::colors::UNMATCHED_COLOR);
    for (v, &region) in symmetry.graph.labels.iter().enumerate() {
        if group.contains(&region) {
            assert_eq!(colors[v], group_colour, "vertex {v} in region {region}");
        } else {
            assert_ne!(colors[v], group_colour, "vertex {v} outside the limb group");
        }
    }
}

#[test]
fn symmetry_detection_pairs_left_and_right_limbs_of_a_humanoid() {
    let rest = humanoid(0, 4000, Proportions::default());
    let shape = Shape::mesh(rest.vertices.clone(), &rest.triangles).unwrap();
    let symmetry = Symmetry::detect(&shape, &Params::default(), &mut NoProgress).unwrap();
    // The hands: the vertices with the largest and smallest x.
    let by_x = |sign: f64| {
        rest.vertices
            .iter()
            .enumerate()
            .max_by(|(_, p), (_, q)| (sign * p[0]).total_cmp(&(sign * q[0])))
            .unwrap()
            .0
    };
    let (left, right) = (
        symmetry.graph.labels[by_x(1.0)],
        symmetry.graph.labels[by_x(-1.0)],
    );
    assert_ne!(left, right, "the two hands are different regions");
    let group = symmetry.groups.iter().find(|g| g.contains(&left)).unwrap();
    assert!(
        group.contains(&right),
        "left and right hands pair up: {:?}",
        symmetry.groups
    );
}

#[test]
fn cancelling_stops_the_pipeline_promptly() {
    let rest = humanoid(0, 3000, Proportions::default());
    let posed = humanoid(1, 3000, Proportions::default());
    let a = Shape::mesh(rest.vertices, &rest.triangles).unwrap();
    let b = Shape::mesh(posed.vertices, &posed.triangles).unwrap();
    for cancel_at in [
        Stage::Eigenbasis,
        Stage::Segmentation,
        Stage::Matching,
        Stage::SymmetryBreaking,
    ] {
        // Promptly = no stage reports progress after the one that was cancelled (a count,
        // not a wall-clock bound, so a loaded machine cannot fail it).
        let (mut cancelled, mut calls_after) = (false, 0);
        let mut progress = |stage: Stage, _f: f32| {
            calls_after += usize::from(cancelled);
            cancelled |= stage == cancel_at;
            stage != cancel_at
        };
        let result = Correspondence::compute(&a, &b, &Params::default(), &mut progress);
        assert!(
            matches!(result, Err(Error::Cancelled)),
            "{cancel_at:?}: {:?}",
            result.map(|r| r.k)
        );
        assert_eq!(
            calls_after, 0,
            "{cancel_at:?}: progress went on after cancelling"
        );
    }
}

#[test]
fn identical_results_for_identical_inputs_on_any_thread_count() {
    let rest = humanoid(0, 3000, Proportions::default());
    let posed = humanoid(5, 3000, Proportions::default());
    let a = Shape::mesh(rest.vertices, &rest.triangles).unwrap();
    let b = Shape::mesh(posed.vertices, &posed.triangles).unwrap();
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let params = Params {
                    eigen: EigenParams {
                        threads,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                Correspondence::compute(&a, &b, &params, &mut NoProgress).unwrap()
            })
    };
    let one = on(1);
    let two = on(2);
    assert_eq!(one.regions_a(), two.regions_a());
    assert_eq!(one.regions_b(), two.regions_b());
    assert_eq!(one.matches, two.matches);
    assert_eq!(one.matches_one_to_one, two.matches_one_to_one);
}

#[test]
fn cancelling_inside_the_k_loop_stops_the_segmentation() {
    let rest = humanoid(0, 3000, Proportions::default());
    let posed = humanoid(1, 3000, Proportions::default());
    let a = Shape::mesh(rest.vertices, &rest.triangles).unwrap();
    let b = Shape::mesh(posed.vertices, &posed.triangles).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let mut reports = Vec::new();
    let result = pool.install(|| {
        let mut progress = |stage: Stage, fraction: f32| {
            if stage == Stage::Segmentation {
                reports.push(fraction);
            }
            !(stage == Stage::Segmentation && fraction > 0.0)
        };
        Correspondence::compute(&a, &b, &Params::default(), &mut progress)
    });
    assert!(matches!(result, Err(Error::Cancelled)));
    // Reports while the first batch of k values runs (every 25 ms, docs/decisions.md, "Cancellation within 0.2 s"), then the
    // first report past it cancels; nothing after the cancel.
    let cancelled_at = reports
        .iter()
        .position(|&f| f > 0.0)
        .expect("a report past 0");
    assert_eq!(cancelled_at, reports.len() - 1, "{reports:?}");
    assert!(reports[cancelled_at] < 1.0, "{reports:?}");
}

/// A small three-limbed star (about 600 vertices) for the awkward inputs below.
fn small_star() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let star = synth::figure(&FigureSpec {
        kind: FigureKind::Star { limbs: 3 },
        target_vertices: 600,
        ..Default::default()
    })
    .unwrap();
    (star.vertices, star.triangles)
}

#[test]
fn awkward_but_valid_inputs_give_an_answer_or_a_typed_error_never_a_panic() {
    let (v, f) = small_star();
    let n = v.len() as u32;
    // Two separate copies plus unreferenced vertices.
    let mut vertices = v.clone();
    vertices.extend(v.iter().map(|p| [p[0] + 10.0, p[1], p[2]]));
    vertices.extend([[50.0, 0.0, 0.0], [0.0, 50.0, 0.0]]);
    let mut faces = f.clone();
    faces.extend(f.iter().map(|t| t.map(|i| i + n)));
    let two_pieces = Shape::mesh(vertices, &faces).unwrap();
    let single = Shape::mesh(v.clone(), &f).unwrap();
    // A point cloud with repeated points.
    let mut points = v.clone();
    points.extend_from_slice(&v[..50]);
    let cloud = Shape::point_cloud(points).unwrap();
    // The smallest shape the library accepts.
    let tiny_points: Vec<[f64; 3]> = v.iter().step_by(v.len() / 40).take(40).copied().collect();
    let tiny = Shape::point_cloud(tiny_points).unwrap();

    let params = Params::default();
    for (name, a, b) in [
        ("two pieces vs one", &two_pieces, &single),
        ("mesh vs cloud with duplicates", &single, &cloud),
        ("tiny cloud vs mesh", &tiny, &single),
    ] {
        match Correspondence::compute(a, b, &params, &mut NoProgress) {
            Ok(result) => {
                println!("{name}: k = {}, {} matches", result.k, result.matches.len());
                assert_eq!(result.regions_a().len(), a.n_vertices(), "{name}");
                assert_eq!(result.regions_b().len(), b.n_vertices(), "{name}");
                let n_a = result.graph_a.n_nodes() as u32;
                assert!(result.regions_a().iter().all(|&r| r < n_a), "{name}");
                for &(i, j) in &result.matches_one_to_one {
                    assert!(result.matches.contains(&(i, j)), "{name}");
                }
            }
            Err(e) => assert!(
                matches!(e, Error::InvalidParameter { .. } | Error::Numerical { .. }),
                "{name}: {e}"
            ),
        }
    }
}

/// An answer with no region matched is an error that names `gap_ratio` (a tiny gap ratio
/// leaves every region with more candidates than `max_symmetry_order`), never a success
/// with zero matches; 0 is in the option's range [0, 1] and fails the same way.
#[test]
fn no_matched_region_is_an_error_naming_gap_ratio() {
    let a = humanoid(0, 800, Proportions::default());
    let b = humanoid(3, 800, Proportions::default());
    let a = Shape::mesh(a.vertices, &a.triangles).unwrap();
    let b = Shape::mesh(b.vertices, &b.triangles).unwrap();
    for gap_ratio in [1e-20, 0.0] {
        let mut params = Params {
            verify_hypotheses: false,
            ..Params::default()
        };
        params.matching.gap_ratio = gap_ratio;
        let err = Correspondence::compute(&a, &b, &params, &mut NoProgress).unwrap_err();
        assert!(
            matches!(
                err,
                Error::InvalidParameter {
                    name: "gap_ratio",
                    ..
                }
            ),
            "{err}"
        );
        let message = err.to_string();
        assert!(message.contains("no region") && message.contains("max_symmetry_order"));
    }
    let params = Params {
        verify_hypotheses: false,
        ..Params::default()
    };
    let result = Correspondence::compute(&a, &b, &params, &mut NoProgress).unwrap();
    assert!(!result.matches.is_empty());
}
