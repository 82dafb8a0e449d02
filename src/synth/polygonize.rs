//! Polygonisation of the implicit field: block-sparse sampling on a regular grid, then
//! surface nets (dual contouring) that put one vertex on each marching-cubes patch of a
//! cell and one quad across each grid edge the surface crosses.
//!
//! A cell whose corner signs are ambiguous gets one vertex per patch, the patches being
//! those of marching cubes with the rule "inside corners diagonal on a face are
//! separated". Both cells that share a face see the same rule, so the result is a closed
//! 2-manifold except in rare grid-scale configurations, which the caller detects and
//! avoids by moving the grid.

use std::collections::HashMap;

use super::field::Field;
use super::geom::{add, dist, lerp, scale, V3};

/// Cells per block edge.
const BLOCK: usize = 8;
/// Nodes per block edge.
const NODES: usize = BLOCK + 1;
/// Marks "no patch" in the cube table.
const NO_PATCH: u8 = u8::MAX;

/// A regular grid of cubic cells of side `h`, covered by `blocks` blocks of BLOCK^3 cells;
/// node `(i, j, k)` is at `origin + h (i, j, k)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Grid {
    origin: V3,
    h: f64,
    blocks: [usize; 3],
}

impl Grid {
    /// Grid covering the box `[lo, hi]` with a margin of three cells, with nodes placed
    /// symmetrically about the box centre and then shifted by `shift` cells (each within
    /// [0, 1)).
    pub fn around(lo: V3, hi: V3, h: f64, shift: V3) -> Grid {
        let mut origin = [0.0; 3];
        let mut blocks = [0; 3];
        for a in 0..3 {
            let centre = 0.5 * (lo[a] + hi[a]);
            let half_cells = ((0.5 * (hi[a] - lo[a])) / h).ceil() as usize + 3;
            blocks[a] = (2 * half_cells).div_ceil(BLOCK);
            origin[a] = centre - half_cells as f64 * h + shift[a] * h;
        }
        Grid { origin, h, blocks }
    }

    pub fn spacing(&self) -> f64 {
        self.h
    }

    fn node(&self, i: [usize; 3]) -> V3 {
        [
            self.origin[0] + i[0] as f64 * self.h,
            self.origin[1] + i[1] as f64 * self.h,
            self.origin[2] + i[2] as f64 * self.h,
        ]
    }

    fn block_count(&self) -> usize {
        self.blocks[0] * self.blocks[1] * self.blocks[2]
    }

    /// Nearest node to `p`, if it is on the grid.
    fn nearest_node(&self, p: V3) -> Option<[usize; 3]> {
        let mut n = [0; 3];
        for a in 0..3 {
            let x = ((p[a] - self.origin[a]) / self.h).round();
            if !(x >= 0.0 && x <= (self.blocks[a] * BLOCK) as f64) {
                return None;
            }
            n[a] = x as usize;
        }
        Some(n)
    }

    /// The nodes near each segment of `axes` as chains of edge-adjacent nodes, grouped by
    /// the blocks that hold them (a node on a block face belongs to every block around it),
    /// as local node indices.
    fn forced_nodes(&self, axes: &[(V3, V3)]) -> HashMap<(usize, usize, usize), Vec<usize>> {
        let mut nodes: Vec<[usize; 3]> = Vec::new();
        for &(a, b) in axes {
            let steps = (dist(a, b) / (0.25 * self.h)).ceil().max(1.0) as usize;
            let mut prev: Option<[usize; 3]> = None;
            for s in 0..=steps {
                let p = lerp(a, b, s as f64 / steps as f64);
                let Some(target) = self.nearest_node(p) else {
                    continue;
                };
                // Walk from the previous node to this one one axis at a time, each time
                // taking the step that stays nearest to the axis point.
                if let Some(mut cur) = prev {
                    while cur != target {
                        let mut best: Option<([usize; 3], f64)> = None;
                        for k in 0..3 {
                            if cur[k] == target[k] {
                                continue;
                            }
                            let mut next = cur;
                            next[k] = if target[k] > cur[k] {
                                cur[k] + 1
                            } else {
                                cur[k] - 1
                            };
                            let d = dist(self.node(next), p);
                            if best.is_none_or(|(_, bd)| d < bd) {
                                best = Some((next, d));
                            }
                        }
                        cur = best.expect("nodes differ").0;
                        nodes.push(cur);
                    }
                }
                nodes.push(target);
                prev = Some(target);
            }
        }
        nodes.sort_unstable();
        nodes.dedup();
        let mut by_block: HashMap<(usize, usize, usize), Vec<usize>> = HashMap::new();
        for n in nodes {
            // Blocks whose node range 0..=BLOCK holds this node, per axis.
            let range = |a: usize| {
                let b = n[a] / BLOCK;
                let lo = if n[a] % BLOCK == 0 && b > 0 { b - 1 } else { b };
                lo..=b.min(self.blocks[a] - 1)
            };
            for bz in range(2) {
                for by in range(1) {
                    for bx in range(0) {
                        let l = [n[0] - bx * BLOCK, n[1] - by * BLOCK, n[2] - bz * BLOCK];
                        if l.iter().all(|&x| x <= BLOCK) {
                            by_block
                                .entry((bx, by, bz))
                                .or_default()
                                .push(node_index(l[0], l[1], l[2]));
                        }
                    }
                }
            }
        }
        by_block
    }
}

/// Cube corner `c` has offset `(c & 1, c >> 1 & 1, c >> 2 & 1)`. Edge `e` runs along axis
/// `a = e / 4`; its start corner has bit `(a + 1) % 3` equal to `e & 1` and bit
/// `(a + 2) % 3` equal to `e >> 1 & 1`.
fn edge_corners(e: usize) -> (usize, usize) {
    let a = e / 4;
    let c0 = ((e & 1) << ((a + 1) % 3)) | (((e >> 1) & 1) << ((a + 2) % 3));
    (c0, c0 | (1 << a))
}

/// For each of the 256 corner sign masks (bit set = inside), the patch of each cube edge
/// the surface crosses, and the number of patches.
pub(crate) struct CubeTable {
    patch: [[u8; 12]; 256],
    count: [u8; 256],
}

impl CubeTable {
    pub fn new() -> CubeTable {
        let mut patch = [[NO_PATCH; 12]; 256];
        let mut count = [0u8; 256];
        for mask in 0..256usize {
            let inside = |c: usize| mask >> c & 1 == 1;
            // Components of the inside corners (joined along cube edges) and of the outside
            // corners (joined along cube edges, and across a face whose other diagonal is
            // inside).
            let mut parent: [usize; 8] = std::array::from_fn(|c| c);
            fn find(p: &mut [usize; 8], mut c: usize) -> usize {
                while p[c] != c {
                    c = p[c];
                }
                c
            }
            let union = |p: &mut [usize; 8], a: usize, b: usize| {
                let (ra, rb) = (find(p, a), find(p, b));
                p[ra.max(rb)] = ra.min(rb);
            };
            for e in 0..12 {
                let (c0, c1) = edge_corners(e);
                if inside(c0) == inside(c1) {
                    union(&mut parent, c0, c1);
                }
            }
            for a in 0..3 {
                for s in 0..2 {
                    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                    let corner = |u: usize, v: usize| (s << a) | (u << b) | (v << c);
                    let (d0, d1) = ((corner(0, 0), corner(1, 1)), (corner(1, 0), corner(0, 1)));
                    for (out, other) in [(d0, d1), (d1, d0)] {
                        if !inside(out.0) && !inside(out.1) && inside(other.0) && inside(other.1) {
                            union(&mut parent, out.0, out.1);
                        }
                    }
                }
            }
            // One patch per (inside component, outside component) pair across crossed edges.
            let mut keys: Vec<(usize, usize)> = Vec::new();
            for (e, slot) in patch[mask].iter_mut().enumerate() {
                let (c0, c1) = edge_corners(e);
                if inside(c0) == inside(c1) {
                    continue;
                }
                let (ci, co) = if inside(c0) { (c0, c1) } else { (c1, c0) };
                let key = (find(&mut parent, ci), find(&mut parent, co));
                let id = match keys.iter().position(|&k| k == key) {
                    Some(i) => i,
                    None => {
                        keys.push(key);
                        keys.len() - 1
                    }
                };
                *slot = id as u8;
            }
            count[mask] = keys.len() as u8;
        }
        CubeTable { patch, count }
    }
}

/// The sampled field of one block that holds crossed cells.
struct Block {
    /// Global index of the block's first cell.
    cell0: [usize; 3],
    /// Field values at the NODES^3 nodes.
    values: Vec<f32>,
    /// Corner sign mask of each of the BLOCK^3 cells.
    masks: Vec<u8>,
    /// First vertex of each cell (filled by the vertex pass).
    first_vertex: Vec<u32>,
}

fn node_index(i: usize, j: usize, k: usize) -> usize {
    (k * NODES + j) * NODES + i
}

fn cell_index(i: usize, j: usize, k: usize) -> usize {
    (k * BLOCK + j) * BLOCK + i
}

/// Offset of cube corner `c`.
fn corner_offset(c: usize) -> [usize; 3] {
    [c & 1, (c >> 1) & 1, (c >> 2) & 1]
}

/// The field sampled on the blocks of a grid that the surface passes through.
pub(crate) struct Sampled {
    grid: Grid,
    blocks: Vec<Block>,
    /// Dense map from block number to its index in `blocks` (u32::MAX when not sampled).
    block_of: Vec<u32>,
}

impl Sampled {
    /// Samples `field` on `grid`, skipping every block the surface cannot reach: the field is
    /// 1-Lipschitz, so a block whose centre value exceeds its half-diagonal has one sign.
    ///
    /// The grid nodes along each segment of `axes` (the bones' axes, which lie inside the
    /// figure) are forced inside, as a chain of edge-adjacent nodes; so a part thinner than
    /// the grid spacing stays attached instead of falling between the nodes.
    pub fn new(field: &Field, grid: Grid, axes: &[(V3, V3)]) -> Sampled {
        let h = grid.h;
        let half_diagonal = 3f64.sqrt() * 0.5 * BLOCK as f64 * h;
        let forced = grid.forced_nodes(axes);
        let mut blocks = Vec::new();
        let mut block_of = vec![u32::MAX; grid.block_count()];
        let mut subset = Vec::new();
        let [nbx, nby, nbz] = grid.blocks;
        for bz in 0..nbz {
            for by in 0..nby {
                for bx in 0..nbx {
                    let cell0 = [bx * BLOCK, by * BLOCK, bz * BLOCK];
                    let centre = add(grid.node(cell0), scale([1.0; 3], 0.5 * BLOCK as f64 * h));
                    field.subset_near(centre, half_diagonal, &mut subset);
                    let fc = field.eval_in(centre, &subset);
                    let block_forced = forced.get(&(bx, by, bz));
                    if fc.abs() > half_diagonal * (1.0 + 1e-9) && block_forced.is_none() {
                        continue;
                    }
                    let mut values = vec![0f32; NODES * NODES * NODES];
                    for k in 0..NODES {
                        for j in 0..NODES {
                            for i in 0..NODES {
                                let p = grid.node([cell0[0] + i, cell0[1] + j, cell0[2] + k]);
                                values[node_index(i, j, k)] = field.eval_in(p, &subset) as f32;
                            }
                        }
                    }
                    for &n in block_forced.into_iter().flatten() {
                        values[n] = values[n].min((-0.1 * h) as f32);
                    }
                    let mut masks = vec![0u8; BLOCK * BLOCK * BLOCK];
                    let mut crossed = false;
                    for k in 0..BLOCK {
                        for j in 0..BLOCK {
                            for i in 0..BLOCK {
                                let mut m = 0u8;
                                for c in 0..8 {
                                    let o = corner_offset(c);
                                    if values[node_index(i + o[0], j + o[1], k + o[2])] < 0.0 {
                                        m |= 1 << c;
                                    }
                                }
                                crossed |= m != 0 && m != 255;
                                masks[cell_index(i, j, k)] = m;
                            }
                        }
                    }
                    if crossed {
                        block_of[(bz * nby + by) * nbx + bx] = blocks.len() as u32;
                        blocks.push(Block {
                            cell0,
                            values,
                            masks,
                            first_vertex: Vec::new(),
                        });
                    }
                }
            }
        }
        Sampled {
            grid,
            blocks,
            block_of,
        }
    }

    /// Number of vertices the surface nets will have.
    pub fn vertex_count(&self, table: &CubeTable) -> usize {
        self.blocks
            .iter()
            .flat_map(|b| b.masks.iter())
            .map(|&m| table.count[m as usize] as usize)
            .sum()
    }

    /// The block and local cell of global cell `g` (`None` outside the sampled blocks).
    fn locate(&self, g: [i64; 3]) -> Option<(usize, usize)> {
        let mut b = [0usize; 3];
        let mut l = [0usize; 3];
        for a in 0..3 {
            if g[a] < 0 {
                return None;
            }
            let ga = g[a] as usize;
            b[a] = ga / BLOCK;
            l[a] = ga % BLOCK;
            if b[a] >= self.grid.blocks[a] {
                return None;
            }
        }
        let n = (b[2] * self.grid.blocks[1] + b[1]) * self.grid.blocks[0] + b[0];
        let bi = self.block_of[n];
        (bi != u32::MAX).then(|| (bi as usize, cell_index(l[0], l[1], l[2])))
    }

    /// Surface nets: the vertices (mean of the crossings of each patch's edges, not yet on
    /// the surface) and outward-oriented quads. Fails if the surface reaches the grid edge.
    pub fn surface_nets(mut self, table: &CubeTable) -> Result<(Vec<V3>, Vec<[u32; 4]>), String> {
        let grid = self.grid;
        // Vertex pass: in block order, then cell order.
        let mut vertices: Vec<V3> = Vec::new();
        for block in &mut self.blocks {
            block.first_vertex = vec![u32::MAX; BLOCK * BLOCK * BLOCK];
            for k in 0..BLOCK {
                for j in 0..BLOCK {
                    for i in 0..BLOCK {
                        let ci = cell_index(i, j, k);
                        let mask = block.masks[ci] as usize;
                        let n_patches = table.count[mask] as usize;
                        if n_patches == 0 {
                            continue;
                        }
                        block.first_vertex[ci] = vertices.len() as u32;
                        let mut sum = [[0.0f64; 3]; 12];
                        let mut num = [0usize; 12];
                        for e in 0..12 {
                            let p = table.patch[mask][e];
                            if p == NO_PATCH {
                                continue;
                            }
                            let (c0, c1) = edge_corners(e);
                            let (o0, o1) = (corner_offset(c0), corner_offset(c1));
                            let f0 =
                                block.values[node_index(i + o0[0], j + o0[1], k + o0[2])] as f64;
                            let f1 =
                                block.values[node_index(i + o1[0], j + o1[1], k + o1[2])] as f64;
                            let base = block.cell0;
                            let p0 = grid.node([
                                base[0] + i + o0[0],
                                base[1] + j + o0[1],
                                base[2] + k + o0[2],
                            ]);
                            let p1 = grid.node([
                                base[0] + i + o1[0],
                                base[1] + j + o1[1],
                                base[2] + k + o1[2],
                            ]);
                            let x = lerp(p0, p1, f0 / (f0 - f1));
                            sum[p as usize] = add(sum[p as usize], x);
                            num[p as usize] += 1;
                        }
                        for p in 0..n_patches {
                            vertices.push(scale(sum[p], 1.0 / num[p] as f64));
                        }
                    }
                }
            }
        }
        // Quad pass: the edge from each crossed cell's first corner along each axis.
        let mut quads = Vec::new();
        for block in &self.blocks {
            for k in 0..BLOCK {
                for j in 0..BLOCK {
                    for i in 0..BLOCK {
                        let mask = block.masks[cell_index(i, j, k)] as usize;
                        if table.count[mask] == 0 {
                            continue;
                        }
                        let g = [
                            (block.cell0[0] + i) as i64,
                            (block.cell0[1] + j) as i64,
                            (block.cell0[2] + k) as i64,
                        ];
                        let start_inside = mask & 1 == 1;
                        for a in 0..3 {
                            if (mask >> (1 << a) & 1 == 1) == start_inside {
                                continue;
                            }
                            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                            // The four cells around the edge, counter-clockwise seen from +a.
                            let mut quad = [0u32; 4];
                            for (slot, (db, dc)) in
                                [(1, 1), (0, 1), (0, 0), (1, 0)].into_iter().enumerate()
                            {
                                let mut cell = g;
                                cell[b] -= db;
                                cell[c] -= dc;
                                let (bi, ci) = self.locate(cell).ok_or_else(|| {
                                    "the surface reaches the grid boundary".to_string()
                                })?;
                                let nb = &self.blocks[bi];
                                let m = nb.masks[ci] as usize;
                                let e = a * 4 + db as usize + 2 * dc as usize;
                                let p = table.patch[m][e];
                                if p == NO_PATCH || nb.first_vertex[ci] == u32::MAX {
                                    return Err("inconsistent cell signs".to_string());
                                }
                                quad[slot] = nb.first_vertex[ci] + p as u32;
                            }
                            if !start_inside {
                                quad.reverse();
                            }
                            quads.push(quad);
                        }
                    }
                }
            }
        }
        Ok((vertices, quads))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::field::RoundCone;

    #[test]
    fn table_counts_patches() {
        let t = CubeTable::new();
        assert_eq!(t.count[0], 0);
        assert_eq!(t.count[255], 0);
        assert_eq!(t.count[1], 1);
        // Two inside corners diagonal on the face z = 0: separated.
        assert_eq!(t.count[0b0000_1001], 2);
        // Two inside corners at opposite cube corners: separated.
        assert_eq!(t.count[0b1000_0001], 2);
        // Complement of a diagonal pair: the outside corners join across the face.
        assert_eq!(t.count[!0b0000_1001u8 as usize], 1);
        for mask in 1..255 {
            let crossed = (0..12).filter(|&e| {
                let (c0, c1) = edge_corners(e);
                (mask >> c0 & 1) != (mask >> c1 & 1)
            });
            assert!(crossed.clone().count() >= 3);
            for e in crossed {
                assert!(t.patch[mask][e] < t.count[mask]);
            }
        }
    }

    #[test]
    fn sphere_nets_are_closed() {
        let field = Field::new(&[RoundCone::new([0.0; 3], [0.0; 3], 0.5, 0.5)], 0.05);
        let (lo, hi) = field.bounds();
        let sampled = Sampled::new(&field, Grid::around(lo, hi, 0.05, [0.0, 0.3, 0.7]), &[]);
        let table = CubeTable::new();
        let n = sampled.vertex_count(&table);
        let (v, q) = sampled.surface_nets(&table).unwrap();
        assert_eq!(v.len(), n);
        // Euler characteristic of a quad sphere: V - E + F = V - 2F + F = 2.
        assert_eq!(v.len() as i64 - q.len() as i64, 2);
        // Every quad is outward: its normal points away from the centre.
        for quad in &q {
            let c = scale(
                add(
                    add(v[quad[0] as usize], v[quad[1] as usize]),
                    add(v[quad[2] as usize], v[quad[3] as usize]),
                ),
                0.25,
            );
            let n = crate::synth::geom::area_vector(
                v[quad[0] as usize],
                v[quad[1] as usize],
                v[quad[2] as usize],
            );
            assert!(crate::synth::geom::dot(n, c) > 0.0);
        }
    }
}
