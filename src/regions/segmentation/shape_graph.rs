//! Step 3 (paper, section 4): the shape graph of a clustering, a node per connected region.

use super::*;

/// The shape graph of one shape (paper, section 4, step 3; docs/design.md, step 8) with the
/// default [`GraphParams`]. See [`shape_graph_with`].
pub fn shape_graph(
    shape: &Shape,
    mass: &[f64],
    descriptors: MatRef<f64>,
    centroids: MatRef<f64>,
    labels: &[u32],
) -> ShapeGraph {
    shape_graph_with(
        shape,
        mass,
        descriptors,
        centroids,
        labels,
        &GraphParams::default(),
    )
}

/// The shape graph of one shape from its joint clustering.
///
/// - `labels[v]` is the cluster of input vertex `v` (its nearest centroid); `descriptors`
///   (rank-aligned, one row per input vertex) and `centroids` (k x d) give every vertex its
///   second nearest centroid under `params.metric`.
/// - A region is a connected set (over [`Shape::edges`]) of active vertices of one cluster.
///   Regions below `params.min_region_area` of the total mass are merged, smallest first, into the
///   neighbouring region they share most edges with (ties: the larger, then the lower
///   numbered); a merge that makes two regions of the absorbing cluster touch unites them.
///   Every remaining region is a node, numbered by its smallest vertex index.
/// - The expanded region `R*` of region `R` of cluster `c` is the connected set containing
///   `R` in `R` plus the vertices whose second nearest centroid is `c`
///   ([`RegionExpansion::SecondNearestBand`]), or among all vertices whose first or second
///   nearest centroid is `c` ([`RegionExpansion::FirstOrSecondNearest`]); `R` and `S` are
///   joined by an edge when `S` intersects `R*`. Edges are found on the regions before
///   merging and then contracted: a merged node's expanded region is the union of its
///   parts'.
/// - Unreferenced vertices take the node of their representative; node area is the sum of
///   mass (normalised to sum 1), node descriptor the mass-weighted mean descriptor.
///
/// # Panics
/// When a slice or matrix does not have one entry per input vertex, the centroids and
/// descriptors have different columns, or a label is not below the number of centroids.
pub fn shape_graph_with(
    shape: &Shape,
    mass: &[f64],
    descriptors: MatRef<f64>,
    centroids: MatRef<f64>,
    labels: &[u32],
    params: &GraphParams,
) -> ShapeGraph {
    let edges = shape.edges();
    let connectivity = Connectivity {
        active: shape.active_vertices(),
        representative: shape.representative(),
        edges: &edges,
    };
    build_graph(&connectivity, mass, descriptors, centroids, labels, params)
}

/// What the graph construction needs from a shape (edges computed once per pair).
pub(super) struct Connectivity<'a> {
    pub(super) active: &'a [u32],
    pub(super) representative: &'a [u32],
    pub(super) edges: &'a [(u32, u32)],
}

pub(super) fn build_graph(
    conn: &Connectivity,
    mass: &[f64],
    descriptors: MatRef<f64>,
    centroids: MatRef<f64>,
    labels: &[u32],
    params: &GraphParams,
) -> ShapeGraph {
    let (metric, min_region_area) = (params.metric, params.min_region_area);
    let n = conn.representative.len();
    let (k, d) = (centroids.nrows(), centroids.ncols());
    assert_eq!(mass.len(), n, "shape graph: one mass per input vertex");
    assert_eq!(labels.len(), n, "shape graph: one label per input vertex");
    assert_eq!(
        descriptors.nrows(),
        n,
        "shape graph: one descriptor row per input vertex"
    );
    assert_eq!(
        descriptors.ncols(),
        d,
        "shape graph: descriptor and centroid columns differ"
    );
    let active = conn.active;
    assert!(
        active.iter().all(|&v| (labels[v as usize] as usize) < k),
        "shape graph: a label is not below the number of centroids ({k})"
    );
    let mass: Vec<f64> = mass
        .iter()
        .map(|&m| if m > 0.0 && m.is_finite() { m } else { 0.0 })
        .collect();

    // Second nearest centroid of every active vertex.
    let centroid_rows: Vec<f64> = (0..k)
        .flat_map(|c| (0..d).map(move |j| centroids[(c, j)]))
        .collect();
    let second_active: Vec<u32> = active
        .par_iter()
        .map(|&v| {
            if k < 2 {
                return u32::MAX;
            }
            let row: Vec<f64> = (0..d).map(|j| descriptors[(v as usize, j)]).collect();
            nearest(metric, &row, &centroid_rows, d, labels[v as usize] as usize).0
        })
        .collect();
    let mut second = vec![u32::MAX; n];
    for (&v, &s) in active.iter().zip(&second_active) {
        second[v as usize] = s;
    }

    // Regions: connected components of each cluster.
    let (mut regions, region_of) = Regions::components(n, active, conn.edges, labels, &mass);
    let first_vertex = regions.first_vertex.clone();
    let total_mass: f64 = regions.area.iter().sum();
    if min_region_area > 0.0 {
        regions.merge_fragments(min_region_area * total_mass);
    }

    // Nodes: the surviving regions, numbered by smallest vertex.
    let (survivors, node_of_region) = regions.nodes();
    let n_nodes = survivors.len();
    let node_cluster: Vec<u32> = survivors
        .iter()
        .map(|&r| regions.cluster[r as usize])
        .collect();
    let mut node_of = vec![u32::MAX; n];
    for &v in active {
        node_of[v as usize] = node_of_region[region_of[v as usize] as usize];
    }

    // Edges on the regions before fragments were merged, then contracted (a merged
    // node's expanded region is the union of its parts').
    let mut regions_of_cluster: Vec<Vec<u32>> = vec![Vec::new(); k];
    for (r, &c) in regions.cluster.iter().enumerate() {
        regions_of_cluster[c as usize].push(r as u32);
    }
    let region_edges = match params.expansion {
        RegionExpansion::SecondNearestBand => {
            band_edges(conn, labels, &second, &region_of, &regions_of_cluster)
        }
        RegionExpansion::FirstOrSecondNearest => first_or_second_edges(
            conn,
            labels,
            &second,
            &region_of,
            &regions_of_cluster,
            &first_vertex,
        ),
    };
    let mut graph_edges: Vec<(u32, u32)> = region_edges
        .into_iter()
        .map(|(r, s)| (node_of_region[r as usize], node_of_region[s as usize]))
        .filter(|(x, y)| x != y)
        .map(|(x, y)| (x.min(y), x.max(y)))
        .collect();
    graph_edges.sort_unstable();
    graph_edges.dedup();

    // Per input vertex: labels, areas and descriptors.
    let graph_labels: Vec<u32> = conn
        .representative
        .iter()
        .map(|&r| node_of[r as usize])
        .collect();
    let mut node_area = vec![0.0; n_nodes];
    let mut node_count = vec![0usize; n_nodes];
    let mut weighted = vec![vec![0.0; d]; n_nodes];
    let mut plain = vec![vec![0.0; d]; n_nodes];
    for (v, &node) in graph_labels.iter().enumerate() {
        let node = node as usize;
        node_area[node] += mass[v];
        node_count[node] += 1;
        for j in 0..d {
            weighted[node][j] += mass[v] * descriptors[(v, j)];
            plain[node][j] += descriptors[(v, j)];
        }
    }
    let node_descriptor: Vec<Vec<f64>> = (0..n_nodes)
        .map(|node| {
            if node_area[node] > 0.0 {
                weighted[node].iter().map(|x| x / node_area[node]).collect()
            } else {
                plain[node]
                    .iter()
                    .map(|x| x / node_count[node].max(1) as f64)
                    .collect()
            }
        })
        .collect();
    let total: f64 = node_area.iter().sum();
    if total > 0.0 {
        for a in &mut node_area {
            *a /= total;
        }
    } else {
        for (a, &count) in node_area.iter_mut().zip(&node_count) {
            *a = count as f64 / n as f64;
        }
    }
    ShapeGraph {
        labels: graph_labels,
        node_cluster,
        node_area,
        node_descriptor,
        edges: graph_edges,
    }
}

/// Region edges of [`RegionExpansion::SecondNearestBand`]: for every cluster `c`, the
/// connected pieces of the band (vertices not of cluster `c` whose second nearest centroid
/// is `c`); a region of cluster `c` touching a piece is joined to every region the piece
/// meets.
fn band_edges(
    conn: &Connectivity,
    labels: &[u32],
    second: &[u32],
    region_of: &[u32],
    regions_of_cluster: &[Vec<u32>],
) -> Vec<(u32, u32)> {
    let n = labels.len();
    let mut edges = Vec::new();
    for (c, cluster_regions) in regions_of_cluster.iter().enumerate() {
        if cluster_regions.is_empty() {
            continue;
        }
        let c = c as u32;
        let in_band = |v: u32| second[v as usize] == c && labels[v as usize] != c;
        let mut sets = DisjointSets::new(n);
        for &(u, v) in conn.edges {
            if in_band(u) && in_band(v) {
                sets.union(u as usize, v as usize);
            }
        }
        // (band piece, region of cluster c touching it)
        let mut attached: Vec<(usize, u32)> = Vec::new();
        for &(u, v) in conn.edges {
            for (x, y) in [(u, v), (v, u)] {
                if labels[x as usize] == c && in_band(y) {
                    attached.push((sets.find(y as usize), region_of[x as usize]));
                }
            }
        }
        attached.sort_unstable();
        attached.dedup();
        if attached.is_empty() {
            continue;
        }
        // (band piece, region it meets)
        let mut met: Vec<(usize, u32)> = conn
            .active
            .iter()
            .filter(|&&v| in_band(v))
            .map(|&v| (sets.find(v as usize), region_of[v as usize]))
            .collect();
        met.sort_unstable();
        met.dedup();
        let mut i = 0;
        for &(piece, region) in &attached {
            while i < met.len() && met[i].0 < piece {
                i += 1;
            }
            let mut j = i;
            while j < met.len() && met[j].0 == piece {
                edges.push((region, met[j].1));
                j += 1;
            }
        }
    }
    edges
}

/// Region edges of [`RegionExpansion::FirstOrSecondNearest`]: for every cluster `c`, the
/// connected pieces of the vertices whose first or second nearest centroid is `c`; every
/// region of cluster `c` is joined to every region its piece meets.
fn first_or_second_edges(
    conn: &Connectivity,
    labels: &[u32],
    second: &[u32],
    region_of: &[u32],
    regions_of_cluster: &[Vec<u32>],
    first_vertex: &[u32],
) -> Vec<(u32, u32)> {
    let n = labels.len();
    let mut edges = Vec::new();
    for (c, cluster_regions) in regions_of_cluster.iter().enumerate() {
        if cluster_regions.is_empty() {
            continue;
        }
        let c = c as u32;
        let eligible = |v: u32| labels[v as usize] == c || second[v as usize] == c;
        let mut sets = DisjointSets::new(n);
        for &(u, v) in conn.edges {
            if eligible(u) && eligible(v) {
                sets.union(u as usize, v as usize);
            }
        }
        let mut expanded: HashMap<usize, Vec<u32>> = HashMap::new();
        for &r in cluster_regions {
            let root = sets.find(first_vertex[r as usize] as usize);
            expanded.entry(root).or_default().push(r);
        }
        let mut met: Vec<(usize, u32)> = conn
            .active
            .iter()
            .filter(|&&v| eligible(v))
            .map(|&v| (sets.find(v as usize), region_of[v as usize]))
            .filter(|(root, _)| expanded.contains_key(root))
            .collect();
        met.sort_unstable();
        met.dedup();
        for (root, other) in met {
            for &r in &expanded[&root] {
                edges.push((r, other));
            }
        }
    }
    edges
}

/// Connected regions while fragments are merged (also the Reeb baseline's level components,
/// `shapecorr_eval::reeb`).
#[derive(Default)]
pub struct Regions {
    /// The cluster (Reeb: level interval) of each region.
    pub cluster: Vec<u32>,
    /// The area of each region (sum of its vertices' mass).
    pub area: Vec<f64>,
    /// The smallest vertex of each region.
    pub first_vertex: Vec<u32>,
    /// Neighbouring regions and the number of edges shared with each.
    pub neighbours: Vec<BTreeMap<u32, u32>>,
    /// The region this one was merged into (`u32::MAX`: still a region).
    pub absorbed_into: Vec<u32>,
}

impl Regions {
    /// The connected components, over `edges`, of the active vertices of each label: their
    /// label (`cluster`), area (sum of `mass`), smallest vertex and neighbours; with the
    /// region of every vertex (`u32::MAX` for inactive ones). Nothing is merged yet.
    pub fn components(
        n: usize,
        active: &[u32],
        edges: &[(u32, u32)],
        labels: &[u32],
        mass: &[f64],
    ) -> (Regions, Vec<u32>) {
        let mut sets = DisjointSets::new(n);
        for &(u, v) in edges {
            if labels[u as usize] == labels[v as usize] {
                sets.union(u as usize, v as usize);
            }
        }
        let mut region_of = vec![u32::MAX; n];
        let mut region_of_root: HashMap<usize, u32> = HashMap::new();
        let mut regions = Regions::default();
        for &v in active {
            let next = regions.cluster.len() as u32;
            let r = *region_of_root.entry(sets.find(v as usize)).or_insert(next);
            if r == next {
                regions.cluster.push(labels[v as usize]);
                regions.area.push(0.0);
                regions.first_vertex.push(v);
                regions.neighbours.push(BTreeMap::new());
                regions.absorbed_into.push(u32::MAX);
            }
            region_of[v as usize] = r;
            regions.area[r as usize] += mass[v as usize];
        }
        for &(u, v) in edges {
            let (ru, rv) = (region_of[u as usize], region_of[v as usize]);
            if ru != rv {
                *regions.neighbours[ru as usize].entry(rv).or_insert(0) += 1;
                *regions.neighbours[rv as usize].entry(ru).or_insert(0) += 1;
            }
        }
        (regions, region_of)
    }

    /// The regions that survived merging, numbered by smallest vertex (`survivors[node]` is
    /// the region of that node), and the node of every region (merged ones: their
    /// absorber's).
    pub fn nodes(&self) -> (Vec<u32>, Vec<u32>) {
        let mut survivors: Vec<u32> = (0..self.cluster.len() as u32)
            .filter(|&r| self.absorbed_into[r as usize] == u32::MAX)
            .collect();
        survivors.sort_by_key(|&r| self.first_vertex[r as usize]);
        let mut node_of_region = vec![u32::MAX; self.cluster.len()];
        for (node, &r) in survivors.iter().enumerate() {
            node_of_region[r as usize] = node as u32;
        }
        for r in 0..self.cluster.len() {
            node_of_region[r] = node_of_region[self.resolve(r as u32) as usize];
        }
        (survivors, node_of_region)
    }

    /// The region that `r` ended up in after merges.
    pub fn resolve(&self, mut r: u32) -> u32 {
        while self.absorbed_into[r as usize] != u32::MAX {
            r = self.absorbed_into[r as usize];
        }
        r
    }

    /// Merges regions below `threshold` area, smallest first, into the neighbour sharing
    /// most edges (ties: the larger, then the lower numbered); regions of the absorbing
    /// cluster that touched the fragment join too. A region without neighbours (a separate
    /// piece of the shape) stays.
    pub fn merge_fragments(&mut self, threshold: f64) {
        loop {
            let fragment = (0..self.cluster.len())
                .filter(|&r| {
                    self.absorbed_into[r] == u32::MAX
                        && self.area[r] < threshold
                        && !self.neighbours[r].is_empty()
                })
                .min_by(|&x, &y| self.area[x].total_cmp(&self.area[y]).then(x.cmp(&y)));
            let Some(fragment) = fragment else { break };
            let target = *self.neighbours[fragment]
                .iter()
                .max_by(|(&x, &cx), (&y, &cy)| {
                    cx.cmp(&cy)
                        .then(self.area[x as usize].total_cmp(&self.area[y as usize]))
                        .then(y.cmp(&x))
                })
                .expect("the fragment has neighbours")
                .0;
            let others: Vec<u32> = self.neighbours[fragment].keys().copied().collect();
            self.absorb(target, fragment as u32);
            // Regions of the target's cluster that touched the fragment now touch the
            // target: they are one connected region of that cluster.
            for other in others {
                if other != target
                    && self.absorbed_into[other as usize] == u32::MAX
                    && self.cluster[other as usize] == self.cluster[target as usize]
                {
                    self.absorb(target, other);
                }
            }
        }
    }

    fn absorb(&mut self, target: u32, absorbed: u32) {
        let (t, a) = (target as usize, absorbed as usize);
        self.absorbed_into[a] = target;
        self.area[t] += self.area[a];
        self.first_vertex[t] = self.first_vertex[t].min(self.first_vertex[a]);
        let moved = std::mem::take(&mut self.neighbours[a]);
        for (other, count) in moved {
            self.neighbours[other as usize].remove(&absorbed);
            if other != target {
                *self.neighbours[t].entry(other).or_insert(0) += count;
                *self.neighbours[other as usize].entry(target).or_insert(0) += count;
            }
        }
        self.neighbours[t].remove(&absorbed);
    }
}
