//! Symmetry breaking (paper, section 5.2; docs/design.md, step 12; docs/decisions.md, "One-to-one method"): from the symmetric
//! (many-to-many) region matches to a one-to-one region correspondence.
//!
//! The symmetric matches fall into groups, the connected components of their bipartite
//! graph: a 1x1 group is a settled match, a 2x2 group is typically a left/right pair
//! (two arms matched to two arms). Every other group must choose one of its options, its
//! maximum-cardinality matchings inside the symmetric matches, and the choices must agree
//! with each other (flip all limbs or none). Two methods:
//!
//! - [`OneToOneMethod::WholeAssignment`] (default; docs/decisions.md, "One-to-one method", the measured best):
//!   choose all groups' options together to minimise the unweighted distortion of the
//!   region distances, `E(P) = (1/|P|^2) * sum_{(i,j),(k,l) in P} c(D1[i,k] - D2[j,l])`
//!   with the cost `c` of [`DistortionCost`]: squared by default (measured better than
//!   the absolute value, docs/decisions.md, "Distortion cost"); [`distortion_energy`] is the absolute form.
//!   Exhaustively when the product of the option counts is at most
//!   [`SymmetryParams::exhaustive_limit`]; otherwise by group-wise sweeps from a greedy
//!   start and seeded random starts.
//! - [`OneToOneMethod::Greedy`]: the paper's greedy growth, [`greedy_one_to_one`], kept for
//!   comparison (it flips some limbs and not others more often, docs/decisions.md, "One-to-one method").
//!
//! A global left/right flip of the answer is not an error (paper, section 5.2).

use faer::MatRef;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::{Error, Result};

/// Default [`SymmetryParams::exhaustive_limit`]: the first study (docs/decisions.md, "One-to-one search") minimised exhaustively up
/// to about 5000 combinations (a few milliseconds here).
pub const DEFAULT_EXHAUSTIVE_LIMIT: usize = 5000;
/// Default [`SymmetryParams::restarts`]: random starts of the local search besides the
/// greedy start ("several seeded random choices", docs/decisions.md, "One-to-one search").
pub const DEFAULT_RESTARTS: usize = 8;
/// Groups with more options than this are re-chosen in the sweeps by an assignment on
/// summed costs instead of trying every option (docs/decisions.md, "One-to-one search": "more than ~120
/// options"; 120 = 5!, a 5x5 group).
pub const LARGE_GROUP_OPTIONS: usize = 120;
/// Most options enumerated for one group (8!, a complete 8x8 group, the paper's maximum
/// symmetry order); a group with more is never searched exhaustively.
pub const ENUMERATION_CAP: usize = 40_320;
/// Sweeps of the local search before it gives up on converging (it converges in a handful).
const MAX_SWEEPS: usize = 100;
/// Relative improvement a move must make to be taken (guards against cycling on rounding).
const IMPROVEMENT_TOLERANCE: f64 = 1e-12;

/// How [`one_to_one`] resolves the symmetric groups.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OneToOneMethod {
    /// Minimise the distortion of region distances over all groups' choices together
    /// (docs/decisions.md, "One-to-one method": one-to-one accuracy 0.954 against 0.892 for the greedy growth).
    WholeAssignment,
    /// The paper's greedy growth from the smallest ambiguous group ([`greedy_one_to_one`]).
    Greedy,
}

/// Parameters of [`one_to_one`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SymmetryParams {
    /// Largest product of the groups' option counts searched exhaustively (default
    /// [`DEFAULT_EXHAUSTIVE_LIMIT`]); above it, local search. 0 always uses local search.
    pub exhaustive_limit: usize,
    /// Random starts of the local search besides the greedy start (default
    /// [`DEFAULT_RESTARTS`]).
    pub restarts: usize,
    /// Seed of the random starts; the result is a function of the inputs and the seed.
    pub seed: u64,
    /// Whole assignment (default) or the paper's greedy growth.
    pub method: OneToOneMethod,
    /// Per-pair cost of the whole-assignment energy ([`DistortionCost::Squared`] by default).
    pub cost: DistortionCost,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

/// The cost of one pair of matched pairs in the whole-assignment energy.
///
/// Measured (`shapecorr bench regions`, one-to-one accuracy with a global flip allowed,
/// everything else at its default): FAUST 126 pairs 0.944 absolute / 0.947 squared (the
/// squared cost repairs the three pairs whose arms were flipped but not their legs, 0.82-0.85
/// to 0.95-0.96); TOSCA 41 pairs 0.963 / 0.973. `|d|^1.5` and `|d|^3` also gave 0.947 on
/// FAUST; the relative `|d| / (D1 + D2)` 0.938. Arm-to-leg distances differ between the
/// same and the opposite side by only a few percent, and squaring lets these large-distance
/// terms outweigh the many small differences between neighbouring regions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DistortionCost {
    /// `|D1[i,k] - D2[j,l]|` (docs/decisions.md, "Distortion cost").
    Absolute,
    /// `(D1[i,k] - D2[j,l])^2`.
    Squared,
}

impl Default for SymmetryParams {
    fn default() -> Self {
        SymmetryParams {
            exhaustive_limit: DEFAULT_EXHAUSTIVE_LIMIT,
            restarts: DEFAULT_RESTARTS,
            seed: 0x5eed,
            method: OneToOneMethod::WholeAssignment,
            cost: DistortionCost::Squared,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

/// Connected components of the bipartite graph of `matches` (region `a` of shape A to
/// region `b` of shape B): for each, its A regions and its B regions, both ascending. The
/// components are ordered by their smallest A region.
pub fn bipartite_groups(matches: &[(u32, u32)]) -> Vec<(Vec<u32>, Vec<u32>)> {
    let n_a = matches.iter().map(|m| m.0 as usize + 1).max().unwrap_or(0);
    let n_b = matches.iter().map(|m| m.1 as usize + 1).max().unwrap_or(0);
    crate::regions::matching::symmetry_groups(matches, n_a, n_b)
}

/// The unweighted distortion of a one-to-one correspondence `pairs` (docs/design.md, step 12):
/// `E(P) = (1/|P|^2) * sum_{(i,j),(k,l) in P} |D1[i,k] - D2[j,l]|` over ordered pairs;
/// 0 for no pairs.
///
/// # Panics
/// When a region index is outside its matrix.
pub fn distortion_energy(pairs: &[(u32, u32)], d1: MatRef<'_, f64>, d2: MatRef<'_, f64>) -> f64 {
    if pairs.is_empty() {
        return 0.0;
    }
    let costs = PairCost {
        d1,
        d2,
        cost: DistortionCost::Absolute,
    };
    let sum: f64 = pairs
        .iter()
        .map(|&p| pairs.iter().map(|&q| costs.of(p, q)).sum::<f64>())
        .sum();
    sum / (pairs.len() as f64).powi(2)
}

/// One-to-one region matches from symmetric ones: a subset of `symmetric` in which every
/// region appears at most once on each side (see the module docs for the methods). With
/// [`OneToOneMethod::WholeAssignment`] every group keeps a maximum matching (as many
/// matches as it can); the greedy method may leave a region of an uneven group unmatched.
/// `d1` (A regions) and `d2` (B regions) are the region distance matrices of the two
/// shapes ([`crate::geodesic::region_distance_matrix`]). Sorted by A region.
///
/// Errors with [`Error::InvalidParameter`] when a matrix is not square or has a non-finite
/// entry, or a match names a region outside its matrix.
pub fn one_to_one(
    symmetric: &[(u32, u32)],
    d1: MatRef<'_, f64>,
    d2: MatRef<'_, f64>,
    params: &SymmetryParams,
) -> Result<Vec<(u32, u32)>> {
    let matches = validated(symmetric, d1, d2)?;
    let mut answer = match params.method {
        OneToOneMethod::Greedy => paper_greedy(&matches, d1, d2),
        OneToOneMethod::WholeAssignment => {
            let problem =
                Problem::new(&matches, d1, d2, params.exhaustive_limit).with_cost(params.cost);
            problem.solve(params)
        }
    };
    answer.sort_unstable();
    Ok(answer)
}

/// The paper's greedy symmetry breaking (section 5.2), on region distances: resolve the
/// smallest group with more than one region on both sides arbitrarily (its first
/// maximum-cardinality matching); `V` = its first A region, `W` = that region's match. Then
/// repeatedly take the ambiguous A region `R` nearest to `V` (`min_{v in V} D1[R, v]`, the
/// region-level stand-in for the paper's mean vertex distance to `V`), match it to the
/// candidate `S` nearest to `W` (`min_{w in W} D2[S, w]`), drop the other matches of `R`
/// and `S`, and add `R`, `S` to `V`, `W`. Ties go to the smaller index. Errors as
/// [`one_to_one`]; the result is sorted by A region.
pub fn greedy_one_to_one(
    symmetric: &[(u32, u32)],
    d1: MatRef<'_, f64>,
    d2: MatRef<'_, f64>,
) -> Result<Vec<(u32, u32)>> {
    let matches = validated(symmetric, d1, d2)?;
    let mut answer = paper_greedy(&matches, d1, d2);
    answer.sort_unstable();
    Ok(answer)
}

/// Checks the inputs; returns the matches sorted without duplicates.
fn validated(
    symmetric: &[(u32, u32)],
    d1: MatRef<'_, f64>,
    d2: MatRef<'_, f64>,
) -> Result<Vec<(u32, u32)>> {
    for (name, d) in [("d1", d1), ("d2", d2)] {
        if d.nrows() != d.ncols() {
            return Err(Error::InvalidParameter {
                name,
                reason: format!(
                    "a region distance matrix must be square, got {} x {}",
                    d.nrows(),
                    d.ncols()
                ),
            });
        }
        for j in 0..d.ncols() {
            for i in 0..d.nrows() {
                if !d[(i, j)].is_finite() {
                    return Err(Error::InvalidParameter {
                        name,
                        reason: format!("entry ({i}, {j}) is {}; distances must be finite (use a large finite value between pieces)", d[(i, j)]),
                    });
                }
            }
        }
    }
    for &(a, b) in symmetric {
        if a as usize >= d1.nrows() || b as usize >= d2.nrows() {
            return Err(Error::InvalidParameter {
                name: "symmetric",
                reason: format!(
                    "match ({a}, {b}) is outside the distance matrices ({} regions on A, {} on B)",
                    d1.nrows(),
                    d2.nrows()
                ),
            });
        }
    }
    let mut matches = symmetric.to_vec();
    matches.sort_unstable();
    matches.dedup();
    Ok(matches)
}

/// `|D1[i,k] - D2[j,l]|` (or its square) for pairs `(i,j)`, `(k,l)`.
#[derive(Clone, Copy)]
struct PairCost<'a> {
    d1: MatRef<'a, f64>,
    d2: MatRef<'a, f64>,
    cost: DistortionCost,
}

impl PairCost<'_> {
    #[inline]
    fn of(&self, p: (u32, u32), q: (u32, u32)) -> f64 {
        let d = self.d1[(p.0 as usize, q.0 as usize)] - self.d2[(p.1 as usize, q.1 as usize)];
        match self.cost {
            DistortionCost::Absolute => d.abs(),
            DistortionCost::Squared => d * d,
        }
    }

    /// Sum of the costs of `p` against every pair of `rest`.
    fn against(&self, p: (u32, u32), rest: &[(u32, u32)]) -> f64 {
        rest.iter().map(|&q| self.of(p, q)).sum()
    }

    /// Sum over ordered pairs within `pairs`.
    fn within(&self, pairs: &[(u32, u32)]) -> f64 {
        pairs.iter().map(|&p| self.against(p, pairs)).sum()
    }
}

/// An ambiguous group of symmetric matches and its options.
struct Group {
    a: Vec<u32>,
    b: Vec<u32>,
    /// The group's symmetric matches, sorted.
    edges: Vec<(u32, u32)>,
    /// Maximum-cardinality matchings inside `edges` (all of them when `complete`).
    options: Vec<Vec<(u32, u32)>>,
    complete: bool,
}

impl Group {
    /// Re-chosen by an assignment rather than by trying every option.
    fn is_large(&self) -> bool {
        !self.complete || self.options.len() > LARGE_GROUP_OPTIONS
    }
}

/// The whole-assignment problem: settled pairs and the groups still to choose.
struct Problem<'a> {
    costs: PairCost<'a>,
    fixed: Vec<(u32, u32)>,
    groups: Vec<Group>,
    exhaustive_limit: usize,
}

/// One choice per group.
type State = Vec<Vec<(u32, u32)>>;

impl<'a> Problem<'a> {
    fn new(
        matches: &[(u32, u32)],
        d1: MatRef<'a, f64>,
        d2: MatRef<'a, f64>,
        exhaustive_limit: usize,
    ) -> Problem<'a> {
        let cap = exhaustive_limit.clamp(LARGE_GROUP_OPTIONS, ENUMERATION_CAP);
        let mut fixed = Vec::new();
        let mut groups = Vec::new();
        for (a, b) in bipartite_groups(matches) {
            let edges: Vec<(u32, u32)> = matches
                .iter()
                .copied()
                .filter(|m| a.binary_search(&m.0).is_ok())
                .collect();
            if a.len() == 1 && b.len() == 1 {
                fixed.push(edges[0]);
                continue;
            }
            let (options, complete) = max_matchings(&a, &b, &edges, cap);
            groups.push(Group {
                a,
                b,
                edges,
                options,
                complete,
            });
        }
        Problem {
            costs: PairCost {
                d1,
                d2,
                cost: DistortionCost::Absolute,
            },
            fixed,
            groups,
            exhaustive_limit,
        }
    }

    /// The same problem scored with `cost` per pair of pairs.
    fn with_cost(mut self, cost: DistortionCost) -> Self {
        self.costs.cost = cost;
        self
    }

    fn solve(&self, params: &SymmetryParams) -> Vec<(u32, u32)> {
        let exhaustive = self.groups.iter().all(|g| g.complete)
            && self
                .groups
                .iter()
                .try_fold(1usize, |product, g| product.checked_mul(g.options.len()))
                .is_some_and(|product| product <= self.exhaustive_limit);
        let state = if exhaustive {
            self.exhaustive()
        } else {
            self.local_search(params)
        };
        self.pairs(&state, usize::MAX)
    }

    /// All pairs of a state (fixed ones included), leaving out group `skip`.
    fn pairs(&self, state: &State, skip: usize) -> Vec<(u32, u32)> {
        let mut pairs = self.fixed.clone();
        for (g, choice) in state.iter().enumerate() {
            if g != skip {
                pairs.extend_from_slice(choice);
            }
        }
        pairs
    }

    /// Sum over ordered pairs of the state; `|P|` is the same for every state (each group
    /// keeps its maximum cardinality), so this orders states as the energy does.
    fn total(&self, state: &State) -> f64 {
        self.costs.within(&self.pairs(state, usize::MAX))
    }

    /// Every combination of options; the first minimum in odometer order.
    fn exhaustive(&self) -> State {
        let mut index = vec![0usize; self.groups.len()];
        let mut state: State = self.groups.iter().map(|g| g.options[0].clone()).collect();
        let mut best = (self.total(&state), state.clone());
        loop {
            // Next combination, last group fastest.
            let mut g = self.groups.len();
            loop {
                if g == 0 {
                    return best.1;
                }
                g -= 1;
                index[g] += 1;
                if index[g] < self.groups[g].options.len() {
                    state[g] = self.groups[g].options[index[g]].clone();
                    break;
                }
                index[g] = 0;
                state[g] = self.groups[g].options[0].clone();
            }
            let total = self.total(&state);
            if total < best.0 {
                best = (total, state.clone());
            }
        }
    }

    /// Group-wise sweeps from the greedy start and `params.restarts` random starts; the
    /// best result (the earliest start on ties).
    fn local_search(&self, params: &SymmetryParams) -> State {
        let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
        let mut best: Option<(f64, State)> = None;
        for start in 0..=params.restarts {
            let mut state = if start == 0 {
                self.greedy_start()
            } else {
                self.random_start(&mut rng)
            };
            self.sweep_until_stable(&mut state);
            let total = self.total(&state);
            if best.as_ref().is_none_or(|b| total < b.0) {
                best = Some((total, state));
            }
        }
        best.map(|b| b.1).unwrap_or_default()
    }

    /// Greedy growth with distance signatures: starting from the settled pairs (or, with
    /// none, from the group with the fewest options), repeatedly resolve the group nearest
    /// to the resolved A regions by its best choice against the resolved pairs.
    fn greedy_start(&self) -> State {
        let n = self.groups.len();
        let mut state: State = vec![Vec::new(); n];
        let mut resolved = self.fixed.clone();
        let mut done = vec![false; n];
        for _ in 0..n {
            let next = (0..n)
                .filter(|&g| !done[g])
                .min_by(|&g, &h| {
                    let key = |g: usize| {
                        if resolved.is_empty() {
                            self.groups[g].options.len() as f64
                        } else {
                            self.groups[g]
                                .a
                                .iter()
                                .flat_map(|&a| {
                                    resolved
                                        .iter()
                                        .map(move |r| self.costs.d1[(a as usize, r.0 as usize)])
                                })
                                .fold(f64::INFINITY, f64::min)
                        }
                    };
                    key(g).total_cmp(&key(h)).then(g.cmp(&h))
                })
                .expect("a group is left");
            state[next] = self.best_choice(next, &resolved, None);
            resolved.extend_from_slice(&state[next]);
            done[next] = true;
        }
        state
    }

    /// A uniformly random option for an enumerated group; for a large group, the
    /// maximum-cardinality matching of least random cost.
    fn random_start(&self, rng: &mut ChaCha8Rng) -> State {
        self.groups
            .iter()
            .map(|g| {
                if g.is_large() {
                    let costs: Vec<f64> = g.edges.iter().map(|_| rng.random::<f64>()).collect();
                    assign_group(g, &costs)
                } else {
                    g.options[rng.random_range(0..g.options.len())].clone()
                }
            })
            .collect()
    }

    /// Re-chooses each group's option with the others fixed until nothing changes.
    fn sweep_until_stable(&self, state: &mut State) {
        for _ in 0..MAX_SWEEPS {
            let mut changed = false;
            for g in 0..self.groups.len() {
                let rest = self.pairs(state, g);
                let choice = self.best_choice(g, &rest, Some(&state[g]));
                if choice != state[g] {
                    state[g] = choice;
                    changed = true;
                }
            }
            if !changed {
                return;
            }
        }
    }

    /// Cost of group `g` choosing `choice` against the pairs `rest` (the part of the
    /// total that depends on the choice).
    fn group_cost(&self, choice: &[(u32, u32)], rest: &[(u32, u32)]) -> f64 {
        2.0 * choice
            .iter()
            .map(|&p| self.costs.against(p, rest))
            .sum::<f64>()
            + self.costs.within(choice)
    }

    /// The best option of group `g` against the pairs `rest`: every option for an
    /// enumerated group; for a large group, the assignment on the summed costs against
    /// `rest` improved by swaps. Keeps `current` unless the new choice is clearly better.
    fn best_choice(
        &self,
        g: usize,
        rest: &[(u32, u32)],
        current: Option<&Vec<(u32, u32)>>,
    ) -> Vec<(u32, u32)> {
        let group = &self.groups[g];
        let mut best: Option<(f64, Vec<(u32, u32)>)> =
            current.map(|c| (self.group_cost(c, rest), c.clone()));
        let mut consider = |choice: Vec<(u32, u32)>, cost: f64| {
            let better = match &best {
                None => true,
                Some((b, _)) => cost < b - IMPROVEMENT_TOLERANCE * (1.0 + b.abs()),
            };
            if better {
                best = Some((cost, choice));
            }
        };
        if group.is_large() {
            let summed: Vec<f64> = group
                .edges
                .iter()
                .map(|&e| self.costs.against(e, rest))
                .collect();
            let mut choice = assign_group(group, &summed);
            self.improve_by_swaps(group, &mut choice, rest);
            let cost = self.group_cost(&choice, rest);
            consider(choice, cost);
        } else {
            for option in &group.options {
                let cost = self.group_cost(option, rest);
                consider(option.clone(), cost);
            }
        }
        best.expect("a group has at least one option").1
    }

    /// Local moves inside a large group that keep it a maximum-cardinality matching:
    /// exchange the partners of two pairs, or move a pair's end to a free region.
    fn improve_by_swaps(&self, group: &Group, choice: &mut Vec<(u32, u32)>, rest: &[(u32, u32)]) {
        let is_edge = |e: (u32, u32)| group.edges.binary_search(&e).is_ok();
        let mut cost = self.group_cost(choice, rest);
        for _ in 0..MAX_SWEEPS {
            let mut improved = false;
            let mut candidates: Vec<Vec<(u32, u32)>> = Vec::new();
            for x in 0..choice.len() {
                for y in x + 1..choice.len() {
                    let (p, q) = (choice[x], choice[y]);
                    if is_edge((p.0, q.1)) && is_edge((q.0, p.1)) {
                        let mut c = choice.clone();
                        c[x] = (p.0, q.1);
                        c[y] = (q.0, p.1);
                        candidates.push(c);
                    }
                }
                let p = choice[x];
                for &a in &group.a {
                    if !choice.iter().any(|m| m.0 == a) && is_edge((a, p.1)) {
                        let mut c = choice.clone();
                        c[x] = (a, p.1);
                        candidates.push(c);
                    }
                }
                for &b in &group.b {
                    if !choice.iter().any(|m| m.1 == b) && is_edge((p.0, b)) {
                        let mut c = choice.clone();
                        c[x] = (p.0, b);
                        candidates.push(c);
                    }
                }
            }
            for mut c in candidates {
                let c_cost = self.group_cost(&c, rest);
                if c_cost < cost - IMPROVEMENT_TOLERANCE * (1.0 + cost.abs()) {
                    c.sort_unstable();
                    *choice = c;
                    cost = c_cost;
                    improved = true;
                    break;
                }
            }
            if !improved {
                return;
            }
        }
    }
}

/// The maximum-cardinality matching of `group` with least total cost (`costs` per edge of
/// `group.edges`), sorted.
fn assign_group(group: &Group, costs: &[f64]) -> Vec<(u32, u32)> {
    let n = group.a.len().max(group.b.len());
    let floor = costs.iter().copied().fold(f64::INFINITY, f64::min);
    let shifted: Vec<f64> = costs.iter().map(|c| c - floor).collect();
    // Any assignment using one more real edge is cheaper than any using fewer.
    let forbidden = 1.0 + 2.0 * shifted.iter().sum::<f64>();
    let mut matrix = vec![forbidden; n * n];
    for (e, &(a, b)) in group.edges.iter().enumerate() {
        let row = group.a.binary_search(&a).expect("edge in group");
        let col = group.b.binary_search(&b).expect("edge in group");
        matrix[row * n + col] = shifted[e];
    }
    let assignment = min_cost_assignment(&matrix, n);
    let mut choice: Vec<(u32, u32)> = assignment
        .iter()
        .enumerate()
        .filter(|&(row, &col)| {
            row < group.a.len() && col < group.b.len() && matrix[row * n + col] < forbidden
        })
        .map(|(row, &col)| (group.a[row], group.b[col]))
        .collect();
    choice.sort_unstable();
    choice
}

/// Minimum-cost perfect assignment of a square `n x n` cost matrix (row-major, finite
/// entries), by shortest augmenting paths with potentials (Hungarian method, Jonker-Volgenant
/// style), O(n^3). Returns the column of every row.
///
/// # Panics
/// When `cost.len() != n * n`.
pub fn min_cost_assignment(cost: &[f64], n: usize) -> Vec<usize> {
    assert_eq!(cost.len(), n * n, "the cost matrix must be n x n");
    // 1-based rows and columns; column 0 is the virtual start of each augmenting path.
    let mut u = vec![0.0; n + 1];
    let mut v = vec![0.0; n + 1];
    let mut row_of_col = vec![0usize; n + 1];
    let mut way = vec![0usize; n + 1];
    for row in 1..=n {
        row_of_col[0] = row;
        let mut col0 = 0;
        let mut min_slack = vec![f64::INFINITY; n + 1];
        let mut used = vec![false; n + 1];
        loop {
            used[col0] = true;
            let row0 = row_of_col[col0];
            let mut delta = f64::INFINITY;
            let mut col1 = 0;
            for col in 1..=n {
                if !used[col] {
                    let slack = cost[(row0 - 1) * n + col - 1] - u[row0] - v[col];
                    if slack < min_slack[col] {
                        min_slack[col] = slack;
                        way[col] = col0;
                    }
                    if min_slack[col] < delta {
                        delta = min_slack[col];
                        col1 = col;
                    }
                }
            }
            for col in 0..=n {
                if used[col] {
                    u[row_of_col[col]] += delta;
                    v[col] -= delta;
                } else {
                    min_slack[col] -= delta;
                }
            }
            col0 = col1;
            if row_of_col[col0] == 0 {
                break;
            }
        }
        loop {
            let col1 = way[col0];
            row_of_col[col0] = row_of_col[col1];
            col0 = col1;
            if col0 == 0 {
                break;
            }
        }
    }
    let mut col_of_row = vec![0usize; n];
    for col in 1..=n {
        col_of_row[row_of_col[col] - 1] = col - 1;
    }
    col_of_row
}

/// The maximum-cardinality matchings of the bipartite graph `edges` between `a` and `b`
/// (both sorted), in lexicographic order of the A regions' choices, at most `cap` of them;
/// the flag is false when there were more.
pub(crate) fn max_matchings(
    a: &[u32],
    b: &[u32],
    edges: &[(u32, u32)],
    cap: usize,
) -> (Vec<Vec<(u32, u32)>>, bool) {
    let mut adjacency: Vec<Vec<usize>> = vec![Vec::new(); a.len()];
    for &(x, y) in edges {
        let row = a.binary_search(&x).expect("edge in group");
        let col = b.binary_search(&y).expect("edge in group");
        adjacency[row].push(col);
    }
    for list in &mut adjacency {
        list.sort_unstable();
    }
    let size = maximum_matching_size(&adjacency, b.len());

    struct Search<'s> {
        a: &'s [u32],
        b: &'s [u32],
        adjacency: &'s [Vec<usize>],
        size: usize,
        cap: usize,
        used: Vec<bool>,
        current: Vec<(u32, u32)>,
        found: Vec<Vec<(u32, u32)>>,
        truncated: bool,
    }
    impl Search<'_> {
        fn run(&mut self, row: usize) {
            if self.truncated {
                return;
            }
            if self.current.len() == self.size {
                if self.found.len() == self.cap {
                    self.truncated = true;
                } else {
                    self.found.push(self.current.clone());
                }
                return;
            }
            // Not enough A regions left to reach the maximum size.
            if row == self.a.len() || self.current.len() + (self.a.len() - row) < self.size {
                return;
            }
            for k in 0..self.adjacency[row].len() {
                let col = self.adjacency[row][k];
                if !self.used[col] {
                    self.used[col] = true;
                    self.current.push((self.a[row], self.b[col]));
                    self.run(row + 1);
                    self.current.pop();
                    self.used[col] = false;
                }
            }
            // Leave this A region unmatched.
            self.run(row + 1);
        }
    }
    let mut search = Search {
        a,
        b,
        adjacency: &adjacency,
        size,
        cap,
        used: vec![false; b.len()],
        current: Vec::with_capacity(size),
        found: Vec::new(),
        truncated: false,
    };
    search.run(0);
    (search.found, !search.truncated)
}

/// Size of a maximum matching (augmenting paths, Kuhn's algorithm).
fn maximum_matching_size(adjacency: &[Vec<usize>], n_cols: usize) -> usize {
    fn augment(
        row: usize,
        adjacency: &[Vec<usize>],
        seen: &mut [bool],
        row_of_col: &mut [usize],
    ) -> bool {
        for &col in &adjacency[row] {
            if !seen[col] {
                seen[col] = true;
                if row_of_col[col] == usize::MAX
                    || augment(row_of_col[col], adjacency, seen, row_of_col)
                {
                    row_of_col[col] = row;
                    return true;
                }
            }
        }
        false
    }
    let mut row_of_col = vec![usize::MAX; n_cols];
    let mut size = 0;
    for row in 0..adjacency.len() {
        let mut seen = vec![false; n_cols];
        if augment(row, adjacency, &mut seen, &mut row_of_col) {
            size += 1;
        }
    }
    size
}

/// The paper's greedy growth on deduplicated, validated matches (see
/// [`greedy_one_to_one`]).
fn paper_greedy(
    matches: &[(u32, u32)],
    d1: MatRef<'_, f64>,
    d2: MatRef<'_, f64>,
) -> Vec<(u32, u32)> {
    let (n_a, n_b) = (d1.nrows(), d2.nrows());
    let mut of_a: Vec<Vec<u32>> = vec![Vec::new(); n_a];
    let mut of_b: Vec<Vec<u32>> = vec![Vec::new(); n_b];
    for &(a, b) in matches {
        of_a[a as usize].push(b);
        of_b[b as usize].push(a);
    }
    // Match a to b alone: every other match of a or of b goes.
    fn resolve(a: u32, b: u32, of_a: &mut [Vec<u32>], of_b: &mut [Vec<u32>]) {
        for other in std::mem::take(&mut of_a[a as usize]) {
            of_b[other as usize].retain(|&x| x != a);
        }
        for other in std::mem::take(&mut of_b[b as usize]) {
            of_a[other as usize].retain(|&x| x != b);
        }
        of_a[a as usize] = vec![b];
        of_b[b as usize] = vec![a];
    }
    let ambiguous = |a: usize, of_a: &[Vec<u32>], of_b: &[Vec<u32>]| match of_a[a].as_slice() {
        [] => false,
        [b] => of_b[*b as usize].len() > 1,
        _ => true,
    };

    let groups: Vec<(Vec<u32>, Vec<u32>)> = bipartite_groups(matches)
        .into_iter()
        .filter(|(a, b)| a.len() > 1 || b.len() > 1)
        .collect();
    let mut near_v: Vec<u32> = Vec::new();
    let mut near_w: Vec<u32> = Vec::new();
    // Seed: the smallest group with more than one region on both sides (any ambiguous group
    // when there is none), resolved by its first maximum-cardinality matching.
    let seed = groups
        .iter()
        .filter(|(a, b)| a.len() > 1 && b.len() > 1)
        .min_by_key(|(a, b)| (a.len().max(b.len()), a.len() + b.len()))
        .or_else(|| {
            groups
                .iter()
                .min_by_key(|(a, b)| (a.len().max(b.len()), a.len() + b.len()))
        });
    if let Some((a, b)) = seed {
        let edges: Vec<(u32, u32)> = matches
            .iter()
            .copied()
            .filter(|m| a.binary_search(&m.0).is_ok())
            .collect();
        let (options, _) = max_matchings(a, b, &edges, 1);
        for &(x, y) in &options[0] {
            resolve(x, y, &mut of_a, &mut of_b);
        }
        for &x in a {
            if !options[0].iter().any(|m| m.0 == x) {
                for other in std::mem::take(&mut of_a[x as usize]) {
                    of_b[other as usize].retain(|&z| z != x);
                }
            }
        }
        near_v.push(options[0][0].0);
        near_w.push(options[0][0].1);
    }
    loop {
        let distance_to = |x: usize, set: &[u32], d: MatRef<'_, f64>| {
            set.iter()
                .map(|&y| d[(x, y as usize)])
                .fold(f64::INFINITY, f64::min)
        };
        let next = (0..n_a)
            .filter(|&a| ambiguous(a, &of_a, &of_b))
            .min_by(|&x, &y| {
                distance_to(x, &near_v, d1)
                    .total_cmp(&distance_to(y, &near_v, d1))
                    .then(x.cmp(&y))
            });
        let Some(r) = next else { break };
        let s = of_a[r]
            .iter()
            .copied()
            .min_by(|&x, &y| {
                distance_to(x as usize, &near_w, d2)
                    .total_cmp(&distance_to(y as usize, &near_w, d2))
                    .then(x.cmp(&y))
            })
            .expect("an ambiguous region has a candidate");
        resolve(r as u32, s, &mut of_a, &mut of_b);
        near_v.push(r as u32);
        near_w.push(s);
    }
    (0..n_a)
        .filter_map(|a| match of_a[a].as_slice() {
            [b] => Some((a as u32, *b)),
            _ => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// Every permutation of 0..n, by Heap's algorithm.
    fn permutations(n: usize) -> Vec<Vec<usize>> {
        fn heap(k: usize, items: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
            if k <= 1 {
                out.push(items.clone());
                return;
            }
            for i in 0..k {
                heap(k - 1, items, out);
                let j = if k.is_multiple_of(2) { i } else { 0 };
                items.swap(j, k - 1);
            }
        }
        let mut out = Vec::new();
        heap(n, &mut (0..n).collect(), &mut out);
        out
    }

    #[test]
    fn assignment_matches_brute_force() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for n in 1..=6 {
            for trial in 0..20 {
                // Some trials with many ties (small integers).
                let cost: Vec<f64> = (0..n * n)
                    .map(|_| {
                        if trial % 2 == 0 {
                            rng.random::<f64>() * 10.0 - 3.0
                        } else {
                            f64::from(rng.random_range(0..3u32))
                        }
                    })
                    .collect();
                let assignment = min_cost_assignment(&cost, n);
                let mut seen = assignment.clone();
                seen.sort_unstable();
                assert_eq!(seen, (0..n).collect::<Vec<_>>(), "a permutation");
                let total = |p: &[usize]| (0..n).map(|r| cost[r * n + p[r]]).sum::<f64>();
                let best = permutations(n)
                    .iter()
                    .map(|p| total(p))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    (total(&assignment) - best).abs() < 1e-9,
                    "n {n} trial {trial}"
                );
            }
        }
        assert!(min_cost_assignment(&[], 0).is_empty());
    }

    fn complete(a: &[u32], b: &[u32]) -> Vec<(u32, u32)> {
        a.iter()
            .flat_map(|&x| b.iter().map(move |&y| (x, y)))
            .collect()
    }

    #[test]
    fn complete_groups_have_factorial_options() {
        for (k, count) in [(2usize, 2usize), (3, 6), (4, 24), (5, 120)] {
            let a: Vec<u32> = (0..k as u32).collect();
            let b: Vec<u32> = (10..10 + k as u32).collect();
            let (options, complete) = max_matchings(&a, &b, &complete(&a, &b), 1000);
            assert!(complete);
            assert_eq!(options.len(), count);
            let mut distinct = options.clone();
            distinct.sort();
            distinct.dedup();
            assert_eq!(distinct.len(), count);
            for o in &options {
                assert_eq!(o.len(), k);
                let mut bs: Vec<u32> = o.iter().map(|m| m.1).collect();
                bs.sort_unstable();
                assert_eq!(bs, b);
            }
        }
        // 6x6 has 720 options: cut at 100.
        let a: Vec<u32> = (0..6).collect();
        let (options, complete) = max_matchings(&a, &a, &complete(&a, &a), 100);
        assert!(!complete);
        assert_eq!(options.len(), 100);
    }

    #[test]
    fn unbalanced_and_sparse_groups_keep_maximum_cardinality() {
        // 2 x 3 complete: 6 options of 2 pairs.
        let (options, _) = max_matchings(&[0, 1], &[0, 1, 2], &complete(&[0, 1], &[0, 1, 2]), 99);
        assert_eq!(options.len(), 6);
        assert!(options.iter().all(|o| o.len() == 2));
        // 1 x 3: 3 options of one pair.
        let (options, _) = max_matchings(&[4], &[0, 1, 2], &complete(&[4], &[0, 1, 2]), 99);
        assert_eq!(options, vec![vec![(4, 0)], vec![(4, 1)], vec![(4, 2)]]);
        // A path a0-b0, a0-b1, a1-b1: only the perfect matching.
        let path = [(0, 0), (0, 1), (1, 1)];
        let (options, _) = max_matchings(&[0, 1], &[0, 1], &path, 99);
        assert_eq!(options, vec![vec![(0, 0), (1, 1)]]);
        // The assignment also keeps the maximum cardinality, even when a smaller matching
        // is cheaper.
        let group = Group {
            a: vec![0, 1],
            b: vec![0, 1],
            edges: path.to_vec(),
            options,
            complete: true,
        };
        assert_eq!(
            assign_group(&group, &[100.0, 0.0, 100.0]),
            vec![(0, 0), (1, 1)]
        );
        assert_eq!(assign_group(&group, &[0.0, 5.0, 0.0]), vec![(0, 0), (1, 1)]);
        // A complete 3 x 3 group: the cheapest perfect matching (1 + 1 + 2).
        let (a, b) = (vec![2, 5, 7], vec![1, 3, 4]);
        let edges = complete(&a, &b);
        let costs = [5.0, 1.0, 9.0, 1.0, 6.0, 7.0, 3.0, 4.0, 2.0];
        let (options, complete_flag) = max_matchings(&a, &b, &edges, 99);
        let group = Group {
            a,
            b,
            edges,
            options,
            complete: complete_flag,
        };
        assert_eq!(assign_group(&group, &costs), vec![(2, 3), (5, 1), (7, 4)]);
    }

    #[test]
    fn energy_is_zero_for_an_isometry_and_scales_with_pair_count() {
        let d = Mat::from_fn(4, 4, |i, j| (i as f64 - j as f64).abs());
        let identity: Vec<(u32, u32)> = (0..4).map(|i| (i, i)).collect();
        assert_eq!(distortion_energy(&identity, d.as_ref(), d.as_ref()), 0.0);
        // Swapping 0 and 3 on a line of 4: |D[0,k] - D[3,k]| etc.
        let swapped = [(0, 3), (1, 1), (2, 2), (3, 0)];
        let expected: f64 = {
            let image = |i: usize| [3, 1, 2, 0][i];
            let mut sum = 0.0;
            for i in 0..4 {
                for k in 0..4 {
                    sum += (d[(i, k)] - d[(image(i), image(k))]).abs();
                }
            }
            sum / 16.0
        };
        let e = distortion_energy(&swapped, d.as_ref(), d.as_ref());
        assert!((e - expected).abs() < 1e-15 && e > 0.0);
        assert_eq!(distortion_energy(&[], d.as_ref(), d.as_ref()), 0.0);
    }

    /// Matches, D1, D2 and the renumbering of A's regions on B.
    type LineInstance = (Vec<(u32, u32)>, Mat<f64>, Mat<f64>, Vec<u32>);

    /// Points on a slightly stretched line (no symmetry) and their copy renumbered by a
    /// fixed permutation; the first `anchors` regions are matched to their copies alone,
    /// the others all-to-all (one large group).
    fn line_instance(n: usize, anchors: usize) -> LineInstance {
        let x: Vec<f64> = (0..n).map(|i| i as f64 + 0.01 * (i * i) as f64).collect();
        let perm: Vec<u32> = (0..n as u32).map(|i| (i * 5 + 3) % n as u32).collect();
        let d1 = Mat::from_fn(n, n, |i, j| (x[i] - x[j]).abs());
        let mut d2 = Mat::zeros(n, n);
        for i in 0..n {
            for j in 0..n {
                d2[(perm[i] as usize, perm[j] as usize)] = d1[(i, j)];
            }
        }
        let mut matches: Vec<(u32, u32)> =
            (0..anchors as u32).map(|i| (i, perm[i as usize])).collect();
        for i in anchors..n {
            for &image in &perm[anchors..] {
                matches.push((i as u32, image));
            }
        }
        (matches, d1, d2, perm)
    }

    #[test]
    fn sweeps_solve_a_large_group_by_assignment_and_swaps() {
        let params = SymmetryParams {
            exhaustive_limit: 0,
            ..Default::default()
        };
        // With anchors the assignment on summed costs finds the answer; without, the
        // assignment has nothing to go by and the swaps find the line's order (forwards
        // or, a near-isometry, backwards).
        for anchors in [2, 0] {
            let (matches, d1, d2, perm) = line_instance(9, anchors);
            let problem = Problem::new(&matches, d1.as_ref(), d2.as_ref(), 0);
            assert_eq!(problem.groups.len(), 1);
            assert!(problem.groups[0].is_large());
            let result = one_to_one(&matches, d1.as_ref(), d2.as_ref(), &params).unwrap();
            let answer = |reversed: bool| {
                let mut m: Vec<(u32, u32)> = (0..9)
                    .map(|i| (i as u32, perm[if reversed { 8 - i } else { i }]))
                    .collect();
                m.sort_unstable();
                m
            };
            if anchors > 0 {
                assert_eq!(result, answer(false), "anchors {anchors}");
            } else {
                assert!(
                    result == answer(false) || result == answer(true),
                    "{result:?}"
                );
            }
        }
    }
}
