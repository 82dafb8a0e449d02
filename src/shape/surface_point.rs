//! Points of a shape's surface as three vertices and weights: where an input vertex lies on
//! its proxy (docs/design.md, step 16) and where a vertex of B lands on A (the surface map,
//! docs/transfer.md).

/// A point of a shape's surface: three of its vertices and their weights (summing to 1),
/// heaviest first. On a mesh the vertices are a triangle's and the weights barycentric; on
/// a point cloud the three nearest points, weighted inversely to the distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Vertices, heaviest first.
    pub vertices: [u32; 3],
    /// Their weights (barycentric on a mesh), descending, summing to 1.
    pub weights: [f64; 3],
}

impl SurfacePoint {
    /// The vertex nearest on the surface (the heaviest).
    pub fn nearest(&self) -> u32 {
        self.vertices[0]
    }

    /// Vertex `v` itself (weight 1).
    pub fn at(v: u32) -> SurfacePoint {
        SurfacePoint {
            vertices: [v; 3],
            weights: [1.0, 0.0, 0.0],
        }
    }
}

/// Weights inversely proportional to the distance (a point at distance 0 takes all).
pub(crate) fn inverse_distance(near: &[(u32, f64)]) -> SurfacePoint {
    let mut vertices = [near[0].0; 3];
    let mut weights = [1.0, 0.0, 0.0];
    if near[0].1 > 0.0 {
        let inv: Vec<f64> = near.iter().take(3).map(|&(_, d)| 1.0 / d).collect();
        let total: f64 = inv.iter().sum();
        for (i, &(v, _)) in near.iter().take(3).enumerate() {
            vertices[i] = v;
            weights[i] = inv[i] / total;
        }
    }
    SurfacePoint { vertices, weights }
}

/// The triangle `t`'s point with barycentric weights `bary`, heaviest vertex first.
pub(crate) fn heaviest_first(t: [u32; 3], bary: [f64; 3]) -> SurfacePoint {
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| bary[j].total_cmp(&bary[i]).then(i.cmp(&j)));
    SurfacePoint {
        vertices: order.map(|i| t[i]),
        weights: order.map(|i| bary[i]),
    }
}

/// Squared distance from `p` to the triangle and the barycentric weights of the closest
/// point (Ericson, Real-Time Collision Detection, 5.1.5).
pub fn closest_on_triangle(p: &[f64; 3], [a, b, c]: &[[f64; 3]; 3]) -> (f64, [f64; 3]) {
    let sub = |x: &[f64; 3], y: &[f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let dot = |x: &[f64; 3], y: &[f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(&ab, &ap), dot(&ac, &ap));
    let bary = if d1 <= 0.0 && d2 <= 0.0 {
        [1.0, 0.0, 0.0]
    } else {
        let bp = sub(p, b);
        let (d3, d4) = (dot(&ab, &bp), dot(&ac, &bp));
        let cp = sub(p, c);
        let (d5, d6) = (dot(&ab, &cp), dot(&ac, &cp));
        let vc = d1 * d4 - d3 * d2;
        let vb = d5 * d2 - d1 * d6;
        let va = d3 * d6 - d5 * d4;
        if d3 >= 0.0 && d4 <= d3 {
            [0.0, 1.0, 0.0]
        } else if d6 >= 0.0 && d5 <= d6 {
            [0.0, 0.0, 1.0]
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            let v = d1 / (d1 - d3);
            [1.0 - v, v, 0.0]
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            let w = d2 / (d2 - d6);
            [1.0 - w, 0.0, w]
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            [0.0, 1.0 - w, w]
        } else {
            let denom = va + vb + vc;
            if denom <= 0.0 || !denom.is_finite() {
                // A degenerate triangle: its first corner.
                [1.0, 0.0, 0.0]
            } else {
                let (v, w) = (vb / denom, vc / denom);
                [1.0 - v - w, v, w]
            }
        }
    };
    let q = [0, 1, 2].map(|i| bary[0] * a[i] + bary[1] * b[i] + bary[2] * c[i]);
    let d = sub(p, &q);
    (dot(&d, &d), bary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closest_point_of_a_triangle_is_found_in_every_zone() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let inside = closest_on_triangle(&[0.25, 0.25, 2.0], &t);
        assert!((inside.0 - 4.0).abs() < 1e-12);
        assert!((inside.1[1] - 0.25).abs() < 1e-12 && (inside.1[2] - 0.25).abs() < 1e-12);
        assert_eq!(
            closest_on_triangle(&[-1.0, -1.0, 0.0], &t).1,
            [1.0, 0.0, 0.0]
        );
        assert_eq!(
            closest_on_triangle(&[3.0, -1.0, 0.0], &t).1,
            [0.0, 1.0, 0.0]
        );
        let edge = closest_on_triangle(&[1.0, 1.0, 0.0], &t);
        assert!((edge.1[1] - 0.5).abs() < 1e-12 && (edge.1[2] - 0.5).abs() < 1e-12);
        assert!((edge.0 - 0.5).abs() < 1e-12);
    }
}
