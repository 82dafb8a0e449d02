//! Issue 19, item 21: results do not depend on the number of threads, to the last bit.

use shapecorr::options::Options;
use shapecorr::spectral::descriptors::{hks, HksParams};
use shapecorr::synth::{self, FigureKind, FigureSpec};
use shapecorr::{Eigenbasis, NoProgress, PointwiseCorrespondence, Shape};

fn humanoid(pose: usize) -> Shape {
    humanoid_of(pose, 3000)
}

fn humanoid_of(pose: usize, vertices: usize) -> Shape {
    let mesh = synth::figure(&FigureSpec {
        kind: FigureKind::Humanoid,
        pose,
        target_vertices: vertices,
        ..Default::default()
    })
    .unwrap();
    Shape::mesh(mesh.vertices, &mesh.triangles).unwrap()
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// The pointwise correspondence computed in a pool of `threads` threads.
fn pointwise_on(
    threads: usize,
    a: &Shape,
    b: &Shape,
    options: &Options,
) -> PointwiseCorrespondence {
    in_pool(threads, || {
        PointwiseCorrespondence::compute(
            a,
            b,
            &options.params,
            options.pointwise(),
            &mut NoProgress,
        )
        .unwrap()
    })
}

fn bits(values: impl IntoIterator<Item = f64>) -> Vec<u64> {
    values.into_iter().map(f64::to_bits).collect()
}

#[test]
fn eigenbasis_and_hks_are_bit_identical_for_one_and_two_threads() {
    let shape = humanoid(0);
    let mut params = Options::default().params;
    params.eigen.n_eigenpairs = 100; // the pointwise map's basis
    let run = |threads| {
        in_pool(threads, || {
            let basis = Eigenbasis::compute(&shape, &params.eigen).unwrap();
            let h = hks(&basis, &HksParams::default()).unwrap();
            let vectors = bits((0..basis.vectors.ncols()).flat_map(|j| {
                let col: Vec<f64> = (0..basis.vectors.nrows())
                    .map(|i| basis.vectors[(i, j)])
                    .collect();
                col
            }));
            let h = bits(
                (0..h.ncols()).flat_map(|j| (0..h.nrows()).map(|i| h[(i, j)]).collect::<Vec<_>>()),
            );
            (bits(basis.values.clone()), vectors, h)
        })
    };
    let (one, two) = (run(1), run(2));
    assert!(one.0 == two.0, "eigenvalues differ");
    assert!(one.1 == two.1, "eigenvectors differ");
    assert!(one.2 == two.2, "HKS differs");
}

#[test]
fn pointwise_result_graphs_are_bit_identical_for_one_and_two_threads() {
    let (a, b) = (humanoid(0), humanoid(3));
    let options = Options::default();
    let (one, two) = (
        pointwise_on(1, &a, &b, &options),
        pointwise_on(2, &a, &b, &options),
    );
    assert_eq!(one.map.p2p_ba, two.map.p2p_ba);
    for (g1, g2) in [
        (&one.regions.graph_a, &two.regions.graph_a),
        (&one.regions.graph_b, &two.regions.graph_b),
    ] {
        assert_eq!(g1.labels, g2.labels);
        let flat = |g: &shapecorr::regions::graph::ShapeGraph| {
            bits(
                g.node_descriptor
                    .iter()
                    .flatten()
                    .copied()
                    .chain(g.node_area.iter().copied()),
            )
        };
        assert!(flat(g1) == flat(g2), "graph descriptors differ");
    }
}

#[test]
fn the_multiresolution_path_is_identical_for_one_and_two_threads() {
    let (a, b) = (humanoid_of(0, 8000), humanoid_of(3, 8000));
    let mut options = Options::default();
    options.params.multiresolution.above = 4000;
    options.params.multiresolution.proxy_vertices = 2000;
    let (one, two) = (
        pointwise_on(1, &a, &b, &options),
        pointwise_on(2, &a, &b, &options),
    );
    assert!(one.proxies > 0.0, "the proxies were not used");
    assert_eq!(one.map.p2p_ba, two.map.p2p_ba);
    assert_eq!(one.regions.graph_a.labels, two.regions.graph_a.labels);
    assert_eq!(one.regions.graph_b.labels, two.regions.graph_b.labels);
}
