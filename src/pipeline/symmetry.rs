//! Symmetry detection: a shape matched to itself (docs/design.md, step 14), through the pair
//! job ([`run_pair`]), so a dense shape runs on its proxy as a pair does.

use crate::colors::{palette, UNMATCHED_COLOR};
use crate::pipeline::pair::{run_pair, PairJob, PairShapes};
use crate::pipeline::Params;
use crate::progress::Progress;
use crate::regions::graph::ShapeGraph;
use crate::shape::{DisjointSets, Shape};
use crate::Result;

/// Symmetric regions of one shape, found by matching the shape to itself.
#[derive(Debug, Clone)]
pub struct Symmetry {
    /// The shape graph; `graph.labels` is the region of every vertex.
    pub graph: ShapeGraph,
    /// Groups of mutually symmetric regions (each sorted; groups sorted by first region).
    /// A region without a symmetric partner forms a group of its own.
    pub groups: Vec<Vec<u32>>,
    /// The self-matches found, `(region, region)`.
    pub matches: Vec<(u32, u32)>,
}

impl Symmetry {
    /// Self-symmetry groups of a shape: the symmetric matches of the shape with itself, with
    /// no one-to-one step and no second HKS try.
    pub fn detect(shape: &Shape, params: &Params, progress: &mut dyn Progress) -> Result<Symmetry> {
        let params = Params {
            skip_one_to_one: true,
            fallback: None,
            ..params.clone()
        };
        let job = PairJob {
            params: &params,
            map: None,
        };
        let pair = run_pair(PairShapes::Itself(shape), job, progress)?.regions;
        let n = pair.graph_a.n_nodes();
        // Union-find over the self-matches; every region is its own group at first.
        let mut sets = DisjointSets::new(n);
        for &(i, j) in &pair.matches {
            sets.union(i as usize, j as usize);
        }
        let mut by_root: std::collections::BTreeMap<usize, Vec<u32>> = Default::default();
        for region in 0..n {
            by_root
                .entry(sets.find(region))
                .or_default()
                .push(region as u32);
        }
        let mut groups: Vec<Vec<u32>> = by_root.into_values().collect();
        groups.sort();
        Ok(Symmetry {
            graph: pair.graph_a,
            groups,
            matches: pair.matches,
        })
    }

    /// Per-vertex colours: the regions of a group of two or more share a colour (one colour
    /// per group), regions without a symmetric partner are [`UNMATCHED_COLOR`].
    pub fn vertex_colors(&self) -> Vec<[u8; 3]> {
        let mut region_colour = vec![UNMATCHED_COLOR; self.graph.n_nodes()];
        for (index, group) in self.groups.iter().filter(|g| g.len() > 1).enumerate() {
            for &region in group {
                region_colour[region as usize] = palette(index);
            }
        }
        self.graph
            .labels
            .iter()
            .map(|&r| region_colour[r as usize])
            .collect()
    }
}
