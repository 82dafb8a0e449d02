//! Outward normals of a point cloud and its local triangles turned by them, so that a
//! cloud's left and right are known as a mesh's are ([`crate::Shape::oriented_triangles`]):
//! the pointwise map's orientation term and orientation test use them. A close call is not
//! settled by them: there a wrong map can keep more of them than the right one
//! (docs/scans.md, "Point clouds").
//!
//! Normals by PCA over each point's nearest neighbours; their signs made consistent by
//! propagation along a minimum spanning tree of the neighbour graph whose edges cost
//! `1 - |n_i . n_j|` (Hoppe et al., "Surface reconstruction from unorganized points",
//! SIGGRAPH 1992; the method of Open3D's and PCL's consistent orientation), each connected
//! piece then turned outward by the sign of the flux of `p - centroid` through it. Edges
//! that leave the tangent planes cost more, which keeps the tree off edges between two
//! sheets (FAUST_r clouds: 5% of the normals clearly wrong instead of 7%). It still goes
//! wrong where two sheets of the surface come within a few point spacings (thin parts, touching
//! limbs): then the local triangles disagree with their corners' normals, and an
//! orientation that too many of them contradict ([`TRUSTED_AGREEMENT`]) is not used.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashSet};

use crate::shape::neighbors::{local_delaunay_around, pca_normal, PointTree};
use crate::shape::{cross, dot, sub};

/// Neighbours per point for the normals and the propagation graph (Hoppe et al. use 8-15;
/// not tuned).
pub const ORIENTATION_NEIGHBORS: usize = 10;

/// Neighbours per point of the local triangles (those of the point-cloud Laplacian).
const TRIANGLE_NEIGHBORS: usize = crate::spectral::laplacian::POINT_CLOUD_NEIGHBORS;

/// The orientation is trusted when at least this share of the local triangles agree with
/// all three of their corners' normals. Set below every clean development cloud measured
/// (0.76-0.93 on FAUST, FAUST_r and TOSCA_r vertices jittered by 0.2% of the height,
/// docs/scans.md, "Point clouds"); not calibrated on clouds whose orientation fails.
pub const TRUSTED_AGREEMENT: f64 = 0.7;

/// A cloud's outward unit normals and its local triangles turned to agree with them.
#[derive(Debug, Clone)]
pub struct OrientedCloud {
    /// One unit normal per point (zero where the neighbourhood is degenerate).
    pub normals: Vec<[f64; 3]>,
    /// The local Delaunay triangles around every point, each once, counter-clockwise seen
    /// from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Share of `triangles` whose three corners' normals agree with the triangle's side.
    pub agreement: f64,
}

impl OrientedCloud {
    /// Whether the orientation can be used ([`TRUSTED_AGREEMENT`]).
    pub fn trusted(&self) -> bool {
        self.agreement >= TRUSTED_AGREEMENT
    }
}

/// The oriented normals and triangles of `points`.
pub fn orient(points: &[[f64; 3]]) -> OrientedCloud {
    let tree = PointTree::new(points);
    let neighbours: Vec<Vec<(usize, f64)>> = points
        .iter()
        .map(|p| tree.nearest_k(p, ORIENTATION_NEIGHBORS + 1))
        .collect();
    let mut normals: Vec<[f64; 3]> = neighbours
        .iter()
        .map(|near| pca_normal(points, near).unwrap_or([0.0; 3]))
        .collect();
    propagate_signs(points, &neighbours, &mut normals);
    let mut seen = HashSet::new();
    let mut triangles = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let near = tree.nearest_k(p, TRIANGLE_NEIGHBORS + 1);
        for t in local_delaunay_around(points, i, &near) {
            let mut key = t;
            key.sort_unstable();
            if seen.insert(key) {
                triangles.push(t);
            }
        }
    }
    let (mut agreeing, mut counted) = (0usize, 0usize);
    for t in &mut triangles {
        let [a, b, c] = t.map(|v| points[v as usize]);
        let side = cross(&sub(&b, &a), &sub(&c, &a));
        let corners = t.map(|v| dot(&side, &normals[v as usize]));
        if corners.iter().sum::<f64>() < 0.0 {
            t.swap(1, 2);
        }
        if corners.iter().any(|x| *x != 0.0) {
            counted += 1;
            let sign = corners.iter().sum::<f64>().signum();
            agreeing += usize::from(corners.iter().all(|x| x * sign > 0.0));
        }
    }
    OrientedCloud {
        normals,
        triangles,
        agreement: agreeing as f64 / counted.max(1) as f64,
    }
}

/// Makes the normals' signs agree along a minimum spanning tree of the neighbour graph
/// (Prim's, edges costing `1 - |n_i . n_j|` plus how far they leave the tangent planes),
/// each connected piece then turned outward.
fn propagate_signs(
    points: &[[f64; 3]],
    neighbours: &[Vec<(usize, f64)>],
    normals: &mut [[f64; 3]],
) {
    let n = points.len();
    let mut graph: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, near) in neighbours.iter().enumerate() {
        for &(j, _) in near {
            if j != i {
                graph[i].push(j);
                graph[j].push(i);
            }
        }
    }
    for list in &mut graph {
        list.sort_unstable();
        list.dedup();
    }
    let mut piece = vec![usize::MAX; n];
    let mut done = vec![false; n];
    for start in 0..n {
        if piece[start] != usize::MAX {
            continue;
        }
        // The connected piece of `start`.
        let mut members = vec![start];
        piece[start] = start;
        let mut next = 0;
        while next < members.len() {
            let v = members[next];
            next += 1;
            for &w in &graph[v] {
                if piece[w] == usize::MAX {
                    piece[w] = start;
                    members.push(w);
                }
            }
        }
        let seed = members[0];
        // Prim's: the cheapest edge out of the tree first; costs as ordered integers.
        let mut heap = BinaryHeap::new();
        let cost = |normals: &[[f64; 3]], v: usize, w: usize| -> u64 {
            let d = sub(&points[w], &points[v]);
            let length = dot(&d, &d).sqrt();
            let off_plane = if length > 0.0 {
                0.5 * (dot(&d, &normals[v]).abs() + dot(&d, &normals[w]).abs()) / length
            } else {
                0.0
            };
            let c = 1.0 - dot(&normals[v], &normals[w]).abs() + off_plane;
            (c.clamp(0.0, 4.0) * 1e15) as u64
        };
        done[seed] = true;
        for &w in &graph[seed] {
            heap.push(Reverse((cost(normals, seed, w), seed, w)));
        }
        while let Some(Reverse((_, from, to))) = heap.pop() {
            if done[to] {
                continue;
            }
            done[to] = true;
            if dot(&normals[from], &normals[to]) < 0.0 {
                normals[to] = normals[to].map(|x| -x);
            }
            for &w in &graph[to] {
                if !done[w] {
                    heap.push(Reverse((cost(normals, to, w), to, w)));
                }
            }
        }
        // Outward: the flux of `p - centroid` through a closed surface facing out is three
        // times its volume, so positive; the points stand in for equal pieces of area.
        let mut centroid = [0.0; 3];
        for &v in &members {
            for c in 0..3 {
                centroid[c] += points[v][c] / members.len() as f64;
            }
        }
        let flux: f64 = members
            .iter()
            .map(|&v| dot(&normals[v], &sub(&points[v], &centroid)))
            .sum();
        if flux < 0.0 {
            for &v in &members {
                normals[v] = normals[v].map(|x| -x);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::Shape;
    use crate::synth;

    #[test]
    fn a_sampled_figure_gets_its_mesh_normals_and_triangles_facing_out() {
        let mesh = synth::figure(&synth::FigureSpec {
            target_vertices: 3000,
            ..Default::default()
        })
        .unwrap();
        let shape = Shape::mesh(mesh.vertices.clone(), &mesh.triangles).unwrap();
        // The mesh's own area-weighted vertex normals (outward by construction).
        let mut truth = vec![[0.0; 3]; mesh.vertices.len()];
        for t in shape.triangles() {
            let [a, b, c] = t.map(|v| mesh.vertices[v as usize]);
            let n = cross(&sub(&b, &a), &sub(&c, &a));
            for &v in t {
                for k in 0..3 {
                    truth[v as usize][k] += n[k];
                }
            }
        }
        let cloud = orient(&mesh.vertices);
        assert!(cloud.trusted(), "agreement {}", cloud.agreement);
        let agree = (0..truth.len())
            .filter(|&v| dot(&truth[v], &cloud.normals[v]) > 0.0)
            .count();
        assert!(
            agree as f64 >= 0.97 * truth.len() as f64,
            "{agree} of {} normals outward",
            truth.len()
        );
        // Turned the other way round, every normal and triangle turns with it.
        let mirrored: Vec<[f64; 3]> = mesh.vertices.iter().map(|p| [-p[0], p[1], p[2]]).collect();
        let other = orient(&mirrored);
        let flipped = (0..truth.len())
            .filter(|&v| dot(&[-truth[v][0], truth[v][1], truth[v][2]], &other.normals[v]) > 0.0)
            .count();
        assert!(
            flipped as f64 >= 0.97 * truth.len() as f64,
            "{flipped} mirrored"
        );
    }
}
