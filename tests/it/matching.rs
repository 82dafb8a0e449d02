//! Graph matching on hand-made shape graphs: symmetric groups, permutation and swap
//! identities, robustness to an extra node, determinism. Ignored tests measure the variants
//! (`cargo test --release --test it matching:: -- --ignored --nocapture`).

use std::collections::BTreeSet;
use std::time::Instant;

use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shapecorr::regions::graph::ShapeGraph;
use shapecorr::regions::matching::{
    distance_histograms, leading_eigenvector, match_graphs, symmetry_groups, unary_costs, Affinity,
    DistanceTerm, GraphMatching, MatchingParams,
};

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

/// Centre 0 and `arms` chains of two nodes: inner `1 + 2c`, outer `2 + 2c`.
fn star(arms: u32) -> ShapeGraph {
    let mut edges = Vec::new();
    for c in 0..arms {
        edges.push((0, 1 + 2 * c));
        edges.push((1 + 2 * c, 2 + 2 * c));
    }
    graph(1 + 2 * arms as usize, &edges)
}

/// Torso 0, head 1, left arm 2-3, right arm 4-5, left leg 6-8, right leg 9-11 (chains from
/// the torso outwards).
fn humanoid() -> ShapeGraph {
    graph(
        12,
        &[
            (0, 1),
            (0, 2),
            (2, 3),
            (0, 4),
            (4, 5),
            (0, 6),
            (6, 7),
            (7, 8),
            (0, 9),
            (9, 10),
            (10, 11),
        ],
    )
}

/// The humanoid's left/right mirror.
const MIRROR: [u32; 12] = [0, 1, 4, 5, 2, 3, 9, 10, 11, 6, 7, 8];

/// Part of every humanoid node (torso, head, arm, leg).
const PART: [&str; 12] = [
    "torso", "head", "arm", "arm", "arm", "arm", "leg", "leg", "leg", "leg", "leg", "leg",
];

/// `g` relabelled: node `x` becomes `perm[x]`.
fn permuted(g: &ShapeGraph, perm: &[u32]) -> ShapeGraph {
    let edges: Vec<(u32, u32)> = g
        .edges
        .iter()
        .map(|&(i, j)| (perm[i as usize], perm[j as usize]))
        .collect();
    graph(g.n_nodes(), &edges)
}

fn random_permutation(n: usize, seed: u64) -> Vec<u32> {
    let mut perm: Vec<u32> = (0..n as u32).collect();
    perm.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    perm
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

fn run(a: &ShapeGraph, b: &ShapeGraph) -> GraphMatching {
    match_graphs(a, b, &MatchingParams::default()).unwrap()
}

fn run_with(a: &ShapeGraph, b: &ShapeGraph, term: DistanceTerm) -> GraphMatching {
    let params = MatchingParams {
        distance_term: term,
        ..Default::default()
    };
    match_graphs(a, b, &params).unwrap()
}

const TERMS: [DistanceTerm; 2] = [DistanceTerm::Difference, DistanceTerm::Ratio];

fn sorted(mut m: Vec<(u32, u32)>) -> Vec<(u32, u32)> {
    m.sort_unstable();
    m
}

#[test]
fn star_chains_match_all_equivalent_chains_up_to_the_maximum_order() {
    for arms in 2..=9u32 {
        let g = star(arms);
        let m = run(&g, &g);
        let mut expected = vec![(0, 0)];
        if arms <= 8 {
            for c in 0..arms {
                for d in 0..arms {
                    expected.push((1 + 2 * c, 1 + 2 * d));
                    expected.push((2 + 2 * c, 2 + 2 * d));
                }
            }
        }
        assert_eq!(m.matches, sorted(expected), "{arms} arms");
        let groups = symmetry_groups(&m.matches, g.n_nodes(), g.n_nodes());
        let sizes: Vec<usize> = groups.iter().map(|(a, _)| a.len()).collect();
        if arms <= 8 {
            assert_eq!(sizes, vec![1, arms as usize, arms as usize], "{arms} arms");
        } else {
            assert_eq!(sizes, vec![1]);
        }
    }
    // With the authors' order 10, nine chains match again.
    let params = MatchingParams {
        max_symmetry_order: 10,
        ..Default::default()
    };
    let g = star(9);
    assert_eq!(
        match_graphs(&g, &g, &params).unwrap().matches.len(),
        1 + 2 * 81
    );
}

/// The matches a humanoid should get against its copy relabelled by `perm`: every node to
/// its own image and its mirror's image.
fn humanoid_truth(perm: &[u32]) -> Vec<(u32, u32)> {
    let mut truth = BTreeSet::new();
    for x in 0..12u32 {
        truth.insert((x, perm[x as usize]));
        truth.insert((x, perm[MIRROR[x as usize] as usize]));
    }
    truth.into_iter().collect()
}

#[test]
fn humanoid_matches_a_relabelled_copy_up_to_left_right() {
    let a = humanoid();
    for seed in 0..6 {
        let perm = random_permutation(12, seed);
        let b = permuted(&a, &perm);
        for term in [DistanceTerm::Ratio, DistanceTerm::Difference] {
            let params = MatchingParams {
                distance_term: term,
                ..Default::default()
            };
            let m = match_graphs(&a, &b, &params).unwrap();
            assert_eq!(m.matches, humanoid_truth(&perm), "seed {seed} {term:?}");
            let inverse = inverse(&perm);
            for &(x, y) in &m.matches {
                assert_eq!(PART[x as usize], PART[inverse[y as usize] as usize]);
            }
        }
    }
}

/// A spider with legs of 2, 4 and 3 nodes: 0 - 1 - 6, 0 - 2 - 7 - 8 - 9, 0 - 3 - 4 - 5. It
/// has no symmetry, yet nodes 1 and 7 have the same hop-distance histogram (2, 2, 2, 2, 1).
fn spider_2_4_3() -> ShapeGraph {
    graph(
        10,
        &[
            (0, 1),
            (1, 6),
            (0, 2),
            (2, 7),
            (7, 8),
            (8, 9),
            (0, 3),
            (3, 4),
            (4, 5),
        ],
    )
}

#[test]
fn the_second_order_term_breaks_ties_of_the_unary_term() {
    let a = spider_2_4_3();
    let hist = distance_histograms(&a.hop_distances(), 20, false);
    assert_eq!(hist[1], hist[7]);
    for seed in 0..4 {
        let perm = random_permutation(10, 300 + seed);
        let b = permuted(&a, &perm);
        let costs = unary_costs(&hist, &distance_histograms(&b.hop_distances(), 20, false));
        // First order alone cannot tell 1 from 7 ...
        assert_eq!(costs[10 + perm[7] as usize], 0.0);
        assert_eq!(costs[70 + perm[1] as usize], 0.0);
        // ... the matching can: exactly the relabelling.
        for term in TERMS {
            let m = run_with(&a, &b, term);
            let expected = sorted((0..10u32).map(|x| (x, perm[x as usize])).collect());
            assert_eq!(m.matches, expected, "seed {seed} {term:?}");
        }
    }
}

fn inverse(perm: &[u32]) -> Vec<u32> {
    let mut inv = vec![0; perm.len()];
    for (x, &y) in perm.iter().enumerate() {
        inv[y as usize] = x as u32;
    }
    inv
}

/// Humanoid variants that are not isomorphic to it: an extra leaf at `attach`.
fn humanoid_with_leaf(attach: u32) -> ShapeGraph {
    let mut edges = humanoid().edges;
    edges.push((attach, 12));
    graph(13, &edges)
}

/// Pairs of graphs that are not isomorphic, for the swap and permutation identities.
fn test_pairs() -> Vec<(ShapeGraph, ShapeGraph)> {
    let mut pairs = vec![
        (humanoid(), humanoid_with_leaf(0)),
        (humanoid(), humanoid_with_leaf(3)),
        (humanoid_with_leaf(8), humanoid()),
        (star(4), star(5)),
    ];
    for seed in 0..4 {
        pairs.push((
            random_graph(14, 3, 100 + seed),
            random_graph(16, 2, 200 + seed),
        ));
    }
    pairs
}

#[test]
fn swapping_the_graphs_transposes_the_matches() {
    for (case, (a, b)) in test_pairs().iter().enumerate() {
        for term in TERMS {
            let ab = run_with(a, b, term);
            let ba = run_with(b, a, term);
            let transposed = sorted(ab.matches.iter().map(|&(i, j)| (j, i)).collect());
            assert_eq!(ba.matches, transposed, "case {case} {term:?}");
            assert!(!ab.matches.is_empty(), "case {case} {term:?}");
            // The scores are the same eigenvector, transposed.
            let (n_a, n_b) = (a.n_nodes(), b.n_nodes());
            for i in 0..n_a {
                for j in 0..n_b {
                    let (x, y) = (ab.scores[i * n_b + j], ba.scores[j * n_a + i]);
                    assert!(
                        (x - y).abs() <= 1e-9 * x.max(y).max(1e-3),
                        "case {case} {term:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn relabelling_b_relabels_the_matches() {
    for ((case, (a, b)), term) in test_pairs().iter().enumerate().zip(TERMS.iter().cycle()) {
        let run = |a: &ShapeGraph, b: &ShapeGraph| run_with(a, b, *term);
        let perm = random_permutation(b.n_nodes(), case as u64);
        let plain = run(a, b);
        let relabelled = run(a, &permuted(b, &perm));
        let expected = sorted(
            plain
                .matches
                .iter()
                .map(|&(i, j)| (i, perm[j as usize]))
                .collect(),
        );
        assert_eq!(relabelled.matches, expected, "case {case}");
        // Relabelling A too.
        let perm_a = random_permutation(a.n_nodes(), 50 + case as u64);
        let both = run(&permuted(a, &perm_a), &permuted(b, &perm));
        let expected = sorted(
            plain
                .matches
                .iter()
                .map(|&(i, j)| (perm_a[i as usize], perm[j as usize]))
                .collect(),
        );
        assert_eq!(both.matches, expected, "case {case}");
    }
}

#[test]
fn an_extra_leaf_leaves_the_common_structure_matched() {
    let a = humanoid();
    // A side leaf on the torso (a tail), an elbow, a hip, a knee. (A leaf at the end of a
    // chain would make it as long as another kind of chain: the head would become a third
    // arm, an arm a third leg, and the graphs alone could not tell them apart.)
    for attach in [0u32, 2, 6, 7] {
        let b = humanoid_with_leaf(attach);
        let m = run(&a, &b);
        let truth = humanoid_truth(&(0..12).collect::<Vec<u32>>());
        let mut matched = BTreeSet::new();
        for &(x, y) in &m.matches {
            if y == 12 {
                continue; // the extra leaf has no counterpart; anything is fine
            }
            assert!(
                truth.contains(&(x, y)),
                "leaf at {attach}: wrong match ({x}, {y}) in {:?}",
                m.matches
            );
            matched.insert(x);
        }
        // Every part keeps matches; most nodes do.
        assert!(
            matched.len() >= 9,
            "leaf at {attach}: only {} of 12 common nodes matched: {:?}",
            matched.len(),
            m.matches
        );
        for part in ["torso", "head", "arm", "leg"] {
            assert!(
                matched.iter().any(|&x| PART[x as usize] == part),
                "leaf at {attach}: no {part} matched: {:?}",
                m.matches
            );
        }
    }
}

#[test]
fn results_are_deterministic_across_runs_and_threads() {
    let a = random_graph(30, 5, 7);
    let b = random_graph(32, 4, 8);
    let first = run(&a, &b);
    assert_eq!(first, run(&a, &b));
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let again = pool.install(|| run(&a, &b));
        assert_eq!(first, again, "{threads} threads");
    }
}

#[test]
fn scores_are_a_unit_eigenvector_with_one_entry_per_candidate() {
    let (a, b) = (humanoid(), humanoid_with_leaf(3));
    let m = run(&a, &b);
    assert_eq!(m.scores.len(), 12 * 13);
    let norm: f64 = m.scores.iter().map(|s| s * s).sum::<f64>().sqrt();
    assert!((norm - 1.0).abs() < 1e-12);
    assert!(m.scores.iter().all(|&s| s >= 0.0));
    // Every match is its row's best score or within the gap of it.
    for &(i, j) in &m.matches {
        let row = &m.scores[i as usize * 13..(i as usize + 1) * 13];
        let best = row.iter().copied().fold(0.0, f64::max);
        assert!(m.scores[i as usize * 13 + j as usize] >= 0.9f64.powi(8) * best);
    }
}

// ---------------------------------------------------------------------------------------
// Measurements (ignored): timings and the choice of defaults.

fn stage_timings(a: &ShapeGraph, b: &ShapeGraph, params: &MatchingParams) -> (f64, f64, usize) {
    let t0 = Instant::now();
    let (ha, hb) = (a.hop_distances(), b.hop_distances());
    let costs = unary_costs(
        &distance_histograms(&ha, params.histogram_bins, params.normalise_histograms),
        &distance_histograms(&hb, params.histogram_bins, params.normalise_histograms),
    );
    let op = Affinity::new(&ha, &hb, &costs, params.sigma, params.distance_term).unwrap();
    let build = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let eig = leading_eigenvector(&op).unwrap();
    assert!(eig.converged);
    (build, t1.elapsed().as_secs_f64(), eig.products)
}

#[test]
#[ignore = "timing; run with --ignored --nocapture"]
fn timing_16_and_60_nodes() {
    for (n, extra) in [(16, 2), (30, 4), (60, 8)] {
        let a = random_graph(n, extra, 1);
        let b = random_graph(n, extra, 2);
        let params = MatchingParams::default();
        let op = {
            let (ha, hb) = (a.hop_distances(), b.hop_distances());
            let costs = unary_costs(
                &distance_histograms(&ha, 20, false),
                &distance_histograms(&hb, 20, false),
            );
            Affinity::new(&ha, &hb, &costs, 0.5, params.distance_term).unwrap()
        };
        let x = vec![1.0; op.dim()];
        let mut y = vec![0.0; op.dim()];
        let reps = 20;
        let t = Instant::now();
        for _ in 0..reps {
            op.apply(&x, &mut y);
        }
        let product = t.elapsed().as_secs_f64() / reps as f64;
        let (build, eigen, products) = stage_timings(&a, &b, &params);
        let t = Instant::now();
        let m = run(&a, &b);
        let total = t.elapsed().as_secs_f64();
        println!(
            "{n} x {n} nodes ({} candidates): product {:.2} ms, tables {:.2} ms, eigenvector \
             {:.2} ms ({products} products), match_graphs total {:.2} ms, {} matches, {} threads",
            op.dim(),
            product * 1e3,
            build * 1e3,
            eigen * 1e3,
            total * 1e3,
            m.matches.len(),
            rayon::current_num_threads()
        );
        // The same, same graph (large top cluster: every symmetric pair ties).
        let (_, eigen, products) = stage_timings(&a, &a, &params);
        println!(
            "  self-match eigenvector {:.2} ms ({products} products)",
            eigen * 1e3
        );
    }
}

/// A random "articulated" graph with ground truth: a core of `core` nodes (a path with a
/// chord or two) and limbs (chains) of given lengths hung on core nodes, with limbs of equal
/// length hung symmetrically. Returns the edges and, per node, a class id (nodes related by
/// the limb symmetry share the class).
fn articulated(rng: &mut ChaCha8Rng) -> (Vec<(u32, u32)>, Vec<u32>) {
    let core = rng.random_range(2..5u32);
    let mut edges: Vec<(u32, u32)> = (1..core).map(|v| (v - 1, v)).collect();
    let mut class: Vec<u32> = (0..core).collect();
    let mut next = core;
    let pairs = rng.random_range(1..4u32);
    let singles = rng.random_range(1..3u32);
    let mut next_class = core;
    for _ in 0..pairs {
        let attach = rng.random_range(0..core);
        let len = rng.random_range(1..5u32);
        for _side in 0..2 {
            let start = next;
            for t in 0..len {
                edges.push((if t == 0 { attach } else { start + t - 1 }, start + t));
                class.push(next_class + t);
            }
            next += len;
        }
        next_class += len;
    }
    for _ in 0..singles {
        let attach = rng.random_range(0..core);
        let len = rng.random_range(1..4u32);
        for t in 0..len {
            edges.push((if t == 0 { attach } else { next + t - 1 }, next + t));
            class.push(next_class + t);
        }
        next += len;
        next_class += len;
    }
    (edges, class)
}

#[derive(Default)]
struct Tally {
    pairs: usize,
    matches: usize,
    correct: usize,
    covered: usize,
    nodes: usize,
    exact: usize,
}

/// Scores one matching of `a` (classes `class`) against a perturbed copy whose node `y`
/// came from `origin[y]` of `a` (`None` for added nodes).
fn score(t: &mut Tally, m: &GraphMatching, class: &[u32], origin: &[Option<u32>], n_a: usize) {
    t.pairs += 1;
    let mut covered = vec![false; n_a];
    let mut all_right = true;
    for &(x, y) in &m.matches {
        let Some(o) = origin[y as usize] else {
            continue;
        };
        t.matches += 1;
        if class[x as usize] == class[o as usize] {
            t.correct += 1;
            covered[x as usize] = true;
        } else {
            all_right = false;
        }
    }
    t.covered += covered.iter().filter(|&&c| c).count();
    t.nodes += n_a;
    if all_right && covered.iter().all(|&c| c) {
        t.exact += 1;
    }
}

#[test]
#[ignore = "measurement; run with --ignored --nocapture"]
fn measure_variants() {
    let variants: Vec<(&str, MatchingParams)> = [false, true]
        .into_iter()
        .flat_map(|normalise| {
            [DistanceTerm::Difference, DistanceTerm::Ratio]
                .into_iter()
                .map(move |term| {
                    (
                        format!("normalise={normalise} term={term:?}"),
                        MatchingParams {
                            normalise_histograms: normalise,
                            distance_term: term,
                            ..Default::default()
                        },
                    )
                })
        })
        .map(|(name, p)| (Box::leak(name.into_boxed_str()) as &str, p))
        .collect();
    // Perturbations of a random articulated graph: none (relabelled copy), an extra leaf,
    // a node inserted into an edge, an extra chord between neighbours' neighbours, a leaf
    // removed.
    let kinds = [
        "copy",
        "extra leaf",
        "split edge",
        "extra chord",
        "leaf removed",
    ];
    for kind in kinds {
        let mut tallies: Vec<Tally> = variants.iter().map(|_| Tally::default()).collect();
        for seed in 0..200u64 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let (edges, class) = articulated(&mut rng);
            let n = class.len();
            let a = graph(n, &edges);
            let mut b_edges = edges.clone();
            let mut origin: Vec<Option<u32>> = (0..n as u32).map(Some).collect();
            match kind {
                "copy" => {}
                "extra leaf" => {
                    let at = rng.random_range(0..n as u32);
                    b_edges.push((at, n as u32));
                    origin.push(None);
                }
                "split edge" => {
                    let e = rng.random_range(0..b_edges.len());
                    let (x, y) = b_edges.remove(e);
                    b_edges.push((x, n as u32));
                    b_edges.push((n as u32, y));
                    origin.push(None);
                }
                "extra chord" => {
                    let hops = a.hop_distances();
                    let candidates: Vec<(u32, u32)> = (0..n)
                        .flat_map(|x| (x + 1..n).map(move |y| (x, y)))
                        .filter(|&(x, y)| hops[x][y] == 2)
                        .map(|(x, y)| (x as u32, y as u32))
                        .collect();
                    let c = candidates[rng.random_range(0..candidates.len())];
                    b_edges.push(c);
                }
                _ => {
                    let degrees = a.degrees();
                    let leaves: Vec<u32> = (0..n as u32)
                        .filter(|&x| degrees[x as usize] == 1)
                        .collect();
                    let leaf = leaves[rng.random_range(0..leaves.len())];
                    // Drop the leaf: renumber the nodes after it.
                    b_edges.retain(|&(x, y)| x != leaf && y != leaf);
                    let renum = |v: u32| if v > leaf { v - 1 } else { v };
                    b_edges = b_edges.iter().map(|&(x, y)| (renum(x), renum(y))).collect();
                    origin.remove(leaf as usize);
                }
            }
            let nb = origin.len();
            let b = graph(nb, &b_edges);
            // Relabel B so that indices carry no information.
            let perm = random_permutation(nb, seed + 1000);
            let b = permuted(&b, &perm);
            let mut origin_p = vec![None; nb];
            for (y, o) in origin.iter().enumerate() {
                origin_p[perm[y] as usize] = *o;
            }
            for ((_, params), tally) in variants.iter().zip(&mut tallies) {
                let m = match_graphs(&a, &b, params).unwrap();
                score(tally, &m, &class, &origin_p, n);
            }
        }
        println!("{kind}:");
        for ((name, _), t) in variants.iter().zip(&tallies) {
            println!(
                "  {name:40} precision {:.3}  coverage {:.3}  all-right pairs {:.3}  \
                 ({} matches, {} pairs)",
                t.correct as f64 / t.matches.max(1) as f64,
                t.covered as f64 / t.nodes as f64,
                t.exact as f64 / t.pairs as f64,
                t.matches,
                t.pairs
            );
        }
    }
}
