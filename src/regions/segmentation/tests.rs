use super::*;

pub(super) fn column(values: &[f64]) -> Mat<f64> {
    Mat::from_fn(values.len(), 1, |i, _| values[i])
}

fn params(min_region_area: f64) -> GraphParams {
    GraphParams {
        min_region_area,
        ..GraphParams::default()
    }
}

fn path(n: u32) -> (Vec<u32>, Vec<(u32, u32)>) {
    ((0..n).collect(), (0..n - 1).map(|i| (i, i + 1)).collect())
}

#[test]
fn band_expansion_does_not_leak_through_other_regions_of_the_cluster() {
    // A path with descriptor values 1 1 0 0 1 1 2 2 and centroids 0, 1, 2: regions
    // A = {0,1} (cluster 1), B = {2,3} (0), C = {4,5} (1), D = {6,7} (2). Cluster 1 is
    // every other vertex's second nearest, so the paper's first-or-second set of
    // cluster 1 is the whole path and joins A to D; the band does not.
    let (active, edges) = path(8);
    let conn = Connectivity {
        active: &active,
        representative: &active,
        edges: &edges,
    };
    let values = [1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0];
    let labels = [1, 1, 0, 0, 1, 1, 2, 2];
    let descriptors = Mat::from_fn(8, 1, |i, _| values[i]);
    let centroids = Mat::from_fn(3, 1, |c, _| c as f64);
    let graph = |expansion| {
        build_graph(
            &conn,
            &[0.125; 8],
            descriptors.as_ref(),
            centroids.as_ref(),
            &labels,
            &GraphParams {
                min_region_area: 0.0,
                expansion,
                ..GraphParams::default()
            },
        )
    };
    let band = graph(RegionExpansion::SecondNearestBand);
    assert_eq!(band.node_cluster, vec![1, 0, 1, 2]);
    assert_eq!(band.edges, vec![(0, 1), (1, 2), (2, 3)]);
    let paper = graph(RegionExpansion::FirstOrSecondNearest);
    assert_eq!(paper.edges, vec![(0, 1), (0, 2), (0, 3), (1, 2), (2, 3)]);
}

#[test]
fn rank_align_interpolates_between_reference_knots() {
    // Reference 0, 10 with equal mass: knots at ranks 0.25 and 0.75. Other: four equal
    // points at ranks 0.125, 0.375, 0.625, 0.875.
    let aligned = rank_align(
        column(&[0.0, 10.0]).as_ref(),
        &[0.5, 0.5],
        column(&[1.0, 2.0, 3.0, 4.0]).as_ref(),
        &[0.25; 4],
    );
    let got: Vec<f64> = (0..4).map(|i| aligned[(i, 0)]).collect();
    assert_eq!(got, vec![0.0, 2.5, 7.5, 10.0]);
}

#[test]
fn fragments_merge_into_the_neighbour_sharing_most_edges() {
    // A path of 10 vertices: clusters 0 0 0 0 1 0 0 2 2 2; vertex 4 is a fragment
    // between two regions of cluster 0, which then unite.
    let active: Vec<u32> = (0..10).collect();
    let edges: Vec<(u32, u32)> = (0..9).map(|i| (i, i + 1)).collect();
    let conn = Connectivity {
        active: &active,
        representative: &active,
        edges: &edges,
    };
    let labels = [0, 0, 0, 0, 1, 0, 0, 2, 2, 2];
    let descriptors = Mat::from_fn(10, 1, |i, _| labels[i] as f64);
    let centroids = Mat::from_fn(3, 1, |c, _| c as f64);
    let mass = vec![0.1; 10];
    let keep = build_graph(
        &conn,
        &mass,
        descriptors.as_ref(),
        centroids.as_ref(),
        &labels,
        &params(0.0),
    );
    assert_eq!(keep.n_nodes(), 4);
    let merged = build_graph(
        &conn,
        &mass,
        descriptors.as_ref(),
        centroids.as_ref(),
        &labels,
        &params(0.15),
    );
    assert_eq!(merged.n_nodes(), 2);
    assert_eq!(merged.labels, vec![0, 0, 0, 0, 0, 0, 0, 1, 1, 1]);
    assert_eq!(merged.node_cluster, vec![0, 2]);
    assert_eq!(merged.edges, vec![(0, 1)]);
    assert!((merged.node_area[0] - 0.7).abs() < 1e-12);
}

#[test]
fn edges_come_from_second_nearest_overlap() {
    // A path 0..6 with descriptors 0, 0, 1, 1, 3, 3 and centroids 0, 1, 3: region of
    // cluster 0 {0,1}, cluster 1 {2,3}, cluster 2 {4,5}. Second nearest of 0..1 is 1,
    // of 2..3 is 0, of 4..5 is 1: so 0-1 and 1-2 are joined, 0-2 is not.
    let active: Vec<u32> = (0..6).collect();
    let edges: Vec<(u32, u32)> = (0..5).map(|i| (i, i + 1)).collect();
    let conn = Connectivity {
        active: &active,
        representative: &active,
        edges: &edges,
    };
    let values = [0.0, 0.0, 1.0, 1.0, 3.0, 3.0];
    let labels = [0, 0, 1, 1, 2, 2];
    let descriptors = Mat::from_fn(6, 1, |i, _| values[i]);
    let centroids = Mat::from_fn(3, 1, |c, _| [0.0, 1.0, 3.0][c]);
    let g = build_graph(
        &conn,
        &[1.0 / 6.0; 6],
        descriptors.as_ref(),
        centroids.as_ref(),
        &labels,
        &params(0.0),
    );
    assert_eq!(g.edges, vec![(0, 1), (1, 2)]);
    assert_eq!(g.degrees(), vec![1, 2, 1]);
}

#[test]
fn choice_of_k_prefers_acceptable_then_small_k() {
    let cand = |k, acceptable, connected, score| KCandidate {
        k,
        n_nodes_a: 10,
        n_nodes_b: 10,
        connected_a: connected,
        connected_b: connected,
        acceptable,
        score,
        hop_difference: 10 - k as u64,
    };
    let list = vec![
        cand(5, true, true, 0.5),
        cand(6, true, true, 0.0),
        cand(7, true, true, 0.0),
    ];
    assert_eq!(choose_k(&list, KTieBreak::SmallestK), 1);
    assert_eq!(choose_k(&list, KTieBreak::HopDistancesThenSmallestK), 2);
    let none = vec![
        cand(5, false, false, 0.0),
        cand(6, false, true, 2.0),
        cand(7, false, true, 1.0),
    ];
    assert_eq!(choose_k(&none, KTieBreak::SmallestK), 2);
    assert_eq!(degree_weight_tenths(1) + degree_weight_tenths(2), 5);
}
