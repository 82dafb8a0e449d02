//! Nearest-neighbour queries in 3D (kiddo's k-d tree), used for point-cloud connectivity,
//! the point-cloud Laplacian and for giving unreferenced mesh vertices a value.

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

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
