//! The generated figures (`shapecorr::synth`): closed manifold surfaces at the asked
//! resolution, poses and proportions that move the same mesh near-isometrically, the
//! symmetries of the rest poses, and point sampling with ground truth.

use std::collections::HashMap;

use shapecorr::synth::{
    figure, n_poses, sample_points, FigureKind, FigureMesh, FigureSpec, Proportions,
};
use shapecorr::Error;

// ---------------------------------------------------------------------------------------
// Geometry helpers (independent of the library's own code).

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: V) -> f64 {
    dot(a, a).sqrt()
}
fn dist(a: V, b: V) -> f64 {
    norm(sub(a, b))
}

fn corners(m: &FigureMesh, t: [u32; 3]) -> [V; 3] {
    t.map(|i| m.vertices[i as usize])
}

fn areas(m: &FigureMesh) -> Vec<f64> {
    m.triangles
        .iter()
        .map(|&t| {
            let [a, b, c] = corners(m, t);
            0.5 * norm(cross(sub(b, a), sub(c, a)))
        })
        .collect()
}

fn total_area(m: &FigureMesh) -> f64 {
    areas(m).iter().sum()
}

fn signed_volume(m: &FigureMesh) -> f64 {
    m.triangles
        .iter()
        .map(|&t| {
            let [a, b, c] = corners(m, t);
            dot(a, cross(b, c)) / 6.0
        })
        .sum()
}

fn bbox(m: &FigureMesh) -> (V, V) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &m.vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

fn width(m: &FigureMesh) -> f64 {
    let (lo, hi) = bbox(m);
    dist(lo, hi)
}

/// Smallest triangle angle, in degrees.
fn min_angle(m: &FigureMesh) -> f64 {
    let mut worst = 180.0f64;
    for &t in &m.triangles {
        let c = corners(m, t);
        for i in 0..3 {
            let (a, b) = (sub(c[(i + 1) % 3], c[i]), sub(c[(i + 2) % 3], c[i]));
            let cos = (dot(a, b) / (norm(a) * norm(b))).clamp(-1.0, 1.0);
            worst = worst.min(cos.acos().to_degrees());
        }
    }
    worst
}

fn longest_edge(m: &FigureMesh) -> f64 {
    m.triangles
        .iter()
        .flat_map(|&t| {
            let c = corners(m, t);
            [dist(c[0], c[1]), dist(c[1], c[2]), dist(c[2], c[0])]
        })
        .fold(0.0, f64::max)
}

fn mean_edge(m: &FigureMesh) -> f64 {
    let s: f64 = m
        .triangles
        .iter()
        .map(|&t| {
            let c = corners(m, t);
            dist(c[0], c[1]) + dist(c[1], c[2]) + dist(c[2], c[0])
        })
        .sum();
    s / (3 * m.triangles.len()) as f64
}

/// Nearest-point queries on a uniform grid of buckets.
struct Nearest<'a> {
    points: &'a [V],
    cell: f64,
    buckets: HashMap<[i64; 3], Vec<u32>>,
}

impl<'a> Nearest<'a> {
    fn new(points: &'a [V], cell: f64) -> Self {
        let mut buckets: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        for (i, &p) in points.iter().enumerate() {
            buckets
                .entry(Self::key(p, cell))
                .or_default()
                .push(i as u32);
        }
        Nearest {
            points,
            cell,
            buckets,
        }
    }
    fn key(p: V, cell: f64) -> [i64; 3] {
        p.map(|x| (x / cell).floor() as i64)
    }
    /// Distance from `q` to the nearest point (searching rings of buckets outwards).
    fn distance(&self, q: V) -> f64 {
        let k = Self::key(q, self.cell);
        let mut best = f64::INFINITY;
        for r in 0..64i64 {
            if best <= (r - 1).max(0) as f64 * self.cell {
                break;
            }
            for dx in -r..=r {
                for dy in -r..=r {
                    for dz in -r..=r {
                        if dx.abs().max(dy.abs()).max(dz.abs()) != r {
                            continue;
                        }
                        if let Some(b) = self.buckets.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                            for &i in b {
                                best = best.min(dist(q, self.points[i as usize]));
                            }
                        }
                    }
                }
            }
        }
        best
    }
}

/// Problems with `m` as a closed, consistently and outward oriented 2-manifold with one
/// component and Euler characteristic 2 (empty if none).
fn manifold_problems(m: &FigureMesh) -> Vec<String> {
    let n = m.vertices.len();
    let mut problems = Vec::new();
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &m.triangles {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            problems.push(format!("degenerate triangle {t:?}"));
        }
        for s in 0..3 {
            *directed.entry((t[s], t[(s + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &count) in &directed {
        if count != 1 {
            problems.push(format!("directed edge {a}-{b} used {count} times"));
        }
        if !directed.contains_key(&(b, a)) {
            problems.push(format!(
                "edge {a}-{b} is a boundary or inconsistently oriented"
            ));
        }
    }
    // Vertex manifoldness: the triangles around a vertex form one fan.
    let mut fans: Vec<Vec<(u32, u32)>> = vec![Vec::new(); n];
    for t in &m.triangles {
        for s in 0..3 {
            fans[t[s] as usize].push((t[(s + 1) % 3], t[(s + 2) % 3]));
        }
    }
    for (v, fan) in fans.iter().enumerate() {
        if fan.is_empty() {
            problems.push(format!("vertex {v} unused"));
            continue;
        }
        let next: HashMap<u32, u32> = fan.iter().copied().collect();
        let mut b = fan[0].0;
        let mut steps = 0;
        while let Some(&c) = next.get(&b) {
            steps += 1;
            b = c;
            if b == fan[0].0 || steps > fan.len() {
                break;
            }
        }
        if steps != fan.len() {
            problems.push(format!("vertex {v} is not a single fan"));
        }
    }
    // Components over triangles sharing vertices.
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut a: usize) -> usize {
        while p[a] != a {
            p[a] = p[p[a]];
            a = p[a];
        }
        a
    }
    for t in &m.triangles {
        let a = find(&mut parent, t[0] as usize);
        for &o in &t[1..] {
            let b = find(&mut parent, o as usize);
            parent[b] = a;
        }
    }
    let components = (0..n).filter(|&v| find(&mut parent, v) == v).count();
    if components != 1 {
        problems.push(format!("{components} components"));
    }
    let euler = n as i64 - (directed.len() / 2) as i64 + m.triangles.len() as i64;
    if euler != 2 {
        problems.push(format!("Euler characteristic {euler}"));
    }
    if signed_volume(m) <= 0.0 {
        problems.push("non-positive signed volume (inward orientation)".into());
    }
    problems.truncate(10);
    problems
}

/// Whether segment `p q` crosses triangle `t` (strictly inside both).
fn segment_hits_triangle(p: V, q: V, t: [V; 3]) -> bool {
    let d = sub(q, p);
    let e1 = sub(t[1], t[0]);
    let e2 = sub(t[2], t[0]);
    let h = cross(d, e2);
    let a = dot(e1, h);
    if a.abs() < 1e-14 {
        return false;
    }
    let f = 1.0 / a;
    let s = sub(p, t[0]);
    let u = f * dot(s, h);
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qv = cross(s, e1);
    let v = f * dot(d, qv);
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let tt = f * dot(e2, qv);
    (0.0..=1.0).contains(&tt)
}

/// Number of pairs of triangles without a common vertex that intersect.
fn self_intersections(m: &FigureMesh) -> usize {
    let cell = longest_edge(m);
    let mut buckets: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (f, &t) in m.triangles.iter().enumerate() {
        let c = corners(m, t);
        let mut lo = [i64::MAX; 3];
        let mut hi = [i64::MIN; 3];
        for p in c {
            for k in 0..3 {
                let x = (p[k] / cell).floor() as i64;
                lo[k] = lo[k].min(x);
                hi[k] = hi[k].max(x);
            }
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    buckets.entry([x, y, z]).or_default().push(f as u32);
                }
            }
        }
    }
    let mut pairs = std::collections::HashSet::new();
    for b in buckets.values() {
        for (i, &f) in b.iter().enumerate() {
            for &g in &b[i + 1..] {
                let (tf, tg) = (m.triangles[f as usize], m.triangles[g as usize]);
                if tf.iter().any(|v| tg.contains(v)) {
                    continue;
                }
                let (cf, cg) = (corners(m, tf), corners(m, tg));
                let hit = (0..3).any(|s| segment_hits_triangle(cf[s], cf[(s + 1) % 3], cg))
                    || (0..3).any(|s| segment_hits_triangle(cg[s], cg[(s + 1) % 3], cf));
                if hit {
                    pairs.insert((f.min(g), f.max(g)));
                }
            }
        }
    }
    pairs.len()
}

fn spec(kind: FigureKind, pose: usize, target: usize) -> FigureSpec {
    FigureSpec {
        kind,
        pose,
        target_vertices: target,
        proportions: Proportions::default(),
    }
}

fn all_kinds() -> Vec<FigureKind> {
    let mut k = vec![FigureKind::Humanoid, FigureKind::Quadruped];
    k.extend((3..=8).map(|limbs| FigureKind::Star { limbs }));
    k
}

// ---------------------------------------------------------------------------------------
// Tests.

fn assert_target(kind: FigureKind, m: &FigureMesh, target: usize) {
    let n = m.vertices.len() as f64;
    let error = n / target as f64 - 1.0;
    assert!(
        error.abs() <= 0.15,
        "{kind}: {n} vertices for a target of {target} ({:+.1}%)",
        100.0 * error
    );
}

#[test]
fn rest_poses_are_closed_manifolds_without_self_intersections() {
    for kind in all_kinds() {
        let m = figure(&spec(kind, 0, 2000)).unwrap();
        assert_target(kind, &m, 2000);
        let problems = manifold_problems(&m);
        assert!(problems.is_empty(), "{kind}: {problems:?}");
        assert_eq!(
            self_intersections(&m),
            0,
            "{kind} rest pose intersects itself"
        );
        let a = areas(&m);
        let mean = a.iter().sum::<f64>() / a.len() as f64;
        let min = a.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(
            min > 0.01 * mean,
            "{kind}: smallest triangle {min:e}, mean {mean:e}"
        );
    }
}

#[test]
fn humanoid_at_20k_is_a_closed_manifold() {
    let m = figure(&spec(FigureKind::Humanoid, 0, 20_000)).unwrap();
    assert_target(FigureKind::Humanoid, &m, 20_000);
    let problems = manifold_problems(&m);
    assert!(problems.is_empty(), "{problems:?}");
    assert!(min_angle(&m) > 10.0);
}

#[test]
fn vertex_counts_follow_the_target() {
    for kind in [
        FigureKind::Humanoid,
        FigureKind::Quadruped,
        FigureKind::Star { limbs: 5 },
    ] {
        for target in [1000, 5000, 20_000] {
            assert_target(kind, &figure(&spec(kind, 0, target)).unwrap(), target);
        }
    }
    // The smallest accepted target still gives a closed surface near the target.
    for kind in all_kinds() {
        let m = figure(&spec(kind, 0, 500)).unwrap();
        assert_target(kind, &m, 500);
        assert!(manifold_problems(&m).is_empty(), "{kind} at 500 vertices");
    }
}

#[test]
fn hundred_thousand_vertices() {
    let m = figure(&spec(FigureKind::Quadruped, 0, 100_000)).unwrap();
    assert_target(FigureKind::Quadruped, &m, 100_000);
    assert!(manifold_problems(&m).is_empty());
}

#[test]
fn poses_move_the_same_mesh_near_isometrically() {
    for kind in all_kinds() {
        assert!(n_poses(kind) >= 6, "{kind} has {} poses", n_poses(kind));
        let rest = figure(&spec(kind, 0, 2500)).unwrap();
        let rest_area = total_area(&rest);
        let rest_volume = signed_volume(&rest);
        let w = width(&rest);
        let mut previous: Vec<Vec<V>> = vec![rest.vertices.clone()];
        for p in 1..n_poses(kind) {
            let m = figure(&spec(kind, p, 2500)).unwrap();
            assert_eq!(
                m.triangles, rest.triangles,
                "{kind} pose {p}: other triangles"
            );
            assert_eq!(m.vertices.len(), rest.vertices.len());
            let moved = m
                .vertices
                .iter()
                .zip(&rest.vertices)
                .map(|(a, b)| dist(*a, *b))
                .sum::<f64>()
                / m.vertices.len() as f64;
            assert!(
                moved > 0.005 * w,
                "{kind} pose {p}: mean displacement {moved} of width {w}"
            );
            // Distinct from every earlier pose.
            for (q, earlier) in previous.iter().enumerate() {
                let d = m
                    .vertices
                    .iter()
                    .zip(earlier)
                    .map(|(a, b)| dist(*a, *b))
                    .fold(0.0, f64::max);
                assert!(d > 0.05 * w, "{kind} pose {p} is pose {q} again");
            }
            previous.push(m.vertices.clone());
            let a = areas(&m);
            let area: f64 = a.iter().sum();
            assert!(
                (area / rest_area - 1.0).abs() < 0.10,
                "{kind} pose {p}: area ratio {}",
                area / rest_area
            );
            let volume = signed_volume(&m);
            assert!(
                (volume / rest_volume - 1.0).abs() < 0.10,
                "{kind} pose {p}: volume ratio {}",
                volume / rest_volume
            );
            let mean = area / a.len() as f64;
            let min = a.iter().copied().fold(f64::INFINITY, f64::min);
            assert!(
                min > 0.01 * mean,
                "{kind} pose {p}: smallest triangle {min:e}, mean {mean:e}"
            );
            assert_eq!(
                self_intersections(&m),
                0,
                "{kind} pose {p} intersects itself"
            );
        }
    }
}

#[test]
fn proportions_deform_the_same_mesh() {
    let base = figure(&spec(FigureKind::Humanoid, 0, 3000)).unwrap();
    let (lo, hi) = bbox(&base);
    let with = |limb_length: f64, limb_thickness: f64, pose: usize| {
        figure(&FigureSpec {
            proportions: Proportions {
                limb_length,
                limb_thickness,
            },
            ..spec(FigureKind::Humanoid, pose, 3000)
        })
        .unwrap()
    };
    // Longer limbs: taller (legs) and wider (arms), same triangles; the head stays the
    // same shape (it only moves up with the body).
    let long = with(1.3, 1.0, 0);
    assert_eq!(long.triangles, base.triangles);
    let (llo, lhi) = bbox(&long);
    let (height, long_height) = (hi[1] - lo[1], lhi[1] - llo[1]);
    assert!(
        long_height > 1.1 * height,
        "height {height} -> {long_height}"
    );
    assert!(
        lhi[0] - llo[0] > 1.15 * (hi[0] - lo[0]),
        "arm span did not grow"
    );
    let top = |m: &FigureMesh| {
        let i = (0..m.vertices.len())
            .max_by(|&a, &b| base.vertices[a][1].total_cmp(&base.vertices[b][1]))
            .unwrap();
        m.vertices[i]
    };
    let head_top_shift = sub(top(&long), top(&base));
    for (a, b) in long.vertices.iter().zip(&base.vertices) {
        if b[1] > 1.6 {
            assert!(
                dist(sub(*a, *b), head_top_shift) < 1e-3,
                "the head changed shape"
            );
        }
    }
    // Thicker limbs: more area, about the same height.
    let thick = with(1.0, 1.3, 0);
    assert_eq!(thick.triangles, base.triangles);
    assert!(total_area(&thick) > 1.1 * total_area(&base));
    let (tlo, thi) = bbox(&thick);
    assert!(((thi[1] - tlo[1]) / height - 1.0).abs() < 0.05);
    // Proportions combine with poses.
    let posed = with(1.2, 0.9, 2);
    assert_eq!(posed.triangles, base.triangles);
    assert!(manifold_problems(&posed).is_empty());
    assert_eq!(self_intersections(&posed), 0);
}

/// Largest distance from a transformed vertex to the nearest original vertex.
fn max_mismatch(m: &FigureMesh, transform: impl Fn(V) -> V) -> f64 {
    let nearest = Nearest::new(&m.vertices, mean_edge(m));
    m.vertices
        .iter()
        .map(|&p| nearest.distance(transform(p)))
        .fold(0.0, f64::max)
}

#[test]
fn humanoid_rest_pose_is_mirror_symmetric() {
    let m = figure(&spec(FigureKind::Humanoid, 0, 5000)).unwrap();
    let w = width(&m);
    let mirror = |p: V| [-p[0], p[1], p[2]];
    let d = max_mismatch(&m, mirror);
    assert!(d < 0.005 * w, "mirror mismatch {d} of width {w}");
    // The asymmetric poses are not symmetric (so the check can fail).
    let posed = figure(&spec(FigureKind::Humanoid, 3, 5000)).unwrap();
    assert!(max_mismatch(&posed, mirror) > 0.05 * w);
}

#[test]
fn star_rest_pose_is_n_fold_symmetric() {
    for limbs in 3..=8 {
        let kind = FigureKind::Star { limbs };
        let m = figure(&spec(kind, 0, 3000)).unwrap();
        let w = width(&m);
        let rotate = |angle: f64| {
            move |p: V| {
                let (s, c) = angle.sin_cos();
                [c * p[0] - s * p[2], p[1], s * p[0] + c * p[2]]
            }
        };
        let step = std::f64::consts::TAU / limbs as f64;
        let d = max_mismatch(&m, rotate(step));
        // The grid is not n-fold symmetric, so the vertices match up to about an edge length.
        assert!(
            d < 1.5 * mean_edge(&m),
            "{kind}: rotation mismatch {d}, mean edge {}",
            mean_edge(&m)
        );
        // Half a step puts limbs between limbs.
        assert!(max_mismatch(&m, rotate(0.5 * step)) > 0.05 * w, "{kind}");
    }
}

#[test]
fn figures_are_deterministic() {
    for kind in [FigureKind::Humanoid, FigureKind::Star { limbs: 7 }] {
        let s = FigureSpec {
            proportions: Proportions {
                limb_length: 1.1,
                limb_thickness: 0.9,
            },
            ..spec(kind, 2, 3000)
        };
        assert_eq!(figure(&s).unwrap(), figure(&s).unwrap());
    }
}

#[test]
fn sample_points_have_ground_truth() {
    let m = figure(&spec(FigureKind::Humanoid, 1, 3000)).unwrap();
    let w = width(&m);
    let edge = longest_edge(&m);
    let clean = sample_points(&m, 4000, 0.0, 7).unwrap();
    assert_eq!(clean.points.len(), 4000);
    assert_eq!(clean.source_vertex.len(), 4000);
    for (p, &v) in clean.points.iter().zip(&clean.source_vertex) {
        assert!((v as usize) < m.vertices.len());
        assert!(
            dist(*p, m.vertices[v as usize]) <= edge,
            "point {p:?} far from its vertex"
        );
    }
    // Uniform by area: the share of points in the upper half matches its share of area.
    let mid = 0.5 * (bbox(&m).0[1] + bbox(&m).1[1]);
    let upper_area: f64 = m
        .triangles
        .iter()
        .zip(areas(&m))
        .filter(|(t, _)| corners(&m, **t).iter().map(|c| c[1]).sum::<f64>() / 3.0 > mid)
        .map(|(_, a)| a)
        .sum();
    let upper_share = upper_area / total_area(&m);
    let upper_points = clean.points.iter().filter(|p| p[1] > mid).count() as f64 / 4000.0;
    assert!(
        (upper_points - upper_share).abs() < 0.03,
        "{upper_points} vs {upper_share}"
    );
    // Same seed, same cloud; another seed, another cloud.
    assert_eq!(clean, sample_points(&m, 4000, 0.0, 7).unwrap());
    assert_ne!(
        clean.points,
        sample_points(&m, 4000, 0.0, 8).unwrap().points
    );
    // Noise: bounded by noise * width, and really there.
    let noise = 0.03;
    let noisy = sample_points(&m, 4000, noise, 7).unwrap();
    assert_eq!(noisy, sample_points(&m, 4000, noise, 7).unwrap());
    let mean_distance = |c: &shapecorr::synth::SampledCloud| {
        c.points
            .iter()
            .zip(&c.source_vertex)
            .map(|(p, &v)| dist(*p, m.vertices[v as usize]))
            .sum::<f64>()
            / c.points.len() as f64
    };
    for (p, &v) in noisy.points.iter().zip(&noisy.source_vertex) {
        assert!(
            dist(*p, m.vertices[v as usize]) <= edge + noise * w,
            "noise larger than asked"
        );
    }
    let (d0, d1) = (mean_distance(&clean), mean_distance(&noisy));
    assert!(
        d1 > d0 + 0.25 * noise * w,
        "noise barely moved the points: {d0} -> {d1}"
    );
}

#[test]
fn sample_points_rejects_bad_arguments() {
    let m = figure(&spec(FigureKind::Star { limbs: 4 }, 0, 1000)).unwrap();
    for (n, noise) in [(0, 0.0), (10, -0.1), (10, f64::NAN), (10, f64::INFINITY)] {
        assert!(
            matches!(
                sample_points(&m, n, noise, 1),
                Err(Error::InvalidParameter { .. })
            ),
            "n={n} noise={noise}"
        );
    }
    let empty = FigureMesh::default();
    assert!(matches!(
        sample_points(&empty, 10, 0.0, 1),
        Err(Error::InvalidParameter { .. })
    ));
    let broken = FigureMesh {
        vertices: vec![[0.0; 3]; 3],
        triangles: vec![[0, 1, 5]],
    };
    assert!(matches!(
        sample_points(&broken, 10, 0.0, 1),
        Err(Error::InvalidParameter { .. })
    ));
}

#[test]
fn invalid_specs_are_rejected() {
    let ok = spec(FigureKind::Humanoid, 0, 1000);
    let bad = [
        FigureSpec {
            kind: FigureKind::Star { limbs: 2 },
            ..ok
        },
        FigureSpec {
            kind: FigureKind::Star { limbs: 9 },
            ..ok
        },
        FigureSpec {
            target_vertices: 499,
            ..ok
        },
        FigureSpec {
            target_vertices: 200_001,
            ..ok
        },
        FigureSpec {
            pose: n_poses(FigureKind::Humanoid),
            ..ok
        },
        FigureSpec {
            kind: FigureKind::Quadruped,
            pose: n_poses(FigureKind::Quadruped),
            ..ok
        },
        FigureSpec {
            proportions: Proportions {
                limb_length: 0.0,
                limb_thickness: 1.0,
            },
            ..ok
        },
        FigureSpec {
            proportions: Proportions {
                limb_length: 1.0,
                limb_thickness: -1.0,
            },
            ..ok
        },
        FigureSpec {
            proportions: Proportions {
                limb_length: f64::NAN,
                limb_thickness: 1.0,
            },
            ..ok
        },
        FigureSpec {
            proportions: Proportions {
                limb_length: 1.0,
                limb_thickness: f64::INFINITY,
            },
            ..ok
        },
    ];
    for s in bad {
        assert!(
            matches!(figure(&s), Err(Error::InvalidParameter { .. })),
            "{s:?} accepted"
        );
    }
}

#[test]
fn kinds_parse_and_print() {
    assert_eq!(FigureKind::parse("humanoid"), Some(FigureKind::Humanoid));
    assert_eq!(
        FigureKind::parse(" Quadruped "),
        Some(FigureKind::Quadruped)
    );
    assert_eq!(
        FigureKind::parse("star5"),
        Some(FigureKind::Star { limbs: 5 })
    );
    assert_eq!(
        FigureKind::parse("star:8"),
        Some(FigureKind::Star { limbs: 8 })
    );
    for s in ["", "star", "star:", "star-3", "starx", "human", "star 5"] {
        assert_eq!(FigureKind::parse(s), None, "{s:?}");
    }
    for kind in all_kinds() {
        assert_eq!(FigureKind::parse(&kind.to_string()), Some(kind));
    }
    assert_eq!(FigureSpec::default(), spec(FigureKind::Humanoid, 0, 5000));
}

/// Prints generation times (run in release: `cargo test --release --test it
/// synth_figures::timing -- --ignored --nocapture`).
#[test]
#[ignore]
fn timing() {
    for kind in [
        FigureKind::Humanoid,
        FigureKind::Quadruped,
        FigureKind::Star { limbs: 8 },
    ] {
        for target in [5000, 20_000, 100_000, 200_000] {
            let start = std::time::Instant::now();
            let m = figure(&spec(kind, 2, target)).unwrap();
            eprintln!(
                "{kind} pose 2, {} vertices: {:.3} s",
                m.vertices.len(),
                start.elapsed().as_secs_f64()
            );
        }
    }
}
