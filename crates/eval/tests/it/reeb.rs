//! The Reeb-graph baseline (paper section 6.2, Table 1 "Reeb"): graph structure on
//! generated figures with known functions, the equal-area levels, and the baseline end to
//! end through the same matcher and scores as the main method.

use shapecorr::correspondence::Params;
use shapecorr::evaluation::score_correspondence;
use shapecorr::regions::graph::ShapeGraph;
use shapecorr::synth::{self, FigureKind, FigureMesh, FigureSpec};
use shapecorr::ReadAs;
use shapecorr::{EigenParams, Eigenbasis, Error, Shape};
use shapecorr_eval::reeb::{
    hks_function, level_boundaries, level_of, reeb_correspondence, reeb_graph, shape_reeb_graph,
    ReebParams,
};

fn figure(kind: FigureKind, pose: usize, vertices: usize) -> FigureMesh {
    synth::figure(&FigureSpec {
        kind,
        pose,
        target_vertices: vertices,
        ..Default::default()
    })
    .unwrap()
}

fn mesh(f: &FigureMesh) -> Shape {
    Shape::mesh(f.vertices.clone(), &f.triangles).unwrap()
}

fn basis(shape: &Shape, n: usize) -> Eigenbasis {
    Eigenbasis::compute(
        shape,
        &EigenParams {
            n_eigenpairs: n,
            ..Default::default()
        },
    )
    .unwrap()
}

/// Distance from the vertical (y) axis: the star's limbs lie in the xz plane.
fn radial(shape: &Shape) -> Vec<f64> {
    shape
        .vertices()
        .iter()
        .map(|p| (p[0] * p[0] + p[2] * p[2]).sqrt())
        .collect()
}

fn height(shape: &Shape) -> Vec<f64> {
    shape.vertices().iter().map(|p| p[1]).collect()
}

/// Number of nodes of every level.
fn nodes_per_level(g: &ShapeGraph, levels: usize) -> Vec<usize> {
    let mut count = vec![0; levels];
    for &c in &g.node_cluster {
        count[c as usize] += 1;
    }
    count
}

fn is_tree(g: &ShapeGraph) -> bool {
    g.is_connected() && g.edges.len() + 1 == g.n_nodes()
}

#[test]
fn star_radial_function_gives_a_star_shaped_tree() {
    // Body radius 0.3, limbs from 0.25 to about 1.26 from the axis: below 0.5 the body with
    // the limb roots is one piece, every band beyond cuts each limb once.
    for limbs in [3, 5] {
        let shape = mesh(&figure(FigureKind::Star { limbs }, 0, 2000));
        let mass = vec![1.0; shape.n_vertices()];
        let boundaries = [0.5, 0.8, 1.05];
        let g = reeb_graph(&shape, &mass, &radial(&shape), &boundaries, 0.0).unwrap();
        assert_eq!(nodes_per_level(&g, 4), vec![1, limbs, limbs, limbs]);
        assert!(is_tree(&g), "edges {:?}", g.edges);
        let mut degrees = g.degrees();
        degrees.sort_unstable();
        let mut expected = vec![1; limbs];
        expected.extend(vec![2; 2 * limbs]);
        expected.push(limbs);
        assert_eq!(degrees, expected);
        // Every edge joins consecutive levels.
        for &(i, j) in &g.edges {
            let (ci, cj) = (g.node_cluster[i as usize], g.node_cluster[j as usize]);
            assert_eq!(ci.abs_diff(cj), 1, "edge ({i}, {j}) skips a level");
        }
    }
}

#[test]
fn humanoid_height_levels_split_legs_and_end_in_one_head() {
    let shape = mesh(&figure(FigureKind::Humanoid, 0, 3000));
    let b = basis(&shape, 10);
    let f = height(&shape);
    let levels = 8;
    let boundaries = level_boundaries(&[(&f, &b.mass)], levels).unwrap();
    let g = reeb_graph(&shape, &b.mass, &f, &boundaries, 0.002).unwrap();
    let per_level = nodes_per_level(&g, levels);
    println!("height graph: {per_level:?}, edges {:?}", g.edges);
    assert_eq!(per_level[0], 2, "the lowest eighth of the area is two feet");
    assert_eq!(per_level[levels - 1], 1, "the top eighth is the head");
    assert!(is_tree(&g), "a genus-0 body gives a tree: {:?}", g.edges);
}

/// Checks that the graph (built without merging) is exactly the components of the levels.
fn assert_components_of_levels(shape: &Shape, f: &[f64], boundaries: &[f64], g: &ShapeGraph) {
    let n = shape.n_vertices();
    assert_eq!(g.labels.len(), n);
    let level: Vec<u32> = f.iter().map(|&x| level_of(x, boundaries)).collect();
    let edges = shape.edges();
    let mut adjacency = vec![Vec::new(); n];
    for &(u, v) in &edges {
        adjacency[u as usize].push(v as usize);
        adjacency[v as usize].push(u as usize);
        let (lu, lv) = (g.labels[u as usize], g.labels[v as usize]);
        if level[u as usize] == level[v as usize] {
            assert_eq!(lu, lv, "an edge inside one level crosses nodes");
        } else {
            assert_ne!(lu, lv, "a node spans two levels");
        }
    }
    // Every node is one level and one connected set.
    let mut members = vec![Vec::new(); g.n_nodes()];
    for (v, &l) in g.labels.iter().enumerate() {
        assert_eq!(g.node_cluster[l as usize], level[v]);
        members[l as usize].push(v);
    }
    for (node, list) in members.iter().enumerate() {
        assert!(!list.is_empty(), "node {node} has no vertex");
        let mut seen = vec![false; n];
        let mut stack = vec![list[0]];
        seen[list[0]] = true;
        let mut reached = 1;
        while let Some(v) = stack.pop() {
            for &w in &adjacency[v] {
                if !seen[w] && g.labels[w] as usize == node {
                    seen[w] = true;
                    reached += 1;
                    stack.push(w);
                }
            }
        }
        assert_eq!(reached, list.len(), "node {node} is not connected");
    }
    // Nodes adjacent exactly when a vertex edge joins them.
    let mut expected: Vec<(u32, u32)> = edges
        .iter()
        .map(|&(u, v)| (g.labels[u as usize], g.labels[v as usize]))
        .filter(|(x, y)| x != y)
        .map(|(x, y)| (x.min(y), x.max(y)))
        .collect();
    expected.sort_unstable();
    expected.dedup();
    assert_eq!(g.edges, expected);
}

#[test]
fn nodes_are_the_connected_components_of_each_level() {
    let shape = mesh(&figure(FigureKind::Humanoid, 3, 3000));
    let b = basis(&shape, 30);
    let f = hks_function(&b, 0.1).unwrap();
    let boundaries = level_boundaries(&[(&f, &b.mass)], 8).unwrap();
    let g = reeb_graph(&shape, &b.mass, &f, &boundaries, 0.0).unwrap();
    println!("HKS graph without merging: {} nodes", g.n_nodes());
    assert!(g.n_nodes() >= 8, "at least one node per level");
    assert_components_of_levels(&shape, &f, &boundaries, &g);
    // The same for the radial function on a posed star, a different kind of level set.
    let star = mesh(&figure(FigureKind::Star { limbs: 4 }, 3, 1500));
    let r = radial(&star);
    let sb = [0.4, 0.6, 0.7, 0.9, 1.1];
    let g = reeb_graph(&star, &vec![1.0; star.n_vertices()], &r, &sb, 0.0).unwrap();
    assert_components_of_levels(&star, &r, &sb, &g);
}

#[test]
fn labels_cover_every_vertex_and_node_areas_sum_to_one() {
    let shape = mesh(&figure(FigureKind::Humanoid, 5, 3000));
    let b = basis(&shape, 30);
    let params = ReebParams::default();
    let g = shape_reeb_graph(&shape, &b, &params).unwrap();
    let f = hks_function(&b, params.hks_time).unwrap();
    let n = shape.n_vertices();
    assert_eq!(g.labels.len(), n);
    let total: f64 = b.mass.iter().sum();
    let mut area = vec![0.0; g.n_nodes()];
    let mut lo = vec![f64::INFINITY; g.n_nodes()];
    let mut hi = vec![f64::NEG_INFINITY; g.n_nodes()];
    for ((&l, &m), &x) in g.labels.iter().zip(&b.mass).zip(&f) {
        let l = l as usize;
        area[l] += m / total;
        lo[l] = lo[l].min(x);
        hi[l] = hi[l].max(x);
    }
    let sum: f64 = g.node_area.iter().sum();
    assert!((sum - 1.0).abs() < 1e-12, "areas sum to {sum}");
    let adjacency = g.adjacency();
    for node in 0..g.n_nodes() {
        assert!((area[node] - g.node_area[node]).abs() < 1e-12);
        // Fragments were merged: no node below the threshold unless it stands alone.
        assert!(
            g.node_area[node] >= params.min_area_fraction || adjacency[node].is_empty(),
            "node {node} of area {} survived",
            g.node_area[node]
        );
        let mean = g.node_descriptor[node][0];
        assert!(lo[node] <= mean && mean <= hi[node]);
    }
    let unmerged = shape_reeb_graph(
        &shape,
        &b,
        &ReebParams {
            min_area_fraction: 0.0,
            ..params.clone()
        },
    )
    .unwrap();
    println!(
        "{} nodes, {} before merging",
        g.n_nodes(),
        unmerged.n_nodes()
    );
    assert!(g.n_nodes() <= unmerged.n_nodes());
    assert!(g.is_connected());
    // Deterministic.
    assert_eq!(g, shape_reeb_graph(&shape, &b, &params).unwrap());
}

#[test]
fn quantile_levels_hold_equal_area_and_ignore_monotone_rescaling() {
    let a = mesh(&figure(FigureKind::Humanoid, 0, 3000));
    let b = mesh(&figure(FigureKind::Humanoid, 4, 3000));
    let (ba, bb) = (basis(&a, 30), basis(&b, 30));
    let (fa, fb) = (
        hks_function(&ba, 0.1).unwrap(),
        hks_function(&bb, 0.1).unwrap(),
    );
    let levels = 6;
    let area_per_level = |f: &[f64], mass: &[f64], bounds: &[f64]| {
        let total: f64 = mass.iter().sum();
        let mut area = vec![0.0; levels];
        for (x, m) in f.iter().zip(mass) {
            area[level_of(*x, bounds) as usize] += m / total;
        }
        area
    };
    let largest_vertex = |mass: &[f64]| {
        let total: f64 = mass.iter().sum();
        mass.iter().fold(0.0f64, |x, &m| x.max(m / total))
    };
    let own = level_boundaries(&[(&fa, &ba.mass)], levels).unwrap();
    assert_eq!(own.len(), levels - 1);
    let step = largest_vertex(&ba.mass);
    for area in area_per_level(&fa, &ba.mass, &own) {
        assert!((area - 1.0 / levels as f64).abs() <= step + 1e-12, "{area}");
    }
    // A shape taken twice has its own quantiles.
    assert_eq!(
        level_boundaries(&[(&fa, &ba.mass), (&fa, &ba.mass)], levels).unwrap(),
        own
    );
    // Joint quantiles: the two shapes together hold 2/levels per level.
    let joint = level_boundaries(&[(&fa, &ba.mass), (&fb, &bb.mass)], levels).unwrap();
    let (xa, xb) = (
        area_per_level(&fa, &ba.mass, &joint),
        area_per_level(&fb, &bb.mass, &joint),
    );
    let step = step.max(largest_vertex(&bb.mass));
    for (p, q) in xa.iter().zip(&xb) {
        assert!((p + q - 2.0 / levels as f64).abs() <= step + 1e-12);
    }
    // The log of the function gives the same levels (quantiles ignore monotone maps).
    let log: Vec<f64> = fa.iter().map(|x| x.ln()).collect();
    let log_bounds = level_boundaries(&[(&log, &ba.mass)], levels).unwrap();
    for (x, y) in fa.iter().zip(&log) {
        assert_eq!(level_of(*x, &own), level_of(*y, &log_bounds));
    }
}

#[test]
fn permuting_the_vertices_permutes_the_graph() {
    let star = figure(FigureKind::Star { limbs: 5 }, 2, 2000);
    let shape = mesh(&star);
    let n = shape.n_vertices();
    let perm: Vec<usize> = (0..n).map(|i| (i * 7919 + 11) % n).collect();
    assert!(!n.is_multiple_of(7919));
    let mut inverse = vec![0u32; n];
    for (new, &old) in perm.iter().enumerate() {
        inverse[old] = new as u32;
    }
    let permuted = Shape::mesh(
        perm.iter().map(|&old| star.vertices[old]).collect(),
        &star
            .triangles
            .iter()
            .map(|t| t.map(|v| inverse[v as usize]))
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let b = basis(&shape, 30);
    let f = height(&shape);
    let bounds = level_boundaries(&[(&f, &b.mass)], 7).unwrap();
    let g = reeb_graph(&shape, &b.mass, &f, &bounds, 0.002).unwrap();
    let pf: Vec<f64> = perm.iter().map(|&old| f[old]).collect();
    let pm: Vec<f64> = perm.iter().map(|&old| b.mass[old]).collect();
    let pbounds = level_boundaries(&[(&pf, &pm)], 7).unwrap();
    assert_eq!(bounds, pbounds);
    let pg = reeb_graph(&permuted, &pm, &pf, &pbounds, 0.002).unwrap();
    assert_eq!(g.n_nodes(), pg.n_nodes());
    // Labels equal up to a bijection of the nodes, which also maps the edges.
    let mut relabel = vec![u32::MAX; g.n_nodes()];
    for (new, &old) in perm.iter().enumerate() {
        let (l, pl) = (g.labels[old], pg.labels[new]);
        if relabel[l as usize] == u32::MAX {
            relabel[l as usize] = pl;
        }
        assert_eq!(relabel[l as usize], pl, "nodes differ beyond relabelling");
    }
    let mut mapped: Vec<(u32, u32)> = g
        .edges
        .iter()
        .map(|&(i, j)| {
            let (x, y) = (relabel[i as usize], relabel[j as usize]);
            (x.min(y), x.max(y))
        })
        .collect();
    mapped.sort_unstable();
    assert_eq!(mapped, pg.edges);
}

#[test]
fn a_point_cloud_uses_its_neighbour_graph() {
    let star = figure(FigureKind::Star { limbs: 5 }, 0, 3000);
    let cloud = synth::sample_points(&star, 4000, 0.0, 3).unwrap();
    let shape = Shape::point_cloud(cloud.points).unwrap();
    let b = basis(&shape, 10);
    let g = reeb_graph(&shape, &b.mass, &radial(&shape), &[0.5, 0.8, 1.05], 0.002).unwrap();
    assert_eq!(nodes_per_level(&g, 4), vec![1, 5, 5, 5]);
    assert!(is_tree(&g));
    assert_eq!(g.labels.len(), shape.n_vertices());
}

#[test]
fn merging_tames_a_noisy_point_cloud() {
    let body = figure(FigureKind::Humanoid, 0, 3000);
    let params = ReebParams::default();
    let unmerged = ReebParams {
        min_area_fraction: 0.0,
        ..params.clone()
    };
    let m = mesh(&body);
    let on_mesh = shape_reeb_graph(&m, &basis(&m, 30), &params).unwrap();
    let cloud = synth::sample_points(&body, 4000, 0.01, 5).unwrap();
    let c = Shape::point_cloud(cloud.points).unwrap();
    let bc = basis(&c, 30);
    let (g, raw) = (
        shape_reeb_graph(&c, &bc, &params).unwrap(),
        shape_reeb_graph(&c, &bc, &unmerged).unwrap(),
    );
    println!(
        "mesh {} nodes; noisy cloud {} nodes merged, {} unmerged",
        on_mesh.n_nodes(),
        g.n_nodes(),
        raw.n_nodes()
    );
    assert!(g.n_nodes() < raw.n_nodes());
    assert!(g.is_connected());
}

#[test]
fn the_baseline_runs_end_to_end_through_the_main_matcher() {
    let rest = figure(FigureKind::Humanoid, 0, 3000);
    let mirror = synth::mirror_map(&rest);
    let a = mesh(&rest);
    let posed = mesh(&figure(FigureKind::Humanoid, 2, 3000));
    let params = Params::default();
    let ba = Eigenbasis::compute(&a, &params.eigen).unwrap();
    let bb = Eigenbasis::compute(&posed, &params.eigen).unwrap();
    let reeb = ReebParams::default();
    let truth: Vec<(u32, u32)> = (0..a.n_vertices() as u32).map(|v| (v, v)).collect();
    let flipped: Vec<(u32, u32)> = truth
        .iter()
        .map(|&(x, y)| (mirror[x as usize], y))
        .collect();

    // A shape with itself: identical graphs, so the matcher must find (nearly) the truth.
    let same = reeb_correspondence(&a, &ba, &a, &ba, &reeb, &params).unwrap();
    let s = score_correspondence(&same, &ba.mass, &ba.mass, &truth, Some(&flipped));
    println!("self: {s:?}");
    assert_eq!(same.graph_a, same.graph_b);
    assert!(
        s.symmetric >= 0.9,
        "self-match symmetric accuracy {}",
        s.symmetric
    );

    let result = reeb_correspondence(&a, &ba, &posed, &bb, &reeb, &params).unwrap();
    let s = score_correspondence(&result, &ba.mass, &bb.mass, &truth, Some(&flipped));
    println!(
        "rest vs pose 2: {s:?}, nodes {}/{}, timings {:?}",
        result.graph_a.n_nodes(),
        result.graph_b.n_nodes(),
        result.timings
    );
    for x in [
        s.symmetric,
        s.one_to_one,
        s.one_to_one_flip.unwrap(),
        s.coverage,
    ] {
        assert!(x.is_finite() && (0.0..=1.0).contains(&x), "{s:?}");
    }
    assert_eq!(result.k, reeb.levels);
    assert_eq!(result.candidates.len(), 1);
    let c = &result.candidates[0];
    assert_eq!(
        (c.n_nodes_a, c.n_nodes_b),
        (result.graph_a.n_nodes(), result.graph_b.n_nodes())
    );
    assert_eq!((s.n_regions_a, s.n_regions_b), (c.n_nodes_a, c.n_nodes_b));
    for g in [&result.graph_a, &result.graph_b] {
        assert!((6..=60).contains(&g.n_nodes()), "{} nodes", g.n_nodes());
    }
    assert!(!result.matches.is_empty());
    assert!(result
        .matches_one_to_one
        .iter()
        .all(|m| result.matches.contains(m)));
    let mut seen_a = std::collections::BTreeSet::new();
    let mut seen_b = std::collections::BTreeSet::new();
    for &(i, j) in &result.matches_one_to_one {
        assert!(seen_a.insert(i) && seen_b.insert(j), "not one-to-one");
    }
    let t = &result.timings;
    assert!(t.total >= t.matching && t.total >= t.segmentation && t.matching >= 0.0);

    // Skipping the one-to-one step leaves it empty and the rest unchanged.
    let skip = Params {
        skip_one_to_one: true,
        ..params.clone()
    };
    let no121 = reeb_correspondence(&a, &ba, &posed, &bb, &reeb, &skip).unwrap();
    assert!(no121.matches_one_to_one.is_empty());
    assert_eq!(no121.matches, result.matches);
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    fn invalid<T>(r: shapecorr::Result<T>) -> bool {
        matches!(r, Err(Error::InvalidParameter { .. }))
    }
    for p in [
        ReebParams {
            hks_time: 0.0,
            ..Default::default()
        },
        ReebParams {
            hks_time: f64::NAN,
            ..Default::default()
        },
        ReebParams {
            levels: 0,
            ..Default::default()
        },
        ReebParams {
            min_area_fraction: 0.5,
            ..Default::default()
        },
        ReebParams {
            min_area_fraction: -0.1,
            ..Default::default()
        },
    ] {
        assert!(invalid(p.validate()), "{p:?} accepted");
    }
    assert!(ReebParams::default().validate().is_ok());

    let shape = mesh(&figure(FigureKind::Star { limbs: 3 }, 0, 800));
    let n = shape.n_vertices();
    let (f, m) = (radial(&shape), vec![1.0; n]);
    assert!(invalid(reeb_graph(&shape, &m[1..], &f, &[0.5], 0.0)));
    assert!(invalid(reeb_graph(&shape, &m, &f[1..], &[0.5], 0.0)));
    let mut nan = f.clone();
    nan[3] = f64::NAN;
    assert!(invalid(reeb_graph(&shape, &m, &nan, &[0.5], 0.0)));
    assert!(invalid(reeb_graph(&shape, &m, &f, &[0.8, 0.5], 0.0)));
    assert!(invalid(reeb_graph(&shape, &m, &f, &[f64::INFINITY], 0.0)));
    assert!(invalid(reeb_graph(&shape, &vec![0.0; n], &f, &[0.5], 0.0)));
    assert!(invalid(reeb_graph(&shape, &m, &f, &[0.5], 0.7)));
    assert!(invalid(level_boundaries(&[], 4)));
    assert!(invalid(level_boundaries(&[(&f, &m)], 0)));
    assert!(invalid(level_boundaries(&[(&f, &m[1..])], 4)));
    assert!(invalid(level_boundaries(&[(&nan, &m)], 4)));

    // An eigenbasis of another shape.
    let other = mesh(&figure(FigureKind::Star { limbs: 4 }, 0, 1200));
    let b_other = basis(&other, 10);
    let b_shape = basis(&shape, 10);
    assert!(invalid(shape_reeb_graph(
        &shape,
        &b_other,
        &ReebParams::default()
    )));
    assert!(invalid(reeb_correspondence(
        &shape,
        &b_shape,
        &other,
        &b_shape,
        &ReebParams::default(),
        &Params::default()
    )));
}

/// FAUST pairs from the shared benchmark data (skips when absent): node counts per number
/// of levels, and consecutive pairs of the list (`REEB_FAUST_SHAPES`, e.g. `000,009,019`)
/// scored against the identity. Run with
/// `cargo test --release -p shapecorr-eval --test it reeb::faust -- --ignored --nocapture`.
#[test]
#[ignore = "reads ../shared/data/faust; a measurement, not a check"]
fn faust_reeb_baseline() {
    let names = std::env::var("REEB_FAUST_SHAPES").unwrap_or_else(|_| "000,009,019".into());
    let names: Vec<String> = names.split(',').map(|s| format!("tr_reg_{s}")).collect();
    measure_on_benchmark("faust", &names, "template_mirror.txt");
}

/// As [`faust_reeb_baseline`] on TOSCA shapes of one class (`REEB_TOSCA_SHAPES`, default
/// `cat0,cat1`; mirror map `<class>_mirror.txt`).
#[test]
#[ignore = "reads ../shared/data/tosca; a measurement, not a check"]
fn tosca_reeb_baseline() {
    let names = std::env::var("REEB_TOSCA_SHAPES").unwrap_or_else(|_| "cat0,cat1".into());
    let names: Vec<String> = names.split(',').map(String::from).collect();
    let class: String = names[0].chars().filter(|c| c.is_alphabetic()).collect();
    measure_on_benchmark("tosca", &names, &format!("{class}_mirror.txt"));
}

/// Shapes `names` (`.ply`) of the benchmark folder `dataset`, which share one vertex order.
fn measure_on_benchmark(dataset: &str, names: &[String], mirror_file: &str) {
    let root = std::env::var("SHAPECORR_DATA").unwrap_or_else(|_| "../shared/data".into());
    let folder = std::path::Path::new(&root).join(dataset);
    if !folder.is_dir() {
        println!("no data under {}", folder.display());
        return;
    }
    let mirror: Vec<u32> = std::fs::read_to_string(folder.join(mirror_file))
        .unwrap()
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    let params = Params::default();
    let mut shapes = Vec::new();
    for name in names {
        let path = folder.join(format!("{name}.ply"));
        let shape = Shape::read(&path, ReadAs::Auto).unwrap_or_else(|e| panic!("{e}"));
        let b = Eigenbasis::compute(&shape, &params.eigen).unwrap();
        for levels in [5, 6, 8, 10] {
            let counts: Vec<usize> = [0.0, 0.002, 0.005]
                .iter()
                .map(|&min_area_fraction| {
                    let p = ReebParams {
                        levels,
                        min_area_fraction,
                        ..Default::default()
                    };
                    shape_reeb_graph(&shape, &b, &p).unwrap().n_nodes()
                })
                .collect();
            println!("{name} levels {levels}: nodes (min area 0 / 0.002 / 0.005) {counts:?}");
        }
        shapes.push((name.clone(), shape, b));
    }
    // Consecutive pairs of the list, at 6 and 8 levels, joint and per-shape quantiles.
    for pair in shapes.windows(2) {
        let ((na, a, ba), (nb, b, bb)) = (&pair[0], &pair[1]);
        let truth: Vec<(u32, u32)> = (0..a.n_vertices() as u32).map(|v| (v, v)).collect();
        let flipped: Vec<(u32, u32)> = truth
            .iter()
            .map(|&(x, y)| (mirror[x as usize], y))
            .collect();
        for (levels, joint_levels) in [(8, true), (8, false), (6, true)] {
            let reeb = ReebParams {
                levels,
                joint_levels,
                ..Default::default()
            };
            let r = reeb_correspondence(a, ba, b, bb, &reeb, &params).unwrap();
            let s = score_correspondence(&r, &ba.mass, &bb.mass, &truth, Some(&flipped));
            println!(
                "{na} -> {nb} levels {levels} joint {joint_levels}: symmetric {:.3}, \
                 one-to-one {:.3} (flip ok {:.3}), coverage {:.3}, unmatched {:.3}, \
                 nodes {}/{}, {:.2} s",
                s.symmetric,
                s.one_to_one,
                s.one_to_one_flip.unwrap(),
                s.coverage,
                s.unmatched,
                s.n_regions_a,
                s.n_regions_b,
                r.timings.total
            );
        }
    }
}
