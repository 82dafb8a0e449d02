//! The validated input shape: a triangle mesh or a point cloud.
//!
//! Validation happens once, here, at the boundary. Fatal problems (non-finite coordinates,
//! face indices out of range, too few vertices, zero area) are typed [`Error`]s; problems the
//! pipeline can live with (degenerate or duplicate faces, unreferenced vertices, several
//! connected pieces, non-manifold edges, inconsistent orientation, polygons) are repaired or
//! ignored and reported as [`Warning`]s. The caller's vertex order is kept exactly: every
//! per-vertex output of the library is indexed by the input vertices.

pub mod cloud_orientation;
pub mod io;
pub mod neighbors;
mod objects;
pub mod proxy;
pub mod repair;
pub mod smoothing;
pub mod surface_point;
mod warning;

use std::collections::HashMap;

use crate::progress::{polled, Cancel, Progress, Stage};
use crate::shape::io::RawShape;
use crate::shape::neighbors::{symmetric_knn_graph, PointTree};
pub use crate::shape::objects::{ObjectsLeftOut, TOUCHING_OBJECTS_AREA};
use crate::shape::repair::PieceRole;
pub use crate::shape::repair::Repairs;
pub use crate::shape::warning::Warning;
use crate::{Error, Result};

/// Fewest usable vertices the pipeline accepts. The point-cloud Laplacian looks at
/// [`crate::spectral::laplacian::POINT_CLOUD_NEIGHBORS`] neighbours of every point and the
/// descriptors need a spectrum of some length, so anything smaller is rejected.
pub const MIN_VERTICES: usize = 32;

/// Neighbours per point in the point-cloud connectivity graph (paper, section 6.3: k = 6).
pub const POINT_CLOUD_GRAPH_K: usize = 6;

/// How [`Shape::read`] treats a file's faces.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum ReadAs {
    /// A mesh when the file has faces, a point cloud when it has none.
    #[default]
    Auto,
    /// A point cloud: the faces, if any, are ignored.
    PointCloud,
}

impl ReadAs {
    /// [`ReadAs::PointCloud`] when `points` is set (a front end's "treat as points" switch),
    /// else [`ReadAs::Auto`].
    pub fn point_cloud_when(points: bool) -> ReadAs {
        if points {
            ReadAs::PointCloud
        } else {
            ReadAs::Auto
        }
    }
}

/// Whether a shape is a triangle mesh or a point cloud.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum ShapeKind {
    /// A triangle mesh (vertices and faces).
    Mesh,
    /// A point cloud (vertices only; connectivity from a k-nearest-neighbour graph).
    PointCloud,
}

/// A validated triangle mesh or point cloud, in the caller's vertex order.
#[derive(Debug, Clone)]
pub struct Shape {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    /// Triangles that join nearby pieces of a mesh for the spectral stages
    /// ([`Repairs::join_gap`]); not faces of the shape.
    bridges: Vec<[u32; 3]>,
    kind: ShapeKind,
    /// Input vertices the computation runs on (all of them for a point cloud; those used by
    /// a face for a mesh), ascending.
    active: Vec<u32>,
    /// For every input vertex, the active vertex whose values it takes (itself if active).
    representative: Vec<u32>,
    n_pieces: usize,
    warnings: Vec<Warning>,
    /// [`Shape::fingerprint`], computed on first use.
    fingerprint: std::sync::OnceLock<u64>,
    /// A point cloud's oriented local triangles ([`Shape::oriented_triangles`]), computed on
    /// first use.
    cloud_faces: std::sync::OnceLock<Option<Vec<[u32; 3]>>>,
    /// Whether its Laplacian is built on the intrinsic Delaunay triangulation of its
    /// triangles ([`Shape::intrinsic_delaunay`]).
    intrinsic_delaunay: bool,
}

impl Shape {
    /// A triangle mesh. Faces are validated and cleaned, and the default [`Repairs`] made;
    /// see the module docs.
    pub fn mesh(vertices: Vec<[f64; 3]>, triangles: &[[u32; 3]]) -> Result<Shape> {
        let polygons: Vec<&[u32]> = triangles.iter().map(|t| t.as_slice()).collect();
        Shape::mesh_with_slices(vertices, &polygons, &Repairs::default())
    }

    /// A mesh from polygons of any size (quads and n-gons are triangulated).
    pub fn mesh_from_polygons(vertices: Vec<[f64; 3]>, polygons: &[Vec<u32>]) -> Result<Shape> {
        Shape::mesh_with(vertices, polygons, &Repairs::default())
    }

    /// A mesh from polygons, with the given repairs ([`Repairs::none`] for none).
    pub fn mesh_with(
        vertices: Vec<[f64; 3]>,
        polygons: &[Vec<u32>],
        repairs: &Repairs,
    ) -> Result<Shape> {
        let polygons: Vec<&[u32]> = polygons.iter().map(|p| p.as_slice()).collect();
        Shape::mesh_with_slices(vertices, &polygons, repairs)
    }

    fn mesh_with_slices(
        vertices: Vec<[f64; 3]>,
        polygons: &[&[u32]],
        repairs: &Repairs,
    ) -> Result<Shape> {
        let cancel = Cancel::default();
        Shape::build(vertices, polygons, ShapeKind::Mesh, repairs, &cancel)
    }

    /// A point cloud (no faces), with the default [`Repairs`].
    pub fn point_cloud(vertices: Vec<[f64; 3]>) -> Result<Shape> {
        Shape::point_cloud_with(vertices, &Repairs::default())
    }

    /// A point cloud with the given repairs.
    pub fn point_cloud_with(vertices: Vec<[f64; 3]>, repairs: &Repairs) -> Result<Shape> {
        Shape::build(
            vertices,
            &[],
            ShapeKind::PointCloud,
            repairs,
            &Cancel::default(),
        )
    }

    /// A shape from a file's contents: a point cloud when it has no faces or when `read_as`
    /// says so, a mesh otherwise.
    pub fn from_raw(raw: RawShape, read_as: ReadAs) -> Result<Shape> {
        Shape::from_raw_with(raw, read_as, &Repairs::default())
    }

    /// [`Shape::from_raw`] with the given repairs.
    pub fn from_raw_with(raw: RawShape, read_as: ReadAs, repairs: &Repairs) -> Result<Shape> {
        Shape::from_raw_cancellable(raw, read_as, repairs, &Cancel::default())
    }

    /// [`Shape::from_raw_with`], stopping with [`Error::Cancelled`] between its steps once
    /// `cancel` is set.
    fn from_raw_cancellable(
        raw: RawShape,
        read_as: ReadAs,
        repairs: &Repairs,
        cancel: &Cancel,
    ) -> Result<Shape> {
        if read_as == ReadAs::PointCloud || raw.polygons.is_empty() {
            Shape::build(raw.vertices, &[], ShapeKind::PointCloud, repairs, cancel)
        } else {
            let polygons: Vec<&[u32]> = raw.polygons.iter().map(|p| p.as_slice()).collect();
            Shape::build(raw.vertices, &polygons, ShapeKind::Mesh, repairs, cancel)
        }
    }

    /// Reads a file (OFF, OBJ, PLY, XYZ/PTS) into a shape: `Shape::read(path, ReadAs::Auto)`.
    pub fn read(path: &std::path::Path, read_as: ReadAs) -> Result<Shape> {
        Shape::read_with(path, read_as, &Repairs::default())
    }

    /// [`Shape::read`] with the given repairs.
    pub fn read_with(path: &std::path::Path, read_as: ReadAs, repairs: &Repairs) -> Result<Shape> {
        Shape::from_raw_with(crate::shape::io::read_shape(path)?, read_as, repairs)
    }

    /// [`Shape::read_with`] reporting to `progress` as [`Stage::Reading`] (the parse from 0
    /// to 0.5, the repairs from 0.5 to 1) every [`crate::progress::POLL_INTERVAL`]; a
    /// cancel stops reading within a few thousand lines or elements and the repairs between
    /// their steps, with [`Error::Cancelled`].
    pub fn read_watched(
        path: &std::path::Path,
        read_as: ReadAs,
        repairs: &Repairs,
        progress: &mut dyn Progress,
    ) -> Result<Shape> {
        let raw = polled(progress, Stage::Reading, (0.0, 0.5), |cancel| {
            crate::shape::io::read_shape_cancellable(path, cancel)
        })?;
        polled(progress, Stage::Reading, (0.5, 1.0), |cancel| {
            Shape::from_raw_cancellable(raw, read_as, repairs, cancel)
        })
    }

    fn build(
        vertices: Vec<[f64; 3]>,
        polygons: &[&[u32]],
        kind: ShapeKind,
        repairs: &Repairs,
        cancel: &Cancel,
    ) -> Result<Shape> {
        for (i, v) in vertices.iter().enumerate() {
            if let Some(&value) = v.iter().find(|c| !c.is_finite()) {
                return Err(Error::NonFiniteCoordinate { vertex: i, value });
            }
        }
        let n = vertices.len();
        if n < MIN_VERTICES {
            return Err(Error::TooFewVertices {
                received: n,
                required: MIN_VERTICES,
            });
        }
        let mut warnings = Vec::new();
        let Repaired {
            triangles,
            active,
            welded_to,
            bridges,
        } = match kind {
            ShapeKind::Mesh => {
                Shape::repaired_mesh(&vertices, polygons, repairs, &mut warnings, cancel)?
            }
            ShapeKind::PointCloud => {
                Shape::repaired_cloud(&vertices, repairs, &mut warnings, cancel)?
            }
        };
        cancel.check()?;
        if active.len() < MIN_VERTICES {
            return Err(Error::TooFewVertices {
                received: active.len(),
                required: MIN_VERTICES,
            });
        }
        let mut representative = representatives(&vertices, &active, cancel)?;
        cancel.check()?;
        for (v, rep) in representative.iter_mut().enumerate() {
            let root = welded_to[v];
            if root as usize != v && representative_is_active(&active, root) {
                *rep = root;
            }
        }
        let mut shape = Shape {
            vertices,
            triangles,
            bridges,
            kind,
            active,
            representative,
            n_pieces: 0,
            warnings,
            fingerprint: std::sync::OnceLock::new(),
            cloud_faces: std::sync::OnceLock::new(),
            intrinsic_delaunay: false,
        };
        match kind {
            ShapeKind::Mesh => {
                let area = shape.mesh_area();
                if !(area > 0.0) {
                    return Err(Error::ZeroArea {
                        detail: format!("{} faces, all of zero area", shape.triangles.len()),
                    });
                }
                let needles = shape.count_needle_faces(area);
                if needles > 0 {
                    shape
                        .warnings
                        .push(Warning::NeedleOrZeroAreaFaces { count: needles });
                }
                cancel.check()?;
                shape.check_edges(cancel)?;
            }
            ShapeKind::PointCloud => {
                let extent = bounding_box_diagonal(&shape.active_points());
                if !(extent > 0.0) {
                    return Err(Error::ZeroArea {
                        detail: format!("all {} points coincide", shape.vertices.len()),
                    });
                }
            }
        }
        cancel.check()?;
        shape.n_pieces = shape.count_pieces(cancel)?;
        if shape.n_pieces > 1 {
            shape.warnings.push(Warning::DisconnectedPieces {
                count: shape.n_pieces,
            });
        }
        Ok(shape)
    }

    /// A mesh's cleaned triangles, its active vertices and every vertex's weld target, after
    /// the [`Repairs`]: far vertices and their faces dropped, coincident vertices welded,
    /// faces cleaned, small pieces dropped.
    fn repaired_mesh(
        vertices: &[[f64; 3]],
        polygons: &[&[u32]],
        repairs: &Repairs,
        warnings: &mut Vec<Warning>,
        cancel: &Cancel,
    ) -> Result<Repaired> {
        let n = vertices.len();
        // Indices are checked before anything looks at them.
        let mut triangles = clean_faces(vertices, polygons, warnings, cancel)?;
        if triangles.is_empty() {
            return Err(Error::ZeroArea {
                detail: if polygons.is_empty() {
                    "the mesh has no faces; read vertices without faces as a point cloud"
                        .to_string()
                } else {
                    format!("all {} faces repeat a corner", polygons.len())
                },
            });
        }
        let used_by = |triangles: &[[u32; 3]]| -> Vec<u32> {
            let mut used = vec![false; n];
            for t in triangles {
                for &v in t {
                    used[v as usize] = true;
                }
            }
            (0..n as u32).filter(|&v| used[v as usize]).collect()
        };
        cancel.check()?;
        let referenced = used_by(&triangles);
        let mut dropped = vec![false; n];
        if repairs.outliers {
            let far = repair::far_vertices(vertices, &referenced);
            if !far.is_empty() && far.len() < referenced.len() {
                for &v in &far {
                    dropped[v as usize] = true;
                }
                triangles.retain(|t| !t.iter().any(|&v| dropped[v as usize]));
                warnings.push(Warning::FarVerticesDropped { count: far.len() });
            }
        }
        cancel.check()?;
        let kept = used_by(&triangles);
        let size = repair::robust_size(vertices, &kept);
        cancel.check()?;
        let welded_to = repair::weld(vertices, &kept, repairs.weld_tolerance * size, cancel)?;
        cancel.check()?;
        let welded = kept.iter().filter(|&&v| welded_to[v as usize] != v).count();
        if welded > 0 {
            for t in &mut triangles {
                *t = t.map(|v| welded_to[v as usize]);
            }
            let (degenerate, duplicate) = drop_improper_faces(&mut triangles, cancel)?;
            warnings.push(Warning::VerticesWelded { count: welded });
            if degenerate + duplicate > 0 {
                warnings.push(Warning::DegenerateFacesDropped {
                    count: degenerate + duplicate,
                });
            }
        }
        cancel.check()?;
        let mut bridges = if repairs.join_gap > 0.0 {
            repair::bridges_between_pieces(vertices, &triangles, repairs.join_gap * size, cancel)?
        } else {
            Vec::new()
        };
        cancel.check()?;
        let roles = repair::piece_roles_of_triangles(
            vertices,
            &triangles,
            &bridges,
            repairs.debris_fraction,
            cancel,
        )?;
        cancel.check()?;
        if roles.iter().any(|&r| r != PieceRole::Kept) {
            let left_out = left_out_pieces(n, &triangles, &roles);
            let mut role = roles.iter();
            triangles.retain(|_| role.next() == Some(&PieceRole::Kept));
            let (pieces, vertices) = left_out.debris;
            if pieces > 0 {
                warnings.push(Warning::SmallPiecesDropped { pieces, vertices });
            }
            let (pieces, vertices) = left_out.separate;
            if pieces > 0 {
                warnings.push(Warning::SeparateObjectsDropped { pieces, vertices });
            }
        }
        let active = used_by(&triangles);
        if !bridges.is_empty() {
            let mut kept = vec![false; n];
            for &v in &active {
                kept[v as usize] = true;
            }
            bridges.retain(|t| t.iter().all(|&v| kept[v as usize]));
            let before = count_pieces_of(n, &triangles, &[]);
            let after = count_pieces_of(n, &triangles, &bridges);
            if after < before {
                warnings.push(Warning::PiecesJoined {
                    pieces: before,
                    into: after,
                    bridges: bridges.len(),
                });
            }
        }
        let unreferenced = n - referenced.len();
        if unreferenced > 0 {
            warnings.push(Warning::UnreferencedVertices {
                count: unreferenced,
            });
        }
        Ok(Repaired {
            triangles,
            active,
            welded_to,
            bridges,
        })
    }

    /// A point cloud's active points and every point's weld target, after the [`Repairs`]:
    /// far points dropped, coincident points welded, isolated points and small pieces of the
    /// neighbour graph dropped.
    fn repaired_cloud(
        vertices: &[[f64; 3]],
        repairs: &Repairs,
        warnings: &mut Vec<Warning>,
        cancel: &Cancel,
    ) -> Result<Repaired> {
        let all: Vec<u32> = (0..vertices.len() as u32).collect();
        let mut active = all.clone();
        if repairs.outliers {
            let far = repair::far_vertices(vertices, &all);
            if !far.is_empty() {
                let mut is_far = vec![false; vertices.len()];
                for &v in &far {
                    is_far[v as usize] = true;
                }
                active.retain(|&v| !is_far[v as usize]);
                warnings.push(Warning::FarVerticesDropped { count: far.len() });
            }
        }
        cancel.check()?;
        let size = repair::robust_size(vertices, &active);
        let welded_to = repair::weld(vertices, &active, repairs.weld_tolerance * size, cancel)?;
        cancel.check()?;
        let before = active.len();
        active.retain(|&v| welded_to[v as usize] == v);
        if active.len() < before {
            warnings.push(Warning::VerticesWelded {
                count: before - active.len(),
            });
        }
        if repairs.outliers && active.len() >= MIN_VERTICES {
            let before = active.len();
            active = repair::dense_points(vertices, &active, cancel)?;
            if active.len() < before {
                warnings.push(Warning::OutlierPointsDropped {
                    count: before - active.len(),
                });
            }
        }
        cancel.check()?;
        if active.len() >= MIN_VERTICES {
            let (kept, left_out) =
                repair::keep_cloud_figure(vertices, &active, repairs.debris_fraction, cancel)?;
            let (pieces, vertices) = left_out.debris;
            if pieces > 0 {
                warnings.push(Warning::SmallPiecesDropped { pieces, vertices });
            }
            let (pieces, vertices) = left_out.separate;
            if pieces > 0 {
                warnings.push(Warning::SeparateObjectsDropped { pieces, vertices });
            }
            active = kept;
        }
        Ok(Repaired {
            triangles: Vec::new(),
            active,
            welded_to,
            bridges: Vec::new(),
        })
    }

    /// Vertex positions in the caller's order and units.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// The cleaned triangles (empty for a point cloud), indexing [`Shape::vertices`].
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// For every vertex, the indices of the triangles that use it (empty lists for a point
    /// cloud). Built on demand: O(n) time and memory.
    pub fn triangles_around_vertices(&self) -> Vec<Vec<u32>> {
        let mut around = vec![Vec::new(); self.vertices.len()];
        for (f, t) in self.triangles.iter().enumerate() {
            for &v in t {
                around[v as usize].push(f as u32);
            }
        }
        around
    }

    /// Whether its Laplacian (and its heat geodesics) are built on the intrinsic Delaunay
    /// triangulation of its triangles (a refined low-poly mesh's,
    /// [`crate::shape::proxy::Proxy::refine`]), not on the triangles as they are.
    pub fn intrinsic_delaunay(&self) -> bool {
        self.intrinsic_delaunay
    }

    /// The same shape, its Laplacian built on the intrinsic Delaunay triangulation.
    pub(crate) fn with_intrinsic_delaunay(mut self) -> Shape {
        self.intrinsic_delaunay = self.kind == ShapeKind::Mesh;
        self
    }

    /// Mesh or point cloud.
    pub fn kind(&self) -> ShapeKind {
        self.kind
    }

    /// Number of input vertices.
    pub fn n_vertices(&self) -> usize {
        self.vertices.len()
    }

    /// Input vertices the computation runs on, ascending (unreferenced mesh vertices are
    /// left out).
    pub fn active_vertices(&self) -> &[u32] {
        &self.active
    }

    /// For every input vertex, the active vertex whose values it takes (itself if active).
    pub fn representative(&self) -> &[u32] {
        &self.representative
    }

    /// Number of connected pieces (of the surface joined by its [`Shape::bridges`], or of
    /// the point cloud's kNN graph).
    pub fn n_pieces(&self) -> usize {
        self.n_pieces
    }

    /// A 64-bit hash of the vertex positions, the triangles and the kind, computed once: two
    /// shapes with the same vertex count but other positions or faces (another shape, or A
    /// and B swapped) differ, so a map can check that it is given the shapes it was made
    /// from. Not stable across Rust versions (std's SipHash): never store it.
    pub fn fingerprint(&self) -> u64 {
        *self.fingerprint.get_or_init(|| {
            use std::hash::{DefaultHasher, Hasher};
            let mut hasher = DefaultHasher::new();
            hasher.write_u8(self.kind as u8);
            hasher.write_usize(self.vertices.len());
            for p in &self.vertices {
                let mut bytes = [0u8; 24];
                for (c, x) in p.iter().enumerate() {
                    bytes[8 * c..8 * c + 8].copy_from_slice(&x.to_bits().to_le_bytes());
                }
                hasher.write(&bytes);
            }
            hasher.write_usize(self.triangles.len());
            for t in &self.triangles {
                let mut bytes = [0u8; 12];
                for (c, v) in t.iter().enumerate() {
                    bytes[4 * c..4 * c + 4].copy_from_slice(&v.to_le_bytes());
                }
                hasher.write(&bytes);
            }
            hasher.finish()
        })
    }

    /// What was repaired or ignored while building the shape.
    pub fn warnings(&self) -> &[Warning] {
        &self.warnings
    }

    /// Total surface area of a mesh in the input units (0 for a point cloud: its area is
    /// estimated by the Laplacian's mass, [`crate::spectral::laplacian::Laplacian::input_area`]).
    pub fn mesh_area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| triangle_area(&self.vertices, t))
            .sum()
    }

    /// Length of the bounding-box diagonal of the active vertices, the "width" of the shape.
    pub fn width(&self) -> f64 {
        bounding_box_diagonal(&self.active_points())
    }

    /// Positions of the active vertices, in [`Shape::active_vertices`] order.
    fn active_points(&self) -> Vec<[f64; 3]> {
        self.active
            .iter()
            .map(|&v| self.vertices[v as usize])
            .collect()
    }

    /// Mean edge length; for a point cloud, the mean distance to the nearest other point
    /// (the scale the proxies' lifting and the surface map measure tears in).
    pub fn mean_edge_length(&self) -> f64 {
        let p = self.vertices();
        let edges = self.edges();
        if !edges.is_empty() {
            return edges
                .iter()
                .map(|&(i, j)| distance(&p[i as usize], &p[j as usize]))
                .sum::<f64>()
                / edges.len() as f64;
        }
        let active: Vec<[f64; 3]> = self
            .active_vertices()
            .iter()
            .map(|&v| p[v as usize])
            .collect();
        let tree = PointTree::new(&active);
        active
            .iter()
            .map(|q| {
                tree.nearest_k(q, 2)
                    .last()
                    .map_or(0.0, |&(_, d2)| d2.sqrt())
            })
            .sum::<f64>()
            / active.len() as f64
    }

    /// Undirected edges between active vertices, each once as (low, high), sorted: mesh edges,
    /// or the symmetric k-nearest-neighbour graph (k = [`POINT_CLOUD_GRAPH_K`]) of a point cloud.
    pub fn edges(&self) -> Vec<(u32, u32)> {
        let mut edges: Vec<(u32, u32)> = match self.kind {
            ShapeKind::Mesh => self
                .triangles
                .iter()
                .chain(&self.bridges)
                .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
                .map(|(a, b)| (a.min(b), a.max(b)))
                .collect(),
            ShapeKind::PointCloud => {
                let active = &self.active;
                symmetric_knn_graph(&self.active_points(), POINT_CLOUD_GRAPH_K)
                    .into_iter()
                    .enumerate()
                    .flat_map(|(i, list)| {
                        list.into_iter()
                            .filter(move |&j| j > i)
                            .map(move |j| (active[i], active[j]))
                    })
                    .collect()
            }
        };
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    /// A copy of the shape with moved vertices (same faces), e.g. after a rigid motion.
    pub fn with_vertices(&self, vertices: Vec<[f64; 3]>) -> Result<Shape> {
        match self.kind {
            ShapeKind::Mesh => Shape::mesh(vertices, &self.triangles),
            ShapeKind::PointCloud => Shape::point_cloud(vertices),
        }
    }

    /// The same shape (faces, repairs, active vertices) with its vertices moved to
    /// `vertices`, one per input vertex ([`smoothing::taubin_smoothed`]).
    pub(crate) fn with_moved_vertices(&self, vertices: Vec<[f64; 3]>) -> Shape {
        assert_eq!(
            vertices.len(),
            self.vertices.len(),
            "one position per vertex"
        );
        Shape {
            vertices,
            triangles: self.triangles.clone(),
            bridges: self.bridges.clone(),
            kind: self.kind,
            active: self.active.clone(),
            representative: self.representative.clone(),
            n_pieces: self.n_pieces,
            warnings: self.warnings.clone(),
            fingerprint: std::sync::OnceLock::new(),
            cloud_faces: std::sync::OnceLock::new(),
            intrinsic_delaunay: self.intrinsic_delaunay,
        }
    }

    /// Triangles that join nearby pieces of a mesh for the spectral stages (the Laplacian,
    /// [`Shape::edges`]), made by [`Repairs::join_gap`]; they are not faces: transfers,
    /// surface maps and orientation use [`Shape::triangles`] only.
    pub fn bridges(&self) -> &[[u32; 3]] {
        &self.bridges
    }

    /// The faces with one consistent orientation, each connected piece facing outward
    /// (positive signed volume about its centroid; for a flat open piece, the orientation
    /// most of its faces had). Orientation is carried across edges shared by exactly two
    /// faces, so a few flipped faces (an [`Warning::InconsistentOrientation`]) are turned
    /// back and pieces joined only at non-manifold edges are oriented separately. `None`
    /// for a non-orientable surface (a Moebius strip). A point cloud gets its local
    /// Delaunay triangles turned by its outward normals ([`cloud_orientation`]), or `None`
    /// where that orientation is not trusted. The orientation terms of the pointwise map
    /// need it; the Laplacian does not.
    pub fn oriented_triangles(&self) -> Option<Vec<[u32; 3]>> {
        if self.kind == ShapeKind::PointCloud {
            return self
                .cloud_faces
                .get_or_init(|| {
                    let oriented = cloud_orientation::orient(&self.active_points());
                    oriented.trusted().then(|| {
                        oriented
                            .triangles
                            .iter()
                            .map(|t| t.map(|i| self.active[i as usize]))
                            .collect()
                    })
                })
                .clone();
        }
        let faces = &self.triangles;
        // For every undirected edge, the faces using it and whether each runs it low -> high.
        let mut uses: HashMap<(u32, u32), Vec<(u32, bool)>> = HashMap::new();
        for (f, t) in faces.iter().enumerate() {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                uses.entry((a.min(b), a.max(b)))
                    .or_default()
                    .push((f as u32, a < b));
            }
        }
        let edge_of = |t: &[u32; 3], c: usize| {
            let (a, b) = (t[c], t[(c + 1) % 3]);
            ((a.min(b), a.max(b)), a < b)
        };
        // Breadth-first over faces; flip[f]: whether face f must be reversed.
        let mut flip: Vec<Option<bool>> = vec![None; faces.len()];
        let mut oriented = faces.clone();
        let mut queue = std::collections::VecDeque::new();
        for start in 0..faces.len() {
            if flip[start].is_some() {
                continue;
            }
            flip[start] = Some(false);
            queue.push_back(start);
            let mut piece = Vec::new();
            while let Some(f) = queue.pop_front() {
                piece.push(f);
                let flipped = flip[f].expect("queued faces have a flip");
                for c in 0..3 {
                    let (key, forward) = edge_of(&faces[f], c);
                    let users = &uses[&key];
                    if users.len() != 2 {
                        continue;
                    }
                    let (g, g_forward) = users[if users[0].0 as usize == f { 1 } else { 0 }];
                    // Neighbours agree when they run the shared edge in opposite directions.
                    let want = flipped ^ (forward == g_forward);
                    match flip[g as usize] {
                        None => {
                            flip[g as usize] = Some(want);
                            queue.push_back(g as usize);
                        }
                        Some(have) if have != want => return None,
                        Some(_) => {}
                    }
                }
            }
            // The piece's orientation up to one sign: outward by its signed volume.
            let turned = |f: usize| {
                let t = faces[f];
                if flip[f] == Some(true) {
                    [t[0], t[2], t[1]]
                } else {
                    t
                }
            };
            let mut centroid = [0.0; 3];
            for &f in &piece {
                for &v in &faces[f] {
                    for (c, x) in centroid.iter_mut().zip(self.vertices[v as usize]) {
                        *c += x / (3 * piece.len()) as f64;
                    }
                }
            }
            let (mut volume, mut area) = (0.0, 0.0);
            for &f in &piece {
                let [a, b, c] = turned(f).map(|v| sub(&self.vertices[v as usize], &centroid));
                volume += dot(&a, &cross(&b, &c)) / 6.0;
                area += triangle_area(&self.vertices, &faces[f]);
            }
            let reverse = if volume.abs() > 1e-6 * area.powf(1.5) {
                volume < 0.0
            } else {
                2 * piece.iter().filter(|&&f| flip[f] == Some(true)).count() > piece.len()
            };
            for &f in &piece {
                let t = turned(f);
                oriented[f] = if reverse { [t[0], t[2], t[1]] } else { t };
            }
        }
        Some(oriented)
    }

    fn count_needle_faces(&self, total_area: f64) -> usize {
        let mean = total_area / self.triangles.len() as f64;
        self.triangles
            .iter()
            .filter(|t| triangle_area(&self.vertices, t) < NEEDLE_AREA_FRACTION * mean)
            .count()
    }

    /// Counts non-manifold edges and orientation conflicts and records them as warnings.
    fn check_edges(&mut self, cancel: &Cancel) -> Result<()> {
        // For every undirected edge: number of faces using it, and how many of them run it
        // from low to high.
        let mut uses: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
        for (i, t) in self.triangles.iter().enumerate() {
            cancel.check_every(i)?;
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                let entry = uses.entry((a.min(b), a.max(b))).or_insert((0, 0));
                entry.0 += 1;
                if a < b {
                    entry.1 += 1;
                }
            }
        }
        let non_manifold = uses.values().filter(|(n, _)| *n > 2).count();
        let flipped = uses
            .values()
            .filter(|(n, forward)| *n == 2 && *forward != 1)
            .count();
        if non_manifold > 0 {
            self.warnings.push(Warning::NonManifoldEdges {
                count: non_manifold,
            });
        }
        if flipped > 0 {
            self.warnings
                .push(Warning::InconsistentOrientation { edges: flipped });
        }
        Ok(())
    }

    fn count_pieces(&self, cancel: &Cancel) -> Result<usize> {
        let mut sets = DisjointSets::new(self.vertices.len());
        match self.kind {
            // The triangles' sides join the same vertices as the sorted edges, with no sort.
            ShapeKind::Mesh => {
                for (i, t) in self.triangles.iter().chain(&self.bridges).enumerate() {
                    cancel.check_every(i)?;
                    sets.union(t[0] as usize, t[1] as usize);
                    sets.union(t[1] as usize, t[2] as usize);
                }
            }
            ShapeKind::PointCloud => {
                for (i, (a, b)) in self.edges().into_iter().enumerate() {
                    cancel.check_every(i)?;
                    sets.union(a as usize, b as usize);
                }
            }
        }
        let mut roots: Vec<usize> = Vec::with_capacity(self.active.len());
        for (i, &v) in self.active.iter().enumerate() {
            cancel.check_every(i)?;
            roots.push(sets.find(v as usize));
        }
        roots.sort_unstable();
        roots.dedup();
        Ok(roots.len())
    }
}

/// What the repairs leave of a shape's input.
struct Repaired {
    /// The kept, cleaned triangles (none for a point cloud).
    triangles: Vec<[u32; 3]>,
    /// The kept vertices, ascending.
    active: Vec<u32>,
    /// For every vertex, the vertex it was welded to (itself when none).
    welded_to: Vec<u32>,
    /// Triangles joining nearby pieces ([`repair::bridges_between_pieces`]).
    bridges: Vec<[u32; 3]>,
}

/// Connected pieces of the vertices used by `triangles` and `bridges`.
/// The pieces left out by `roles` (one per triangle, [`PieceRole`]) and their vertices
/// (a vertex of a piece that is kept is not counted).
fn left_out_pieces(n: usize, triangles: &[[u32; 3]], roles: &[PieceRole]) -> repair::LeftOut {
    let mut kept = vec![false; n];
    let mut pieces = DisjointSets::new(n);
    for (t, &role) in triangles.iter().zip(roles) {
        if role == PieceRole::Kept {
            t.iter().for_each(|&v| kept[v as usize] = true);
        } else {
            pieces.union(t[0] as usize, t[1] as usize);
            pieces.union(t[1] as usize, t[2] as usize);
        }
    }
    let mut role_of_root: HashMap<usize, (PieceRole, usize)> = HashMap::new();
    let mut counted = vec![false; n];
    for (t, &role) in triangles.iter().zip(roles) {
        if role == PieceRole::Kept {
            continue;
        }
        let entry = role_of_root
            .entry(pieces.find(t[0] as usize))
            .or_insert((role, 0));
        for &v in t {
            if !kept[v as usize] && !counted[v as usize] {
                counted[v as usize] = true;
                entry.1 += 1;
            }
        }
    }
    let mut left_out = repair::LeftOut::default();
    for (role, vertices) in role_of_root.into_values() {
        left_out.add(role, vertices);
    }
    left_out
}

fn count_pieces_of(n: usize, triangles: &[[u32; 3]], bridges: &[[u32; 3]]) -> usize {
    let mut sets = DisjointSets::new(n);
    let mut used = vec![false; n];
    for t in triangles.iter().chain(bridges) {
        sets.union(t[0] as usize, t[1] as usize);
        sets.union(t[1] as usize, t[2] as usize);
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut roots: Vec<usize> = (0..n).filter(|&v| used[v]).map(|v| sets.find(v)).collect();
    roots.sort_unstable();
    roots.dedup();
    roots.len()
}

/// A face whose area is below this fraction of the mean face area counts as a needle.
const NEEDLE_AREA_FRACTION: f64 = 1e-8;

/// Checks indices, triangulates polygons, drops faces with repeated corners and duplicates.
fn clean_faces(
    vertices: &[[f64; 3]],
    polygons: &[&[u32]],
    warnings: &mut Vec<Warning>,
    cancel: &Cancel,
) -> Result<Vec<[u32; 3]>> {
    let n = vertices.len();
    let mut triangles = Vec::with_capacity(polygons.len());
    let mut n_polygons = 0;
    for (face, polygon) in polygons.iter().enumerate() {
        cancel.check_every(face)?;
        if polygon.len() < 3 {
            return Err(Error::FaceTooSmall {
                face,
                corners: polygon.len(),
            });
        }
        if let Some(&index) = polygon.iter().find(|&&i| i as usize >= n) {
            return Err(Error::FaceIndexOutOfRange {
                face,
                index: index as u64,
                n_vertices: n,
            });
        }
        if polygon.len() > 3 {
            n_polygons += 1;
        }
        triangulate(vertices, polygon, &mut triangles);
    }
    if n_polygons > 0 {
        warnings.push(Warning::PolygonsTriangulated { count: n_polygons });
    }
    let (degenerate, duplicate) = drop_improper_faces(&mut triangles, cancel)?;
    if degenerate > 0 {
        warnings.push(Warning::DegenerateFacesDropped { count: degenerate });
    }
    if duplicate > 0 {
        warnings.push(Warning::DuplicateFacesDropped { count: duplicate });
    }
    Ok(triangles)
}

/// Drops the faces with a repeated corner, then those with the same corners as an earlier
/// face; returns how many of each.
fn drop_improper_faces(triangles: &mut Vec<[u32; 3]>, cancel: &Cancel) -> Result<(usize, usize)> {
    let before = triangles.len();
    triangles.retain(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0]);
    let degenerate = before - triangles.len();
    let mut seen = std::collections::HashSet::with_capacity(triangles.len());
    let mut first = Vec::with_capacity(triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        cancel.check_every(i)?;
        let mut key = *t;
        key.sort_unstable();
        first.push(seen.insert(key));
    }
    let before = triangles.len();
    let mut first = first.into_iter();
    triangles.retain(|_| first.next().unwrap_or(true));
    Ok((degenerate, before - triangles.len()))
}

/// Splits a polygon into triangles: a quad along its shorter diagonal, larger polygons as
/// a fan from the first corner (exact for convex polygons).
fn triangulate(vertices: &[[f64; 3]], polygon: &[u32], out: &mut Vec<[u32; 3]>) {
    match *polygon {
        [a, b, c] => out.push([a, b, c]),
        [a, b, c, d] => {
            let ac = distance(&vertices[a as usize], &vertices[c as usize]);
            let bd = distance(&vertices[b as usize], &vertices[d as usize]);
            if ac <= bd {
                out.extend([[a, b, c], [a, c, d]]);
            } else {
                out.extend([[a, b, d], [b, c, d]]);
            }
        }
        _ => {
            for k in 1..polygon.len() - 1 {
                out.push([polygon[0], polygon[k], polygon[k + 1]]);
            }
        }
    }
}

/// Whether `v` is in the ascending list `active`.
fn representative_is_active(active: &[u32], v: u32) -> bool {
    active.binary_search(&v).is_ok()
}

/// For every vertex, itself if active, else the nearest active vertex.
fn representatives(vertices: &[[f64; 3]], active: &[u32], cancel: &Cancel) -> Result<Vec<u32>> {
    let mut representative: Vec<u32> = (0..vertices.len() as u32).collect();
    if active.len() == vertices.len() {
        return Ok(representative);
    }
    let active_points: Vec<[f64; 3]> = active.iter().map(|&v| vertices[v as usize]).collect();
    let tree = PointTree::new(&active_points);
    let mut is_active = vec![false; vertices.len()];
    for &v in active {
        is_active[v as usize] = true;
    }
    for (v, rep) in representative.iter_mut().enumerate() {
        cancel.check_every(v)?;
        if !is_active[v] {
            *rep = active[tree.nearest(&vertices[v])];
        }
    }
    Ok(representative)
}

/// Area of triangle `t`.
///
/// The edges are scaled by a power of two before the cross product (exact, so the result is
/// bit-identical for ordinary sizes), so a tiny or huge shape (a 1e-100 scale:
/// docs/decisions.md, "Shapes far from unit size") does not underflow or overflow in the
/// squared lengths.
pub fn triangle_area(vertices: &[[f64; 3]], t: &[u32; 3]) -> f64 {
    let [a, b, c] = t.map(|i| vertices[i as usize]);
    let u = sub(&b, &a);
    let v = sub(&c, &a);
    let largest = u.iter().chain(&v).fold(0.0f64, |m, x| m.max(x.abs()));
    let scale = power_of_two_near(largest);
    let (u, v) = (u.map(|x| x / scale), v.map(|x| x / scale));
    0.5 * norm(&cross(&u, &v)) * scale * scale
}

/// A power of two within a factor 2 of `x` (1 for 0 or a non-finite `x`): dividing by it
/// is exact.
pub fn power_of_two_near(x: f64) -> f64 {
    if x > 0.0 && x.is_finite() {
        2f64.powi(x.log2().floor() as i32)
    } else {
        1.0
    }
}

/// Corners `(min, max)` of the axis-aligned bounding box of `points` (infinite for none).
pub fn bounding_box(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Length of the axis-aligned bounding box's diagonal (0 for no points).
pub fn bounding_box_diagonal(points: &[[f64; 3]]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let (lo, hi) = bounding_box(points);
    distance(&lo, &hi)
}

pub(crate) fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn norm(a: &[f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

pub(crate) fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    norm(&sub(a, b))
}

/// Union-find with path halving, for connected pieces.
pub(crate) struct DisjointSets {
    parent: Vec<usize>,
}

impl DisjointSets {
    pub(crate) fn new(n: usize) -> Self {
        DisjointSets {
            parent: (0..n).collect(),
        }
    }

    pub(crate) fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    pub(crate) fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            // Smaller root wins, so the result does not depend on the order of unions.
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.parent[hi] = lo;
        }
    }
}
