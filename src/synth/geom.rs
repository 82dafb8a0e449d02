//! Small 3-vector helpers on `[f64; 3]`, the point type of the generated meshes.

pub(crate) type V3 = [f64; 3];

#[inline]
pub(crate) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline]
pub(crate) fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub(crate) fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

#[inline]
pub(crate) fn dist(a: V3, b: V3) -> f64 {
    norm(sub(a, b))
}

/// `a` scaled to unit length (unchanged if it is zero).
#[inline]
pub(crate) fn normalize(a: V3) -> V3 {
    let n = norm(a);
    if n > 0.0 {
        scale(a, 1.0 / n)
    } else {
        a
    }
}

/// Point `a + t (b - a)`.
#[inline]
pub(crate) fn lerp(a: V3, b: V3, t: f64) -> V3 {
    add(a, scale(sub(b, a), t))
}

/// Twice the area vector of triangle `abc` (its direction is the right-hand normal).
#[inline]
pub(crate) fn area_vector(a: V3, b: V3, c: V3) -> V3 {
    cross(sub(b, a), sub(c, a))
}

/// Area of triangle `abc`.
#[inline]
pub(crate) fn triangle_area(a: V3, b: V3, c: V3) -> f64 {
    0.5 * norm(area_vector(a, b, c))
}

/// Shape quality of triangle `abc`: 1 for equilateral, 0 for degenerate
/// (`4 sqrt(3) area / sum of squared edge lengths`).
pub(crate) fn triangle_quality(a: V3, b: V3, c: V3) -> f64 {
    let l2 = dot(sub(b, a), sub(b, a)) + dot(sub(c, b), sub(c, b)) + dot(sub(a, c), sub(a, c));
    if l2 <= 0.0 {
        return 0.0;
    }
    4.0 * 3f64.sqrt() * triangle_area(a, b, c) / l2
}

/// Signed volume of the tetrahedron (origin, a, b, c); summed over a closed, outward
/// oriented surface it gives the enclosed volume.
#[inline]
pub(crate) fn signed_volume_term(a: V3, b: V3, c: V3) -> f64 {
    dot(a, cross(b, c)) / 6.0
}
