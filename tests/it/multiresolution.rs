//! Dense shapes run on proxies (docs/design.md, step 16); the regions and the map come back to every input
//! vertex, clean and as accurate as at full resolution.

use shapecorr::pipeline::multiresolution::Multiresolution;
use shapecorr::pipeline::{Correspondence, Params};
use shapecorr::shape::proxy::Proxy;
use shapecorr::synth::{self, FigureKind, FigureMesh, FigureSpec};
use shapecorr::{Error, NoProgress, PointwiseCorrespondence, PointwiseParams, Shape, Stage};

fn humanoid(pose: usize, vertices: usize) -> FigureMesh {
    synth::figure(&FigureSpec {
        kind: FigureKind::Humanoid,
        pose,
        target_vertices: vertices,
        ..Default::default()
    })
    .unwrap()
}

fn mesh(figure: &FigureMesh) -> Shape {
    Shape::mesh(figure.vertices.clone(), &figure.triangles).unwrap()
}

fn distance(p: &[f64; 3], q: &[f64; 3]) -> f64 {
    (0..3).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>().sqrt()
}

fn mean_edge(shape: &Shape) -> f64 {
    let edges = shape.edges();
    let p = shape.vertices();
    edges
        .iter()
        .map(|&(i, j)| distance(&p[i as usize], &p[j as usize]))
        .sum::<f64>()
        / edges.len() as f64
}

/// Proxies of about `proxy_vertices` for shapes above twice that.
fn on_proxies(proxy_vertices: usize) -> Params {
    Params {
        multiresolution: Multiresolution {
            above: 2 * proxy_vertices,
            proxy_vertices,
            ..Default::default()
        },
        ..Params::default()
    }
}

/// Mean Euclidean distance between each vertex of B's image and its true image (the same
/// vertex of A: generated figures share the vertex order), over sqrt(area of A).
fn map_error(a: &Shape, p2p_ba: &[u32]) -> f64 {
    let p = a.vertices();
    p2p_ba
        .iter()
        .enumerate()
        .map(|(v, &w)| distance(&p[v], &p[w as usize]))
        .sum::<f64>()
        / p2p_ba.len() as f64
        / a.mesh_area().sqrt()
}

#[test]
fn a_proxy_keeps_input_vertices_and_locates_every_vertex_on_its_surface() {
    let shape = mesh(&humanoid(2, 12_000));
    let proxy = Proxy::build(&shape, 2_000).unwrap();
    let n = proxy.shape.n_vertices();
    assert!((1_600..=2_400).contains(&n), "proxy of {n} vertices");
    assert_eq!(proxy.origin.len(), n);
    let input_vertex: Vec<u32> = (0..n as u32).map(|w| proxy.input_vertex(w)).collect();
    assert!(input_vertex.windows(2).all(|w| w[0] < w[1]));
    let edge = mean_edge(&proxy.shape);
    let mut worst: f64 = 0.0;
    for (v, at) in proxy.location.iter().enumerate() {
        let total: f64 = at.weights.iter().sum();
        assert!((total - 1.0).abs() < 1e-9 && at.weights.iter().all(|&w| w >= 0.0));
        assert!(at.weights[0] >= at.weights[1] && at.weights[1] >= at.weights[2]);
        let point = [0, 1, 2].map(|c| {
            (0..3)
                .map(|i| at.weights[i] * proxy.shape.vertices()[at.vertices[i] as usize][c])
                .sum::<f64>()
        });
        worst = worst.max(distance(&point, &shape.vertices()[v]));
    }
    // Every input vertex lies on the proxy's surface up to the simplification's error.
    assert!(
        worst < 0.5 * edge,
        "worst distance {worst}, proxy edge {edge}"
    );
    for (i, &v) in input_vertex.iter().enumerate() {
        let at = proxy.location[v as usize];
        assert_eq!((at.vertices[0], at.weights[0]), (i as u32, 1.0));
    }
}

#[test]
fn a_proxy_of_a_point_cloud_keeps_input_points() {
    let figure = humanoid(1, 6_000);
    let cloud = synth::sample_points(&figure, 20_000, 0.0, 3).unwrap();
    let shape = Shape::point_cloud(cloud.points.clone()).unwrap();
    let proxy = Proxy::build(&shape, 3_000).unwrap();
    let n = proxy.shape.n_vertices();
    assert!((2_000..=4_000).contains(&n), "proxy of {n} points");
    for i in 0..n {
        let v = proxy.input_vertex(i as u32);
        assert_eq!(proxy.shape.vertices()[i], shape.vertices()[v as usize]);
        assert_eq!(proxy.location[v as usize].nearest(), i as u32);
    }
}

#[test]
fn proxy_sizes_are_checked() {
    let shape = mesh(&humanoid(0, 3_000));
    assert!(matches!(
        Proxy::build(&shape, 10_000),
        Err(Error::InvalidParameter { .. })
    ));
    let params = Params {
        multiresolution: Multiresolution {
            above: 1_000,
            proxy_vertices: 1_000,
            ..Default::default()
        },
        ..Params::default()
    };
    let err = Correspondence::compute(&shape, &shape, &params, &mut NoProgress).unwrap_err();
    assert!(matches!(
        err,
        Error::InvalidParameter {
            name: "proxy_vertices",
            ..
        }
    ));
}

/// Vertices whose region differs from every neighbour's: speckle the lifting must not make.
fn speckles(shape: &Shape, labels: &[u32]) -> usize {
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); shape.n_vertices()];
    for (i, j) in shape.edges() {
        neighbours[i as usize].push(j);
        neighbours[j as usize].push(i);
    }
    (0..shape.n_vertices())
        .filter(|&v| {
            !neighbours[v].is_empty()
                && neighbours[v]
                    .iter()
                    .all(|&w| labels[w as usize] != labels[v])
        })
        .count()
}

#[test]
fn dense_pairs_run_on_proxies_and_come_back_clean_and_as_accurate() {
    let (a, b) = (mesh(&humanoid(0, 12_000)), mesh(&humanoid(3, 12_000)));
    let pointwise = PointwiseParams::default();
    let mut stages = Vec::new();
    let mut progress = |stage: Stage, _: f32| {
        stages.push(stage);
        true
    };
    let dense =
        PointwiseCorrespondence::compute(&a, &b, &on_proxies(3_000), &pointwise, &mut progress)
            .unwrap();
    assert!(stages.contains(&Stage::Proxy));
    let full_params = Params {
        multiresolution: Multiresolution {
            above: 0,
            ..Multiresolution::default()
        },
        ..Params::default()
    };
    let full = PointwiseCorrespondence::compute(&a, &b, &full_params, &pointwise, &mut NoProgress)
        .unwrap();
    assert_eq!(full.proxies, 0.0);
    assert!(dense.proxies > 0.0);
    let graph_a = &dense.regions.graph_a;
    let graph_b = &dense.regions.graph_b;
    assert_eq!(graph_a.labels.len(), a.n_vertices());
    assert_eq!(graph_b.labels.len(), b.n_vertices());
    assert_eq!(speckles(&a, &graph_a.labels), 0);
    assert_eq!(speckles(&b, &graph_b.labels), 0);
    assert_eq!(dense.map.p2p_ba.len(), b.n_vertices());
    let (e_dense, e_full) = (
        map_error(&a, &dense.map.p2p_ba),
        map_error(&a, &full.map.p2p_ba),
    );
    println!("map error: proxies {e_dense:.4}, full resolution {e_full:.4}");
    assert!(e_dense < 0.03, "proxy map error {e_dense}");
    assert!(
        e_dense <= 1.1 * e_full + 0.002,
        "proxies {e_dense} against full resolution {e_full}"
    );
    // The regions agree with the map they came with: most of B's vertices map into the
    // region of A their own region is matched to.
    let matched: std::collections::BTreeSet<(u32, u32)> =
        dense.regions.matches.iter().copied().collect();
    let agree = (0..b.n_vertices())
        .filter(|&v| {
            let ra = graph_a.labels[dense.map.p2p_ba[v] as usize];
            matched.contains(&(ra, graph_b.labels[v]))
        })
        .count();
    assert!(agree as f64 > 0.8 * b.n_vertices() as f64, "{agree} agree");
}

#[test]
fn a_cancel_while_building_proxies_stops_the_job() {
    let (a, b) = (mesh(&humanoid(0, 12_000)), mesh(&humanoid(3, 12_000)));
    let mut cancel_at_proxy = |stage: Stage, _: f32| stage != Stage::Proxy;
    let err =
        Correspondence::compute(&a, &b, &on_proxies(3_000), &mut cancel_at_proxy).unwrap_err();
    assert!(matches!(err, Error::Cancelled));
}
