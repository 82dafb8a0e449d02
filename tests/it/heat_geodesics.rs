//! Heat-method geodesics against exact distances: a flat grid (Euclidean) and a sphere
//! (great circles), one source and several, and the errors for bad sources.

use crate::common;

use shapecorr::geodesic::HeatGeodesics;
use shapecorr::Shape;

/// A flat n x n grid of the unit square, each cell split into two triangles.
fn grid(n: usize) -> Shape {
    let mut vertices = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            vertices.push([i as f64 / n as f64, j as f64 / n as f64, 0.0]);
        }
    }
    let index = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            triangles.push([index(i, j), index(i + 1, j), index(i + 1, j + 1)]);
            triangles.push([index(i, j), index(i + 1, j + 1), index(i, j + 1)]);
        }
    }
    Shape::mesh(vertices, &triangles).unwrap()
}

/// Mean relative error over vertices farther than `min_distance` from the sources.
fn mean_relative_error(computed: &[f64], exact: &[f64], min_distance: f64) -> f64 {
    let pairs: Vec<(f64, f64)> = computed
        .iter()
        .zip(exact)
        .filter(|(_, &e)| e > min_distance)
        .map(|(&c, &e)| (c, e))
        .collect();
    pairs.iter().map(|(c, e)| (c - e).abs() / e).sum::<f64>() / pairs.len() as f64
}

#[test]
fn flat_grid_distances_are_within_two_percent() {
    let n = 60;
    let shape = grid(n);
    let solver = HeatGeodesics::new(&shape).unwrap();
    let source = (n / 2 * (n + 1) + n / 2) as u32; // the centre
    let d = solver.distances(&[source]).unwrap();
    let c = shape.vertices()[source as usize];
    let exact: Vec<f64> = shape
        .vertices()
        .iter()
        .map(|p| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt())
        .collect();
    assert_eq!(d[source as usize], 0.0);
    let error = mean_relative_error(&d, &exact, 0.1);
    let dijkstra = shapecorr::geodesic::edge_graph_distances(&shape, &[source], 1.0);
    let graph_error = mean_relative_error(&dijkstra, &exact, 0.1);
    println!("grid {n}x{n}: mean relative error {error:.4} (edge-graph Dijkstra {graph_error:.4})");
    assert!(error < 0.02, "mean relative error {error}");
    assert!(
        error < graph_error,
        "heat {error} vs edge graph {graph_error}"
    );
}

#[test]
fn sphere_distances_are_within_two_percent_from_one_source_and_from_two() {
    let (vertices, triangles) = common::icosphere(5);
    let shape = Shape::mesh(vertices.clone(), &triangles).unwrap();
    let solver = HeatGeodesics::new(&shape).unwrap();
    let great_circle = |p: &[f64; 3], q: &[f64; 3]| {
        let dot = (p[0] * q[0] + p[1] * q[1] + p[2] * q[2]).clamp(-1.0, 1.0);
        dot.acos()
    };
    let a = 0u32;
    let d = solver.distances(&[a]).unwrap();
    let exact: Vec<f64> = vertices
        .iter()
        .map(|p| great_circle(p, &vertices[0]))
        .collect();
    let error = mean_relative_error(&d, &exact, 0.2);
    println!(
        "icosphere(5), {} vertices: mean relative error {error:.4}",
        vertices.len()
    );
    assert!(error < 0.02, "one source: mean relative error {error}");
    // The antipode is pi away.
    let antipode = (0..vertices.len())
        .max_by(|&i, &j| exact[i].total_cmp(&exact[j]))
        .unwrap();
    assert!((d[antipode] - std::f64::consts::PI).abs() < 0.03 * std::f64::consts::PI);

    // Two sources: the distance to the nearer one.
    let b = antipode as u32;
    let d2 = solver.distances(&[a, b]).unwrap();
    let exact2: Vec<f64> = vertices
        .iter()
        .map(|p| great_circle(p, &vertices[0]).min(great_circle(p, &vertices[antipode])))
        .collect();
    let error2 = mean_relative_error(&d2, &exact2, 0.2);
    assert!(error2 < 0.02, "two sources: mean relative error {error2}");
}

#[test]
fn bad_sources_are_errors_and_pieces_without_a_source_are_unreachable() {
    let shape = grid(10);
    let solver = HeatGeodesics::new(&shape).unwrap();
    assert!(solver.distances(&[]).is_err());
    assert!(solver.distances(&[121]).is_err());
    // Two separate grids: the second has no source.
    let g = grid(10);
    let mut vertices = g.vertices().to_vec();
    let mut triangles = g.triangles().to_vec();
    let offset = vertices.len() as u32;
    vertices.extend(g.vertices().iter().map(|p| [p[0] + 5.0, p[1], p[2]]));
    triangles.extend(g.triangles().iter().map(|t| t.map(|v| v + offset)));
    // The repairs would leave the second grid out as a separate object.
    let keep_pieces = shapecorr::shape::Repairs {
        debris_fraction: 0.0,
        ..Default::default()
    };
    let polygons: Vec<Vec<u32>> = triangles.iter().map(|t| t.to_vec()).collect();
    let two = Shape::mesh_with(vertices, &polygons, &keep_pieces).unwrap();
    let d = HeatGeodesics::new(&two).unwrap().distances(&[0]).unwrap();
    assert!(d[..offset as usize].iter().all(|x| x.is_finite()));
    assert!(d[offset as usize..].iter().all(|x| x.is_infinite()));
}
