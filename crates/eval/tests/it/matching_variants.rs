//! Measurement of the graph-matching variants on benchmark pairs (moved from the pipeline's
//! tests: it needs the dataset registry).

use std::collections::HashMap;
use std::time::Instant;

use shapecorr::evaluation::score as region_scores;
use shapecorr::geodesic::region_distance_matrix;
use shapecorr::regions::matching::match_hop_distances;
use shapecorr::regions::matching::{
    distance_histograms, leading_eigenvector, unary_costs, Affinity, DistanceTerm, MatchingParams,
};
use shapecorr::regions::segmentation::{segment_pair, SegmentationParams};
use shapecorr::regions::symmetry::{one_to_one, SymmetryParams};
use shapecorr::spectral::descriptors::{hks, HksParams};
use shapecorr::{EigenParams, Eigenbasis, ReadAs, Shape};
use shapecorr_eval::datasets::{default_data_root, read_pairs, Dataset};

/// Real-data measurement: benchmark pairs (`SHAPECORR_DATA` or `../shared/data`; the list
/// `pairs/$MATCHING_DATASET.txt`, default `faust`), segmented by the default pipeline,
/// matched with every variant; symmetric and one-to-one (flip allowed) region accuracy.
/// `MATCHING_PAIRS` (default 24) pairs, spread over the pair list.
#[test]
#[ignore = "measurement on benchmark data; run with --ignored --nocapture"]
fn measure_variants_on_benchmark_pairs() {
    let root = default_data_root();
    let dataset = std::env::var("MATCHING_DATASET").unwrap_or_else(|_| "faust".into());
    let list = root.join(format!("pairs/{dataset}.txt"));
    if !list.is_file() {
        eprintln!("note: {} not found; skipping", list.display());
        return;
    }
    let pairs = read_pairs(&list).unwrap();
    let dataset = Dataset::for_pairs_file(&root, &list).unwrap();
    let wanted: usize = std::env::var("MATCHING_PAIRS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(24);
    let step = (pairs.len() / wanted.max(1)).max(1);
    let chosen: Vec<_> = pairs.iter().step_by(step).take(wanted).collect();

    let variants = variants();
    let mut cache: HashMap<String, std::rc::Rc<Prepared>> = HashMap::new();
    let mut prepare = |name: &str| {
        cache
            .entry(name.to_string())
            .or_insert_with(|| std::rc::Rc::new(prepare_shape(&dataset, name)))
            .clone()
    };
    // Per variant, per category: sums of symmetric accuracy, one-to-one (flip) accuracy,
    // coverage, and the counts.
    let mut sums: HashMap<(usize, String), [f64; 4]> = HashMap::new();
    let mut eigen_ms = Vec::new();
    let mut products = Vec::new();
    let mut max_dense_difference: f64 = 0.0;
    for pair in &chosen {
        let (a, b) = (prepare(&pair.source), prepare(&pair.target));
        let seg = segment_pair(
            &a.shape,
            &a.mass,
            a.hks.as_ref(),
            &b.shape,
            &b.mass,
            b.hks.as_ref(),
            &SegmentationParams::default(),
        )
        .unwrap();
        let (ga, gb) = (&seg.graph_a, &seg.graph_b);
        let (na, nb) = (ga.n_nodes(), gb.n_nodes());
        let d1 = region_distance_matrix(
            &a.shape,
            &a.mass,
            &ga.labels,
            na,
            1.0 / a.shape.mesh_area().sqrt(),
        );
        let d2 = region_distance_matrix(
            &b.shape,
            &b.mass,
            &gb.labels,
            nb,
            1.0 / b.shape.mesh_area().sqrt(),
        );
        let (truth, flipped) = dataset
            .ground_truth(
                &pair.source,
                &pair.target,
                a.shape.n_vertices(),
                b.shape.n_vertices(),
            )
            .unwrap();
        let (ha, hb) = (ga.hop_distances(), gb.hop_distances());
        check_eigensolver(&ha, &hb, &mut products, &mut max_dense_difference);
        let mut line = format!(
            "{} -> {} ({}, k {}, {na}/{nb} regions):",
            pair.source, pair.target, pair.category, seg.k
        );
        for (v, (_, params)) in variants.iter().enumerate() {
            let t = Instant::now();
            let m = match_hop_distances(&ha, &hb, params).unwrap();
            eigen_ms.push(t.elapsed().as_secs_f64() * 1e3);
            let o2o = one_to_one(
                &m.matches,
                d1.as_ref(),
                d2.as_ref(),
                &SymmetryParams::default(),
            )
            .unwrap();
            let s = region_scores(
                &ga.labels,
                &gb.labels,
                &a.mass,
                &b.mass,
                &m.matches,
                &o2o,
                &truth,
                flipped.as_deref(),
            );
            let o2o_flip = s.one_to_one_flip.unwrap_or(s.one_to_one);
            for cat in [pair.category.clone(), "all".to_string()] {
                let e = sums.entry((v, cat)).or_insert([0.0; 4]);
                e[0] += s.symmetric;
                e[1] += o2o_flip;
                e[2] += s.coverage;
                e[3] += 1.0;
            }
            if v < 4 {
                line += &format!(" [{:.2} {:.2}]", s.symmetric, o2o_flip);
            }
        }
        println!("{line}");
    }
    print_accuracy(&variants, &sums);
    print_solver_costs(products, eigen_ms, max_dense_difference);
}

/// The matching variants measured: symmetry gap and order, histogram normalisation and
/// distance term.
fn variants() -> Vec<(String, MatchingParams)> {
    let mut variants: Vec<(String, MatchingParams)> = Vec::new();
    for (gap, order) in [(0.9, 8), (0.95, 10)] {
        for normalise in [false, true] {
            for term in [DistanceTerm::Difference, DistanceTerm::Ratio] {
                variants.push((
                    format!("gap {gap} order {order} normalise={normalise:5} {term:?}"),
                    MatchingParams {
                        gap_ratio: gap,
                        max_symmetry_order: order,
                        normalise_histograms: normalise,
                        distance_term: term,
                        ..Default::default()
                    },
                ));
            }
        }
    }
    variants
}

/// A shape with what the segmentation needs: its mass matrix and HKS.
struct Prepared {
    shape: Shape,
    mass: Vec<f64>,
    hks: faer::Mat<f64>,
}

fn prepare_shape(dataset: &Dataset, name: &str) -> Prepared {
    let shape = Shape::read(&dataset.shape_path(name).unwrap(), ReadAs::Auto).unwrap();
    let basis = Eigenbasis::compute(&shape, &EigenParams::default()).unwrap();
    let hks = hks(&basis, &HksParams::default()).unwrap();
    Prepared {
        mass: basis.mass.clone(),
        shape,
        hks,
    }
}

/// The eigensolver on real graphs: converged, and equal to a dense decomposition.
fn check_eigensolver(
    ha: &[Vec<u32>],
    hb: &[Vec<u32>],
    products: &mut Vec<usize>,
    max_dense_difference: &mut f64,
) {
    for term in [DistanceTerm::Difference, DistanceTerm::Ratio] {
        let costs = unary_costs(
            &distance_histograms(ha, 20, false),
            &distance_histograms(hb, 20, false),
        );
        let op = Affinity::new(ha, hb, &costs, 0.5, term).unwrap();
        let eig = leading_eigenvector(&op).unwrap();
        assert!(eig.converged, "{eig:?}");
        products.push(eig.products);
        if op.dim() <= 1024 {
            let n = op.dim();
            let dense = faer::Mat::from_fn(n, n, |p, q| op.entry(p, q));
            let evd = dense.self_adjoint_eigen(faer::Side::Lower).unwrap();
            let diff = (0..n)
                .map(|p| (evd.U()[(p, n - 1)].abs() - eig.vector[p]).abs())
                .fold(0.0, f64::max);
            *max_dense_difference = max_dense_difference.max(diff);
        }
    }
}

/// Per category, each variant's mean accuracies over the pairs.
fn print_accuracy(
    variants: &[(String, MatchingParams)],
    sums: &HashMap<(usize, String), [f64; 4]>,
) {
    let mut cats: Vec<String> = sums.keys().map(|k| k.1.clone()).collect();
    cats.sort();
    cats.dedup();
    for cat in cats {
        println!("{cat}:");
        for (v, (name, _)) in variants.iter().enumerate() {
            let e = sums[&(v, cat.clone())];
            println!(
                "  {name:50} symmetric {:.3}  one-to-one (flip) {:.3}  coverage {:.3}  ({} pairs)",
                e[0] / e[3],
                e[1] / e[3],
                e[2] / e[3],
                e[3]
            );
        }
    }
}

/// Eigensolver products and matching time over all pairs and variants.
fn print_solver_costs(mut products: Vec<usize>, mut eigen_ms: Vec<f64>, max_dense_difference: f64) {
    products.sort_unstable();
    println!(
        "eigensolver: products median {} max {}; largest difference to a dense \
         decomposition (graphs up to 32 x 32 nodes) {max_dense_difference:.1e}",
        products[products.len() / 2],
        products[products.len() - 1]
    );
    eigen_ms.sort_by(f64::total_cmp);
    println!(
        "match_hop_distances: median {:.2} ms, max {:.2} ms",
        eigen_ms[eigen_ms.len() / 2],
        eigen_ms[eigen_ms.len() - 1]
    );
}
