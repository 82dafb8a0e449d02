//! The shape graph (paper, section 4): a node for every connected region of every joint
//! cluster, edges between regions whose expanded regions overlap. Built by
//! [`crate::regions::segmentation`], matched by [`crate::regions::matching`].

/// A shape's decomposition into regions and the graph over them.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeGraph {
    /// Region (node) of every input vertex, in the caller's vertex order.
    pub labels: Vec<u32>,
    /// Joint cluster (k-means centroid index) of every node.
    pub node_cluster: Vec<u32>,
    /// Area of every node's region on the unit-area shape (sums to 1).
    pub node_area: Vec<f64>,
    /// Area-weighted mean (rank-aligned) descriptor of every node, one row per node.
    pub node_descriptor: Vec<Vec<f64>>,
    /// Undirected edges `(i, j)` with `i < j`, sorted, without duplicates.
    pub edges: Vec<(u32, u32)>,
}

/// Marks an unreachable node in [`ShapeGraph::hop_distances`].
pub const UNREACHABLE: u32 = u32::MAX;

impl ShapeGraph {
    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.node_cluster.len()
    }

    /// Neighbours of every node, ascending.
    pub fn adjacency(&self) -> Vec<Vec<u32>> {
        let mut adjacency = vec![Vec::new(); self.n_nodes()];
        for &(i, j) in &self.edges {
            adjacency[i as usize].push(j);
            adjacency[j as usize].push(i);
        }
        for list in &mut adjacency {
            list.sort_unstable();
        }
        adjacency
    }

    /// Degree of every node.
    pub fn degrees(&self) -> Vec<usize> {
        self.adjacency().iter().map(Vec::len).collect()
    }

    /// Graph (hop) distance between every pair of nodes, by breadth-first search;
    /// [`UNREACHABLE`] between different connected components.
    pub fn hop_distances(&self) -> Vec<Vec<u32>> {
        let adjacency = self.adjacency();
        let n = self.n_nodes();
        let mut all = Vec::with_capacity(n);
        for source in 0..n {
            let mut distance = vec![UNREACHABLE; n];
            distance[source] = 0;
            let mut queue = std::collections::VecDeque::from([source]);
            while let Some(node) = queue.pop_front() {
                for &next in &adjacency[node] {
                    let next = next as usize;
                    if distance[next] == UNREACHABLE {
                        distance[next] = distance[node] + 1;
                        queue.push_back(next);
                    }
                }
            }
            all.push(distance);
        }
        all
    }

    /// True when every node can reach every other.
    pub fn is_connected(&self) -> bool {
        self.n_nodes() > 0 && self.hop_distances()[0].iter().all(|&d| d != UNREACHABLE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path(n: u32) -> ShapeGraph {
        ShapeGraph {
            labels: vec![],
            node_cluster: vec![0; n as usize],
            node_area: vec![1.0 / n as f64; n as usize],
            node_descriptor: vec![vec![]; n as usize],
            edges: (0..n - 1).map(|i| (i, i + 1)).collect(),
        }
    }

    #[test]
    fn hop_distances_on_a_path_and_two_pieces() {
        let g = path(4);
        assert_eq!(g.hop_distances()[0], vec![0, 1, 2, 3]);
        assert_eq!(g.degrees(), vec![1, 2, 2, 1]);
        assert!(g.is_connected());
        let mut split = path(4);
        split.edges.retain(|&e| e != (1, 2));
        assert_eq!(
            split.hop_distances()[0],
            vec![0, 1, UNREACHABLE, UNREACHABLE]
        );
        assert!(!split.is_connected());
    }
}
