//! The multiresolution path for dense and low-poly shapes (docs/design.md, step 16).
//!
//! Above [`Multiresolution::above`] active vertices a shape is replaced by a proxy of about
//! [`Multiresolution::proxy_vertices`] vertices ([`Proxy::build`]); below
//! [`Multiresolution::refine_below`] a mesh by a refined copy of the same surface of at least
//! that many ([`Proxy::refine`]: every input vertex is one of its vertices). The whole
//! pipeline runs on the working shapes and its answers come back to every input vertex:
//! - regions: every input vertex takes the region of its nearest proxy vertex on the proxy
//!   surface ([`Proxy::lift_nearest`]);
//! - the map: every input vertex of B is located on B's proxy, its three proxy vertices are
//!   mapped to A's proxy, and where their images lie close together the point they span
//!   with the same weights is taken to its nearest input vertex of A (a 3D k-d tree); where
//!   they do not (the map tears there), the image of the heaviest is kept ([`lift_map`]).
//!   An image on A's refined copy is the input vertex of A nearest on the input triangle it
//!   lies on (its heaviest corner, [`Proxy::input_vertex`]).
//!
//! Nothing compares full-resolution vertex sets pairwise: building a proxy and lifting are
//! O(n log n) in the input's vertices, the rest runs on the proxies.

use rayon::prelude::*;

use crate::pipeline::correspondence::Correspondence;
use crate::progress::{polled, Cancel, Progress, Stage};
use crate::shape::neighbors::PointTree;
use crate::shape::proxy::{Proxy, ProxyKind};
use crate::shape::smoothing;
use crate::shape::ShapeKind;
use crate::shape::{distance, ObjectsLeftOut, Shape, Warning};
use crate::spectral::eigen::{check_max_vertices, EigenParams};
use crate::Result;

/// When the pipeline runs on proxies, and how large they are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Multiresolution {
    /// A shape with more active vertices than this gets a proxy (0: never).
    pub above: usize,
    /// About how many vertices a proxy has.
    pub proxy_vertices: usize,
    /// A mesh with fewer active vertices than this runs on a refined copy of at least this
    /// many ([`Proxy::refine`]; 0: never). Point clouds are left as they are, and a shape
    /// above [`Multiresolution::above`] gets a proxy whatever this is.
    pub refine_below: usize,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

/// Default [`Multiresolution::above`]: 1.5 times the proxy's size (below it a proxy would
/// save less than a third of the vertices). FAUST (6.9K), FAUST_r, TOSCA_r and the camel
/// gallop (5K) run at full resolution; TOSCA (15.8K-52.6K) and anything denser on proxies.
pub const DEFAULT_PROXY_ABOVE: usize = 12_000;

/// Default [`Multiresolution::proxy_vertices`]: about the resolution of FAUST (6.9K), where
/// the full-resolution pipeline was measured (docs/results.md).
pub const DEFAULT_PROXY_VERTICES: usize = 8_000;

/// Default [`Multiresolution::refine_below`], chosen on generated figures decimated to 150,
/// 300 and 1,000 vertices (docs/decisions.md, "Low-poly meshes: a refined working mesh"):
/// 300 vertices refined to 4.8K failed 0 of 6 pairs (to 1.2K: 1 of 6, as they are: 4 of 6),
/// and a larger threshold only made the smallest meshes larger and slower (150 vertices
/// refined to 9.6K: 4 of 6 failed). FAUST (6.9K), TOSCA and the 5K figures are above it and run as before.
pub const DEFAULT_REFINE_BELOW: usize = 2_000;

/// The working shape of one input shape, as results report it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Working {
    /// What the pipeline ran on.
    pub kind: WorkingKind,
    /// Its active vertices.
    pub vertices: usize,
    /// Whether its positions were smoothed because the input is a noisy mesh
    /// ([`crate::shape::smoothing`]).
    pub smoothed: bool,
    /// Objects touching the figure that were left out because the pair matched better
    /// without them ([`Shape::without_touching_objects`]); zero when none.
    pub objects_left_out: ObjectsLeftOut,
    /// Pieces touching the figure that the pair could not try leaving out because the
    /// time limit passed first (`time_limit_s`); they were matched as part of it. Zero when
    /// none.
    pub objects_not_tried: usize,
}

/// What the pipeline ran on for one input shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum WorkingKind {
    /// The input shape itself.
    Input,
    /// A simplified proxy of a dense shape ([`Proxy::build`]).
    Proxy,
    /// A refined copy of a low-poly mesh ([`Proxy::refine`]).
    Refined,
}

impl Working {
    /// The pair's warnings about this side: objects touching the figure left out
    /// ([`Working::objects_left_out`]) or not tried ([`Working::objects_not_tried`]).
    pub fn pair_warnings(&self) -> Vec<Warning> {
        let ObjectsLeftOut { pieces, vertices } = self.objects_left_out;
        let left_out = (pieces > 0).then_some(Warning::TouchingObjectsLeftOut { pieces, vertices });
        let pieces = self.objects_not_tried;
        let not_tried = (pieces > 0).then_some(Warning::TouchingObjectsNotTried { pieces });
        left_out.into_iter().chain(not_tried).collect()
    }

    /// The working shape of `shape` with its proxy, if any.
    pub fn of(shape: &Shape, proxy: Option<&Proxy>) -> Working {
        match proxy {
            None => Working {
                kind: WorkingKind::Input,
                vertices: shape.active_vertices().len(),
                smoothed: false,
                objects_left_out: ObjectsLeftOut::default(),
                objects_not_tried: 0,
            },
            Some(p) => Working {
                kind: match p.kind {
                    ProxyKind::Simplified => WorkingKind::Proxy,
                    ProxyKind::Refined => WorkingKind::Refined,
                    ProxyKind::Smoothed => WorkingKind::Input,
                },
                vertices: p.shape.active_vertices().len(),
                smoothed: p.smoothed,
                objects_left_out: ObjectsLeftOut::default(),
                objects_not_tried: 0,
            },
        }
    }
}

impl Default for Multiresolution {
    fn default() -> Self {
        Multiresolution {
            above: DEFAULT_PROXY_ABOVE,
            proxy_vertices: DEFAULT_PROXY_VERTICES,
            refine_below: DEFAULT_REFINE_BELOW,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

impl Multiresolution {
    /// Checks the sizes: a proxy needs at least 64 vertices and fewer than `above`.
    pub fn validate(&self) -> Result<()> {
        if self.above != 0 && (self.proxy_vertices < 64 || self.proxy_vertices >= self.above) {
            return Err(crate::Error::InvalidParameter {
                name: "proxy_vertices",
                reason: format!(
                    "need 64 <= proxy_vertices < proxy_above = {}, got {}",
                    self.above, self.proxy_vertices
                ),
            });
        }
        Ok(())
    }

    /// The vertices `shape` is computed on: its proxy's size, or its own.
    pub fn working_size(&self, shape: &Shape) -> usize {
        self.working_size_of(shape.active_vertices().len())
    }

    /// The vertices a shape of `n` active vertices is computed on (a refined mesh's
    /// estimated: a closed mesh has about three edges per vertex, so a subdivision
    /// quadruples it).
    pub fn working_size_of(&self, n: usize) -> usize {
        if self.above != 0 && n > self.above {
            n.min(self.proxy_vertices)
        } else if n > 0 && n < self.refine_below {
            let mut refined = 4 * n;
            while refined < self.refine_below {
                refined *= 4;
            }
            refined
        } else {
            n
        }
    }

    /// Whether `shape` runs on a proxy (simplified or refined).
    pub fn applies_to(&self, shape: &Shape) -> bool {
        self.kind_for(shape).is_some()
    }

    /// The proxy `shape` gets, if any.
    pub fn kind_for(&self, shape: &Shape) -> Option<ProxyKind> {
        let n = shape.active_vertices().len();
        if self.above != 0 && n > self.above {
            Some(ProxyKind::Simplified)
        } else if n < self.refine_below && shape.kind() == ShapeKind::Mesh {
            Some(ProxyKind::Refined)
        } else {
            None
        }
    }

    /// The proxies of the shapes that need one (None for a shape that runs as it is).
    pub(crate) fn proxies(
        &self,
        [a, b]: [&Shape; 2],
        eigen: &EigenParams,
        progress: &mut dyn Progress,
    ) -> Result<[Option<Proxy>; 2]> {
        check_max_vertices(a, eigen).map_err(|e| e.in_shape('A'))?;
        check_max_vertices(b, eigen).map_err(|e| e.in_shape('B'))?;
        if !self.applies_to(a) && !self.applies_to(b) {
            return Ok([smoothed_if_noisy(a, None), smoothed_if_noisy(b, None)]);
        }
        polled(progress, Stage::Proxy, (0.0, 0.5), |cancel| {
            let proxy_a = self.build(a, cancel).map_err(|e| e.in_shape('A'))?;
            cancel.set_fraction(0.5);
            let proxy_b = self.build(b, cancel).map_err(|e| e.in_shape('B'))?;
            Ok([smoothed_if_noisy(a, proxy_a), smoothed_if_noisy(b, proxy_b)])
        })
    }

    /// The proxy of one shape when it needs one, cancellable like [`Self::proxies`].
    pub(crate) fn proxy_polled(
        &self,
        shape: &Shape,
        eigen: &EigenParams,
        progress: &mut dyn Progress,
    ) -> Result<Option<Proxy>> {
        check_max_vertices(shape, eigen)?;
        if !self.applies_to(shape) {
            return Ok(smoothed_if_noisy(shape, None));
        }
        polled(progress, Stage::Proxy, (0.0, 0.5), |cancel| {
            Ok(smoothed_if_noisy(shape, self.build(shape, cancel)?))
        })
    }

    /// The proxy `shape` needs, if any, before smoothing.
    fn build(&self, shape: &Shape, cancel: &Cancel) -> Result<Option<Proxy>> {
        cancel.check()?;
        match self.kind_for(shape) {
            Some(ProxyKind::Simplified) => {
                Proxy::build_cancellable(shape, self.proxy_vertices, cancel).map(Some)
            }
            Some(ProxyKind::Refined) => {
                Proxy::refine_cancellable(shape, self.refine_below, cancel).map(Some)
            }
            _ => Ok(None),
        }
    }
}

impl Multiresolution {
    /// The proxy of `shape` when it needs one.
    pub(crate) fn proxy(&self, shape: &Shape) -> Result<Option<Proxy>> {
        let proxy = match self.kind_for(shape) {
            Some(ProxyKind::Simplified) => Some(Proxy::build(shape, self.proxy_vertices)?),
            Some(ProxyKind::Refined) => Some(Proxy::refine(shape, self.refine_below)?),
            _ => None,
        };
        Ok(smoothed_if_noisy(shape, proxy))
    }
}

/// The working shape with scanner noise taken out when it is a noisy mesh
/// ([`smoothing::is_noisy`]): a simplified proxy smoothed, or a smoothed copy of a shape that
/// runs as it is. A refined copy of a low-poly mesh is left as it is (three quarters of its
/// edges lie inside a flat input face, so the median angle does not see noise).
fn smoothed_if_noisy(shape: &Shape, proxy: Option<Proxy>) -> Option<Proxy> {
    match proxy {
        Some(p) if p.kind == ProxyKind::Simplified && smoothing::is_noisy(&p.shape) => {
            Some(p.into_smoothed())
        }
        None if smoothing::is_noisy(shape) => Some(Proxy::smoothed_copy(shape)),
        other => other,
    }
}

/// The shape the pipeline runs on: the proxy's, or the shape itself.
pub(crate) fn working<'a>(shape: &'a Shape, proxy: &'a Option<Proxy>) -> &'a Shape {
    proxy.as_ref().map_or(shape, |p| &p.shape)
}

/// The regions' labels of the working shapes brought back to every input vertex.
pub(crate) fn lift_regions(regions: &mut Correspondence, [proxy_a, proxy_b]: [Option<&Proxy>; 2]) {
    for (graph, proxy) in [
        (&mut regions.graph_a, proxy_a),
        (&mut regions.graph_b, proxy_b),
    ] {
        if let Some(proxy) = proxy {
            graph.labels = proxy.lift_nearest(&graph.labels);
        }
    }
}

/// Input vertices per block between cancel checks in [`lift_map`].
const LIFT_BLOCK: usize = 16_384;

/// Images further apart than this many mean proxy edges of A are not interpolated (the map
/// tears between them): the heaviest one's is kept. Not tuned: three edges is a triangle's
/// images spread over about one ring of A's proxy.
const TEAR_EDGES: f64 = 3.0;

/// The map from B's working shape to A's (`p2p_ba`, one A vertex of the working shape per B
/// vertex of the working shape) brought to every input vertex of B, as input vertices of
/// A. See the module docs.
pub(crate) fn lift_map(
    (a, proxy_a): (&Shape, Option<&Proxy>),
    (b, proxy_b): (&Shape, Option<&Proxy>),
    p2p_ba: &[u32],
    progress: &mut dyn Progress,
) -> Result<Vec<u32>> {
    if proxy_a.is_none() && proxy_b.is_none() {
        return Ok(p2p_ba.to_vec());
    }
    polled(progress, Stage::Proxy, (0.5, 1.0), |cancel| {
        lift_map_polling((a, proxy_a), (b, proxy_b), p2p_ba, cancel)
    })
}

/// [`lift_map`] on the calling thread, polling `cancel` between blocks.
fn lift_map_polling(
    (a, proxy_a): (&Shape, Option<&Proxy>),
    (b, proxy_b): (&Shape, Option<&Proxy>),
    p2p_ba: &[u32],
    cancel: &Cancel,
) -> Result<Vec<u32>> {
    let working_a = proxy_a.map_or(a, |p| &p.shape);
    // A proxy vertex of A as an input vertex of A.
    let input_a = |v: u32| proxy_a.map_or(v, |p| p.input_vertex(v));
    let active_a = a.active_vertices();
    let tree = PointTree::new(
        &active_a
            .iter()
            .map(|&v| a.vertices()[v as usize])
            .collect::<Vec<_>>(),
    );
    let tear = TEAR_EDGES * working_a.mean_edge_length();
    let n_b = b.n_vertices();
    let mut out = Vec::with_capacity(n_b);
    for start in (0..n_b).step_by(LIFT_BLOCK) {
        cancel.check()?;
        cancel.set_fraction(start as f32 / n_b as f32);
        let end = (start + LIFT_BLOCK).min(n_b);
        let block: Vec<u32> = (start..end)
            .into_par_iter()
            .map(|v| {
                let Some(proxy_b) = proxy_b else {
                    return input_a(p2p_ba[v]);
                };
                let at = proxy_b.location[v];
                let images = at.vertices.map(|w| input_a(p2p_ba[w as usize]));
                if at.weights[1] <= 0.0 {
                    return images[0];
                }
                let points = images.map(|i| a.vertices()[i as usize]);
                let spread = (0..3)
                    .flat_map(|i| (i + 1..3).map(move |j| (i, j)))
                    .filter(|&(i, j)| at.weights[i] > 0.0 && at.weights[j] > 0.0)
                    .map(|(i, j)| distance(&points[i], &points[j]))
                    .fold(0.0, f64::max);
                if spread > tear {
                    return images[0];
                }
                let point =
                    [0, 1, 2].map(|c| (0..3).map(|i| at.weights[i] * points[i][c]).sum::<f64>());
                active_a[tree.nearest(&point)]
            })
            .collect();
        out.extend(block);
    }
    Ok(out)
}
