//! Joint segmentation (`shapecorr::regions::segmentation`): rank alignment, weighted joint k-means,
//! shape graphs on generated figures, the choice of k on two poses, and (ignored, needs
//! the FAUST data) the figures on real scans.

use crate::common;

use std::collections::HashMap;
use std::path::Path;
use std::time::Instant;

use common::permutation;
use faer::{Mat, MatRef};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shapecorr::regions::graph::ShapeGraph;
use shapecorr::regions::segmentation::Described;
use shapecorr::regions::segmentation::{
    joint_kmeans, joint_kmeans_with, rank_align, segment_pair, shape_graph, shape_graph_with,
    GraphParams, JointClustering, KMeansMetric, KMeansParams, KTieBreak, RegionExpansion,
    SegmentationParams,
};
use shapecorr::spectral::descriptors::{hks, HksParams};
use shapecorr::synth::{figure, figure_poses, FigureKind, FigureSpec, Proportions};
use shapecorr::NoProgress;
use shapecorr::ReadAs;
use shapecorr::{EigenParams, Eigenbasis, Shape};

/// One shape as `segment_pair` reads it.
fn described<'a>(shape: &'a Shape, mass: &'a [f64], descriptors: MatRef<'a, f64>) -> Described<'a> {
    Described {
        shape,
        mass,
        descriptors,
    }
}

// ---------------------------------------------------------------------------------------
// Helpers

fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

fn column(values: &[f64]) -> Mat<f64> {
    Mat::from_fn(values.len(), 1, |i, _| values[i])
}

fn col(m: &Mat<f64>, j: usize) -> Vec<f64> {
    (0..m.nrows()).map(|i| m[(i, j)]).collect()
}

fn assert_close(a: &[f64], b: &[f64]) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() < 1e-12, "{a:?} vs {b:?}");
    }
}

/// Weighted CDF `sum_i w_i [x_i <= t] / sum_i w_i`.
fn cdf(values: &[f64], weights: &[f64], t: f64) -> f64 {
    let total: f64 = weights.iter().sum();
    values
        .iter()
        .zip(weights)
        .filter(|(&x, _)| x <= t)
        .map(|(_, &w)| w)
        .sum::<f64>()
        / total
}

/// True when two labelings are the same partition (equal up to renaming the labels).
fn same_partition(a: &[u32], b: &[u32]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let mut forward = HashMap::new();
    let mut backward = HashMap::new();
    a.iter()
        .zip(b)
        .all(|(&x, &y)| *forward.entry(x).or_insert(y) == y && *backward.entry(y).or_insert(x) == x)
}

/// A shape with its eigenbasis mass and HKS.
struct Prepared {
    shape: Shape,
    mass: Vec<f64>,
    hks: Mat<f64>,
}

fn prepare(shape: Shape) -> Prepared {
    let basis = Eigenbasis::compute(&shape, &EigenParams::default(), &mut NoProgress).unwrap();
    let hks = hks(&basis, &HksParams::default()).unwrap();
    Prepared {
        shape,
        mass: basis.mass,
        hks,
    }
}

fn figure_shape(kind: FigureKind, pose: usize, vertices: usize) -> Shape {
    let mesh = figure(&FigureSpec {
        kind,
        pose,
        target_vertices: vertices,
        ..Default::default()
    })
    .unwrap();
    Shape::mesh(mesh.vertices, &mesh.triangles).unwrap()
}

/// Checks the invariants every shape graph must satisfy.
fn check_graph(shape: &Shape, mass: &[f64], graph: &ShapeGraph) {
    let n = shape.n_vertices();
    let n_nodes = graph.n_nodes();
    assert_eq!(graph.labels.len(), n);
    assert!(graph.labels.iter().all(|&l| (l as usize) < n_nodes));
    let mut used = vec![false; n_nodes];
    for &l in &graph.labels {
        used[l as usize] = true;
    }
    assert!(used.iter().all(|&u| u), "a node has no vertex");
    assert_eq!(graph.node_area.len(), n_nodes);
    assert_eq!(graph.node_descriptor.len(), n_nodes);
    let total: f64 = graph.node_area.iter().sum();
    assert!((total - 1.0).abs() < 1e-9, "node areas sum to {total}");
    // Node area is the mass of its vertices.
    let mass_total: f64 = mass.iter().sum();
    let mut area = vec![0.0; n_nodes];
    for (v, &l) in graph.labels.iter().enumerate() {
        area[l as usize] += mass[v] / mass_total;
    }
    for (a, b) in area.iter().zip(&graph.node_area) {
        assert!((a - b).abs() < 1e-9);
    }
    // Edges sorted, i < j, unique.
    assert!(graph.edges.windows(2).all(|w| w[0] < w[1]));
    assert!(graph
        .edges
        .iter()
        .all(|&(i, j)| i < j && (j as usize) < n_nodes));
    // Every node's region is connected on the mesh (over the active vertices).
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for (u, v) in shape.edges() {
        if graph.labels[u as usize] == graph.labels[v as usize] {
            let (ru, rv) = (find(&mut parent, u as usize), find(&mut parent, v as usize));
            parent[ru.max(rv)] = ru.min(rv);
        }
    }
    let mut root_of_node = vec![usize::MAX; n_nodes];
    for &v in shape.active_vertices() {
        let node = graph.labels[v as usize] as usize;
        let root = find(&mut parent, v as usize);
        if root_of_node[node] == usize::MAX {
            root_of_node[node] = root;
        }
        assert_eq!(root_of_node[node], root, "node {node} is not connected");
    }
}

/// Area of A whose vertex i lies, on B, in a node of the same joint cluster (vertex i of A
/// corresponds to vertex i of B).
fn region_consistency(
    mass_a: &[f64],
    graph_a: &ShapeGraph,
    graph_b: &ShapeGraph,
    a_to_b: &[usize],
) -> f64 {
    let total: f64 = mass_a.iter().sum();
    mass_a
        .iter()
        .enumerate()
        .filter(|&(i, _)| {
            graph_a.node_cluster[graph_a.labels[i] as usize]
                == graph_b.node_cluster[graph_b.labels[a_to_b[i]] as usize]
        })
        .map(|(_, &m)| m)
        .sum::<f64>()
        / total
}

fn degree_histogram(g: &ShapeGraph) -> Vec<usize> {
    let mut h = Vec::new();
    for d in g.degrees() {
        if h.len() <= d {
            h.resize(d + 1, 0);
        }
        h[d] += 1;
    }
    h
}

// ---------------------------------------------------------------------------------------
// Rank alignment

#[test]
fn rank_align_of_an_increasing_function_gives_back_the_reference() {
    let mut r = rng(1);
    let n = 700;
    let reference: Vec<f64> = (0..n).map(|_| r.random::<f64>() * 3.0 - 1.0).collect();
    let mass: Vec<f64> = (0..n).map(|_| 0.2 + r.random::<f64>()).collect();
    // Other = exp(3 x) + 5 in a permuted order, same masses.
    let perm = permutation(n, 7);
    let other: Vec<f64> = perm
        .iter()
        .map(|&i| (3.0 * reference[i]).exp() + 5.0)
        .collect();
    let other_mass: Vec<f64> = perm.iter().map(|&i| mass[i]).collect();
    let aligned = rank_align(
        column(&reference).as_ref(),
        &mass,
        column(&other).as_ref(),
        &other_mass,
    );
    for (row, &i) in perm.iter().enumerate() {
        assert!(
            (aligned[(row, 0)] - reference[i]).abs() < 1e-12,
            "row {row}: {} vs {}",
            aligned[(row, 0)],
            reference[i]
        );
    }
}

#[test]
fn rank_align_output_has_the_reference_area_cdf_and_is_monotone() {
    let mut r = rng(2);
    let (n_ref, n_other, d) = (900, 1300, 3);
    let reference = Mat::from_fn(n_ref, d, |_, j| r.random::<f64>().powi(j as i32 + 1));
    let ref_mass: Vec<f64> = (0..n_ref).map(|_| r.random::<f64>() + 0.1).collect();
    let other = Mat::from_fn(n_other, d, |_, j| {
        (r.random::<f64>() * 10.0).sin() * (j + 1) as f64
    });
    let other_mass: Vec<f64> = (0..n_other)
        .map(|i| {
            if i % 10 == 0 {
                0.0
            } else {
                r.random::<f64>() + 0.5
            }
        })
        .collect();
    let aligned = rank_align(reference.as_ref(), &ref_mass, other.as_ref(), &other_mass);
    let max_ref = ref_mass.iter().cloned().fold(0.0, f64::max) / ref_mass.iter().sum::<f64>();
    let max_other = other_mass.iter().cloned().fold(0.0, f64::max) / other_mass.iter().sum::<f64>();
    for j in 0..d {
        let (rv, ov, av) = (col(&reference, j), col(&other, j), col(&aligned, j));
        // Every output value lies in the reference's range.
        let lo = rv.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = rv.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        assert!(av.iter().all(|&x| x >= lo && x <= hi));
        // Monotone: a larger input never gets a smaller output.
        let mut order: Vec<usize> = (0..n_other).collect();
        order.sort_by(|&x, &y| ov[x].total_cmp(&ov[y]));
        assert!(order.windows(2).all(|w| av[w[0]] <= av[w[1]]));
        // Area CDFs agree up to one point's mass on each side.
        for step in 0..=50 {
            let t = lo + (hi - lo) * step as f64 / 50.0;
            let gap = (cdf(&rv, &ref_mass, t) - cdf(&av, &other_mass, t)).abs();
            assert!(
                gap <= max_ref + max_other + 1e-12,
                "column {j}, t = {t}: CDF gap {gap}"
            );
        }
    }
}

#[test]
fn rank_align_is_invariant_to_vertex_permutation_and_counts_mass() {
    let mut r = rng(3);
    let n = 400;
    // Few distinct values, so that ties matter.
    let reference = Mat::from_fn(n, 2, |_, _| (r.random::<f64>() * 20.0).floor());
    let ref_mass: Vec<f64> = (0..n).map(|_| r.random::<f64>()).collect();
    let other = Mat::from_fn(n, 2, |_, _| (r.random::<f64>() * 30.0).floor());
    let other_mass: Vec<f64> = (0..n).map(|_| r.random::<f64>()).collect();
    let base = rank_align(reference.as_ref(), &ref_mass, other.as_ref(), &other_mass);

    let p = permutation(n, 11);
    let q = permutation(n, 12);
    let ref_p = Mat::from_fn(n, 2, |i, j| reference[(p[i], j)]);
    let ref_mass_p: Vec<f64> = p.iter().map(|&i| ref_mass[i]).collect();
    let other_q = Mat::from_fn(n, 2, |i, j| other[(q[i], j)]);
    let other_mass_q: Vec<f64> = q.iter().map(|&i| other_mass[i]).collect();
    let permuted = rank_align(ref_p.as_ref(), &ref_mass_p, other_q.as_ref(), &other_mass_q);
    for i in 0..n {
        for j in 0..2 {
            assert_eq!(permuted[(i, j)], base[(q[i], j)]);
        }
    }

    // A vertex of double mass counts as two vertices of single mass, in either shape.
    let reference = column(&[0.0, 1.0, 2.0, 3.0]);
    let split_reference = column(&[0.0, 1.0, 2.0, 2.0, 3.0]);
    let other = column(&[10.0, 20.0, 30.0, 40.0, 50.0]);
    let doubled = rank_align(
        reference.as_ref(),
        &[1.0, 1.0, 2.0, 1.0],
        other.as_ref(),
        &[1.0; 5],
    );
    let split = rank_align(
        split_reference.as_ref(),
        &[1.0; 5],
        other.as_ref(),
        &[1.0; 5],
    );
    assert_close(&col(&doubled, 0), &col(&split, 0));
    let heavy_other = rank_align(
        split_reference.as_ref(),
        &[1.0; 5],
        column(&[10.0, 20.0, 30.0, 40.0]).as_ref(),
        &[1.0, 1.0, 2.0, 1.0],
    );
    let split_other = rank_align(
        split_reference.as_ref(),
        &[1.0; 5],
        column(&[10.0, 20.0, 30.0, 30.0, 40.0]).as_ref(),
        &[1.0; 5],
    );
    assert_close(
        &col(&heavy_other, 0),
        &[
            split_other[(0, 0)],
            split_other[(1, 0)],
            split_other[(2, 0)],
            split_other[(4, 0)],
        ],
    );
    // A zero-mass vertex still gets a value (that of its rank among the others).
    let zero = rank_align(
        reference.as_ref(),
        &[1.0; 4],
        column(&[1.0, 2.0, 2.5, 3.0, 4.0]).as_ref(),
        &[1.0, 1.0, 0.0, 1.0, 1.0],
    );
    assert_eq!(zero[(2, 0)], 1.5);
}

// ---------------------------------------------------------------------------------------
// Joint k-means

/// Points of one shape: rows, masses, true cluster.
type Sample = (Mat<f64>, Vec<f64>, Vec<u32>);

/// Three well-separated blobs in 4 dimensions; shape A samples them with 300/100/50
/// points, B with 60/200/120, masses making every blob 1/3 of each shape.
fn blobs(seed: u64) -> (Sample, Sample) {
    let mut r = rng(seed);
    let centres = [
        [0.0, 0.0, 0.0, 0.0],
        [5.0, 1.0, 0.0, 2.0],
        [0.0, 6.0, 4.0, -3.0],
    ];
    let mut make = |counts: [usize; 3]| {
        let mut rows = Vec::new();
        let mut mass = Vec::new();
        let mut truth = Vec::new();
        for (b, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                rows.push(centres[b].map(|c| c + r.random::<f64>() - 0.5));
                mass.push(1.0 / (3.0 * count as f64));
                truth.push(b as u32);
            }
        }
        let m = Mat::from_fn(rows.len(), 4, |i, j| rows[i][j]);
        (m, mass, truth)
    };
    (make([300, 100, 50]), make([60, 200, 120]))
}

#[test]
fn joint_kmeans_recovers_separated_weighted_clusters() {
    let ((a, mass_a, truth_a), (b, mass_b, truth_b)) = blobs(5);
    for metric in [KMeansMetric::CityBlock, KMeansMetric::Euclidean] {
        let result = joint_kmeans_with(
            a.as_ref(),
            &mass_a,
            b.as_ref(),
            &mass_b,
            &KMeansParams {
                k: 3,
                restarts: 3,
                seed: 9,
                metric,
                ..Default::default()
            },
        );
        let mut labels = result.labels_a.clone();
        labels.extend(&result.labels_b);
        let mut truth = truth_a.clone();
        truth.extend(&truth_b);
        assert!(same_partition(&labels, &truth), "{metric:?}");
        assert_eq!(result.centroids.nrows(), 3);
        // Centroids lie inside their blobs (medians / means of points within +-0.5).
        for c in 0..3 {
            let blob = truth[labels.iter().position(|&l| l == c as u32).unwrap()] as usize;
            let centre = [
                [0.0, 0.0, 0.0, 0.0],
                [5.0, 1.0, 0.0, 2.0],
                [0.0, 6.0, 4.0, -3.0],
            ][blob];
            for (j, &x) in centre.iter().enumerate() {
                assert!((result.centroids[(c, j)] - x).abs() < 0.5);
            }
        }
    }
}

#[test]
fn joint_kmeans_weights_by_mass_and_ignores_zero_mass_points() {
    // One dimension, k = 1: the centroid of all stacked points, each shape weighing 1.
    let centroid = |a: &[f64], mass_a: &[f64], b: &[f64], metric| {
        let result = joint_kmeans_with(
            column(a).as_ref(),
            mass_a,
            column(b).as_ref(),
            &[1.0],
            &KMeansParams {
                k: 1,
                restarts: 1,
                seed: 0,
                metric,
                ..Default::default()
            },
        );
        result.centroids[(0, 0)]
    };
    let a = [0.0, 1.0, 2.0, 3.0, 4.0];
    // City block: the lower weighted median. Weights 0.1 x 4 and 0.6 on 4, B's 1.0 on 1:
    // the cumulative weight reaches half (1.0) at 1...
    let city = KMeansMetric::CityBlock;
    assert_eq!(centroid(&a, &[0.1, 0.1, 0.1, 0.1, 0.6], &[1.0], city), 1.0);
    // ...more mass on A's 4 does not move it (B's point holds half the weight)...
    assert_eq!(
        centroid(&a, &[0.05, 0.05, 0.05, 0.05, 0.8], &[1.0], city),
        1.0
    );
    // ...until B's point sits on 4 as well. Masses are normalised per shape.
    assert_eq!(centroid(&a, &[1.0, 1.0, 1.0, 1.0, 16.0], &[4.0], city), 4.0);
    // Euclidean: the weighted mean, (0.1 + 0.2 + 0.3 + 2.4 + 1.0) / 2.
    let mean = centroid(
        &a,
        &[0.1, 0.1, 0.1, 0.1, 0.6],
        &[1.0],
        KMeansMetric::Euclidean,
    );
    assert!((mean - 2.0).abs() < 1e-12, "{mean}");

    // Zero-mass outliers far away are labelled but do not move the centroids.
    let ((a, mass_a, _), (b, mass_b, _)) = blobs(6);
    for metric in [KMeansMetric::CityBlock, KMeansMetric::Euclidean] {
        let params = KMeansParams {
            k: 3,
            restarts: 2,
            seed: 4,
            metric,
            ..Default::default()
        };
        let plain = joint_kmeans_with(a.as_ref(), &mass_a, b.as_ref(), &mass_b, &params);
        let n = a.nrows();
        let with_outliers =
            Mat::from_fn(
                n + 3,
                4,
                |i, j| if i < n { a[(i, j)] } else { 100.0 + i as f64 },
            );
        let mut mass_outliers = mass_a.clone();
        mass_outliers.extend([0.0; 3]);
        let outliers = joint_kmeans_with(
            with_outliers.as_ref(),
            &mass_outliers,
            b.as_ref(),
            &mass_b,
            &params,
        );
        assert_eq!(outliers.centroids, plain.centroids);
        assert_eq!(&outliers.labels_a[..n], &plain.labels_a[..]);
        assert_eq!(outliers.labels_a.len(), n + 3);
        assert_eq!(outliers.labels_b, plain.labels_b);
    }
}

fn hks_pair(vertices: usize) -> (Prepared, Prepared) {
    let meshes = figure_poses(
        FigureKind::Humanoid,
        vertices,
        Proportions::default(),
        &[0, 3],
    )
    .unwrap();
    let mut shapes = meshes
        .into_iter()
        .map(|m| prepare(Shape::mesh(m.vertices, &m.triangles).unwrap()));
    (shapes.next().unwrap(), shapes.next().unwrap())
}

#[test]
fn joint_kmeans_is_deterministic_on_any_thread_count_and_fills_every_cluster() {
    let (a, b) = hks_pair(2500);
    let n = a.mass.len();
    let p = permutation(n, 5);
    let a_p = Mat::from_fn(n, a.hks.ncols(), |i, j| a.hks[(p[i], j)]);
    let mass_p: Vec<f64> = p.iter().map(|&i| a.mass[i]).collect();
    for metric in [KMeansMetric::Euclidean, KMeansMetric::CityBlock] {
        let params = KMeansParams {
            k: 8,
            restarts: 3,
            seed: 17,
            metric,
            ..Default::default()
        };
        let run = |threads: usize| -> JointClustering {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    joint_kmeans_with(a.hks.as_ref(), &a.mass, b.hks.as_ref(), &b.mass, &params)
                })
        };
        let one = run(1);
        assert_eq!(one, run(4), "{metric:?}");
        assert_eq!(one, run(3), "{metric:?}");
        // Every cluster holds mass.
        let mut cluster_mass = [0.0; 8];
        for (&l, &m) in one.labels_a.iter().zip(&a.mass) {
            cluster_mass[l as usize] += m;
        }
        for (&l, &m) in one.labels_b.iter().zip(&b.mass) {
            cluster_mass[l as usize] += m;
        }
        assert!(cluster_mass.iter().all(|&m| m > 0.0), "{cluster_mass:?}");
        // The row order of the input does not matter.
        let permuted = joint_kmeans_with(a_p.as_ref(), &mass_p, b.hks.as_ref(), &b.mass, &params);
        assert_eq!(permuted.centroids, one.centroids);
        assert_eq!(permuted.labels_b, one.labels_b);
        assert!((0..n).all(|i| permuted.labels_a[i] == one.labels_a[p[i]]));
    }
}

// ---------------------------------------------------------------------------------------
// Shape graphs

#[test]
fn humanoid_graph_is_connected_and_its_regions_partition_the_mesh() {
    let h = prepare(figure_shape(FigureKind::Humanoid, 0, 4000));
    for k in [5, 7] {
        let clustering = joint_kmeans(h.hks.as_ref(), &h.mass, h.hks.as_ref(), &h.mass, k, 3, 1);
        assert_eq!(clustering.labels_a, clustering.labels_b);
        for min_area in [0.0, 0.002] {
            let graph = shape_graph_with(
                &h.shape,
                &h.mass,
                h.hks.as_ref(),
                clustering.centroids.as_ref(),
                &clustering.labels_a,
                &GraphParams {
                    min_region_area: min_area,
                    ..GraphParams::default()
                },
            );
            check_graph(&h.shape, &h.mass, &graph);
            assert!(graph.is_connected(), "k = {k}, min area {min_area}");
            assert!(graph.n_nodes() >= k);
            if min_area > 0.0 {
                assert!(graph.node_area.iter().all(|&a| a >= min_area));
            }
            // Node descriptors are the area-weighted means.
            let node = graph.labels[0] as usize;
            let members: Vec<usize> = (0..h.mass.len())
                .filter(|&v| graph.labels[v] as usize == node)
                .collect();
            let w: f64 = members.iter().map(|&v| h.mass[v]).sum();
            let mean: f64 = members
                .iter()
                .map(|&v| h.mass[v] * h.hks[(v, 3)])
                .sum::<f64>()
                / w;
            assert!((graph.node_descriptor[node][3] - mean).abs() < 1e-9 * mean.abs().max(1.0));
        }
    }
}

#[test]
fn star_graph_has_five_fold_structure() {
    let s = prepare(figure_shape(FigureKind::Star { limbs: 5 }, 0, 4000));
    for k in 3..=5 {
        let clustering = joint_kmeans(s.hks.as_ref(), &s.mass, s.hks.as_ref(), &s.mass, k, 3, 2);
        let graph = shape_graph(
            &s.shape,
            &s.mass,
            s.hks.as_ref(),
            clustering.centroids.as_ref(),
            &clustering.labels_a,
        );
        check_graph(&s.shape, &s.mass, &graph);
        assert!(graph.is_connected());
        let degrees = graph.degrees();
        let tips: Vec<usize> = (0..graph.n_nodes()).filter(|&i| degrees[i] == 1).collect();
        assert_eq!(tips.len(), 5, "k = {k}: degrees {degrees:?}");
        // The tips are the same part of five limbs: same cluster, equal areas and means.
        let cluster = graph.node_cluster[tips[0]];
        assert!(tips.iter().all(|&t| graph.node_cluster[t] == cluster));
        let areas: Vec<f64> = tips.iter().map(|&t| graph.node_area[t]).collect();
        let mean_area = areas.iter().sum::<f64>() / 5.0;
        assert!(
            areas
                .iter()
                .all(|a| (a - mean_area).abs() < 0.1 * mean_area),
            "{areas:?}"
        );
        for j in 0..s.hks.ncols() {
            let values: Vec<f64> = tips.iter().map(|&t| graph.node_descriptor[t][j]).collect();
            let mean = values.iter().sum::<f64>() / 5.0;
            assert!(
                values.iter().all(|v| (v - mean).abs() < 0.02 * mean.abs()),
                "{values:?}"
            );
        }
        // Node counts come in fives apart from the body: every cluster has 1 or 5 nodes.
        let mut per_cluster = vec![0; k];
        for &c in &graph.node_cluster {
            per_cluster[c as usize] += 1;
        }
        assert!(
            per_cluster.iter().all(|&c| c == 1 || c == 5),
            "k = {k}: {per_cluster:?}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// The pair

fn permuted_shape(shape: &Shape, p: &[usize]) -> Shape {
    // New vertex i is old vertex p[i].
    let mut inverse = vec![0u32; p.len()];
    for (new, &old) in p.iter().enumerate() {
        inverse[old] = new as u32;
    }
    let vertices: Vec<[f64; 3]> = p.iter().map(|&old| shape.vertices()[old]).collect();
    let triangles: Vec<[u32; 3]> = shape
        .triangles()
        .iter()
        .map(|t| t.map(|v| inverse[v as usize]))
        .collect();
    Shape::mesh(vertices, &triangles).unwrap()
}

#[test]
fn two_poses_give_consistent_segmentations_independent_of_vertex_order() {
    let (a, b) = hks_pair(4000);
    let params = SegmentationParams::default();
    let result = segment_pair(
        described(&a.shape, &a.mass, a.hks.as_ref()),
        described(&b.shape, &b.mass, b.hks.as_ref()),
        &params,
        &mut NoProgress,
    )
    .unwrap();
    assert!((params.k_min..=params.k_max).contains(&result.k));
    assert_eq!(result.candidates.len(), params.k_max - params.k_min + 1);
    let chosen = result.candidates.iter().find(|c| c.k == result.k).unwrap();
    assert!(chosen.acceptable);
    assert!(result.graph_a.n_nodes() <= 60 && result.graph_b.n_nodes() <= 60);
    assert!(result.graph_a.is_connected() && result.graph_b.is_connected());
    check_graph(&a.shape, &a.mass, &result.graph_a);
    check_graph(&b.shape, &b.mass, &result.graph_b);
    let identity: Vec<usize> = (0..a.mass.len()).collect();
    let consistency = region_consistency(&a.mass, &result.graph_a, &result.graph_b, &identity);
    assert!(consistency > 0.85, "consistency {consistency}");
    // No k with a better (lower) score was passed over among the acceptable ones.
    for c in result.candidates.iter().filter(|c| c.acceptable) {
        assert!(c.score > chosen.score || (c.score == chosen.score && c.k >= result.k));
    }

    // A with its vertices permuted: the same segmentation, relabelled.
    let n = a.mass.len();
    let p = permutation(n, 21);
    let shape_p = permuted_shape(&a.shape, &p);
    let mass_p: Vec<f64> = p.iter().map(|&i| a.mass[i]).collect();
    let hks_p = Mat::from_fn(n, a.hks.ncols(), |i, j| a.hks[(p[i], j)]);
    let again = segment_pair(
        described(&shape_p, &mass_p, hks_p.as_ref()),
        described(&b.shape, &b.mass, b.hks.as_ref()),
        &params,
        &mut NoProgress,
    )
    .unwrap();
    assert_eq!(again.k, result.k);
    assert_eq!(again.candidates, result.candidates);
    assert_eq!(again.graph_b, result.graph_b);
    let labels_back: Vec<u32> = {
        let mut back = vec![0u32; n];
        for (new, &old) in p.iter().enumerate() {
            back[old] = again.graph_a.labels[new];
        }
        back
    };
    assert!(same_partition(&labels_back, &result.graph_a.labels));
    assert_eq!(
        degree_histogram(&again.graph_a),
        degree_histogram(&result.graph_a)
    );
}

#[test]
fn segment_pair_falls_back_when_no_k_is_acceptable() {
    // Two separate stars in one shape: every graph is disconnected, so no k is acceptable;
    // the best-scoring k is still returned.
    let star = figure(&FigureSpec {
        kind: FigureKind::Star { limbs: 3 },
        target_vertices: 900,
        ..Default::default()
    })
    .unwrap();
    let n = star.vertices.len() as u32;
    let mut vertices = star.vertices.clone();
    vertices.extend(star.vertices.iter().map(|v| [v[0] + 5.0, v[1], v[2]]));
    let mut triangles = star.triangles.clone();
    triangles.extend(star.triangles.iter().map(|t| t.map(|v| v + n)));
    // The repairs would leave the second star out as a separate object.
    let keep_pieces = shapecorr::shape::Repairs {
        debris_fraction: 0.0,
        ..Default::default()
    };
    let polygons: Vec<Vec<u32>> = triangles.iter().map(|t| t.to_vec()).collect();
    let two = prepare(Shape::mesh_with(vertices, &polygons, &keep_pieces).unwrap());
    let params = SegmentationParams {
        k_min: 3,
        k_max: 5,
        ..Default::default()
    };
    let result = segment_pair(
        described(&two.shape, &two.mass, two.hks.as_ref()),
        described(&two.shape, &two.mass, two.hks.as_ref()),
        &params,
        &mut NoProgress,
    )
    .unwrap();
    assert!(result
        .candidates
        .iter()
        .all(|c| !c.acceptable && !c.connected_a));
    assert!(!result.graph_a.is_connected());
    let best = result
        .candidates
        .iter()
        .map(|c| c.score)
        .fold(f64::INFINITY, f64::min);
    let chosen = result.candidates.iter().find(|c| c.k == result.k).unwrap();
    assert_eq!(chosen.score, best);
    check_graph(&two.shape, &two.mass, &result.graph_a);

    // One connected star with too small a region limit: the connected graphs compete.
    let one = prepare(figure_shape(FigureKind::Star { limbs: 3 }, 0, 900));
    let tight = SegmentationParams {
        k_min: 3,
        k_max: 5,
        max_regions: 2,
        ..Default::default()
    };
    let result = segment_pair(
        described(&one.shape, &one.mass, one.hks.as_ref()),
        described(&one.shape, &one.mass, one.hks.as_ref()),
        &tight,
        &mut NoProgress,
    )
    .unwrap();
    assert!(result.candidates.iter().all(|c| !c.acceptable));
    assert_eq!(result.k, 3, "equal graphs everywhere: the smallest k");
    assert!(result.graph_a.is_connected());
    assert_eq!(result.graph_a, result.graph_b);
}

#[test]
fn segment_pair_rejects_bad_inputs() {
    let h = prepare(figure_shape(FigureKind::Star { limbs: 3 }, 0, 800));
    let run = |params: &SegmentationParams, mass: &[f64], desc: &Mat<f64>| {
        segment_pair(
            described(&h.shape, &h.mass, h.hks.as_ref()),
            Described {
                shape: &h.shape,
                mass,
                descriptors: desc.as_ref(),
            },
            params,
            &mut NoProgress,
        )
    };
    let ok = SegmentationParams::default();
    assert!(run(&ok, &h.mass, &h.hks).is_ok());
    let bad_k = SegmentationParams {
        k_min: 6,
        k_max: 5,
        ..Default::default()
    };
    assert!(run(&bad_k, &h.mass, &h.hks).is_err());
    let bad_area = SegmentationParams {
        min_region_area: -0.1,
        ..Default::default()
    };
    assert!(run(&bad_area, &h.mass, &h.hks).is_err());
    assert!(run(&ok, &h.mass[1..], &h.hks).is_err());
    let mut nan_mass = h.mass.clone();
    nan_mass[3] = f64::NAN;
    assert!(run(&ok, &nan_mass, &h.hks).is_err());
    let mut nan_desc = h.hks.clone();
    nan_desc[(5, 2)] = f64::NAN;
    assert!(run(&ok, &h.mass, &nan_desc).is_err());
    let narrow = Mat::from_fn(h.hks.nrows(), 3, |i, j| h.hks[(i, j)]);
    assert!(run(&ok, &h.mass, &narrow).is_err());
}

// ---------------------------------------------------------------------------------------
// FAUST (ignored: needs /work/shared/data/faust, research licence, never in the repo)

const FAUST: &str = "/work/shared/data/faust";

/// The FAUST pairs measured: same person in two poses, then different people.
const FAUST_PAIRS: [(usize, usize); 5] = [(0, 1), (10, 15), (0, 21), (12, 43), (30, 57)];

/// Reads the FAUST registrations of the pairs (vertex i corresponds across files); with
/// `noise`, as point clouds with every point moved by up to `noise` of the width per axis.
fn faust_shapes(pairs: &[(usize, usize)], noise: Option<f64>) -> Option<HashMap<usize, Prepared>> {
    let dir = Path::new(FAUST);
    if !dir.join("tr_reg_000.ply").exists() {
        eprintln!("FAUST data not found at {FAUST}; skipping");
        return None;
    }
    let mut ids: Vec<usize> = pairs.iter().flat_map(|&(a, b)| [a, b]).collect();
    ids.sort_unstable();
    ids.dedup();
    let mut shapes = HashMap::new();
    for &id in &ids {
        let path = dir.join(format!("tr_reg_{id:03}.ply"));
        let t = Instant::now();
        let mut shape = Shape::read(&path, ReadAs::point_cloud_when(noise.is_some())).unwrap();
        if let Some(noise) = noise {
            let mut r = rng(id as u64);
            let shift = noise * shape.width();
            let moved: Vec<[f64; 3]> = shape
                .vertices()
                .iter()
                .map(|v| v.map(|x| x + shift * (2.0 * r.random::<f64>() - 1.0)))
                .collect();
            shape = shape.with_vertices(moved).unwrap();
        }
        let prepared = prepare(shape);
        eprintln!(
            "shape {id:03}: eigenbasis + HKS {:.2} s",
            t.elapsed().as_secs_f64()
        );
        shapes.insert(id, prepared);
    }
    Some(shapes)
}

/// Segments every pair with every variant and prints: chosen k, node counts, equal degree
/// histograms, edge counts, region consistency and time.
fn print_variants<S: std::fmt::Display>(
    shapes: &HashMap<usize, Prepared>,
    variants: &[(S, SegmentationParams)],
) {
    for (name, params) in variants {
        eprintln!("\n== {name}");
        let mut total_consistency = 0.0;
        let mut total_seconds = 0.0;
        for &(ia, ib) in &FAUST_PAIRS {
            let (a, b) = (&shapes[&ia], &shapes[&ib]);
            let t = Instant::now();
            let result = segment_pair(
                described(&a.shape, &a.mass, a.hks.as_ref()),
                described(&b.shape, &b.mass, b.hks.as_ref()),
                params,
                &mut NoProgress,
            )
            .unwrap();
            let seconds = t.elapsed().as_secs_f64();
            total_seconds += seconds;
            let identity: Vec<usize> = (0..a.mass.len()).collect();
            let consistency =
                region_consistency(&a.mass, &result.graph_a, &result.graph_b, &identity);
            total_consistency += consistency;
            let equal = degree_histogram(&result.graph_a) == degree_histogram(&result.graph_b);
            let smallest = result
                .graph_a
                .node_area
                .iter()
                .chain(&result.graph_b.node_area)
                .cloned()
                .fold(1.0, f64::min);
            eprintln!(
                "{ia:03}-{ib:03}: k = {:2}, nodes {:2} / {:2}, edges {:3} / {:3}, equal degree \
                 histograms {equal:5}, smallest node {smallest:.4}, consistency {consistency:.3}, \
                 {:.0} ms; k tried (nodes, score): {}",
                result.k,
                result.graph_a.n_nodes(),
                result.graph_b.n_nodes(),
                result.graph_a.edges.len(),
                result.graph_b.edges.len(),
                seconds * 1e3,
                result
                    .candidates
                    .iter()
                    .map(|c| format!(
                        "{}:{}/{}{}{:.1}",
                        c.k,
                        c.n_nodes_a,
                        c.n_nodes_b,
                        if c.acceptable { " " } else { "x " },
                        c.score
                    ))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        let n = FAUST_PAIRS.len() as f64;
        eprintln!(
            "mean consistency {:.3}, mean time {:.0} ms",
            total_consistency / n,
            total_seconds / n * 1e3
        );
    }
}

#[test]
#[ignore = "needs the FAUST registrations; prints figures"]
fn faust_figures() {
    let Some(shapes) = faust_shapes(&FAUST_PAIRS, None) else {
        return;
    };
    let variants: Vec<(&str, SegmentationParams)> = vec![
        ("default", SegmentationParams::default()),
        (
            "no fragment merging",
            SegmentationParams {
                min_region_area: 0.0,
                ..Default::default()
            },
        ),
        (
            "merge below 0.01",
            SegmentationParams {
                min_region_area: 0.01,
                ..Default::default()
            },
        ),
        (
            "paper's first-or-second expansion",
            SegmentationParams {
                expansion: RegionExpansion::FirstOrSecondNearest,
                ..Default::default()
            },
        ),
        (
            "hop-distance tie-break",
            SegmentationParams {
                tie_break: KTieBreak::HopDistancesThenSmallestK,
                ..Default::default()
            },
        ),
        (
            "city-block k-means (the authors')",
            SegmentationParams {
                metric: KMeansMetric::CityBlock,
                ..Default::default()
            },
        ),
    ];
    print_variants(&shapes, &variants);

    // Every k for both metrics: nodes, equal histograms (=) or not (~), consistency, and
    // the time of the joint k-means alone.
    for metric in [KMeansMetric::CityBlock, KMeansMetric::Euclidean] {
        eprintln!("\n== every k, {metric:?}");
        for &(ia, ib) in &FAUST_PAIRS {
            let (a, b) = (&shapes[&ia], &shapes[&ib]);
            let aligned = rank_align(a.hks.as_ref(), &a.mass, b.hks.as_ref(), &b.mass);
            let mut line = format!("{ia:03}-{ib:03}:");
            for k in 5..=10 {
                let t = Instant::now();
                let clustering = joint_kmeans_with(
                    a.hks.as_ref(),
                    &a.mass,
                    aligned.as_ref(),
                    &b.mass,
                    &KMeansParams {
                        k,
                        metric,
                        ..Default::default()
                    },
                );
                let kmeans_ms = t.elapsed().as_secs_f64() * 1e3;
                let params = GraphParams {
                    metric,
                    ..Default::default()
                };
                let graph = |shape: &Prepared, desc: &Mat<f64>, labels: &[u32]| {
                    shape_graph_with(
                        &shape.shape,
                        &shape.mass,
                        desc.as_ref(),
                        clustering.centroids.as_ref(),
                        labels,
                        &params,
                    )
                };
                let ga = graph(a, &a.hks, &clustering.labels_a);
                let gb = graph(b, &aligned, &clustering.labels_b);
                let identity: Vec<usize> = (0..a.mass.len()).collect();
                let consistency = region_consistency(&a.mass, &ga, &gb, &identity);
                let equal = degree_histogram(&ga) == degree_histogram(&gb);
                line += &format!(
                    " k{k}: {}/{} {} {consistency:.3} ({kmeans_ms:.0} ms)",
                    ga.n_nodes(),
                    gb.n_nodes(),
                    if equal { "=" } else { "~" }
                );
            }
            eprintln!("{line}");
        }
    }
}

#[test]
#[ignore = "needs the FAUST registrations; prints figures"]
fn faust_noisy_point_cloud_figures() {
    // Point clouds with 1% noise: where fragments appear and the merge threshold matters.
    let Some(shapes) = faust_shapes(&FAUST_PAIRS, Some(0.01)) else {
        return;
    };
    let mut variants: Vec<(String, SegmentationParams)> = Vec::new();
    for metric in [KMeansMetric::CityBlock, KMeansMetric::Euclidean] {
        for min_region_area in [0.0, 0.001, 0.002, 0.005, 0.01] {
            variants.push((
                format!("{metric:?}, merge below {min_region_area}"),
                SegmentationParams {
                    metric,
                    min_region_area,
                    ..Default::default()
                },
            ));
        }
    }
    print_variants(&shapes, &variants);
}

#[test]
#[ignore = "needs the FAUST registrations; prints figures"]
fn faust_metric_comparison() {
    // 24 pairs of the 60 registrations (6 people, 10 poses each): per person two pairs of
    // their own poses and two pairs with other people. City block against Euclidean
    // k-means, everything else default.
    let mut pairs = Vec::new();
    for person in 0..6 {
        let pose = |i: usize| 10 * person + (person + i) % 10;
        let other = |shift: usize, i: usize| 10 * ((person + shift) % 6) + (person + i) % 10;
        pairs.push((pose(0), pose(3)));
        pairs.push((pose(5), pose(9)));
        pairs.push((pose(1), other(1, 4)));
        pairs.push((pose(7), other(3, 2)));
    }
    let Some(shapes) = faust_shapes(&pairs, None) else {
        return;
    };
    for metric in [KMeansMetric::CityBlock, KMeansMetric::Euclidean] {
        let params = SegmentationParams {
            metric,
            ..Default::default()
        };
        let (mut same, mut different) = (Vec::new(), Vec::new());
        let (mut equal, mut nodes, mut ks) = (0, 0, Vec::new());
        let t = Instant::now();
        for &(ia, ib) in &pairs {
            let (a, b) = (&shapes[&ia], &shapes[&ib]);
            let result = segment_pair(
                described(&a.shape, &a.mass, a.hks.as_ref()),
                described(&b.shape, &b.mass, b.hks.as_ref()),
                &params,
                &mut NoProgress,
            )
            .unwrap();
            let identity: Vec<usize> = (0..a.mass.len()).collect();
            let consistency =
                region_consistency(&a.mass, &result.graph_a, &result.graph_b, &identity);
            if ia / 10 == ib / 10 {
                same.push(consistency);
            } else {
                different.push(consistency);
            }
            equal +=
                usize::from(degree_histogram(&result.graph_a) == degree_histogram(&result.graph_b));
            nodes += result.graph_a.n_nodes() + result.graph_b.n_nodes();
            ks.push(result.k);
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        let worst = |v: &[f64]| v.iter().cloned().fold(1.0, f64::min);
        eprintln!(
            "{metric:?}: {} pairs, consistency same person {:.3} (worst {:.3}, {} pairs), \
             different people {:.3} (worst {:.3}, {} pairs); equal degree histograms {equal}; \
             mean nodes {:.1}; k chosen {ks:?}; {:.0} ms per pair",
            pairs.len(),
            mean(&same),
            worst(&same),
            same.len(),
            mean(&different),
            worst(&different),
            different.len(),
            nodes as f64 / (2 * pairs.len()) as f64,
            t.elapsed().as_secs_f64() * 1e3 / pairs.len() as f64
        );
    }
}

#[test]
#[ignore = "slow (two 52K-vertex eigenbases); prints timings"]
fn large_generated_pair_timing() {
    let t = Instant::now();
    let (a, b) = hks_pair(52_000);
    eprintln!(
        "two humanoids of {} vertices: eigenbases and HKS {:.1} s",
        a.mass.len(),
        t.elapsed().as_secs_f64()
    );
    let aligned = rank_align(a.hks.as_ref(), &a.mass, b.hks.as_ref(), &b.mass);
    for metric in [KMeansMetric::Euclidean, KMeansMetric::CityBlock] {
        for k in [5, 10] {
            let t = Instant::now();
            joint_kmeans_with(
                a.hks.as_ref(),
                &a.mass,
                aligned.as_ref(),
                &b.mass,
                &KMeansParams {
                    k,
                    metric,
                    ..Default::default()
                },
            );
            eprintln!(
                "joint k-means {metric:?}, k = {k}: {:.0} ms",
                t.elapsed().as_secs_f64() * 1e3
            );
        }
    }
    let t = Instant::now();
    let result = segment_pair(
        described(&a.shape, &a.mass, a.hks.as_ref()),
        described(&b.shape, &b.mass, b.hks.as_ref()),
        &SegmentationParams::default(),
        &mut NoProgress,
    )
    .unwrap();
    eprintln!(
        "segment_pair (k = 5..=10): {:.0} ms, k = {}, nodes {} / {}",
        t.elapsed().as_secs_f64() * 1e3,
        result.k,
        result.graph_a.n_nodes(),
        result.graph_b.n_nodes()
    );
}
