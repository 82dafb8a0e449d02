//! Nearest-neighbour queries in 3D (kiddo's k-d tree), used for point-cloud connectivity,
//! the point-cloud Laplacian and for giving unreferenced mesh vertices a value.

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// A k-d tree over a fixed set of 3D points; items are indices into the slice it was built from.
pub struct PointTree {
    tree: ImmutableKdTree<f64, 3>,
    len: usize,
}

impl PointTree {
    /// Builds the tree. `points` must be non-empty and finite (validated by the caller).
    pub fn new(points: &[[f64; 3]]) -> Self {
        let tree = ImmutableKdTree::new_from_slice(points)
            .expect("a k-d tree over a non-empty finite point set always builds");
        PointTree {
            tree,
            len: points.len(),
        }
    }

    /// The `k` nearest points to `query`, closest first (ties broken by index for
    /// determinism), including a point at distance zero if there is one.
    pub fn nearest_k(&self, query: &[f64; 3], k: usize) -> Vec<(usize, f64)> {
        let k = k.min(self.len);
        let Some(k) = NonZeroUsize::new(k) else {
            return Vec::new();
        };
        let mut found: Vec<(usize, f64)> = self
            .tree
            .query(query)
            .nearest_n::<SquaredEuclidean<f64>>(k)
            .execute()
            .into_iter()
            .map(|r| (r.item as usize, r.distance))
            .collect();
        found.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        found
    }

    /// The index of the nearest point to `query`.
    pub fn nearest(&self, query: &[f64; 3]) -> usize {
        self.nearest_k(query, 1)[0].0
    }
}

/// Symmetric k-nearest-neighbour graph: for every point, the sorted indices of the points
/// that are among its `k` nearest or have it among theirs (the point itself excluded).
pub fn symmetric_knn_graph(points: &[[f64; 3]], k: usize) -> Vec<Vec<usize>> {
    let tree = PointTree::new(points);
    let mut adjacency: Vec<Vec<usize>> = vec![Vec::new(); points.len()];
    for (i, p) in points.iter().enumerate() {
        for (j, _) in tree.nearest_k(p, k + 1) {
            if j != i {
                adjacency[i].push(j);
                adjacency[j].push(i);
            }
        }
    }
    for list in &mut adjacency {
        list.sort_unstable();
        list.dedup();
    }
    adjacency
}

/// The triangles around point `i` in the Delaunay triangulation of its `neighbors` (as
/// [`PointTree::nearest_k`] gives them, `i` among them or not) projected on its tangent
/// plane (normal by PCA): the local triangulation of the point-cloud Laplacian (Sharp and
/// Crane 2020, section 5.7). Empty when the neighbourhood is a point.
pub fn local_delaunay_around(
    points: &[[f64; 3]],
    i: usize,
    neighbors: &[(usize, f64)],
) -> Vec<[u32; 3]> {
    let Some((u, v)) = tangent_frame(points, neighbors) else {
        return Vec::new();
    };
    let p = &points[i];
    // The centre first, then the neighbours (excluding the centre and exact duplicates).
    let mut ids = vec![i];
    let mut planar = Vec::with_capacity(neighbors.len() + 1);
    planar.push(delaunator::Point { x: 0.0, y: 0.0 });
    for &(j, d2) in neighbors {
        if j == i || d2 == 0.0 {
            continue;
        }
        let d = super::sub(&points[j], p);
        planar.push(delaunator::Point {
            x: super::dot(&d, &u),
            y: super::dot(&d, &v),
        });
        ids.push(j);
    }
    let triangulation = delaunator::triangulate(&planar);
    triangulation
        .triangles
        .chunks_exact(3)
        .filter(|t| t.contains(&0))
        .map(|t| [ids[t[0]] as u32, ids[t[1]] as u32, ids[t[2]] as u32])
        .collect()
}

/// The unit normal of a neighbourhood by PCA (the direction of least variance; its sign is
/// arbitrary). None when the neighbourhood is a point.
pub fn pca_normal(points: &[[f64; 3]], neighbors: &[(usize, f64)]) -> Option<[f64; 3]> {
    let (u, v) = tangent_frame(points, neighbors)?;
    Some(super::cross(&u, &v))
}

/// Two orthonormal tangent directions at a point from the covariance of its neighbours
/// (the normal is the direction of least variance). None when the neighbourhood is a point.
fn tangent_frame(points: &[[f64; 3]], neighbors: &[(usize, f64)]) -> Option<([f64; 3], [f64; 3])> {
    let n = neighbors.len() as f64;
    let mut mean = Vector3::zeros();
    for &(j, _) in neighbors {
        mean += Vector3::from(points[j]);
    }
    mean /= n;
    let mut covariance = Matrix3::zeros();
    for &(j, _) in neighbors {
        let d = Vector3::from(points[j]) - mean;
        covariance += d * d.transpose();
    }
    let eigen = SymmetricEigen::new(covariance);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
    if !(eigen.eigenvalues[order[0]] > 0.0) {
        return None;
    }
    let u = eigen.eigenvectors.column(order[0]).into_owned();
    let normal = eigen.eigenvectors.column(order[2]).into_owned();
    let v = normal.cross(&u).normalize();
    Some(([u.x, u.y, u.z], [v.x, v.y, v.z]))
}
