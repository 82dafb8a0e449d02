//! The implicit field of a figure: the signed distance to each bone's tapered capsules
//! (round cones), blended into one surface by a polynomial smooth union.
//!
//! The field is negative inside, positive outside, and 1-Lipschitz (each round cone
//! distance is exact, and the smooth union of 1-Lipschitz functions is 1-Lipschitz), which
//! the polygoniser uses to skip empty space.

use super::geom::{dist, dot, norm, scale, sub, V3};

/// Most primitives a field may hold (the figures use at most about 30).
pub(crate) const MAX_PRIMITIVES: usize = 64;

/// A tapered capsule: the convex hull of a sphere of radius `ra` at `a` and one of radius
/// `rb` at `b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RoundCone {
    pub a: V3,
    pub b: V3,
    pub ra: f64,
    pub rb: f64,
}

impl RoundCone {
    pub fn new(a: V3, b: V3, ra: f64, rb: f64) -> RoundCone {
        RoundCone { a, b, ra, rb }
    }

    /// Axis-aligned bounds `(lo, hi)`.
    pub fn bounds(&self) -> (V3, V3) {
        let mut lo = [0.0; 3];
        let mut hi = [0.0; 3];
        for k in 0..3 {
            lo[k] = (self.a[k] - self.ra).min(self.b[k] - self.rb);
            hi[k] = (self.a[k] + self.ra).max(self.b[k] + self.rb);
        }
        (lo, hi)
    }

    /// Precomputed form for fast distance queries.
    pub fn prepare(&self) -> Cone {
        let ba = sub(self.b, self.a);
        let l2 = dot(ba, ba);
        let rr = self.ra - self.rb;
        let a2 = l2 - rr * rr;
        // One sphere inside the other (or no length): the cone is just the larger sphere.
        let sphere = if l2 <= 1e-18 || a2 <= 1e-12 * l2.max(1e-18) {
            Some(if self.ra >= self.rb {
                (self.a, self.ra)
            } else {
                (self.b, self.rb)
            })
        } else {
            None
        };
        Cone {
            a: self.a,
            ba,
            l2,
            rr,
            a2,
            il2: if l2 > 0.0 { 1.0 / l2 } else { 0.0 },
            ra: self.ra,
            rb: self.rb,
            sphere,
        }
    }
}

/// A round cone prepared for exact signed distance evaluation (after Inigo Quilez's
/// round-cone distance, one square root per query).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cone {
    a: V3,
    ba: V3,
    l2: f64,
    rr: f64,
    a2: f64,
    il2: f64,
    ra: f64,
    rb: f64,
    sphere: Option<(V3, f64)>,
}

impl Cone {
    /// Exact signed distance from `p` to the round cone (negative inside).
    #[inline]
    pub fn sdf(&self, p: V3) -> f64 {
        if let Some((c, r)) = self.sphere {
            return dist(p, c) - r;
        }
        let pa = sub(p, self.a);
        let y = dot(pa, self.ba);
        let z = y - self.l2;
        let w = sub(scale(pa, self.l2), scale(self.ba, y));
        let x2 = dot(w, w);
        let y2 = y * y * self.l2;
        let z2 = z * z * self.l2;
        let k = self.rr.signum() * self.rr * self.rr * x2;
        if z.signum() * self.a2 * z2 > k {
            return (x2 + z2).sqrt() * self.il2 - self.rb;
        }
        if y.signum() * self.a2 * y2 < k {
            return (x2 + y2).sqrt() * self.il2 - self.ra;
        }
        ((x2 * self.a2 * self.il2).sqrt() + y * self.rr) * self.il2 - self.ra
    }
}

/// Polynomial smooth minimum of `a` and `b` with blend width `k` (equals `min(a, b)` when
/// they differ by `k` or more; at most `k / 4` below it).
#[inline]
pub(crate) fn smooth_min(a: f64, b: f64, k: f64) -> f64 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

/// The smooth union of a set of round cones.
///
/// The union folds the primitive distances in ascending order and only those within `blend`
/// of the smallest, so the value does not depend on the order of the primitives, and a
/// subset that holds every primitive that can matter near a point (see
/// [`Field::subset_near`]) gives bit-identical values to the full set.
#[derive(Debug, Clone)]
pub(crate) struct Field {
    cones: Vec<Cone>,
    shapes: Vec<RoundCone>,
    blend: f64,
}

impl Field {
    /// Field of `shapes` blended with width `blend` (> 0).
    pub fn new(shapes: &[RoundCone], blend: f64) -> Field {
        assert!(!shapes.is_empty() && shapes.len() <= MAX_PRIMITIVES);
        assert!(blend > 0.0);
        Field {
            cones: shapes.iter().map(RoundCone::prepare).collect(),
            shapes: shapes.to_vec(),
            blend,
        }
    }

    /// Axis-aligned bounds `(lo, hi)` of the surface (the union plus the blend bulge).
    pub fn bounds(&self) -> (V3, V3) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for s in &self.shapes {
            let (l, h) = s.bounds();
            for k in 0..3 {
                lo[k] = lo[k].min(l[k] - 0.25 * self.blend);
                hi[k] = hi[k].max(h[k] + 0.25 * self.blend);
            }
        }
        (lo, hi)
    }

    /// Rough surface area (sum of the primitives' areas, ignoring overlaps); only a first
    /// guess for the grid spacing.
    pub fn rough_area(&self) -> f64 {
        use std::f64::consts::PI;
        self.shapes
            .iter()
            .map(|s| {
                let slant = (dist(s.a, s.b).powi(2) + (s.ra - s.rb).powi(2)).sqrt();
                PI * (s.ra + s.rb) * slant + 2.0 * PI * (s.ra * s.ra + s.rb * s.rb)
            })
            .sum()
    }

    /// Field value at `p` (all primitives).
    #[cfg(test)]
    pub fn eval(&self, p: V3) -> f64 {
        let all: Vec<u16> = (0..self.cones.len() as u16).collect();
        self.eval_in(p, &all)
    }

    /// Field value at `p` using only the primitives in `subset`.
    #[inline]
    pub fn eval_in(&self, p: V3, subset: &[u16]) -> f64 {
        let mut values = [0.0f64; MAX_PRIMITIVES];
        let mut m = f64::INFINITY;
        for (j, &i) in subset.iter().enumerate() {
            let v = self.cones[i as usize].sdf(p);
            values[j] = v;
            m = m.min(v);
        }
        // The participants (within `blend` of the minimum), sorted ascending.
        let mut part = [0.0f64; MAX_PRIMITIVES];
        let mut n = 0;
        for &v in &values[..subset.len()] {
            if v < m + self.blend {
                let mut j = n;
                while j > 0 && part[j - 1] > v {
                    part[j] = part[j - 1];
                    j -= 1;
                }
                part[j] = v;
                n += 1;
            }
        }
        let mut r = part[0];
        for &v in &part[1..n] {
            r = smooth_min(r, v, self.blend);
        }
        r
    }

    /// The primitives that can change the field anywhere within `radius` of `c`, into `out`.
    pub fn subset_near(&self, c: V3, radius: f64, out: &mut Vec<u16>) {
        out.clear();
        let mut values = [0.0f64; MAX_PRIMITIVES];
        let mut m = f64::INFINITY;
        for (i, cone) in self.cones.iter().enumerate() {
            values[i] = cone.sdf(c);
            m = m.min(values[i]);
        }
        // Within the ball each distance moves by at most `radius`, so a primitive whose
        // value stays `blend` above the running minimum never takes part.
        let limit = m + 2.0 * radius + self.blend;
        for (i, &v) in values[..self.cones.len()].iter().enumerate() {
            if v < limit {
                out.push(i as u16);
            }
        }
    }

    /// Gradient at `p` by central differences with step `eps`.
    pub fn gradient_in(&self, p: V3, subset: &[u16], eps: f64) -> V3 {
        let mut g = [0.0; 3];
        for (k, gk) in g.iter_mut().enumerate() {
            let mut p1 = p;
            let mut p0 = p;
            p1[k] += eps;
            p0[k] -= eps;
            *gk = (self.eval_in(p1, subset) - self.eval_in(p0, subset)) / (2.0 * eps);
        }
        g
    }

    /// `p` moved onto the zero level set by Newton steps along the gradient (each step at
    /// most `max_step` long).
    pub fn project(&self, p: V3, subset: &[u16], max_step: f64) -> V3 {
        let eps = 1e-3 * max_step;
        let tol = 1e-7 * max_step;
        let mut q = p;
        for _ in 0..8 {
            let f = self.eval_in(q, subset);
            if f.abs() <= tol {
                break;
            }
            let g = self.gradient_in(q, subset, eps);
            let g2 = dot(g, g);
            if g2 < 1e-12 {
                break;
            }
            let mut step = scale(g, f / g2);
            let len = norm(step);
            if len > max_step {
                step = scale(step, max_step / len);
            }
            q = sub(q, step);
        }
        q
    }

    /// Unit outward normal at `p` (the normalised gradient).
    pub fn normal_in(&self, p: V3, subset: &[u16], eps: f64) -> V3 {
        super::geom::normalize(self.gradient_in(p, subset, eps))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::geom::{add, lerp as point_on};

    /// Distance to the union of spheres along the axis with interpolated radii (the round
    /// cone), by brute force; exact for points outside.
    fn brute(c: &RoundCone, p: V3) -> f64 {
        (0..=20000)
            .map(|i| {
                let t = i as f64 / 20000.0;
                let centre = point_on(c.a, c.b, t);
                dist(p, centre) - (c.ra + t * (c.rb - c.ra))
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn round_cone_distance_matches_brute_force_outside() {
        let cones = [
            RoundCone::new([0.0, 0.0, 0.0], [1.0, 0.2, -0.1], 0.3, 0.1),
            RoundCone::new([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.1, 0.25),
            RoundCone::new([0.2, 0.0, 0.0], [-0.2, 0.0, 0.0], 0.2, 0.2),
        ];
        let pts = [
            [2.0, 0.0, 0.0],
            [0.5, 1.0, 0.3],
            [-1.0, -0.5, 0.2],
            [0.1, 0.5, -0.9],
            [0.0, 2.0, 0.0],
            [0.3, -0.6, 0.1],
        ];
        for c in &cones {
            let prepared = c.prepare();
            for &p in &pts {
                let exact = prepared.sdf(p);
                assert!(exact > 0.0);
                assert!(
                    (exact - brute(c, p)).abs() < 1e-6,
                    "{exact} vs {}",
                    brute(c, p)
                );
            }
            // Inside on the axis.
            assert!(prepared.sdf(point_on(c.a, c.b, 0.5)) < 0.0);
        }
    }

    #[test]
    fn subset_gives_identical_values() {
        let shapes: Vec<RoundCone> = (0..6)
            .map(|i| {
                let x = i as f64 * 0.3;
                RoundCone::new([x, 0.0, 0.0], [x + 0.2, 0.5, 0.1], 0.1, 0.08)
            })
            .collect();
        let field = Field::new(&shapes, 0.05);
        let mut subset = Vec::new();
        let c = [0.5, 0.2, 0.0];
        field.subset_near(c, 0.1, &mut subset);
        assert!(subset.len() < shapes.len());
        for i in 0..50 {
            let t = i as f64 / 50.0;
            let p = [
                c[0] + 0.1 * (t * 7.0).sin() * t,
                c[1] + 0.05 * t,
                c[2] - 0.08 * t,
            ];
            assert_eq!(field.eval(p).to_bits(), field.eval_in(p, &subset).to_bits());
        }
    }

    #[test]
    fn smooth_union_is_order_independent_and_lipschitz() {
        let a = RoundCone::new([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.2, 0.2);
        let b = RoundCone::new([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.2, 0.15);
        let f1 = Field::new(&[a, b], 0.1);
        let f2 = Field::new(&[b, a], 0.1);
        for i in 0..200 {
            let p = [0.01 * i as f64 - 0.5, 0.3, 0.02 * (i % 7) as f64];
            let q = add(p, [0.003, -0.002, 0.001]);
            assert_eq!(f1.eval(p), f2.eval(p));
            assert!((f1.eval(p) - f1.eval(q)).abs() <= dist(p, q) * (1.0 + 1e-9));
        }
    }

    #[test]
    fn projection_lands_on_the_surface() {
        let field = Field::new(&[RoundCone::new([0.0; 3], [1.0, 0.0, 0.0], 0.3, 0.2)], 0.05);
        let q = field.project([0.5, 0.4, 0.1], &[0], 0.1);
        assert!(field.eval(q).abs() < 1e-6);
    }
}
