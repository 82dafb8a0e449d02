//! Graph matching (paper, section 5.1 "Subspace-based Spectral Matching", and the
//! discretisation after it; docs/design.md, steps 10-11): a symmetric, many-to-many correspondence
//! between the nodes of two [`ShapeGraph`]s from their connectivity alone.
//!
//! Candidates are all node pairs `(i, j)`, `i` on A and `j` on B, indexed row-major
//! `c = i * n_b + j`. The affinity matrix `M` (`n_a n_b` square) holds
//! - on the diagonal the unary affinity `exp(-C(i,j) / sigma)`, with
//!   `C(i,j) = ||H_A(i) - H_B(j)||` and `H` the histogram of hop distances from a node;
//! - off the diagonal, for `i != k` and `j != l`, the pairwise affinity
//!   `exp(-(d_g + d_u) / sigma)`, `d_u = |C(i,j) - C(k,l)|` and `d_g` the
//!   [`DistanceTerm`] between `g_A(i,k)` and `g_B(j,l)`; zero where a distance is unreachable;
//!   the whole off-diagonal part is divided by its number of non-zeros, so that it only
//!   breaks ties inside the subspace the unary term selects.
//!
//! The leading eigenvector of `M` (absolute values) scores every candidate;
//! [`discretise`] turns the scores into matches. `M` is never built: [`Affinity`] applies it
//! from compact tables (`O(n_a^2 n_b^2)` per product, `O(diam_A n_b^2 + n_a n_b)` memory).
//!
//! Why not power iteration: after the scaling the second-order part has norm at most about
//! `1 / (n_a n_b)` (rows of up to `n_a n_b` entries below 1, divided by about `(n_a n_b)^2`),
//! so the eigenvalues inside the top unary cluster, which decide between its candidates,
//! lie only about `1e-7..1e-6` apart at 60 x 60 nodes while the diagonal spreads over
//! `(0, 1]`: power iteration (or plain Lanczos) would need millions of products. The
//! diagonally-preconditioned Davidson method of [`leading_eigenvector`] takes the diagonal
//! out and converges in 5-10 products (FAUST and TOSCA graphs: at most 7); it agrees with a
//! dense eigendecomposition (tested, and to `1e-10` on benchmark graphs).

use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{self_adjoint_evd, self_adjoint_evd_scratch, ComputeEigenvectors};
use faer::{Mat, Par};
use rayon::prelude::*;

use crate::regions::graph::{ShapeGraph, UNREACHABLE};
use crate::{Error, Result};

/// The graph-distance term `d_g` of the pairwise affinity, between the hop distance
/// `a = g_A(i,k)` and `b = g_B(j,l)` (both at least 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DistanceTerm {
    /// `|a - b|` (paper, section 5.1).
    Difference,
    /// `max(a, b) / min(a, b) - 1` (the authors' 2018 code, `GenerateSecondOrder.m`):
    /// a difference of one hop costs less between far nodes than between near ones.
    Ratio,
}

impl DistanceTerm {
    /// `d_g(a, b)` for hop distances `a, b >= 1`.
    pub fn eval(self, a: u32, b: u32) -> f64 {
        let (lo, hi) = (a.min(b) as f64, a.max(b) as f64);
        match self {
            DistanceTerm::Difference => hi - lo,
            DistanceTerm::Ratio => hi / lo - 1.0,
        }
    }
}

/// Parameters of the graph matching (paper, section 5.1; docs/design.md, steps 10-11).
#[derive(Debug, Clone, PartialEq)]
pub struct MatchingParams {
    /// Bandwidth of every affinity `exp(-d / sigma)`. Paper: 0.5. (The authors' code
    /// computes `exp(-d * 0.5)`, i.e. a bandwidth of 2 in this convention.)
    pub sigma: f64,
    /// Number of hop-distance histogram bins; bin `b` (0-based) counts the nodes at hop
    /// distance `b + 1`, farther nodes are clamped into the last bin. Authors: 20.
    pub histogram_bins: usize,
    /// Divide every histogram by `n - 1` (fractions of the other nodes instead of counts).
    /// Default `false` (counts, as the paper and the authors' code): measured better on
    /// FAUST (126 pairs: symmetric accuracy 0.930 vs 0.927) and remeshed TOSCA (155 pairs:
    /// 0.860 vs 0.858), and on synthetic graphs that gain or lose a node (fraction of nodes
    /// matched 0.90 vs 0.75 after splitting an edge, equal precision); see
    /// `tests/it/matching.rs`, `measure_variants*`.
    pub normalise_histograms: bool,
    /// Discretisation gap: a sorted score below `gap_ratio` times the previous one ends a
    /// node's matches (0: only a zero score does). Paper: 0.9 (authors' code: 0.95).
    pub gap_ratio: f64,
    /// At most this many matches per node (symmetric groups); a node whose gap comes later
    /// stays unmatched. Paper: 8 (authors' code: 10).
    pub max_symmetry_order: usize,
    /// The graph-distance term of the pairwise affinity. Default
    /// [`DistanceTerm::Difference`] (paper): with everything else fixed it measured level
    /// with or slightly above the authors' ratio (symmetric / one-to-one-with-flip region
    /// accuracy, FAUST 126 pairs 0.930 / 0.923 vs 0.929 / 0.923; remeshed TOSCA 155 pairs
    /// 0.860 / 0.853 vs 0.857 / 0.851; per pair they differ on about 1 pair in 10, both
    /// ways). `tests/it/matching.rs`, `measure_variants_on_benchmark_pairs`.
    pub distance_term: DistanceTerm,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for MatchingParams {
    fn default() -> Self {
        MatchingParams {
            sigma: 0.5,
            histogram_bins: 20,
            normalise_histograms: false,
            gap_ratio: 0.9,
            max_symmetry_order: 8,
            distance_term: DistanceTerm::Difference,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

impl MatchingParams {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<()> {
        if !(self.sigma > 0.0 && self.sigma.is_finite()) {
            return Err(invalid(
                "sigma",
                format!("must be positive and finite, got {}", self.sigma),
            ));
        }
        if self.histogram_bins == 0 {
            return Err(invalid(
                "histogram_bins",
                "must be at least 1, got 0".into(),
            ));
        }
        if !(0.0..=1.0).contains(&self.gap_ratio) {
            return Err(invalid(
                "gap_ratio",
                format!("must be in [0, 1], got {}", self.gap_ratio),
            ));
        }
        if self.max_symmetry_order == 0 {
            return Err(invalid(
                "max_symmetry_order",
                "must be at least 1, got 0".into(),
            ));
        }
        Ok(())
    }
}

fn invalid(name: &'static str, reason: String) -> Error {
    Error::InvalidParameter { name, reason }
}

/// The symmetric correspondence between two graphs.
#[derive(Debug, Clone, PartialEq)]
pub struct GraphMatching {
    /// Matched node pairs `(node of A, node of B)`, many-to-many (symmetric groups), sorted.
    pub matches: Vec<(u32, u32)>,
    /// Leading-eigenvector entry (absolute value) of every candidate, row-major
    /// (`i * n_b + j`).
    pub scores: Vec<f64>,
}

/// Matches the nodes of two shape graphs (paper, section 5.1; docs/design.md, steps 10-11).
///
/// Errors: invalid parameters, a graph without nodes, or edges naming missing nodes.
pub fn match_graphs(
    a: &ShapeGraph,
    b: &ShapeGraph,
    params: &MatchingParams,
) -> Result<GraphMatching> {
    params.validate()?;
    check_graph(a, "a")?;
    check_graph(b, "b")?;
    match_hop_distances(&a.hop_distances(), &b.hop_distances(), params)
}

fn check_graph(g: &ShapeGraph, name: &'static str) -> Result<()> {
    let n = g.n_nodes();
    if n == 0 {
        return Err(invalid(name, "the graph has no nodes".into()));
    }
    if let Some(&(i, j)) = g
        .edges
        .iter()
        .find(|&&(i, j)| i as usize >= n || j as usize >= n)
    {
        return Err(invalid(
            name,
            format!("edge ({i}, {j}) names a node beyond the graph's {n} nodes"),
        ));
    }
    Ok(())
}

/// [`match_graphs`] from the two hop-distance matrices (as [`ShapeGraph::hop_distances`]
/// returns them: square, zero diagonal, [`UNREACHABLE`] between components).
pub fn match_hop_distances(
    hops_a: &[Vec<u32>],
    hops_b: &[Vec<u32>],
    params: &MatchingParams,
) -> Result<GraphMatching> {
    params.validate()?;
    let (n_a, n_b) = (hops_a.len(), hops_b.len());
    let hist_a = distance_histograms(hops_a, params.histogram_bins, params.normalise_histograms);
    let hist_b = distance_histograms(hops_b, params.histogram_bins, params.normalise_histograms);
    let costs = unary_costs(&hist_a, &hist_b);
    let affinity = Affinity::new(hops_a, hops_b, &costs, params.sigma, params.distance_term)?;
    let eigen = leading_eigenvector(&affinity)?;
    let matches = discretise(
        &eigen.vector,
        n_a,
        n_b,
        params.gap_ratio,
        params.max_symmetry_order,
    );
    Ok(GraphMatching {
        matches,
        scores: eigen.vector,
    })
}

/// Hop-distance histogram `H(i)` of every node (paper, eq. before (1)): entry `b` counts the
/// nodes at hop distance `b + 1` from `i`, distances beyond `bins` counting in the last
/// entry; the node itself and unreachable nodes are not counted. With `normalise`, counts
/// are divided by `n - 1`.
pub fn distance_histograms(hops: &[Vec<u32>], bins: usize, normalise: bool) -> Vec<Vec<f64>> {
    let n = hops.len();
    let norm = if normalise && n > 1 {
        1.0 / (n - 1) as f64
    } else {
        1.0
    };
    hops.iter()
        .map(|row| {
            let mut h = vec![0.0; bins];
            if bins == 0 {
                return h;
            }
            for &d in row {
                if d != 0 && d != UNREACHABLE {
                    h[(d as usize).min(bins) - 1] += norm;
                }
            }
            h
        })
        .collect()
}

/// Unary costs `C(i,j) = ||H_A(i) - H_B(j)||_2`, row-major (`i * n_b + j`); histograms of
/// different lengths are compared as if padded with zeros.
pub fn unary_costs(hist_a: &[Vec<f64>], hist_b: &[Vec<f64>]) -> Vec<f64> {
    let mut costs = Vec::with_capacity(hist_a.len() * hist_b.len());
    for ha in hist_a {
        for hb in hist_b {
            let len = ha.len().max(hb.len());
            let sq: f64 = (0..len)
                .map(|t| {
                    let d = ha.get(t).copied().unwrap_or(0.0) - hb.get(t).copied().unwrap_or(0.0);
                    d * d
                })
                .sum();
            costs.push(sq.sqrt());
        }
    }
    costs
}

/// Largest exponent `(C_max - C_min) / (2 sigma)` for which the factored kernel
/// `exp(-|C_p - C_q| / sigma) = min(e^{-x_p} e^{x_q}, e^{x_p} e^{-x_q})` (with
/// `x = (C - C_mid) / sigma`) stays inside the range of f64; beyond it the kernel is
/// evaluated with one `exp` per entry.
const MAX_FACTORED_EXPONENT: f64 = 300.0;

/// The affinity matrix `M` of the spectral matching, held in compact form and applied
/// implicitly (see the module docs).
#[derive(Debug, Clone)]
pub struct Affinity {
    n_a: usize,
    n_b: usize,
    /// `g_A(i,k)`, row-major `n_a x n_a`.
    hops_a: Vec<u32>,
    /// `g_B(j,l)`, row-major `n_b x n_b`.
    hops_b: Vec<u32>,
    costs: Vec<f64>,
    diagonal: Vec<f64>,
    /// For hop distance `a = 1..=max_a` on A: `exp(-d_g(a, g_B(j,l)) / sigma)` at
    /// `(a - 1) n_b^2 + j n_b + l`, zero where `j == l` or `g_B(j,l)` is unreachable.
    pair_table: Vec<f64>,
    /// `exp(+-(C - C_mid) / sigma)` per candidate (factored kernel), empty when not used.
    up: Vec<f64>,
    down: Vec<f64>,
    sigma: f64,
    distance_term: DistanceTerm,
    nonzeros: u64,
    scale: f64,
}

impl Affinity {
    /// The affinity of the candidates of two graphs, from their hop distances and the unary
    /// costs (row-major, `n_a * n_b`).
    pub fn new(
        hops_a: &[Vec<u32>],
        hops_b: &[Vec<u32>],
        costs: &[f64],
        sigma: f64,
        distance_term: DistanceTerm,
    ) -> Result<Affinity> {
        let (n_a, n_b) = (hops_a.len(), hops_b.len());
        if n_a == 0 || n_b == 0 {
            return Err(invalid(
                "graphs",
                format!("both graphs need nodes, got {n_a} and {n_b}"),
            ));
        }
        for (name, hops) in [("hops_a", hops_a), ("hops_b", hops_b)] {
            let n = hops.len();
            if let Some(i) = (0..n).find(|&i| hops[i].len() != n || hops[i][i] != 0) {
                return Err(invalid(
                    name,
                    format!("row {i} of the {n} x {n} distance matrix has length {} or a non-zero diagonal", hops[i].len()),
                ));
            }
        }
        if costs.len() != n_a * n_b || costs.iter().any(|c| !c.is_finite()) {
            return Err(invalid(
                "costs",
                format!(
                    "need {} finite unary costs ({n_a} x {n_b}), got {}",
                    n_a * n_b,
                    costs.len()
                ),
            ));
        }
        if !(sigma > 0.0 && sigma.is_finite()) {
            return Err(invalid(
                "sigma",
                format!("must be positive and finite, got {sigma}"),
            ));
        }
        let flat_a: Vec<u32> = hops_a.iter().flatten().copied().collect();
        let flat_b: Vec<u32> = hops_b.iter().flatten().copied().collect();
        let reachable_pairs =
            |flat: &[u32]| flat.iter().filter(|&&d| d != 0 && d != UNREACHABLE).count() as u64;
        // Structural non-zeros: every (i,k), (j,l) pair with i != k, j != l, both reachable
        // (entries that underflow to zero are counted too).
        let nonzeros = reachable_pairs(&flat_a) * reachable_pairs(&flat_b);
        let scale = if nonzeros > 0 {
            1.0 / nonzeros as f64
        } else {
            0.0
        };
        let max_a = flat_a
            .iter()
            .filter(|&&d| d != UNREACHABLE)
            .max()
            .copied()
            .unwrap_or(0) as usize;
        let nb2 = n_b * n_b;
        let mut pair_table = vec![0.0; max_a * nb2];
        for a in 1..=max_a {
            let block = &mut pair_table[(a - 1) * nb2..a * nb2];
            for (entry, &b) in block.iter_mut().zip(&flat_b) {
                if b != 0 && b != UNREACHABLE {
                    *entry = (-distance_term.eval(a as u32, b) / sigma).exp();
                }
            }
        }
        let diagonal: Vec<f64> = costs.iter().map(|c| (-c / sigma).exp()).collect();
        let (lo, hi) = costs
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &c| {
                (lo.min(c), hi.max(c))
            });
        let (up, down) = if (hi - lo) / (2.0 * sigma) <= MAX_FACTORED_EXPONENT {
            let mid = 0.5 * (lo + hi);
            (
                costs.iter().map(|c| ((c - mid) / sigma).exp()).collect(),
                costs.iter().map(|c| (-(c - mid) / sigma).exp()).collect(),
            )
        } else {
            (Vec::new(), Vec::new())
        };
        Ok(Affinity {
            n_a,
            n_b,
            hops_a: flat_a,
            hops_b: flat_b,
            costs: costs.to_vec(),
            diagonal,
            pair_table,
            up,
            down,
            sigma,
            distance_term,
            nonzeros,
            scale,
        })
    }

    /// Number of candidates `n_a * n_b` (the matrix is that square).
    pub fn dim(&self) -> usize {
        self.n_a * self.n_b
    }

    /// Node counts `(n_a, n_b)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.n_a, self.n_b)
    }

    /// The unary affinities `exp(-C / sigma)` (the diagonal).
    pub fn diagonal(&self) -> &[f64] {
        &self.diagonal
    }

    /// Number of (structurally) non-zero off-diagonal entries.
    pub fn nonzeros(&self) -> u64 {
        self.nonzeros
    }

    /// The factor `1 / nonzeros` applied to the off-diagonal part.
    pub fn off_diagonal_scale(&self) -> f64 {
        self.scale
    }

    /// One entry `M[p][q]`, evaluated from the formula (for tests and small problems).
    pub fn entry(&self, p: usize, q: usize) -> f64 {
        if p == q {
            return self.diagonal[p];
        }
        let (i, j, k, l) = (p / self.n_b, p % self.n_b, q / self.n_b, q % self.n_b);
        if i == k || j == l {
            return 0.0;
        }
        let (a, b) = (self.hops_a[i * self.n_a + k], self.hops_b[j * self.n_b + l]);
        if a == UNREACHABLE || b == UNREACHABLE {
            return 0.0;
        }
        let d_g = self.distance_term.eval(a, b);
        let d_u = (self.costs[p] - self.costs[q]).abs();
        self.scale * (-(d_g + d_u) / self.sigma).exp()
    }

    /// `y = M x`. Each entry of `y` is summed in a fixed order, so the result does not
    /// depend on the number of threads.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        assert_eq!(
            x.len(),
            self.dim(),
            "Affinity::apply: x has the wrong length"
        );
        assert_eq!(
            y.len(),
            self.dim(),
            "Affinity::apply: y has the wrong length"
        );
        let factored = !self.up.is_empty();
        y.par_chunks_mut(self.n_b)
            .enumerate()
            .for_each(|(i, y_row)| {
                if factored {
                    self.apply_row::<true>(i, x, y_row)
                } else {
                    self.apply_row::<false>(i, x, y_row)
                }
            });
    }

    /// Rows `(i, 0..n_b)` of `M x`.
    fn apply_row<const FACTORED: bool>(&self, i: usize, x: &[f64], y_row: &mut [f64]) {
        let (n_a, n_b) = (self.n_a, self.n_b);
        let nb2 = n_b * n_b;
        for (j, y) in y_row.iter_mut().enumerate() {
            let p = i * n_b + j;
            let mut acc = 0.0;
            for k in 0..n_a {
                let a = self.hops_a[i * n_a + k];
                if a == 0 || a == UNREACHABLE {
                    continue;
                }
                let weights = &self.pair_table[(a as usize - 1) * nb2 + j * n_b..][..n_b];
                let base = k * n_b;
                let xs = &x[base..base + n_b];
                acc += if FACTORED {
                    factored_sum(
                        weights,
                        &self.up[base..base + n_b],
                        &self.down[base..base + n_b],
                        xs,
                        self.up[p],
                        self.down[p],
                    )
                } else {
                    let cp = self.costs[p];
                    let inv_sigma = 1.0 / self.sigma;
                    let cs = &self.costs[base..base + n_b];
                    (0..n_b)
                        .map(|l| weights[l] * (-(cp - cs[l]).abs() * inv_sigma).exp() * xs[l])
                        .sum()
                };
            }
            *y = self.diagonal[p] * x[p] + self.scale * acc;
        }
    }
}

/// `sum_l w_l min(down_p up_l, up_p down_l) x_l` in four fixed lanes (vectorisable,
/// deterministic).
#[inline]
fn factored_sum(w: &[f64], up: &[f64], down: &[f64], x: &[f64], up_p: f64, down_p: f64) -> f64 {
    let n = w.len();
    let (up, down, x) = (&up[..n], &down[..n], &x[..n]);
    let term = |l: usize| {
        let e1 = down_p * up[l];
        let e2 = up_p * down[l];
        w[l] * (if e1 < e2 { e1 } else { e2 }) * x[l]
    };
    let mut lanes = [0.0f64; 4];
    let full = n / 4 * 4;
    for s in (0..full).step_by(4) {
        for (t, lane) in lanes.iter_mut().enumerate() {
            *lane += term(s + t);
        }
    }
    for (lane, l) in lanes.iter_mut().zip(full..n) {
        *lane += term(l);
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
}

/// The leading eigenpair of an [`Affinity`] and how it was reached.
#[derive(Debug, Clone, PartialEq)]
pub struct LeadingEigenvector {
    /// Largest eigenvalue.
    pub value: f64,
    /// Its unit eigenvector, entries in absolute value (Perron vector), row-major.
    pub vector: Vec<f64>,
    /// Final residual `||M v - value v||` of the signed vector.
    pub residual: f64,
    /// Matrix products used.
    pub products: usize,
    /// Whether the residual reached [`EIGEN_TOLERANCE`] (otherwise the best vector is
    /// returned after [`EIGEN_MAX_PRODUCTS`] products).
    pub converged: bool,
}

/// Residual tolerance, relative to the eigenvalue (about 1). The eigenvector error is about
/// the residual over the gap to the next eigenvalue, which can be `1e-7` at 60 x 60 nodes
/// (module docs): `1e-13` keeps the scores accurate to about `1e-6`, far below the 10%
/// discretisation gap, and is still well above rounding (about `1e-15`).
pub const EIGEN_TOLERANCE: f64 = 1e-13;
/// Most matrix products before the eigensolver gives up (and returns its best vector).
pub const EIGEN_MAX_PRODUCTS: usize = 400;
/// Largest Davidson basis before a restart.
const DAVIDSON_MAX_BASIS: usize = 24;
/// Ritz vectors kept at a restart (thick restart).
const DAVIDSON_KEEP: usize = 4;
/// Candidates whose unary affinity is within this relative distance of the largest form the
/// start vector (the top cluster).
const START_CLUSTER_TOLERANCE: f64 = 1e-12;

/// Leading eigenvector of `M` by the Davidson method with the diagonal preconditioner
/// `(theta - diag(M))^{-1}`, thick restarts, a fixed start (the indicator of the candidates
/// with the largest unary affinity) and fixed tolerances: deterministic, whatever the
/// number of threads. Returns absolute values.
pub fn leading_eigenvector(op: &Affinity) -> Result<LeadingEigenvector> {
    let n = op.dim();
    let diag = op.diagonal();
    let d_max = diag.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut start: Vec<f64> = diag
        .iter()
        .map(|&d| {
            if d >= d_max - START_CLUSTER_TOLERANCE * d_max.abs() {
                1.0
            } else {
                0.0
            }
        })
        .collect();
    normalise(&mut start);

    let mut basis: Vec<Vec<f64>> = Vec::with_capacity(DAVIDSON_MAX_BASIS);
    let mut images: Vec<Vec<f64>> = Vec::with_capacity(DAVIDSON_MAX_BASIS);
    // Projected matrix V^T M V, row-major, DAVIDSON_MAX_BASIS square.
    let mut projected = vec![0.0; DAVIDSON_MAX_BASIS * DAVIDSON_MAX_BASIS];
    let mut products = 0;
    let mut next = start;
    let mut best;
    loop {
        // Add `next` (orthonormal to the basis) and its image.
        let mut image = vec![0.0; n];
        op.apply(&next, &mut image);
        products += 1;
        let m = basis.len();
        for (r, v) in basis.iter().enumerate() {
            let h = dot(v, &image);
            projected[r * DAVIDSON_MAX_BASIS + m] = h;
            projected[m * DAVIDSON_MAX_BASIS + r] = h;
        }
        projected[m * DAVIDSON_MAX_BASIS + m] = dot(&next, &image);
        basis.push(next);
        images.push(image);
        let m = basis.len();

        // Rayleigh-Ritz.
        let (values, vectors) = small_eigen(&projected, m, DAVIDSON_MAX_BASIS)?;
        let theta = values[m - 1];
        let coefficients: Vec<f64> = (0..m).map(|r| vectors[(r, m - 1)]).collect();
        let u = combine(&basis, &coefficients);
        let mu = combine(&images, &coefficients);
        let residual_vec: Vec<f64> = mu.iter().zip(&u).map(|(a, b)| a - theta * b).collect();
        let residual = dot(&residual_vec, &residual_vec).sqrt();
        let converged = residual <= EIGEN_TOLERANCE * theta.abs().max(f64::MIN_POSITIVE);
        best = LeadingEigenvector {
            value: theta,
            vector: u,
            residual,
            products,
            converged,
        };
        if converged || products >= EIGEN_MAX_PRODUCTS {
            break;
        }

        // Thick restart: keep the top Ritz vectors.
        if m == DAVIDSON_MAX_BASIS {
            let keep = DAVIDSON_KEEP.min(m);
            let mut new_basis = Vec::with_capacity(DAVIDSON_MAX_BASIS);
            let mut new_images = Vec::with_capacity(DAVIDSON_MAX_BASIS);
            for t in 0..keep {
                let col = m - 1 - t;
                let c: Vec<f64> = (0..m).map(|r| vectors[(r, col)]).collect();
                new_basis.push(combine(&basis, &c));
                new_images.push(combine(&images, &c));
            }
            projected.iter_mut().for_each(|h| *h = 0.0);
            for r in 0..keep {
                for s in 0..keep {
                    projected[r * DAVIDSON_MAX_BASIS + s] = dot(&new_basis[r], &new_images[s]);
                }
            }
            symmetrise(&mut projected, keep, DAVIDSON_MAX_BASIS);
            basis = new_basis;
            images = new_images;
        }

        // Preconditioned correction (theta - D)^{-1} r, guarded where theta meets D.
        let guard = 16.0 * f64::EPSILON * theta.abs().max(1.0);
        let mut correction: Vec<f64> = residual_vec
            .iter()
            .zip(diag)
            .map(|(r, d)| r / (theta - d).max(guard))
            .collect();
        if !orthonormalise(&mut correction, &basis) {
            // The preconditioned direction is already spanned: fall back to the residual.
            correction = residual_vec;
            if !orthonormalise(&mut correction, &basis) {
                break;
            }
        }
        next = correction;
    }
    best.vector.iter_mut().for_each(|v| *v = v.abs());
    if !best.value.is_finite() || best.vector.iter().any(|v| !v.is_finite()) {
        return Err(Error::Numerical {
            stage: "graph matching eigenvector",
            reason: "the eigensolver produced non-finite values".into(),
        });
    }
    Ok(best)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn normalise(v: &mut [f64]) {
    let norm = dot(v, v).sqrt();
    if norm > 0.0 {
        v.iter_mut().for_each(|x| *x /= norm);
    }
}

fn combine(vectors: &[Vec<f64>], coefficients: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; vectors[0].len()];
    for (v, &c) in vectors.iter().zip(coefficients) {
        out.iter_mut().zip(v).for_each(|(o, x)| *o += c * x);
    }
    out
}

fn symmetrise(h: &mut [f64], m: usize, stride: usize) {
    for r in 0..m {
        for s in r + 1..m {
            let avg = 0.5 * (h[r * stride + s] + h[s * stride + r]);
            h[r * stride + s] = avg;
            h[s * stride + r] = avg;
        }
    }
}

/// Orthogonalises `v` against the orthonormal `basis` (classical Gram-Schmidt, twice) and
/// normalises it; false when nothing independent is left.
fn orthonormalise(v: &mut [f64], basis: &[Vec<f64>]) -> bool {
    let before = dot(v, v).sqrt();
    if !(before > 0.0) || !before.is_finite() {
        return false;
    }
    for _ in 0..2 {
        let coefficients: Vec<f64> = basis.iter().map(|b| dot(b, v)).collect();
        for (b, c) in basis.iter().zip(coefficients) {
            v.iter_mut().zip(b).for_each(|(x, y)| *x -= c * y);
        }
    }
    let after = dot(v, v).sqrt();
    if !(after > 1e-10 * before) {
        return false;
    }
    v.iter_mut().for_each(|x| *x /= after);
    true
}

/// Eigen-decomposition of the leading `m x m` block of a row-major symmetric matrix with
/// row stride `stride`, sequential (deterministic); ascending eigenvalues.
fn small_eigen(h: &[f64], m: usize, stride: usize) -> Result<(Vec<f64>, Mat<f64>)> {
    let a = Mat::from_fn(m, m, |r, s| 0.5 * (h[r * stride + s] + h[s * stride + r]));
    let mut s = Diag::<f64>::zeros(m);
    let mut u = Mat::<f64>::zeros(m, m);
    let par = Par::Seq;
    let params = Default::default();
    let mut mem = MemBuffer::new(self_adjoint_evd_scratch::<f64>(
        m,
        ComputeEigenvectors::Yes,
        par,
        params,
    ));
    self_adjoint_evd(
        a.as_ref(),
        s.as_mut(),
        Some(u.as_mut()),
        par,
        MemStack::new(&mut mem),
        params,
    )
    .map_err(|e| Error::Numerical {
        stage: "graph matching eigenvector (Rayleigh-Ritz)",
        reason: format!("{e:?}"),
    })?;
    let values = (0..m).map(|r| s[r]).collect();
    Ok((values, u))
}

/// Sorts one node's `(score, index)` candidates high to low (ties by index) and returns how
/// many come before the cut of [`discretise`]; None when no score is positive.
fn list_length(values: &mut [(f64, usize)], gap_ratio: f64) -> Option<usize> {
    values.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    if values.is_empty() || !(values[0].0 > 0.0) {
        return None;
    }
    let cut = (1..values.len())
        .find(|&t| !(values[t].0 >= gap_ratio * values[t - 1].0) || !(values[t].0 > 0.0))
        .unwrap_or(values.len());
    Some(cut)
}

/// The nodes of A and of B whose candidate list in [`discretise`] is longer than
/// `max_symmetry_order` (they stay unmatched): when no match is left, the parameters to
/// change are `gap_ratio` and `max_symmetry_order` if these are many.
pub fn overlong_lists(
    scores: &[f64],
    (n_a, n_b): (usize, usize),
    gap_ratio: f64,
    max_symmetry_order: usize,
) -> usize {
    let overlong = |values: &mut Vec<(f64, usize)>| {
        list_length(values, gap_ratio).is_some_and(|cut| cut > max_symmetry_order)
    };
    let mut values = Vec::with_capacity(n_a.max(n_b));
    let mut count = 0;
    for i in 0..n_a {
        values.clear();
        values.extend((0..n_b).map(|j| (scores[i * n_b + j], j)));
        count += usize::from(overlong(&mut values));
    }
    for j in 0..n_b {
        values.clear();
        values.extend((0..n_a).map(|i| (scores[i * n_b + j], i)));
        count += usize::from(overlong(&mut values));
    }
    count
}

/// Discretisation (paper, end of section 5.1; docs/design.md, step 11). For every node of A, its
/// scores over B sorted high to low (ties by index) are cut before the first value below
/// `gap_ratio` times the previous one (the end of the row counts as a cut; a zero score
/// always cuts); the node keeps the candidates before the cut if they are at most
/// `max_symmetry_order`, and none otherwise. The same for every node of B over A; the result
/// is the matches chosen both ways, sorted.
pub fn discretise(
    scores: &[f64],
    n_a: usize,
    n_b: usize,
    gap_ratio: f64,
    max_symmetry_order: usize,
) -> Vec<(u32, u32)> {
    assert_eq!(
        scores.len(),
        n_a * n_b,
        "discretise: scores must be n_a * n_b"
    );
    let pick = |values: &mut Vec<(f64, usize)>| -> Vec<usize> {
        match list_length(values, gap_ratio) {
            Some(cut) if cut <= max_symmetry_order => values[..cut].iter().map(|v| v.1).collect(),
            _ => Vec::new(),
        }
    };
    let mut from_a = vec![false; n_a * n_b];
    let mut values = Vec::with_capacity(n_a.max(n_b));
    for i in 0..n_a {
        values.clear();
        values.extend((0..n_b).map(|j| (scores[i * n_b + j], j)));
        for j in pick(&mut values) {
            from_a[i * n_b + j] = true;
        }
    }
    let mut matches = Vec::new();
    let mut both = vec![false; n_a * n_b];
    for j in 0..n_b {
        values.clear();
        values.extend((0..n_a).map(|i| (scores[i * n_b + j], i)));
        for i in pick(&mut values) {
            if from_a[i * n_b + j] {
                both[i * n_b + j] = true;
            }
        }
    }
    for i in 0..n_a {
        for j in 0..n_b {
            if both[i * n_b + j] {
                matches.push((i as u32, j as u32));
            }
        }
    }
    matches
}

/// Connected components of the bipartite graph of matches (symmetric groups): for every
/// component with at least one match, its nodes of A and of B, ascending; components ordered
/// by their smallest node of A. Unmatched nodes belong to no group.
///
/// Panics if a match names a node `>= n_a` (or `>= n_b`).
pub fn symmetry_groups(
    matches: &[(u32, u32)],
    n_a: usize,
    n_b: usize,
) -> Vec<(Vec<u32>, Vec<u32>)> {
    // Union-find over A nodes 0..n_a and B nodes n_a..n_a + n_b.
    let mut parent: Vec<usize> = (0..n_a + n_b).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    let mut matched = vec![false; n_a + n_b];
    for &(i, j) in matches {
        let (i, j) = (i as usize, j as usize);
        assert!(
            i < n_a && j < n_b,
            "symmetry_groups: match ({i}, {j}) out of range ({n_a} x {n_b})"
        );
        matched[i] = true;
        matched[n_a + j] = true;
        let (ri, rj) = (find(&mut parent, i), find(&mut parent, n_a + j));
        if ri != rj {
            let (lo, hi) = (ri.min(rj), ri.max(rj));
            parent[hi] = lo;
        }
    }
    // Roots are the smallest member (always an A node for a matched component).
    let mut groups: Vec<(Vec<u32>, Vec<u32>)> = Vec::new();
    let mut group_of_root = vec![usize::MAX; n_a + n_b];
    for (x, &is_matched) in matched.iter().enumerate() {
        if !is_matched {
            continue;
        }
        let root = find(&mut parent, x);
        if group_of_root[root] == usize::MAX {
            group_of_root[root] = groups.len();
            groups.push((Vec::new(), Vec::new()));
        }
        let g = &mut groups[group_of_root[root]];
        if x < n_a {
            g.0.push(x as u32);
        } else {
            g.1.push((x - n_a) as u32);
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Side;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn graph(n: usize, edges: &[(u32, u32)]) -> ShapeGraph {
        let mut edges: Vec<(u32, u32)> = edges.iter().map(|&(i, j)| (i.min(j), i.max(j))).collect();
        edges.sort_unstable();
        edges.dedup();
        ShapeGraph {
            labels: vec![],
            node_cluster: vec![0; n],
            node_area: vec![1.0 / n as f64; n],
            node_descriptor: vec![vec![]; n],
            edges,
        }
    }

    /// A random tree on `n` nodes plus `extra` random edges (seeded).
    fn random_graph(n: usize, extra: usize, seed: u64) -> ShapeGraph {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut edges = Vec::new();
        for v in 1..n {
            edges.push((rng.random_range(0..v) as u32, v as u32));
        }
        for _ in 0..extra {
            let (x, y) = (rng.random_range(0..n) as u32, rng.random_range(0..n) as u32);
            if x != y {
                edges.push((x, y));
            }
        }
        graph(n, &edges)
    }

    fn affinity(a: &ShapeGraph, b: &ShapeGraph, params: &MatchingParams) -> Affinity {
        let (ha, hb) = (a.hop_distances(), b.hop_distances());
        let costs = unary_costs(
            &distance_histograms(&ha, params.histogram_bins, params.normalise_histograms),
            &distance_histograms(&hb, params.histogram_bins, params.normalise_histograms),
        );
        Affinity::new(&ha, &hb, &costs, params.sigma, params.distance_term).unwrap()
    }

    fn dense(op: &Affinity) -> Mat<f64> {
        let n = op.dim();
        Mat::from_fn(n, n, |p, q| op.entry(p, q))
    }

    #[test]
    fn histograms_count_hops_and_clamp_into_the_last_bin() {
        let path = graph(5, &[(0, 1), (1, 2), (2, 3), (3, 4)]);
        let hops = path.hop_distances();
        let h = distance_histograms(&hops, 2, false);
        assert_eq!(h[0], vec![1.0, 3.0]);
        assert_eq!(h[2], vec![2.0, 2.0]);
        let h = distance_histograms(&hops, 20, true);
        assert_eq!(&h[0][..5], &[0.25, 0.25, 0.25, 0.25, 0.0]);
        // Unreachable nodes are not counted.
        let split = graph(4, &[(0, 1), (2, 3)]);
        assert_eq!(
            distance_histograms(&split.hop_distances(), 3, false)[0],
            vec![1.0, 0.0, 0.0]
        );
        let c = unary_costs(&[vec![1.0, 3.0]], &[vec![1.0, 1.0], vec![4.0, 7.0]]);
        assert_eq!(c, vec![2.0, 5.0]);
    }

    #[test]
    fn distance_terms() {
        for (a, b) in [(2, 5), (5, 2)] {
            assert_eq!(DistanceTerm::Difference.eval(a, b), 3.0);
            assert_eq!(DistanceTerm::Ratio.eval(a, b), 1.5);
        }
        assert_eq!(DistanceTerm::Ratio.eval(4, 4), 0.0);
    }

    #[test]
    fn implicit_product_equals_the_formula_both_kernels_and_terms() {
        for (seed, term, sigma) in [
            (1, DistanceTerm::Difference, 0.5),
            (2, DistanceTerm::Ratio, 0.5),
            (3, DistanceTerm::Ratio, 1e-3), // exponent range too large: direct kernel
        ] {
            let a = random_graph(7, 3, seed);
            // B has two components: unreachable pairs must be zero.
            let mut b = random_graph(6, 2, seed + 10);
            b.edges.retain(|&(i, j)| (i < 3) == (j < 3));
            let params = MatchingParams {
                sigma,
                distance_term: term,
                ..Default::default()
            };
            let op = affinity(&a, &b, &params);
            assert_eq!(op.up.is_empty(), sigma < 0.01);
            let m = dense(&op);
            let n = op.dim();
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let x: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let mut y = vec![0.0; n];
            op.apply(&x, &mut y);
            let mut nonzeros = 0u64;
            for p in 0..n {
                let expected: f64 = (0..n).map(|q| m[(p, q)] * x[q]).sum();
                assert!(
                    (y[p] - expected).abs() <= 1e-13 * (1.0 + expected.abs()),
                    "{seed} {p}: {} vs {expected}",
                    y[p]
                );
                for q in 0..n {
                    assert_eq!(m[(p, q)], m[(q, p)]);
                    if p != q && m[(p, q)] != 0.0 {
                        nonzeros += 1;
                    }
                }
            }
            if sigma > 0.01 {
                assert_eq!(nonzeros, op.nonzeros());
            }
            // (i, j) and (k, l) with i == k have no pairwise term.
            assert_eq!(m[(0, 1)], 0.0);
            assert!(m[(0, b.n_nodes() + 1)] > 0.0);
        }
    }

    #[test]
    fn eigenvector_agrees_with_a_dense_eigendecomposition() {
        let star = graph(7, &[(0, 1), (0, 2), (0, 3), (1, 4), (2, 5), (3, 6)]);
        let cases = [
            (random_graph(9, 2, 5), random_graph(10, 3, 6)),
            (random_graph(12, 0, 7), random_graph(12, 0, 7)),
            (star.clone(), star),
        ];
        for (case, (a, b)) in cases.iter().enumerate() {
            for term in [DistanceTerm::Difference, DistanceTerm::Ratio] {
                let params = MatchingParams {
                    distance_term: term,
                    ..Default::default()
                };
                let op = affinity(a, b, &params);
                let ours = leading_eigenvector(&op).unwrap();
                assert!(ours.converged, "case {case}: {ours:?}");
                let evd = dense(&op).self_adjoint_eigen(Side::Lower).unwrap();
                let n = op.dim();
                let value = evd.S()[n - 1];
                let vector: Vec<f64> = (0..n).map(|p| evd.U()[(p, n - 1)].abs()).collect();
                assert!((ours.value - value).abs() < 1e-13, "case {case}");
                let diff = ours
                    .vector
                    .iter()
                    .zip(&vector)
                    .map(|(x, y)| (x - y).abs())
                    .fold(0.0, f64::max);
                assert!(diff < 1e-7, "case {case}: {diff}");
                assert_eq!(
                    discretise(&ours.vector, a.n_nodes(), b.n_nodes(), 0.9, 8),
                    discretise(&vector, a.n_nodes(), b.n_nodes(), 0.9, 8),
                    "case {case}"
                );
            }
        }
    }

    #[test]
    fn discretise_cuts_at_the_gap_and_keeps_mutual_choices() {
        // Row 0: 1.0, 0.95 | 0.5 -> {0, 1}. Row 1: a gradual decline of 4 values with no gap
        // and max order 3 -> unmatched. Row 2: all zero -> unmatched.
        #[rustfmt::skip]
        let scores = [
            1.0,  0.95, 0.5,  0.1,
            0.9,  0.85, 0.8,  0.76,
            0.0,  0.0,  0.0,  0.0,
        ];
        let m = discretise(&scores, 3, 4, 0.9, 3);
        // Columns: col 0: 1.0, 0.9 | 0 -> {0, 1}; but row 1 is unmatched -> only (0, 0).
        // Col 1: 0.95, 0.85 | 0 -> {0, 1} -> (0, 1). Col 2: 0.8 | 0.5 -> {1}; row 1 chose
        // nothing. Col 3: 0.76 | 0.1 -> {1}.
        assert_eq!(m, vec![(0, 0), (0, 1)]);
        // The end of a row counts as a gap: a 1 x 1 problem matches.
        assert_eq!(discretise(&[0.3], 1, 1, 0.9, 8), vec![(0, 0)]);
        // Exactly gap_ratio times the previous is not a gap.
        assert_eq!(discretise(&[1.0, 0.5, 0.5, 1.0], 2, 2, 0.5, 1), vec![]);
        assert_eq!(
            discretise(&[1.0, 0.49, 0.49, 1.0], 2, 2, 0.5, 1),
            vec![(0, 0), (1, 1)]
        );
    }

    #[test]
    fn symmetry_groups_are_bipartite_components() {
        let matches = [(0, 1), (0, 2), (3, 0), (4, 3), (5, 3), (6, 4)];
        let groups = symmetry_groups(&matches, 7, 5);
        assert_eq!(
            groups,
            vec![
                (vec![0], vec![1, 2]),
                (vec![3], vec![0]),
                (vec![4, 5], vec![3]),
                (vec![6], vec![4]),
            ]
        );
        assert!(symmetry_groups(&[], 3, 3).is_empty());
    }

    #[test]
    fn invalid_inputs_are_rejected_with_the_field_name() {
        let g = graph(3, &[(0, 1), (1, 2)]);
        for (params, name) in [
            (
                MatchingParams {
                    sigma: 0.0,
                    ..Default::default()
                },
                "sigma",
            ),
            (
                MatchingParams {
                    gap_ratio: 1.5,
                    ..Default::default()
                },
                "gap_ratio",
            ),
            (
                MatchingParams {
                    histogram_bins: 0,
                    ..Default::default()
                },
                "histogram_bins",
            ),
            (
                MatchingParams {
                    max_symmetry_order: 0,
                    ..Default::default()
                },
                "max_symmetry_order",
            ),
        ] {
            match match_graphs(&g, &g, &params) {
                Err(Error::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
                other => panic!("{name}: {other:?}"),
            }
        }
        let empty = graph(0, &[]);
        assert!(match_graphs(&empty, &g, &MatchingParams::default()).is_err());
        let mut broken = g.clone();
        broken.edges.push((1, 7));
        assert!(match_graphs(&g, &broken, &MatchingParams::default()).is_err());
        // A single node matches a single node.
        let one = graph(1, &[]);
        let m = match_graphs(&one, &one, &MatchingParams::default()).unwrap();
        assert_eq!(m.matches, vec![(0, 0)]);
    }
}
