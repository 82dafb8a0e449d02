//! Colours for looking at results: matched regions share a colour ([`region_colors`]),
//! a map is shown by carrying [`coordinate_colors`] across it.

use crate::shape::DisjointSets;

/// Colours for regions: matched regions share a colour, unmatched regions are dark grey.
/// `pairs` are the matches to colour by; regions connected through matches (a symmetric
/// group) share one colour. Returns per-vertex RGB for A and B.
pub fn region_colors(
    labels_a: &[u32],
    n_a: usize,
    labels_b: &[u32],
    n_b: usize,
    pairs: &[(u32, u32)],
) -> (Vec<[u8; 3]>, Vec<[u8; 3]>) {
    // Union-find over A's regions (0..n_a) and B's regions (n_a..n_a+n_b).
    let mut sets = DisjointSets::new(n_a + n_b);
    for &(i, j) in pairs {
        sets.union(i as usize, n_a + j as usize);
    }
    let mut matched = vec![false; n_a + n_b];
    for &(i, j) in pairs {
        matched[i as usize] = true;
        matched[n_a + j as usize] = true;
    }
    // Number the groups in order of their smallest member, so colours are deterministic.
    let mut group_index = std::collections::BTreeMap::new();
    for (node, &is_matched) in matched.iter().enumerate() {
        if is_matched {
            let root = sets.find(node);
            let next = group_index.len();
            group_index.entry(root).or_insert(next);
        }
    }
    let colour_of = |node: usize, sets: &mut DisjointSets| -> [u8; 3] {
        if matched[node] {
            palette(group_index[&sets.find(node)])
        } else {
            UNMATCHED_COLOR
        }
    };
    let region_colour_a: Vec<[u8; 3]> = (0..n_a).map(|r| colour_of(r, &mut sets)).collect();
    let region_colour_b: Vec<[u8; 3]> = (0..n_b).map(|r| colour_of(n_a + r, &mut sets)).collect();
    (
        labels_a
            .iter()
            .map(|&r| region_colour_a[r as usize])
            .collect(),
        labels_b
            .iter()
            .map(|&r| region_colour_b[r as usize])
            .collect(),
    )
}

/// Colour of unmatched regions (docs/design.md, "Front ends and outputs": dark grey).
pub const UNMATCHED_COLOR: [u8; 3] = [64, 64, 64];

/// The i-th of a sequence of well-separated bright colours (hues stepped by the golden
/// angle, alternating saturation and value so neighbours in the sequence differ).
pub fn palette(i: usize) -> [u8; 3] {
    let hue = (i as f64 * 0.618_033_988_749_895).fract();
    let (s, v) = match i % 3 {
        0 => (0.75, 0.95),
        1 => (0.55, 0.85),
        _ => (0.9, 0.75),
    };
    let h = hue * 6.0;
    let c = v * s;
    let x = c * (1.0 - ((h % 2.0) - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    [r, g, b].map(|t| ((t + m) * 255.0).round() as u8)
}

/// A smooth colour field for looking at maps: each vertex's coordinates normalised to the
/// bounding box, as RGB.
pub fn coordinate_colors(vertices: &[[f64; 3]]) -> Vec<[u8; 3]> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    vertices
        .iter()
        .map(|p| {
            std::array::from_fn(|k| {
                let span = (hi[k] - lo[k]).max(f64::MIN_POSITIVE);
                (((p[k] - lo[k]) / span).clamp(0.0, 1.0) * 255.0).round() as u8
            })
        })
        .collect()
}
