//! Objects touching a figure (docs/scans.md, "Props"): the closed pieces joined to a mesh's
//! figure, or the pieces of a point cloud's neighbour graph beside its figure, which only
//! the pair can tell from parts of it.

use std::collections::{HashMap, HashSet};

use super::{representative_is_active, representatives, triangle_area, DisjointSets};
use super::{Shape, ShapeKind, Warning, MIN_VERTICES};
use crate::progress::Cancel;

/// Share of a mesh's area that the closed pieces joined to its figure may hold at most for
/// [`Shape::without_touching_objects`] to try the shape without them: a prop is smaller
/// than the figure it stands beside (a box a tenth of a person's height holds 9% of the
/// area). Chosen from that, not tuned on a benchmark.
pub const TOUCHING_OBJECTS_AREA: f64 = 0.25;

/// Share of a point cloud's points a piece of its neighbour graph must hold to be tried as
/// an object beside the figure: the debris repair's default share
/// ([`crate::Repairs::debris_fraction`]), so that the small patches a graph splits off a
/// cloud of uneven density stay with the figure.
pub const CLOUD_OBJECT_SHARE: f64 = 0.01;

/// Closed pieces joined to a mesh's figure and left out ([`Shape::without_touching_objects`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ObjectsLeftOut {
    /// Number of pieces.
    pub pieces: usize,
    /// Number of their active vertices.
    pub vertices: usize,
}

impl Shape {
    /// Whether [`Shape::without_touching_objects`] may find objects: a mesh whose pieces
    /// were joined by bridges, or a point cloud in more than one piece. Cheap, and true for
    /// more shapes than have such objects (a figure modelled in open pieces): what a budget
    /// needs before any work.
    pub fn may_have_touching_objects(&self) -> bool {
        match self.kind {
            ShapeKind::Mesh => !self.bridges.is_empty(),
            ShapeKind::PointCloud => self.n_pieces > 1,
        }
    }

    /// The same shape without the objects touching its figure, for the pair to tell a prop
    /// from a part (docs/scans.md, "Props"). For a mesh: the closed pieces joined to its
    /// figure by bridges (a box touching a foot); `None` unless some piece other than the
    /// largest is closed (no boundary edge) and these hold at most [`TOUCHING_OBJECTS_AREA`]
    /// of the area. Open pieces stay: a part modelled apart is cut where it joins the figure
    /// (a head open at the neck, clothes, hair cards). For a point cloud: the pieces of its
    /// neighbour graph ([`Shape::edges`]) other than the largest that hold at least
    /// [`CLOUD_OBJECT_SHARE`] of the points each and at most [`TOUCHING_OBJECTS_AREA`] of
    /// them together (a box near a foot, which the repairs kept as part of the figure
    /// because it is within their reach). Every vertex keeps its index; one left out takes
    /// the answer of the nearest kept vertex.
    pub fn without_touching_objects(&self) -> Option<(Shape, ObjectsLeftOut)> {
        if !self.may_have_touching_objects() {
            return None;
        }
        if self.kind == ShapeKind::PointCloud {
            return self.cloud_without_pieces_beside();
        }
        let n = self.vertices.len();
        let mut sets = DisjointSets::new(n);
        for t in &self.triangles {
            sets.union(t[0] as usize, t[1] as usize);
            sets.union(t[1] as usize, t[2] as usize);
        }
        let mut area_of_root: HashMap<usize, f64> = HashMap::new();
        let mut uses_of_edge: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &self.triangles {
            *area_of_root.entry(sets.find(t[0] as usize)).or_default() +=
                triangle_area(&self.vertices, t);
            for k in 0..3 {
                let (x, y) = (t[k], t[(k + 1) % 3]);
                *uses_of_edge.entry((x.min(y), x.max(y))).or_default() += 1;
            }
        }
        let mut open: HashSet<usize> = HashSet::new();
        for (&(x, _), &uses) in &uses_of_edge {
            if uses == 1 {
                open.insert(sets.find(x as usize));
            }
        }
        let total: f64 = area_of_root.values().sum();
        let (&figure, _) = area_of_root
            .iter()
            .max_by(|x, y| x.1.total_cmp(y.1).then(y.0.cmp(x.0)))?;
        let objects: Vec<usize> = area_of_root
            .keys()
            .copied()
            .filter(|&root| root != figure && !open.contains(&root))
            .collect();
        let objects_area: f64 = objects.iter().map(|r| area_of_root[r]).sum();
        if objects.is_empty() || objects_area > TOUCHING_OBJECTS_AREA * total {
            return None;
        }
        let is_kept: Vec<bool> = (0..n).map(|v| !objects.contains(&sets.find(v))).collect();
        self.keeping(&is_kept, objects.len())
    }

    /// A point cloud without the pieces of its neighbour graph beside its figure
    /// ([`Shape::without_touching_objects`]).
    fn cloud_without_pieces_beside(&self) -> Option<(Shape, ObjectsLeftOut)> {
        let mut sets = DisjointSets::new(self.vertices.len());
        for (a, b) in self.edges() {
            sets.union(a as usize, b as usize);
        }
        // Pieces in the order of their first active point, so ties do not depend on roots.
        let mut points_of_root: Vec<(usize, usize)> = Vec::new();
        let mut slot_of_root: HashMap<usize, usize> = HashMap::new();
        for &v in &self.active {
            let root = sets.find(v as usize);
            let slot = *slot_of_root.entry(root).or_insert_with(|| {
                points_of_root.push((root, 0));
                points_of_root.len() - 1
            });
            points_of_root[slot].1 += 1;
        }
        let total = self.active.len() as f64;
        let figure = (0..points_of_root.len()).max_by(|&i, &j| {
            points_of_root[i]
                .1
                .cmp(&points_of_root[j].1)
                .then(j.cmp(&i))
        })?;
        let objects: HashSet<usize> = (points_of_root.iter().enumerate())
            .filter(|&(i, &(_, count))| i != figure && count as f64 >= CLOUD_OBJECT_SHARE * total)
            .map(|(_, &(root, _))| root)
            .collect();
        let objects_points: usize = (points_of_root.iter())
            .filter(|(root, _)| objects.contains(root))
            .map(|&(_, count)| count)
            .sum();
        if objects.is_empty() || objects_points as f64 > TOUCHING_OBJECTS_AREA * total {
            return None;
        }
        let is_kept: Vec<bool> = (0..self.vertices.len())
            .map(|v| !objects.contains(&sets.find(v)))
            .collect();
        self.keeping(&is_kept, objects.len())
    }

    /// The same shape with only the vertices `is_kept` active (and the faces and bridges
    /// among them), `pieces` objects reported left out; `None` when too few vertices stay.
    fn keeping(&self, is_kept: &[bool], pieces: usize) -> Option<(Shape, ObjectsLeftOut)> {
        let kept = |v: u32| is_kept[v as usize];
        let triangles: Vec<[u32; 3]> = (self.triangles.iter())
            .filter(|t| kept(t[0]))
            .copied()
            .collect();
        let bridges: Vec<[u32; 3]> = (self.bridges.iter())
            .filter(|t| t.iter().all(|&v| kept(v)))
            .copied()
            .collect();
        let active: Vec<u32> = self.active.iter().copied().filter(|&v| kept(v)).collect();
        if active.len() < MIN_VERTICES {
            return None;
        }
        let left_out = ObjectsLeftOut {
            pieces,
            vertices: self.active.len() - active.len(),
        };
        let nearest = representatives(&self.vertices, &active, &Cancel::default()).ok()?;
        let representative = self
            .representative
            .iter()
            .enumerate()
            .map(|(v, &rep)| {
                if representative_is_active(&active, rep) {
                    rep
                } else {
                    nearest[v]
                }
            })
            .collect();
        let mut warnings: Vec<Warning> = self
            .warnings
            .iter()
            .filter(|w| !matches!(w, Warning::DisconnectedPieces { .. }))
            .cloned()
            .collect();
        warnings.push(Warning::TouchingObjectsLeftOut {
            pieces: left_out.pieces,
            vertices: left_out.vertices,
        });
        let mut shape = Shape {
            vertices: self.vertices.clone(),
            triangles,
            bridges,
            kind: self.kind,
            active,
            representative,
            n_pieces: 1,
            warnings,
            fingerprint: std::sync::OnceLock::new(),
            cloud_faces: std::sync::OnceLock::new(),
            intrinsic_delaunay: self.intrinsic_delaunay,
        };
        shape.n_pieces = shape.count_pieces(&Cancel::default()).ok()?;
        if shape.n_pieces > 1 {
            shape.warnings.push(Warning::DisconnectedPieces {
                count: shape.n_pieces,
            });
        }
        Some((shape, left_out))
    }
}
