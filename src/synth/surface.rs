//! Finishing the polygonised surface: projection onto the level set, tangential relaxation
//! for even triangles, splitting quads along their better diagonal, and the closed-manifold
//! check.

use std::collections::HashSet;

use super::field::Field;
use super::geom::{
    add, area_vector, dot, scale, signed_volume_term, sub, triangle_area, triangle_quality, V3,
};

/// Moves every vertex onto the zero level set of `field` (grid spacing `h`).
pub(crate) fn project_all(field: &Field, vertices: &mut [V3], h: f64) {
    let mut subset = Vec::new();
    for p in vertices.iter_mut() {
        field.subset_near(*p, 2.0 * h, &mut subset);
        *p = field.project(*p, &subset, h);
    }
}

/// Vertex neighbours along the quad sides, as compressed rows (sorted, no duplicates).
fn quad_neighbours(n: usize, quads: &[[u32; 4]]) -> (Vec<usize>, Vec<u32>) {
    let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(quads.len() * 8);
    for q in quads {
        for s in 0..4 {
            let (a, b) = (q[s], q[(s + 1) % 4]);
            pairs.push((a, b));
            pairs.push((b, a));
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    let mut start = vec![0usize; n + 1];
    for &(a, _) in &pairs {
        start[a as usize + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    (start, pairs.into_iter().map(|(_, b)| b).collect())
}

/// `iterations` rounds of tangential Laplacian relaxation (each vertex moves half way to the
/// centroid of its neighbours within its tangent plane), each followed by projection back
/// onto the surface. Evens out the triangles without changing the shape.
pub(crate) fn relax(
    field: &Field,
    vertices: &mut [V3],
    quads: &[[u32; 4]],
    h: f64,
    iterations: usize,
) {
    let (start, nbr) = quad_neighbours(vertices.len(), quads);
    let mut subset = Vec::new();
    for _ in 0..iterations {
        let old = vertices.to_vec();
        for (v, p) in vertices.iter_mut().enumerate() {
            let ns = &nbr[start[v]..start[v + 1]];
            if ns.is_empty() {
                continue;
            }
            let mut c = [0.0; 3];
            for &u in ns {
                c = add(c, old[u as usize]);
            }
            let c = scale(c, 1.0 / ns.len() as f64);
            field.subset_near(*p, 2.0 * h, &mut subset);
            let n = field.normal_in(*p, &subset, 1e-3 * h);
            let d = sub(c, *p);
            let d = sub(d, scale(n, dot(d, n)));
            *p = field.project(add(*p, scale(d, 0.5)), &subset, h);
        }
    }
}

/// Splits each quad into two triangles along the diagonal that gives the better worst
/// triangle, avoiding a diagonal that is already an edge (which would make the mesh
/// non-manifold).
pub(crate) fn triangulate(vertices: &[V3], quads: &[[u32; 4]]) -> Vec<[u32; 3]> {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut edges: HashSet<(u32, u32)> = HashSet::with_capacity(quads.len() * 3);
    for q in quads {
        for s in 0..4 {
            edges.insert(key(q[s], q[(s + 1) % 4]));
        }
    }
    let mut tris = Vec::with_capacity(quads.len() * 2);
    for q in quads {
        let p = |i: usize| vertices[q[i] as usize];
        let score = |t0: [usize; 3], t1: [usize; 3]| {
            let n0 = area_vector(p(t0[0]), p(t0[1]), p(t0[2]));
            let n1 = area_vector(p(t1[0]), p(t1[1]), p(t1[2]));
            let folded = if dot(n0, n1) <= 0.0 { -1.0 } else { 0.0 };
            folded
                + triangle_quality(p(t0[0]), p(t0[1]), p(t0[2])).min(triangle_quality(
                    p(t1[0]),
                    p(t1[1]),
                    p(t1[2]),
                ))
        };
        let a = ([0, 1, 2], [0, 2, 3]);
        let b = ([0, 1, 3], [1, 2, 3]);
        let mut sa = score(a.0, a.1);
        let mut sb = score(b.0, b.1);
        if edges.contains(&key(q[0], q[2])) {
            sa -= 10.0;
        }
        if edges.contains(&key(q[1], q[3])) {
            sb -= 10.0;
        }
        let (t0, t1, diag) = if sa >= sb {
            (a.0, a.1, key(q[0], q[2]))
        } else {
            (b.0, b.1, key(q[1], q[3]))
        };
        edges.insert(diag);
        tris.push([q[t0[0]], q[t0[1]], q[t0[2]]]);
        tris.push([q[t1[0]], q[t1[1]], q[t1[2]]]);
    }
    tris
}

/// Checks that `triangles` over `n` vertices form one closed, consistently oriented
/// 2-manifold of genus 0 (every edge in exactly two triangles with opposite directions,
/// every vertex a single fan, one component, Euler characteristic 2) with positive volume
/// and no triangle of zero area. Returns what is wrong otherwise.
pub(crate) fn check_closed_manifold(vertices: &[V3], triangles: &[[u32; 3]]) -> Result<(), String> {
    let n = vertices.len();
    let mut half: Vec<(u32, u32, u32)> = Vec::with_capacity(triangles.len() * 3);
    for (f, t) in triangles.iter().enumerate() {
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] || t.iter().any(|&v| v as usize >= n) {
            return Err(format!("triangle {f} is invalid: {t:?}"));
        }
        for s in 0..3 {
            half.push((t[s], t[(s + 1) % 3], t[(s + 2) % 3]));
        }
    }
    half.sort_unstable();
    for w in half.windows(2) {
        if (w[0].0, w[0].1) == (w[1].0, w[1].1) {
            return Err(format!(
                "edge {}-{} is used twice in the same direction",
                w[0].0, w[0].1
            ));
        }
    }
    let find = |a: u32, b: u32| half.binary_search_by(|h| (h.0, h.1).cmp(&(a, b))).is_ok();
    for h in &half {
        if !find(h.1, h.0) {
            return Err(format!("edge {}-{} has no opposite half-edge", h.0, h.1));
        }
    }
    // Each vertex's link (the opposite edges of its triangles) must be one cycle.
    let mut start = vec![0usize; n + 1];
    for h in &half {
        start[h.0 as usize + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    for v in 0..n {
        let fan = &half[start[v]..start[v + 1]];
        if fan.is_empty() {
            return Err(format!("vertex {v} is in no triangle"));
        }
        // Link edge (b -> c) for each triangle (v, b, c); follow it from the first.
        let next = |b: u32| fan.iter().find(|h| h.1 == b).map(|h| h.2);
        let mut b = fan[0].1;
        let mut steps = 0;
        loop {
            b = next(b).ok_or_else(|| format!("vertex {v} has an open fan"))?;
            steps += 1;
            if b == fan[0].1 || steps > fan.len() {
                break;
            }
        }
        if steps != fan.len() {
            return Err(format!(
                "vertex {v} is non-manifold (its triangles form several fans)"
            ));
        }
    }
    // One component.
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(p: &mut [u32], mut a: u32) -> u32 {
        while p[a as usize] != a {
            p[a as usize] = p[p[a as usize] as usize];
            a = p[a as usize];
        }
        a
    }
    for t in triangles {
        for s in 0..2 {
            let (a, b) = (root(&mut parent, t[s]), root(&mut parent, t[s + 1]));
            parent[a.max(b) as usize] = a.min(b);
        }
    }
    let components = (0..n as u32).filter(|&v| root(&mut parent, v) == v).count();
    if components != 1 {
        return Err(format!("the surface has {components} components"));
    }
    let euler = n as i64 - (half.len() / 2) as i64 + triangles.len() as i64;
    if euler != 2 {
        return Err(format!("Euler characteristic {euler}, expected 2"));
    }
    let volume: f64 = triangles
        .iter()
        .map(|t| {
            signed_volume_term(
                vertices[t[0] as usize],
                vertices[t[1] as usize],
                vertices[t[2] as usize],
            )
        })
        .sum();
    if volume <= 0.0 {
        return Err(format!(
            "signed volume {volume} is not positive (inward orientation)"
        ));
    }
    if let Some(f) = triangles.iter().position(|t| {
        triangle_area(
            vertices[t[0] as usize],
            vertices[t[1] as usize],
            vertices[t[2] as usize],
        ) <= 0.0
    }) {
        return Err(format!("triangle {f} has zero area"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> (Vec<V3>, Vec<[u32; 3]>) {
        let v = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let t = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        (v, t)
    }

    #[test]
    fn manifold_check_accepts_tetrahedron_and_rejects_defects() {
        let (v, t) = tetra();
        check_closed_manifold(&v, &t).unwrap();
        // Inward orientation.
        let flipped: Vec<[u32; 3]> = t.iter().map(|f| [f[0], f[2], f[1]]).collect();
        assert!(check_closed_manifold(&v, &flipped).is_err());
        // A hole.
        assert!(check_closed_manifold(&v, &t[..3]).is_err());
        // One face flipped.
        let mut bad = t.clone();
        bad[0] = [0, 1, 2];
        assert!(check_closed_manifold(&v, &bad).is_err());
        // Two tetrahedra: two components.
        let mut v2 = v.clone();
        v2.extend(v.iter().map(|p| add(*p, [5.0, 0.0, 0.0])));
        let mut t2 = t.clone();
        t2.extend(t.iter().map(|f| [f[0] + 4, f[1] + 4, f[2] + 4]));
        assert!(check_closed_manifold(&v2, &t2).is_err());
    }
}
