//! What the shape's construction repaired or noticed rather than rejected.

#[cfg(doc)]
use super::{Repairs, Shape};

/// Something in the input that was repaired or ignored rather than rejected.
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum Warning {
    /// Faces with a repeated corner (zero area by construction) were dropped.
    DegenerateFacesDropped {
        /// Number of triangles dropped (counted after polygons are split).
        count: usize,
    },
    /// Faces with the same three corners as an earlier face were dropped.
    DuplicateFacesDropped {
        /// Number of triangles dropped (counted after polygons are split).
        count: usize,
    },
    /// Polygons with more than three corners were split into triangles.
    PolygonsTriangulated {
        /// Number of input faces with more than three corners.
        count: usize,
    },
    /// Vertices used by no face; they take the values of the nearest used vertex.
    UnreferencedVertices {
        /// Number of input vertices used by no face.
        count: usize,
    },
    /// The surface (or the point cloud's neighbour graph) has several connected pieces.
    DisconnectedPieces {
        /// Number of connected pieces (at least 2).
        count: usize,
    },
    /// Edges shared by more than two faces (the Laplacian handles them).
    NonManifoldEdges {
        /// Number of edges shared by more than two faces.
        count: usize,
    },
    /// Neighbouring faces with opposite orientation (the Laplacian does not depend on it; the
    /// pointwise map uses [`Shape::oriented_triangles`]).
    InconsistentOrientation {
        /// Number of edges whose two faces run them in the same direction.
        edges: usize,
    },
    /// Faces with (near) zero area but distinct corners; the Laplacian mollifies them.
    NeedleOrZeroAreaFaces {
        /// Number of triangles with area below 1e-8 times the mean triangle area.
        count: usize,
    },
    /// Coincident vertices (UV seams, hard edges, triangle soups) were welded
    /// ([`Repairs::weld_tolerance`]); each takes the values of the vertex it was welded to.
    VerticesWelded {
        /// Number of vertices welded into another one.
        count: usize,
    },
    /// Pieces of the mesh that come close were joined for the spectral stages by bridge
    /// triangles ([`Repairs::join_gap`], [`Shape::bridges`]); no face was added.
    PiecesJoined {
        /// Number of connected pieces of the faces.
        pieces: usize,
        /// Number of pieces once joined.
        into: usize,
        /// Number of bridge triangles.
        bridges: usize,
    },
    /// Small connected pieces (scan debris) were left out ([`Repairs::debris_fraction`]);
    /// their vertices take the values of the nearest kept vertex.
    SmallPiecesDropped {
        /// Number of pieces left out.
        pieces: usize,
        /// Number of their vertices.
        vertices: usize,
    },
    /// Pieces as large as a part of the figure but not joined to its largest piece (a prop,
    /// a base, a second object) were left out ([`Repairs::debris_fraction`] switches it
    /// off with the debris rule); their vertices take the answer of the nearest kept vertex.
    SeparateObjectsDropped {
        /// Number of pieces left out.
        pieces: usize,
        /// Number of their vertices.
        vertices: usize,
    },
    /// Pieces joined to the figure (a prop touching it) were left out because the pair
    /// matched better without them ([`super::Shape::without_touching_objects`],
    /// docs/scans.md, "Props"); their vertices take the answer of the nearest kept vertex.
    TouchingObjectsLeftOut {
        /// Number of pieces left out.
        pieces: usize,
        /// Number of their vertices.
        vertices: usize,
    },
    /// Pieces joined to the figure that the pair could not try leaving out because the
    /// time limit (`time_limit_s`) passed first: they were matched as part of the figure.
    TouchingObjectsNotTried {
        /// Number of pieces.
        pieces: usize,
    },
    /// Vertices far from the rest of the shape were left out ([`Repairs::outliers`]), with
    /// their faces; they take the values of the nearest kept vertex.
    FarVerticesDropped {
        /// Number of vertices left out.
        count: usize,
    },
    /// Isolated points of a point cloud (local-density test) were left out of the
    /// Laplacian and the area ([`Repairs::outliers`]); they take the values of the nearest
    /// kept point.
    OutlierPointsDropped {
        /// Number of points left out.
        count: usize,
    },
}

impl Warning {
    /// Whether it reports a repair ([`Repairs`]) rather than something merely noticed.
    pub fn is_repair(&self) -> bool {
        matches!(
            self,
            Warning::VerticesWelded { .. }
                | Warning::PiecesJoined { .. }
                | Warning::SmallPiecesDropped { .. }
                | Warning::SeparateObjectsDropped { .. }
                | Warning::TouchingObjectsLeftOut { .. }
                | Warning::FarVerticesDropped { .. }
                | Warning::OutlierPointsDropped { .. }
        )
    }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Warning::DegenerateFacesDropped { count } => {
                write!(f, "{count} degenerate faces (repeated corner) dropped")
            }
            Warning::DuplicateFacesDropped { count } => {
                write!(f, "{count} duplicate faces dropped")
            }
            Warning::PolygonsTriangulated { count } => {
                write!(f, "{count} polygons with more than 3 corners triangulated")
            }
            Warning::UnreferencedVertices { count } => write!(
                f,
                "{count} vertices are used by no face; they take the values of the nearest used vertex"
            ),
            Warning::DisconnectedPieces { count } => {
                write!(f, "the shape has {count} disconnected pieces")
            }
            Warning::NonManifoldEdges { count } => {
                write!(f, "{count} non-manifold edges (shared by more than two faces)")
            }
            Warning::InconsistentOrientation { edges } => write!(
                f,
                "{edges} edges join faces of opposite orientation (harmless for the Laplacian; re-oriented for the pointwise map)"
            ),
            Warning::NeedleOrZeroAreaFaces { count } => write!(
                f,
                "{count} faces have (near) zero area; the Laplacian mollifies them"
            ),
            Warning::VerticesWelded { count } => write!(
                f,
                "{count} coincident vertices welded (seams or an unwelded export); they share the answer of the vertex they were welded to"
            ),
            Warning::PiecesJoined {
                pieces,
                into,
                bridges,
            } => write!(
                f,
                "{pieces} pieces that come close joined into {into} for matching ({bridges} bridge triangles; the faces are unchanged)"
            ),
            Warning::SmallPiecesDropped { pieces, vertices } => write!(
                f,
                "{pieces} small loose pieces ({vertices} vertices) left out as debris; they take the answer of the nearest kept vertex"
            ),
            Warning::SeparateObjectsDropped { pieces, vertices } => write!(
                f,
                "{pieces} separate object(s) beside the figure ({vertices} vertices, not joined to its largest piece) left out; they take the answer of the nearest kept vertex"
            ),
            Warning::TouchingObjectsLeftOut { pieces, vertices } => write!(
                f,
                "{pieces} object(s) touching the figure ({vertices} vertices) left out: the pair matched better without them; they take the answer of the nearest kept vertex"
            ),
            Warning::TouchingObjectsNotTried { pieces } => write!(
                f,
                "{pieces} object(s) touching the figure kept: the time limit passed before the pair could try without them; raise time_limit_s to try"
            ),
            Warning::FarVerticesDropped { count } => write!(
                f,
                "{count} vertices far from the rest of the shape left out; they take the answer of the nearest kept vertex"
            ),
            Warning::OutlierPointsDropped { count } => write!(
                f,
                "{count} isolated outlier points left out; they take the answer of the nearest kept point"
            ),
        }
    }
}
