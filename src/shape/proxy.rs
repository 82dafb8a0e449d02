//! Working meshes that stand for an input shape (docs/design.md, step 16): the pipeline runs
//! on a proxy of a few thousand vertices and its answers come back to every input vertex. A
//! dense shape gets a coarser proxy ([`Proxy::build`]); a low-poly mesh a refined copy of
//! the same surface ([`Proxy::refine`]).
//!
//! A mesh is simplified by meshoptimizer's edge collapse (`meshopt::simplify`, quadric
//! error, regularised triangles: the Laplacian wants well-shaped triangles more than an exact
//! silhouette); a point cloud by its point simplification (`meshopt::simplify_points`, a
//! spatial grid). Both keep a subset of the input vertices, so every proxy vertex is an input
//! vertex ([`Proxy::input_vertex`]). Every input vertex is located on the proxy
//! ([`Proxy::location`]): on a mesh the closest point of the proxy surface (a triangle and
//! barycentric weights), on a point cloud its three nearest proxy points (inverse-distance
//! weights). A k-d tree finds the candidates, so building a proxy is O(n log n).

use rayon::prelude::*;

use crate::progress::Cancel;
use crate::shape::neighbors::PointTree;
use crate::shape::smoothing::{self, TAUBIN_STEPS};
use crate::shape::surface_point::{
    closest_on_triangle, heaviest_first, inverse_distance, SurfacePoint,
};
use crate::shape::{Repairs, Shape, ShapeKind};
use crate::Result;

/// A working shape that stands for an input shape, and where each lies on the other.
#[derive(Debug, Clone)]
pub struct Proxy {
    /// How it was made from the input.
    pub kind: ProxyKind,
    /// The shape the pipeline runs on.
    pub shape: Shape,
    /// For every proxy vertex, where it lies on the input surface: the input vertex it is
    /// (weight 1) on a simplified proxy; on a refined one, an input triangle's corners and
    /// barycentric weights (an input vertex keeps weight 1).
    pub origin: Vec<SurfacePoint>,
    /// For every input vertex, where it lies on the proxy (on a refined proxy, exactly the
    /// proxy vertex it is).
    pub location: Vec<SurfacePoint>,
    /// Whether its positions were smoothed because the input is noisy
    /// ([`crate::shape::smoothing`]); its faces and where each vertex lies are unchanged.
    pub smoothed: bool,
}

/// How a proxy was made from its input shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProxyKind {
    /// A subset of the input vertices (meshoptimizer's simplification): a dense shape.
    Simplified,
    /// Every input vertex and triangle's midpoints (midpoint subdivision): a low-poly mesh.
    Refined,
    /// The input's own vertices and faces, its positions smoothed: a noisy mesh
    /// ([`Proxy::smoothed_copy`]).
    Smoothed,
}

/// Proxy candidates checked per input vertex: the triangles around its nearest proxy
/// vertices (not tuned; `tests/it/multiresolution.rs` checks that every located point lies
/// within half a proxy edge of its vertex on a 12K figure with a 2K proxy).
const NEAREST_PROXY_VERTICES: usize = 4;

impl Proxy {
    /// A proxy of `shape` with about `target_vertices` vertices (at least 3 fewer than the
    /// shape's active vertices, else [`crate::Error::InvalidParameter`]).
    pub fn build(shape: &Shape, target_vertices: usize) -> Result<Proxy> {
        Proxy::build_cancellable(shape, target_vertices, &Cancel::default())
    }

    /// [`Proxy::build`], stopping with [`crate::Error::Cancelled`] soon after `cancel` is set:
    /// between the pieces of a dense mesh's simplification ([`PIECE_TRIANGLES`]) and between
    /// blocks of [`LOCATE_BLOCK`] input vertices while locating them.
    pub fn build_cancellable(
        shape: &Shape,
        target_vertices: usize,
        cancel: &Cancel,
    ) -> Result<Proxy> {
        let active = shape.active_vertices();
        if target_vertices < 64 || target_vertices >= active.len() {
            return Err(crate::Error::InvalidParameter {
                name: "proxy_vertices",
                reason: format!(
                    "a proxy needs 64 or more vertices and fewer than the shape's {}, got {target_vertices}",
                    active.len()
                ),
            });
        }
        let positions: Vec<[f32; 3]> = shape
            .vertices()
            .iter()
            .map(|p| p.map(|x| x as f32))
            .collect();
        let (kept, triangles) = match shape.kind() {
            ShapeKind::Mesh => {
                let triangles = simplified_triangles(
                    shape,
                    &positions,
                    target_vertices,
                    PIECE_TRIANGLES,
                    cancel,
                )?;
                let mut kept: Vec<u32> = triangles.iter().flatten().copied().collect();
                kept.sort_unstable();
                kept.dedup();
                (kept, triangles)
            }
            ShapeKind::PointCloud => {
                let points: Vec<[f32; 3]> = active.iter().map(|&v| positions[v as usize]).collect();
                let mut kept: Vec<u32> =
                    meshopt::simplify_points_decoder(&points, None, 0.0, target_vertices)
                        .into_iter()
                        .map(|i| active[i as usize])
                        .collect();
                kept.sort_unstable();
                kept.dedup();
                (kept, Vec::new())
            }
        };
        let mut proxy_index = vec![u32::MAX; shape.n_vertices()];
        for (i, &v) in kept.iter().enumerate() {
            proxy_index[v as usize] = i as u32;
        }
        let vertices: Vec<[f64; 3]> = kept.iter().map(|&v| shape.vertices()[v as usize]).collect();
        let proxy_shape = match shape.kind() {
            ShapeKind::Mesh => {
                let triangles: Vec<Vec<u32>> = triangles
                    .iter()
                    .map(|t| t.iter().map(|&v| proxy_index[v as usize]).collect())
                    .collect();
                Shape::mesh_with(vertices, &triangles, &Repairs::default())?
            }
            ShapeKind::PointCloud => Shape::point_cloud_with(vertices, &Repairs::default())?,
        };
        cancel.check()?;
        let location = locate(shape, &proxy_shape, cancel)?;
        Ok(Proxy {
            kind: ProxyKind::Simplified,
            shape: proxy_shape,
            origin: kept.into_iter().map(SurfacePoint::at).collect(),
            location,
            smoothed: false,
        })
    }

    /// The input vertex that stands for proxy vertex `w`: the one it is, or the heaviest
    /// corner of the input triangle it lies on.
    pub fn input_vertex(&self, w: u32) -> u32 {
        self.origin[w as usize].nearest()
    }

    /// A per-vertex value of the proxy taken by every input vertex from its nearest proxy
    /// vertex on the surface (region labels: the boundaries follow the proxy's, with no
    /// isolated vertex of another label).
    pub fn lift_nearest<T: Copy>(&self, proxy_values: &[T]) -> Vec<T> {
        self.location
            .iter()
            .map(|p| proxy_values[p.nearest() as usize])
            .collect()
    }
}

/// How many vertices a mesh of `active` active vertices and `edges` edges has after one
/// midpoint subdivision: one more per edge.
pub fn refined_size(active: usize, edges: usize) -> usize {
    active + edges
}

impl Proxy {
    /// A refined copy of mesh `shape`: every triangle split into four at its edges'
    /// midpoints, repeated until the copy has at least `at_least` active vertices (and at
    /// least once). The input's vertices keep their indices and positions and the surface is
    /// the same, so every input vertex is exactly a proxy vertex and every proxy vertex lies
    /// on an input triangle. A point cloud gives [`crate::Error::InvalidParameter`].
    pub fn refine(shape: &Shape, at_least: usize) -> Result<Proxy> {
        Proxy::refine_cancellable(shape, at_least, &Cancel::default())
    }

    /// [`Proxy::refine`], stopping with [`crate::Error::Cancelled`] soon after `cancel` is
    /// set (looked at every [`LOCATE_BLOCK`] triangles).
    pub fn refine_cancellable(shape: &Shape, at_least: usize, cancel: &Cancel) -> Result<Proxy> {
        if shape.kind() != ShapeKind::Mesh {
            return Err(crate::Error::InvalidParameter {
                name: "refine_below",
                reason: "a point cloud has no triangles to refine".into(),
            });
        }
        let mut vertices = shape.vertices().to_vec();
        let mut origin: Vec<SurfacePoint> =
            (0..vertices.len() as u32).map(SurfacePoint::at).collect();
        let mut triangles = shape.triangles().to_vec();
        let mut active = shape.active_vertices().len();
        loop {
            let mut midpoint = std::collections::HashMap::with_capacity(triangles.len() * 3 / 2);
            let mut split = Vec::with_capacity(triangles.len() * 4);
            for (f, &[a, b, c]) in triangles.iter().enumerate() {
                if f % LOCATE_BLOCK == 0 {
                    cancel.check()?;
                }
                let mut mid = |p: u32, q: u32| -> u32 {
                    *midpoint.entry((p.min(q), p.max(q))).or_insert_with(|| {
                        let (x, y) = (vertices[p as usize], vertices[q as usize]);
                        vertices.push([0, 1, 2].map(|i| 0.5 * (x[i] + y[i])));
                        origin.push(halfway(&origin[p as usize], &origin[q as usize]));
                        (vertices.len() - 1) as u32
                    })
                };
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                split.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
            }
            active = refined_size(active, midpoint.len());
            triangles = split;
            if active >= at_least || midpoint.is_empty() {
                break;
            }
        }
        let polygons: Vec<Vec<u32>> = triangles.iter().map(|t| t.to_vec()).collect();
        // Midpoint subdivision keeps a low-poly mesh's long thin triangles; their intrinsic
        // Delaunay flips give the Laplacian non-negative weights (docs/decisions.md,
        // "Low-poly meshes: a refined working mesh": 300-vertex pairs 0.067 -> 0.025).
        // A shape whose pieces were joined has its refined copy joined too.
        let repairs = Repairs {
            join_gap: if shape.bridges().is_empty() {
                0.0
            } else {
                Repairs::default().join_gap
            },
            ..Repairs::none()
        };
        let refined = Shape::mesh_with(vertices, &polygons, &repairs)?.with_intrinsic_delaunay();
        let representative = shape.representative();
        let location = (0..shape.n_vertices())
            .map(|v| SurfacePoint::at(representative[v]))
            .collect();
        Ok(Proxy {
            kind: ProxyKind::Refined,
            shape: refined,
            origin,
            location,
            smoothed: false,
        })
    }
}

impl Proxy {
    /// A copy of mesh `shape` with its positions smoothed ([`smoothing::taubin_smoothed`]):
    /// every vertex is itself, so the answers come back unchanged.
    pub fn smoothed_copy(shape: &Shape) -> Proxy {
        let copy = shape.with_moved_vertices(smoothing::taubin_smoothed(shape, TAUBIN_STEPS));
        let representative = shape.representative();
        Proxy {
            kind: ProxyKind::Smoothed,
            shape: copy,
            origin: (0..shape.n_vertices() as u32)
                .map(SurfacePoint::at)
                .collect(),
            location: (0..shape.n_vertices())
                .map(|v| SurfacePoint::at(representative[v]))
                .collect(),
            smoothed: true,
        }
    }

    /// This proxy with its positions smoothed ([`smoothing::taubin_smoothed`]).
    pub fn into_smoothed(self) -> Proxy {
        let moved = smoothing::taubin_smoothed(&self.shape, TAUBIN_STEPS);
        Proxy {
            shape: self.shape.with_moved_vertices(moved),
            smoothed: true,
            ..self
        }
    }
}

/// The point halfway between two points of one input triangle, on its corners (heaviest
/// first, ties to the lower index).
fn halfway(p: &SurfacePoint, q: &SurfacePoint) -> SurfacePoint {
    let mut corners: Vec<(u32, f64)> = Vec::with_capacity(6);
    for (v, w) in p
        .vertices
        .iter()
        .zip(p.weights)
        .chain(q.vertices.iter().zip(q.weights))
    {
        if w <= 0.0 {
            continue;
        }
        match corners.iter_mut().find(|(u, _)| u == v) {
            Some((_, total)) => *total += 0.5 * w,
            None => corners.push((*v, 0.5 * w)),
        }
    }
    corners.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
    let mut point = SurfacePoint::at(corners[0].0);
    for (i, &(v, w)) in corners.iter().take(3).enumerate() {
        point.vertices[i] = v;
        point.weights[i] = w;
    }
    point
}

/// Triangles per piece of a dense mesh's first simplification pass: meshoptimizer's
/// simplification is one call that cannot be interrupted, so a piece bounds the wait for a
/// cancel (docs/decisions.md, "Dense shapes: limits": 100K triangles waited 0.62 s on 2
/// shared cores).
pub const PIECE_TRIANGLES: usize = 50_000;

/// What the first pass keeps of a dense mesh: this many times the proxy's triangles, so that
/// the last pass (one call on the whole surface) starts from a mesh of a bounded size.
const FIRST_PASS_MARGIN: usize = 4;

/// The triangles meshoptimizer keeps for about `target_vertices` vertices, in input indices.
/// A mesh of more than `2 * FIRST_PASS_MARGIN` times the target's triangles and more than
/// `piece` triangles is first simplified piece by piece ([`simplified_in_pieces`]).
fn simplified_triangles(
    shape: &Shape,
    positions: &[[f32; 3]],
    target_vertices: usize,
    piece: usize,
    cancel: &Cancel,
) -> Result<Vec<[u32; 3]>> {
    // A closed surface has about two triangles per vertex.
    let target_indices = 3 * 2 * target_vertices;
    let triangles = shape.triangles();
    let indices: Vec<u32> = if triangles.len() > piece
        && 3 * triangles.len() > 2 * FIRST_PASS_MARGIN * target_indices
    {
        simplified_in_pieces(
            triangles,
            positions,
            FIRST_PASS_MARGIN * target_indices,
            piece,
            cancel,
        )?
    } else {
        triangles.iter().flatten().copied().collect()
    };
    cancel.check()?;
    // The error bound is left open (1.0 of the mesh's extent): the count decides.
    let kept = meshopt::simplify_decoder(
        &indices,
        positions,
        target_indices,
        1.0,
        meshopt::SimplifyOptions::Regularize,
        None,
    );
    Ok(kept.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect())
}

/// A dense mesh's first simplification pass, to about `target_indices` indices in all: the
/// triangles in slabs of `piece` triangles along the bounding box's longest axis (by
/// centroid), each slab simplified on its own with its border locked (so the slabs still
/// meet), `cancel` looked at before each slab. The slabs run in parallel; their order, and
/// so the result, does not depend on the threads.
fn simplified_in_pieces(
    triangles: &[[u32; 3]],
    positions: &[[f32; 3]],
    target_indices: usize,
    piece: usize,
    cancel: &Cancel,
) -> Result<Vec<u32>> {
    let centroid =
        |t: &[u32; 3], c: usize| t.iter().map(|&v| positions[v as usize][c]).sum::<f32>();
    let extent = |c: usize| {
        let (lo, hi) = triangles.iter().fold((f32::MAX, f32::MIN), |(lo, hi), t| {
            let x = centroid(t, c);
            (lo.min(x), hi.max(x))
        });
        hi - lo
    };
    let axis = (0..3)
        .max_by(|&a, &b| extent(a).total_cmp(&extent(b)))
        .unwrap_or(0);
    // The keys computed once, with a look at `cancel` (the sort itself cannot be stopped).
    let mut keyed: Vec<(f32, u32)> = Vec::with_capacity(triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        cancel.check_every(i)?;
        keyed.push((centroid(t, axis), i as u32));
    }
    keyed.par_sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    cancel.check()?;
    let order: Vec<u32> = keyed.into_iter().map(|(_, i)| i).collect();
    let keep = target_indices as f64 / (3 * triangles.len()) as f64;
    let slabs: Vec<Result<Vec<u32>>> = order
        .par_chunks(piece)
        .map(|slab| {
            cancel.check()?;
            // The slab's vertices renumbered from 0, for a call whose cost is the slab's.
            let mut own: Vec<u32> = slab.iter().flat_map(|&f| triangles[f as usize]).collect();
            own.sort_unstable();
            own.dedup();
            let local = |v: u32| own.binary_search(&v).unwrap_or_default() as u32;
            let indices: Vec<u32> = slab
                .iter()
                .flat_map(|&f| triangles[f as usize].map(local))
                .collect();
            let points: Vec<[f32; 3]> = own.iter().map(|&v| positions[v as usize]).collect();
            let target = ((indices.len() as f64 * keep) as usize / 3 * 3).max(3);
            let kept = meshopt::simplify_decoder(
                &indices,
                &points,
                target,
                1.0,
                meshopt::SimplifyOptions::LockBorder | meshopt::SimplifyOptions::Regularize,
                None,
            );
            Ok(kept.into_iter().map(|v| own[v as usize]).collect())
        })
        .collect();
    let mut indices = Vec::with_capacity(2 * target_indices);
    for slab in slabs {
        indices.extend(slab?);
    }
    Ok(indices)
}

/// Input vertices located (or triangles refined) per block between two looks at the cancel
/// flag.
const LOCATE_BLOCK: usize = 16_384;

/// Where every input vertex of `shape` lies on `proxy` (an inactive vertex where its
/// representative lies).
fn locate(shape: &Shape, proxy: &Shape, cancel: &Cancel) -> Result<Vec<SurfacePoint>> {
    let proxy_active = proxy.active_vertices();
    let active_points: Vec<[f64; 3]> = proxy_active
        .iter()
        .map(|&v| proxy.vertices()[v as usize])
        .collect();
    let tree = PointTree::new(&active_points);
    let incident = proxy.triangles_around_vertices();
    let at = |query: &[f64; 3]| -> SurfacePoint {
        let near = tree.nearest_k(query, NEAREST_PROXY_VERTICES.max(3));
        if proxy.kind() == ShapeKind::PointCloud {
            return inverse_distance(
                &near
                    .iter()
                    .map(|&(i, d2)| (proxy_active[i], d2.sqrt()))
                    .collect::<Vec<_>>(),
            );
        }
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for &(i, _) in near.iter().take(NEAREST_PROXY_VERTICES) {
            for &f in &incident[proxy_active[i] as usize] {
                let t = proxy.triangles()[f as usize];
                let corners = t.map(|v| proxy.vertices()[v as usize]);
                let (d2, bary) = closest_on_triangle(query, &corners);
                if best.is_none_or(|(b, bf, _)| d2 < b || (d2 == b && f < bf)) {
                    best = Some((d2, f, bary));
                }
            }
        }
        let (_, f, bary) = best.expect("every active proxy vertex lies on a triangle");
        heaviest_first(proxy.triangles()[f as usize], bary)
    };
    let representative = shape.representative();
    let n = shape.n_vertices();
    let mut own: Vec<SurfacePoint> = Vec::with_capacity(n);
    for start in (0..n).step_by(LOCATE_BLOCK) {
        cancel.check()?;
        cancel.set_fraction(start as f32 / n as f32);
        let end = (start + LOCATE_BLOCK).min(n);
        own.par_extend((start..end).into_par_iter().map(|v| {
            if representative[v] as usize == v {
                at(&shape.vertices()[v])
            } else {
                SurfacePoint {
                    vertices: [0; 3],
                    weights: [1.0, 0.0, 0.0],
                }
            }
        }));
    }
    Ok((0..n).map(|v| own[representative[v] as usize]).collect())
}
