//! Symmetry breaking (paper, section 5.2; DESIGN section 4): region distances on surfaces
//! (`shapecorr::geodesic`) and one-to-one region matches from symmetric ones
//! (`shapecorr::regions::symmetry`), on constructed layouts whose right answers are known, on
//! generated figures, and (timings) on the benchmark shapes when present.

use std::path::{Path, PathBuf};
use std::time::Instant;

use faer::Mat;
use proptest::prelude::*;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use shapecorr::geodesic::{edge_graph_distances, region_distance_matrix};
use shapecorr::regions::symmetry::{
    bipartite_groups, distortion_energy, greedy_one_to_one, one_to_one, OneToOneMethod,
    SymmetryParams,
};
use shapecorr::synth::{figure_poses, FigureKind, Proportions};
use shapecorr::ReadAs;
use shapecorr::{Error, Shape};

// ---------------------------------------------------------------------------------------
// Layouts: region centres with a left/right mirror, distances = Euclidean distances.

type V = [f64; 3];

fn dist(a: V, b: V) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Region centres and, for every region, its mirror image (itself on the symmetry plane).
struct Layout {
    points: Vec<V>,
    mirror: Vec<usize>,
}

impl Layout {
    /// Adds a region on the plane x = 0.
    fn centre(&mut self, p: V) {
        self.mirror.push(self.points.len());
        self.points.push(p);
    }

    /// Adds a left region at `p` (x < 0) and its mirror image, left first.
    fn pair(&mut self, p: V) {
        let n = self.points.len();
        self.points.push(p);
        self.points.push([-p[0], p[1], p[2]]);
        self.mirror.extend([n + 1, n]);
    }

    fn len(&self) -> usize {
        self.points.len()
    }

    /// Euclidean distances between the centres, regions renumbered by `perm` (region `i`
    /// of the layout is region `perm[i]` of the matrix).
    fn distances(&self, perm: &[usize]) -> Mat<f64> {
        let n = self.len();
        let mut d = Mat::zeros(n, n);
        for i in 0..n {
            for j in 0..n {
                d[(perm[i], perm[j])] = dist(self.points[i], self.points[j]);
            }
        }
        d
    }

    /// Symmetric matches from the layout (as A) to its renumbering by `perm` (as B): every
    /// region to its image and to its mirror's image.
    fn symmetric_matches(&self, perm: &[usize]) -> Vec<(u32, u32)> {
        let mut m: Vec<(u32, u32)> = (0..self.len())
            .flat_map(|i| {
                [
                    (i as u32, perm[i] as u32),
                    (i as u32, perm[self.mirror[i]] as u32),
                ]
            })
            .collect();
        m.sort_unstable();
        m.dedup();
        m
    }

    /// Adds the matches of every region of `regions` to the images of all of them (a
    /// group matched all-to-all), keeping `symmetric` sorted without duplicates.
    fn all_to_all(
        &self,
        regions: std::ops::Range<usize>,
        perm: &[usize],
        symmetric: &mut Vec<(u32, u32)>,
    ) {
        for i in regions.clone() {
            for &image in &perm[regions.clone()] {
                symmetric.push((i as u32, image as u32));
            }
        }
        symmetric.sort_unstable();
        symmetric.dedup();
    }

    /// `Some(false)` for the identity (up to `perm`), `Some(true)` for the full mirror
    /// flip, `None` for anything else (a mixed flip, a missing or a wrong match).
    fn orientation(&self, perm: &[usize], result: &[(u32, u32)]) -> Option<bool> {
        let as_set = |flip: bool| {
            let mut m: Vec<(u32, u32)> = (0..self.len())
                .map(|i| {
                    let j = if flip { self.mirror[i] } else { i };
                    (i as u32, perm[j] as u32)
                })
                .collect();
            m.sort_unstable();
            m
        };
        let mut r = result.to_vec();
        r.sort_unstable();
        if r == as_set(false) {
            Some(false)
        } else if r == as_set(true) {
            Some(true)
        } else {
            None
        }
    }
}

/// Torso, head, two arms, two legs (arms first).
fn two_arms_two_legs() -> Layout {
    let mut l = Layout {
        points: Vec::new(),
        mirror: Vec::new(),
    };
    l.centre([0.0, 1.2, 0.0]);
    l.centre([0.0, 1.75, 0.0]);
    l.pair([-0.6, 1.35, 0.0]);
    l.pair([-0.15, 0.5, 0.0]);
    l
}

/// A figure in a T-pose: torso, head, pelvis; upper arms, forearms, hands, thighs, shins,
/// feet as left/right pairs (regions 3..=14, upper arms 3 and 4, thighs 9 and 10).
fn humanoid() -> Layout {
    let mut l = Layout {
        points: Vec::new(),
        mirror: Vec::new(),
    };
    l.centre([0.0, 1.25, 0.0]);
    l.centre([0.0, 1.75, 0.0]);
    l.centre([0.0, 0.9, 0.0]);
    l.pair([-0.5, 1.4, 0.0]);
    l.pair([-0.9, 1.4, 0.0]);
    l.pair([-1.25, 1.4, 0.0]);
    l.pair([-0.15, 0.7, 0.0]);
    l.pair([-0.15, 0.35, 0.0]);
    l.pair([-0.15, 0.05, 0.1]);
    l
}

fn shuffled(n: usize, seed: u64) -> Vec<usize> {
    let mut perm: Vec<usize> = (0..n).collect();
    perm.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
    perm
}

/// Adds symmetric uniform noise in [-amplitude, amplitude] to the off-diagonal entries.
fn add_noise(d: &mut Mat<f64>, amplitude: f64, seed: u64) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for i in 0..d.nrows() {
        for j in i + 1..d.ncols() {
            let e = amplitude * (2.0 * rng.random::<f64>() - 1.0);
            d[(i, j)] += e;
            d[(j, i)] += e;
        }
    }
}

fn local_search() -> SymmetryParams {
    SymmetryParams {
        exhaustive_limit: 0,
        ..SymmetryParams::default()
    }
}

fn greedy() -> SymmetryParams {
    SymmetryParams {
        method: OneToOneMethod::Greedy,
        ..SymmetryParams::default()
    }
}

/// Size of a maximum matching of `edges` (augmenting paths), independent of the library.
fn maximum_matching_size(edges: &[(u32, u32)]) -> usize {
    fn augment(
        a: u32,
        edges: &[(u32, u32)],
        seen: &mut Vec<u32>,
        partner: &mut std::collections::HashMap<u32, u32>,
    ) -> bool {
        for &(x, b) in edges {
            if x == a && !seen.contains(&b) {
                seen.push(b);
                let free = match partner.get(&b) {
                    None => true,
                    Some(&other) => augment(other, edges, seen, partner),
                };
                if free {
                    partner.insert(b, a);
                    return true;
                }
            }
        }
        false
    }
    let mut rows: Vec<u32> = edges.iter().map(|e| e.0).collect();
    rows.sort_unstable();
    rows.dedup();
    let mut partner = std::collections::HashMap::new();
    rows.iter()
        .filter(|&&a| augment(a, edges, &mut Vec::new(), &mut partner))
        .count()
}

/// The result is a subset of the symmetric matches, one-to-one, and (when
/// `maximum_per_group`) keeps a maximum matching in every group.
fn check_one_to_one(symmetric: &[(u32, u32)], result: &[(u32, u32)], maximum_per_group: bool) {
    for m in result {
        assert!(symmetric.contains(m), "{m:?} is not a symmetric match");
    }
    let mut a: Vec<u32> = result.iter().map(|m| m.0).collect();
    let mut b: Vec<u32> = result.iter().map(|m| m.1).collect();
    a.sort_unstable();
    b.sort_unstable();
    let (na, nb) = (a.len(), b.len());
    a.dedup();
    b.dedup();
    assert_eq!((a.len(), b.len()), (na, nb), "not one-to-one: {result:?}");
    if maximum_per_group {
        for (ga, _) in bipartite_groups(symmetric) {
            let edges: Vec<(u32, u32)> = symmetric
                .iter()
                .copied()
                .filter(|m| ga.contains(&m.0))
                .collect();
            let kept = result.iter().filter(|m| ga.contains(&m.0)).count();
            assert_eq!(kept, maximum_matching_size(&edges), "group {ga:?}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// one_to_one on constructed layouts

#[test]
fn two_arms_two_legs_are_resolved_consistently() {
    let layout = two_arms_two_legs();
    for seed in 0..20 {
        let perm = shuffled(layout.len(), seed);
        let d1 = layout.distances(&(0..layout.len()).collect::<Vec<_>>());
        let d2 = layout.distances(&perm);
        let symmetric = layout.symmetric_matches(&perm);
        // Both arms to both arms, both legs to both legs.
        assert_eq!(symmetric.len(), 2 + 4 + 4);
        for params in [SymmetryParams::default(), local_search()] {
            let result = one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &params).unwrap();
            check_one_to_one(&symmetric, &result, true);
            assert!(
                layout.orientation(&perm, &result).is_some(),
                "seed {seed}: mixed flip {result:?}"
            );
            assert!(distortion_energy(&result, d1.as_ref(), d2.as_ref()) < 1e-12);
        }
    }
}

#[test]
fn a_mixed_flip_costs_more_than_a_consistent_one() {
    // The energy itself tells the consistent answers from the mixed ones.
    let layout = two_arms_two_legs();
    let id: Vec<usize> = (0..layout.len()).collect();
    let d = layout.distances(&id);
    let consistent: Vec<(u32, u32)> = vec![(0, 0), (1, 1), (2, 3), (3, 2), (4, 5), (5, 4)];
    let mixed: Vec<(u32, u32)> = vec![(0, 0), (1, 1), (2, 3), (3, 2), (4, 4), (5, 5)];
    assert!(distortion_energy(&consistent, d.as_ref(), d.as_ref()) < 1e-12);
    // The mixed flip errs by |cross - same side| at each of the 8 ordered arm-leg pairs.
    let (arm, leg) = (layout.points[2], layout.points[4]);
    let margin = dist([-arm[0], arm[1], arm[2]], leg) - dist(arm, leg);
    let mixed_energy = distortion_energy(&mixed, d.as_ref(), d.as_ref());
    assert!(margin > 0.1);
    assert!(
        (mixed_energy - 8.0 * margin / 36.0).abs() < 1e-12,
        "{mixed_energy}"
    );
}

#[test]
fn greedy_flips_the_legs_where_the_whole_assignment_does_not() {
    // One noisy distance: in B each upper arm looks slightly nearer to the opposite thigh
    // than to its own (0.70 against 0.78; really 0.96). The greedy growth decides the
    // thighs on that single comparison and flips the legs but not the arms; the whole
    // assignment pays for the noise once, the mixed flip at 72 arm-leg distances.
    let layout = humanoid();
    let id: Vec<usize> = (0..layout.len()).collect();
    let perm = shuffled(layout.len(), 7);
    let d1 = layout.distances(&id);
    let mut d2 = layout.distances(&perm);
    let (upper_left, upper_right, thigh_left, thigh_right) = (3, 4, 9, 10);
    let own = dist(layout.points[upper_left], layout.points[thigh_left]);
    assert!((own - 0.7826).abs() < 1e-3);
    for (arm, thigh) in [(upper_left, thigh_right), (upper_right, thigh_left)] {
        d2[(perm[arm], perm[thigh])] = 0.70;
        d2[(perm[thigh], perm[arm])] = 0.70;
    }
    let symmetric = layout.symmetric_matches(&perm);

    let paper = greedy_one_to_one(&symmetric, d1.as_ref(), d2.as_ref()).unwrap();
    check_one_to_one(&symmetric, &paper, true);
    assert_eq!(layout.orientation(&perm, &paper), None, "{paper:?}");
    let arms_flipped = paper.contains(&(upper_left as u32, perm[upper_right] as u32));
    let legs_flipped = paper.contains(&(thigh_left as u32, perm[thigh_right] as u32));
    assert_ne!(arms_flipped, legs_flipped);
    // The method switch gives the same answer as the function.
    assert_eq!(
        one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &greedy()).unwrap(),
        paper
    );

    for params in [SymmetryParams::default(), local_search()] {
        let whole = one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &params).unwrap();
        check_one_to_one(&symmetric, &whole, true);
        assert!(layout.orientation(&perm, &whole).is_some(), "{whole:?}");
        assert!(
            distortion_energy(&whole, d1.as_ref(), d2.as_ref())
                < distortion_energy(&paper, d1.as_ref(), d2.as_ref())
        );
    }
}

#[test]
fn whole_assignment_is_consistent_under_noise_more_often_than_greedy() {
    let layout = humanoid();
    let id: Vec<usize> = (0..layout.len()).collect();
    let d1 = layout.distances(&id);
    let (mut whole_ok, mut greedy_ok) = (0, 0);
    let trials = 200;
    for seed in 0..trials {
        let perm = shuffled(layout.len(), 1000 + seed);
        let mut d2 = layout.distances(&perm);
        add_noise(&mut d2, 0.12, seed);
        let symmetric = layout.symmetric_matches(&perm);
        let whole = one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &Default::default()).unwrap();
        let paper = greedy_one_to_one(&symmetric, d1.as_ref(), d2.as_ref()).unwrap();
        check_one_to_one(&symmetric, &whole, true);
        check_one_to_one(&symmetric, &paper, false);
        whole_ok += usize::from(layout.orientation(&perm, &whole).is_some());
        greedy_ok += usize::from(layout.orientation(&perm, &paper).is_some());
    }
    eprintln!(
        "consistent under noise: whole assignment {whole_ok}/{trials}, greedy {greedy_ok}/{trials}"
    );
    assert!(whole_ok > greedy_ok, "whole {whole_ok}, greedy {greedy_ok}");
    assert!(whole_ok as f64 >= 0.95 * trials as f64, "whole {whole_ok}");
}

/// A layout, its symmetric matches, D1 and D2.
type Instance = (Layout, Vec<(u32, u32)>, Mat<f64>, Mat<f64>);

/// A random layout: `centres` regions on the plane, `pairs` mirrored pairs and, when
/// `triple`, three regions matched all-to-all (a 3x3 group).
fn random_instance(seed: u64, centres: usize, pairs: usize, triple: bool) -> Instance {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut layout = Layout {
        points: Vec::new(),
        mirror: Vec::new(),
    };
    let coordinate = |rng: &mut ChaCha8Rng| 2.0 * rng.random::<f64>() - 1.0;
    for _ in 0..centres {
        layout.centre([0.0, coordinate(&mut rng), coordinate(&mut rng)]);
    }
    for _ in 0..pairs {
        layout.pair([
            -0.2 - coordinate(&mut rng).abs(),
            coordinate(&mut rng),
            coordinate(&mut rng),
        ]);
    }
    let first_of_triple = layout.len();
    if triple {
        for _ in 0..3 {
            layout.centre([
                coordinate(&mut rng),
                coordinate(&mut rng),
                coordinate(&mut rng),
            ]);
        }
    }
    let perm = shuffled(layout.len(), seed ^ 0xabc);
    let d1 = layout.distances(&(0..layout.len()).collect::<Vec<_>>());
    let mut d2 = layout.distances(&perm);
    add_noise(&mut d2, 0.1, seed);
    let mut symmetric = layout.symmetric_matches(&perm);
    if triple {
        layout.all_to_all(first_of_triple..first_of_triple + 3, &perm, &mut symmetric);
    }
    (layout, symmetric, d1, d2)
}

#[test]
fn exhaustive_and_local_search_agree_on_small_instances() {
    for seed in 0..60 {
        let pairs = 1 + (seed as usize % 8);
        let triple = seed % 3 == 0;
        let (_, symmetric, d1, d2) = random_instance(seed, 2, pairs, triple);
        let exhaustive =
            one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &Default::default()).unwrap();
        let local = one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &local_search()).unwrap();
        check_one_to_one(&symmetric, &exhaustive, true);
        check_one_to_one(&symmetric, &local, true);
        let (e, l) = (
            distortion_energy(&exhaustive, d1.as_ref(), d2.as_ref()),
            distortion_energy(&local, d1.as_ref(), d2.as_ref()),
        );
        assert!(
            (e - l).abs() <= 1e-12 * e.max(1.0),
            "seed {seed}: exhaustive {e}, local {l}"
        );
    }
}

#[test]
fn exhaustive_search_finds_the_minimum_energy() {
    // Against a brute force over every one-to-one subset of a few pairs' options.
    for seed in 0..10 {
        let (layout, symmetric, d1, d2) = random_instance(100 + seed, 1, 3, false);
        let result = one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &Default::default()).unwrap();
        let best = distortion_energy(&result, d1.as_ref(), d2.as_ref());
        // Three pairs: 8 combinations of flips, each group (a, a') to its two B regions.
        let groups: Vec<(Vec<u32>, Vec<u32>)> = bipartite_groups(&symmetric)
            .into_iter()
            .filter(|g| g.0.len() > 1)
            .collect();
        assert_eq!(groups.len(), 3);
        let fixed: Vec<(u32, u32)> = bipartite_groups(&symmetric)
            .into_iter()
            .filter(|g| g.0.len() == 1)
            .map(|g| (g.0[0], g.1[0]))
            .collect();
        let mut minimum = f64::INFINITY;
        for flips in 0..8u32 {
            let mut pairs = fixed.clone();
            for (k, (a, b)) in groups.iter().enumerate() {
                let flip = (flips >> k) & 1 == 1;
                pairs.push((a[0], b[usize::from(flip)]));
                pairs.push((a[1], b[usize::from(!flip)]));
            }
            minimum = minimum.min(distortion_energy(&pairs, d1.as_ref(), d2.as_ref()));
        }
        assert!(
            (best - minimum).abs() <= 1e-12 * minimum,
            "seed {seed}: {best} vs {minimum}"
        );
        assert!(layout.len() == 7);
    }
}

/// 12 mirrored leg pairs along a spine and a hexagonal ring of 6 regions at one end (a
/// 6x6 group of 720 options): 2^12 * 720 combinations, far beyond exhaustive search.
fn centipede() -> (Layout, usize) {
    let mut layout = Layout {
        points: Vec::new(),
        mirror: Vec::new(),
    };
    for k in 0..12 {
        layout.centre([0.0, 0.0, k as f64 * 0.3]);
    }
    for k in 0..12 {
        layout.pair([-1.0, -0.2, k as f64 * 0.3 + 0.05 * (k % 3) as f64]);
    }
    let ring = layout.len();
    // Ring points symmetric about x = 0: three on the left and their mirror images.
    for m in 0..3 {
        let angle = std::f64::consts::PI * (0.5 + m as f64) / 3.0 + std::f64::consts::FRAC_PI_2;
        layout.pair([0.5 * angle.cos(), 0.5 * angle.sin(), -0.6]);
    }
    (layout, ring)
}

#[test]
fn a_large_instance_finishes_quickly_and_consistently() {
    let (layout, ring) = centipede();
    let perm = shuffled(layout.len(), 3);
    let d1 = layout.distances(&(0..layout.len()).collect::<Vec<_>>());
    let d2 = layout.distances(&perm);
    let mut symmetric = layout.symmetric_matches(&perm);
    layout.all_to_all(ring..ring + 6, &perm, &mut symmetric);
    let groups = bipartite_groups(&symmetric);
    assert_eq!(groups.iter().filter(|g| g.0.len() == 2).count(), 12);
    assert_eq!(groups.iter().filter(|g| g.0.len() == 6).count(), 1);

    let start = Instant::now();
    let result = one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &Default::default()).unwrap();
    let elapsed = start.elapsed().as_secs_f64();
    eprintln!(
        "large instance (2^12 * 720 combinations): {:.1} ms",
        1e3 * elapsed
    );
    assert!(elapsed < 1.0, "took {elapsed} s");
    check_one_to_one(&symmetric, &result, true);
    assert!(layout.orientation(&perm, &result).is_some(), "{result:?}");
    assert!(distortion_energy(&result, d1.as_ref(), d2.as_ref()) < 1e-12);

    // With noise the answer stays consistent.
    let mut noisy = d2.clone();
    add_noise(&mut noisy, 0.03, 11);
    let result = one_to_one(&symmetric, d1.as_ref(), noisy.as_ref(), &Default::default()).unwrap();
    assert!(layout.orientation(&perm, &result).is_some(), "{result:?}");
}

#[test]
fn results_are_deterministic_and_seeded() {
    let (layout, ring) = centipede();
    let perm = shuffled(layout.len(), 5);
    let d1 = layout.distances(&(0..layout.len()).collect::<Vec<_>>());
    let mut d2 = layout.distances(&perm);
    add_noise(&mut d2, 0.2, 5);
    let mut symmetric = layout.symmetric_matches(&perm);
    layout.all_to_all(ring..ring + 6, &perm, &mut symmetric);
    // Duplicates and order in the input do not matter.
    let mut reordered = symmetric.clone();
    reordered.reverse();
    reordered.extend_from_slice(&symmetric[..5]);
    for method in [OneToOneMethod::WholeAssignment, OneToOneMethod::Greedy] {
        let params = SymmetryParams {
            method,
            ..Default::default()
        };
        let first = one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &params).unwrap();
        let again = one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &params).unwrap();
        let shuffled_input = one_to_one(&reordered, d1.as_ref(), d2.as_ref(), &params).unwrap();
        assert_eq!(first, again);
        assert_eq!(first, shuffled_input);
        assert!(first.windows(2).all(|w| w[0] < w[1]), "sorted");
    }
}

#[test]
fn bad_inputs_are_errors() {
    let layout = two_arms_two_legs();
    let id: Vec<usize> = (0..layout.len()).collect();
    let d = layout.distances(&id);
    let symmetric = layout.symmetric_matches(&id);
    let params = SymmetryParams::default();
    let not_square = Mat::<f64>::zeros(6, 5);
    assert!(matches!(
        one_to_one(&symmetric, not_square.as_ref(), d.as_ref(), &params),
        Err(Error::InvalidParameter { name: "d1", .. })
    ));
    let out_of_range = [(0u32, 6u32)];
    assert!(matches!(
        one_to_one(&out_of_range, d.as_ref(), d.as_ref(), &params),
        Err(Error::InvalidParameter {
            name: "symmetric",
            ..
        })
    ));
    let mut nan = d.clone();
    nan[(1, 2)] = f64::NAN;
    assert!(matches!(
        greedy_one_to_one(&symmetric, d.as_ref(), nan.as_ref()),
        Err(Error::InvalidParameter { name: "d2", .. })
    ));
    // Nothing to match is not an error.
    assert!(one_to_one(&[], d.as_ref(), d.as_ref(), &params)
        .unwrap()
        .is_empty());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Any symmetric matches, any distances: a one-to-one subset; the whole assignment keeps
    /// a maximum matching in every group.
    #[test]
    fn output_is_a_one_to_one_subset(
        n_a in 1usize..12,
        n_b in 1usize..12,
        seed in any::<u64>(),
        density in 0.05f64..0.6,
        exhaustive_limit in prop_oneof![Just(0usize), Just(5000usize)],
    ) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut symmetric = Vec::new();
        for a in 0..n_a as u32 {
            for b in 0..n_b as u32 {
                if rng.random::<f64>() < density {
                    symmetric.push((a, b));
                }
            }
        }
        let mut random_metric = |n: usize| {
            let points: Vec<V> = (0..n).map(|_| [rng.random(), rng.random(), rng.random()]).collect();
            Mat::from_fn(n, n, |i, j| dist(points[i], points[j]))
        };
        let d1 = random_metric(n_a);
        let d2 = random_metric(n_b);
        let params = SymmetryParams { exhaustive_limit, seed, ..Default::default() };
        let whole = one_to_one(&symmetric, d1.as_ref(), d2.as_ref(), &params).unwrap();
        check_one_to_one(&symmetric, &whole, true);
        let paper = greedy_one_to_one(&symmetric, d1.as_ref(), d2.as_ref()).unwrap();
        check_one_to_one(&symmetric, &paper, false);
    }
}

#[test]
fn bipartite_groups_are_components_in_order() {
    let matches = [(4, 0), (0, 2), (1, 2), (1, 3), (2, 1), (3, 5), (4, 4)];
    let groups = bipartite_groups(&matches);
    assert_eq!(
        groups,
        vec![
            (vec![0, 1], vec![2, 3]),
            (vec![2], vec![1]),
            (vec![3], vec![5]),
            (vec![4], vec![0, 4]),
        ]
    );
    assert!(bipartite_groups(&[]).is_empty());
}

// ---------------------------------------------------------------------------------------
// Region distances on surfaces

/// Barycentric vertex areas, normalised to sum to 1, and the total area.
fn vertex_mass(shape: &Shape) -> (Vec<f64>, f64) {
    let v = shape.vertices();
    let mut mass = vec![0.0; v.len()];
    let mut total = 0.0;
    for t in shape.triangles() {
        let [a, b, c] = t.map(|i| v[i as usize]);
        let (u, w) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let cross = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        let area = 0.5 * (cross[0].powi(2) + cross[1].powi(2) + cross[2].powi(2)).sqrt();
        total += area;
        for &i in t {
            mass[i as usize] += area / 3.0;
        }
    }
    (mass.iter().map(|m| m / total).collect(), total)
}

/// A simple segmentation: `k` seeds by farthest-point sampling from vertex 0 and every
/// vertex labelled by its nearest seed, both along the edge graph.
fn voronoi_labels(shape: &Shape, k: usize) -> Vec<u32> {
    let mut seeds = vec![shape.active_vertices()[0]];
    let mut nearest = edge_graph_distances(shape, &seeds, 1.0);
    let mut label = vec![0u32; shape.n_vertices()];
    for s in 1..k {
        let far = (0..nearest.len())
            .filter(|&v| nearest[v].is_finite())
            .max_by(|&x, &y| nearest[x].total_cmp(&nearest[y]).then(y.cmp(&x)))
            .unwrap() as u32;
        seeds.push(far);
        let d = edge_graph_distances(shape, &[far], 1.0);
        for v in 0..nearest.len() {
            if d[v] < nearest[v] {
                nearest[v] = d[v];
                label[v] = s as u32;
            }
        }
    }
    label
}

fn relative_difference(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    (a - b).norm_l2() / a.norm_l2()
}

#[test]
fn region_distances_of_two_poses_agree() {
    let poses = figure_poses(FigureKind::Humanoid, 4000, Proportions::default(), &[0, 2]).unwrap();
    let shapes: Vec<Shape> = poses
        .iter()
        .map(|m| Shape::mesh(m.vertices.clone(), &m.triangles).unwrap())
        .collect();
    // Vertex i is the same body point in both poses: the rest pose's labels serve both.
    let labels = voronoi_labels(&shapes[0], 12);
    let matrices: Vec<Mat<f64>> = shapes
        .iter()
        .map(|s| {
            let (mass, area) = vertex_mass(s);
            region_distance_matrix(s, &mass, &labels, 12, 1.0 / area.sqrt())
        })
        .collect();
    let (d0, d2) = (&matrices[0], &matrices[1]);
    for d in [d0, d2] {
        for r in 0..12 {
            assert_eq!(d[(r, r)], 0.0);
            for q in 0..12 {
                assert_eq!(d[(r, q)], d[(q, r)]);
                if q != r {
                    assert!(d[(r, q)] > 0.0 && d[(r, q)] < 3.0, "{}", d[(r, q)]);
                }
            }
        }
    }
    let difference = relative_difference(d0, d2);
    // Against the regions of the other pose shuffled: the labels matter.
    let perm = shuffled(12, 1);
    let shuffled_d2 = Mat::from_fn(12, 12, |i, j| d2[(perm[i], perm[j])]);
    let unrelated = relative_difference(d0, &shuffled_d2);
    eprintln!("pose 0 vs 2 region distances: relative difference {difference:.4} (shuffled regions {unrelated:.3})");
    assert!(difference < 0.05, "{difference}");
    assert!(unrelated > 5.0 * difference, "{unrelated}");
}

/// The benchmark data (`SHAPECORR_DATA` or `../shared/data`), if present.
fn benchmark_file(relative: &str) -> Option<PathBuf> {
    let dir = std::env::var_os("SHAPECORR_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data"));
    let path = dir.join(relative);
    if path.is_file() {
        Some(path)
    } else {
        eprintln!("note: {} not found; skipping", path.display());
        None
    }
}

#[test]
fn region_distance_matrix_on_benchmark_shapes() {
    for relative in ["faust/tr_reg_000.ply", "tosca/david0.ply"] {
        let Some(path) = benchmark_file(relative) else {
            continue;
        };
        let shape = Shape::read(&path, ReadAs::Auto).unwrap();
        let (mass, area) = vertex_mass(&shape);
        let labels = voronoi_labels(&shape, 16);
        let start = Instant::now();
        let d = region_distance_matrix(&shape, &mass, &labels, 16, 1.0 / area.sqrt());
        let elapsed = start.elapsed().as_secs_f64();
        eprintln!(
            "{relative}: {} vertices, 16 regions: region_distance_matrix {:.1} ms",
            shape.n_vertices(),
            1e3 * elapsed
        );
        for r in 0..16 {
            assert_eq!(d[(r, r)], 0.0);
            for q in 0..16 {
                assert_eq!(d[(r, q)], d[(q, r)]);
                assert!(d[(r, q)].is_finite());
                if q != r {
                    assert!(d[(r, q)] > 0.0, "{relative}: ({r}, {q})");
                }
            }
        }
    }
}
