//! The point-cloud protocol (paper section 6.3): sampling, noise, seeds, label transfer,
//! scoring, and a small end-to-end run on generated humanoids.

use std::cell::Cell;

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use shapecorr::evaluation::score;
use shapecorr::pipeline::{Correspondence, Params};
use shapecorr::synth::{self, FigureKind, Proportions};
use shapecorr::ReadAs;
use shapecorr::{Error, NoProgress, Shape};
use shapecorr_eval::bench_clouds::{
    cloud_figure, cloud_seed, cloud_table, cloud_trials, largest_extent, sample_cloud,
    sample_surface, score_transferred, transfer_labels, CloudProtocol, CloudTrial, CLOUD_TO_CLOUD,
    MESH_TO_CLOUD,
};
use shapecorr_eval::datasets::Pair;

/// A flat grid of `n x n` squares covering `[x0, x0 + side] x [0, side]` at z = 0.
fn grid(x0: f64, side: f64, n: usize, offset: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let h = side / n as f64;
    let mut vertices = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            vertices.push([x0 + h * i as f64, h * j as f64, 0.0]);
        }
    }
    let id = |i: usize, j: usize| offset + (j * (n + 1) + i) as u32;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (vertices, triangles)
}

/// Two flat squares at z = 0: `[0, 1]^2` in 2 triangles and `[3, 5] x [0, 2]` in 200, so a
/// fifth of the area holds 1% of the triangles. Width (largest extent) 5.
fn two_squares() -> Shape {
    let (mut vertices, mut triangles) = grid(0.0, 1.0, 1, 0);
    let (v2, t2) = grid(3.0, 2.0, 10, vertices.len() as u32);
    vertices.extend(v2);
    triangles.extend(t2);
    // Both squares kept: the repairs would leave the small one out as a separate object.
    let keep_pieces = shapecorr::shape::Repairs {
        debris_fraction: 0.0,
        ..Default::default()
    };
    let polygons: Vec<Vec<u32>> = triangles.iter().map(|t| t.to_vec()).collect();
    Shape::mesh_with(vertices, &polygons, &keep_pieces).unwrap()
}

#[test]
fn sampling_is_uniform_by_area_not_by_triangle_count() {
    let mesh = two_squares();
    let n = 20_000;
    let (cloud, _) = sample_cloud(&mesh, n, 0.0, 11).unwrap();
    assert_eq!(cloud.n_vertices(), n);
    assert!(cloud.triangles().is_empty(), "a cloud has no faces");
    let small = cloud.vertices().iter().filter(|p| p[0] <= 1.0).count() as f64 / n as f64;
    // Binomial standard deviation sqrt(0.2 * 0.8 / 20000) = 0.0028.
    assert!(
        (small - 0.2).abs() < 0.015,
        "the small square holds a fifth of the area but got {small:.4} of the samples"
    );
    // Within the big square, each quarter (by x) gets a quarter of its samples.
    let big: Vec<&[f64; 3]> = cloud.vertices().iter().filter(|p| p[0] >= 3.0).collect();
    for q in 0..4 {
        let lo = 3.0 + 0.5 * q as f64;
        let share =
            big.iter().filter(|p| p[0] >= lo && p[0] < lo + 0.5).count() as f64 / big.len() as f64;
        assert!((share - 0.25).abs() < 0.02, "quarter {q}: {share:.4}");
    }
    for p in cloud.vertices() {
        assert_eq!(p[2], 0.0, "noise 0 keeps the points on the surface");
        let in_small = (0.0..=1.0).contains(&p[0]) && (0.0..=1.0).contains(&p[1]);
        let in_big = (3.0..=5.0).contains(&p[0]) && (0.0..=2.0).contains(&p[1]);
        assert!(in_small || in_big, "{p:?} is off the mesh");
    }
}

#[test]
fn noise_moves_every_coordinate_by_at_most_noise_times_the_largest_extent() {
    let mesh = two_squares();
    assert_eq!(largest_extent(mesh.vertices()), 5.0);
    let noise = 0.02;
    let sample = sample_surface(&mesh, 5000, noise, 5).unwrap();
    assert_eq!(sample.width, 5.0);
    let bound = noise * 5.0;
    let mut largest = [0.0f64; 3];
    let mut mean = [0.0f64; 3];
    for (p, s) in sample.points.iter().zip(&sample.surface) {
        assert_eq!(s[2], 0.0, "surface points lie on the mesh");
        for k in 0..3 {
            let d = p[k] - s[k];
            assert!(d.abs() <= bound + 1e-12, "coordinate {k} moved by {d}");
            largest[k] = largest[k].max(d.abs());
            mean[k] += d / sample.points.len() as f64;
        }
    }
    for k in 0..3 {
        // Uniform in [-bound, bound]: the largest of 5000 comes within 0.1% of the bound,
        // the mean within 4 standard deviations (bound / sqrt(3 * 5000)) of 0.
        assert!(
            largest[k] > 0.99 * bound,
            "coordinate {k}: largest shift {} of bound {bound}",
            largest[k]
        );
        assert!(mean[k].abs() < 4.0 * bound / (15_000f64).sqrt());
    }
    // Noise 0: the points are the surface points, and the same surface points as with noise
    // for the same seed.
    let clean = sample_surface(&mesh, 5000, 0.0, 5).unwrap();
    assert_eq!(clean.points, clean.surface);
    assert_eq!(clean.surface, sample.surface);
}

#[test]
fn every_point_maps_to_its_nearest_mesh_vertex() {
    let rest = synth::figure(&synth::FigureSpec {
        kind: FigureKind::Humanoid,
        target_vertices: 1500,
        ..Default::default()
    })
    .unwrap();
    let mesh = Shape::mesh(rest.vertices, &rest.triangles).unwrap();
    let sample = sample_surface(&mesh, 400, 0.02, 9).unwrap();
    let d2 = |p: &[f64; 3], q: &[f64; 3]| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>();
    for (p, &v) in sample.points.iter().zip(&sample.nearest_vertex) {
        let best = mesh
            .vertices()
            .iter()
            .map(|q| d2(p, q))
            .fold(f64::INFINITY, f64::min);
        assert_eq!(d2(p, &mesh.vertices()[v as usize]), best);
    }
}

#[test]
fn the_same_seed_gives_the_same_cloud_and_another_seed_another() {
    let mesh = two_squares();
    let (a, nearest_a) = sample_cloud(&mesh, 500, 0.01, 42).unwrap();
    let (b, nearest_b) = sample_cloud(&mesh, 500, 0.01, 42).unwrap();
    let (c, _) = sample_cloud(&mesh, 500, 0.01, 43).unwrap();
    assert_eq!(a.vertices(), b.vertices());
    assert_eq!(nearest_a, nearest_b);
    assert_ne!(a.vertices(), c.vertices());
}

#[test]
fn cloud_seeds_are_pinned_and_depend_on_every_field() {
    let base = cloud_seed(0, "tr_reg_000", "tr_reg_009", "B", 1500, 0.01, 0);
    // FNV-1a of the fields (checked against an independent implementation); a change of
    // this value changes every published cloud.
    assert_eq!(base, 0x9ce9_1920_682c_fd6e_u64, "got {base:#x}");
    let others = [
        cloud_seed(1, "tr_reg_000", "tr_reg_009", "B", 1500, 0.01, 0),
        cloud_seed(0, "tr_reg_001", "tr_reg_009", "B", 1500, 0.01, 0),
        cloud_seed(0, "tr_reg_000", "tr_reg_008", "B", 1500, 0.01, 0),
        cloud_seed(0, "tr_reg_000", "tr_reg_009", "A", 1500, 0.01, 0),
        cloud_seed(0, "tr_reg_000", "tr_reg_009", "B", 3000, 0.01, 0),
        cloud_seed(0, "tr_reg_000", "tr_reg_009", "B", 1500, 0.02, 0),
        cloud_seed(0, "tr_reg_000", "tr_reg_009", "B", 1500, 0.01, 1),
        // Names are length-prefixed: moving a character between them changes the seed.
        cloud_seed(0, "tr_reg_00", "0tr_reg_009", "B", 1500, 0.01, 0),
    ];
    for (i, s) in others.iter().enumerate() {
        assert_ne!(*s, base, "variant {i}");
    }
}

#[test]
fn label_transfer_takes_the_nearest_point_and_leaves_uncovered_vertices_out() {
    let vertices = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [3.0, 0.0, 0.0],
    ];
    // Points 0 and 1 map to vertex 0 (point 1 nearer), point 2 to vertex 2, points 3 and 4
    // to vertex 3 at the same distance (the first wins); nothing maps to vertex 1.
    let points = vec![
        [0.3, 0.0, 0.0],
        [0.0, 0.1, 0.0],
        [2.0, 0.0, 0.2],
        [3.0, 0.1, 0.0],
        [3.0, -0.1, 0.0],
    ];
    let nearest = [0, 0, 2, 3, 3];
    let labels = [7, 5, 2, 4, 9];
    let transferred = transfer_labels(&vertices, &points, &nearest, &labels);
    assert_eq!(transferred, vec![Some(5), None, Some(2), Some(4)]);
}

#[test]
fn uncovered_vertices_are_left_out_of_the_ground_truth_not_counted_wrong() {
    // A: 4 vertices in regions 0,0,1,1 (a mesh). B: 4 vertices; B's vertex 3 is uncovered
    // and its plain label would make the pair (3, 3) wrong.
    let labels_a = [Some(0), Some(0), Some(1), Some(1)];
    let labels_b = [Some(0), Some(0), Some(1), None];
    let mass = [0.25; 4];
    let matches = [(0, 0), (1, 1)];
    let truth: Vec<(u32, u32)> = (0..4).map(|v| (v, v)).collect();
    let s = score_transferred(
        &labels_a, &labels_b, 2, 2, &mass, &matches, &matches, &truth, None,
    );
    assert_eq!(s.symmetric, 1.0);
    assert_eq!(s.one_to_one, 1.0);
    assert_eq!(s.one_to_one_flip, None);
    assert_eq!(s.covered, 0.75);
    // The same labels with the uncovered vertex given region 0 and counted: 0.75.
    let filled = score(
        &[0, 0, 1, 1],
        &[0, 0, 1, 0],
        &mass,
        &mass,
        &matches,
        &matches,
        &truth,
        None,
    );
    assert_eq!(filled.symmetric, 0.75);

    // Cloud-to-cloud: a pair counts only when both ends are covered; the flipped ground truth
    // is filtered the same way.
    let labels_a = [Some(0), None, Some(1), Some(1)];
    let flipped = [(0, 2), (1, 3), (2, 0), (3, 1)];
    let s = score_transferred(
        &labels_a,
        &labels_b,
        2,
        2,
        &mass,
        &matches,
        &[],
        &truth,
        Some(&flipped),
    );
    assert_eq!(s.covered, 0.5, "pairs (0,0) and (2,2) are kept");
    assert_eq!(s.symmetric, 1.0);
    assert_eq!(s.one_to_one, 0.0);
    assert_eq!(s.one_to_one_flip, Some(0.0));
}

#[test]
fn a_region_no_mesh_vertex_received_does_not_alias_another_match() {
    // B's correspondence has 3 regions but region 2 reached no mesh vertex. The match
    // (0, 2) must not be read as (1, 0), which a region count inferred from the transferred
    // labels (2) would do: 0 * 2 + 2 == 1 * 2 + 0.
    let labels_a = [Some(0), Some(1)];
    let labels_b = [Some(1), Some(0)];
    let mass = [0.5; 2];
    let truth = [(0, 0), (1, 1)];
    let s = score_transferred(
        &labels_a,
        &labels_b,
        2,
        3,
        &mass,
        &[(0, 2)],
        &[(0, 2)],
        &truth,
        None,
    );
    assert_eq!(s.symmetric, 0.0);
}

#[test]
fn the_default_protocol_is_the_papers_and_bad_ones_are_rejected() {
    let p = CloudProtocol::default();
    assert_eq!(p.densities, vec![6000, 3000, 1500, 500]);
    assert_eq!(p.noise, vec![0.0, 0.01, 0.02]);
    assert_eq!(p.trials, 4);
    p.validate().unwrap();
    let bad = [
        CloudProtocol {
            densities: vec![],
            ..p.clone()
        },
        CloudProtocol {
            densities: vec![1500, 10],
            ..p.clone()
        },
        CloudProtocol {
            noise: vec![],
            ..p.clone()
        },
        CloudProtocol {
            noise: vec![0.0, -0.01],
            ..p.clone()
        },
        CloudProtocol {
            noise: vec![f64::NAN],
            ..p.clone()
        },
        CloudProtocol {
            noise: vec![2.0],
            ..p.clone()
        },
        CloudProtocol {
            trials: 0,
            ..p.clone()
        },
    ];
    for (i, b) in bad.iter().enumerate() {
        assert!(
            matches!(b.validate(), Err(Error::InvalidParameter { .. })),
            "case {i} accepted"
        );
    }
    let mesh = two_squares();
    assert!(sample_cloud(&mesh, 10, 0.0, 0).is_err(), "too few points");
    assert!(sample_cloud(&mesh, 100, -0.1, 0).is_err(), "negative noise");
    let cloud = Shape::point_cloud(mesh.vertices().to_vec()).unwrap();
    assert!(
        sample_cloud(&cloud, 100, 0.0, 0).is_err(),
        "a cloud has no surface"
    );
}

fn trial(mode: &str, density: usize, noise: f64, symmetric: f64, flip: Option<f64>) -> CloudTrial {
    CloudTrial {
        source: "a".into(),
        target: "b".into(),
        category: "all".into(),
        mode: mode.into(),
        density,
        noise,
        trial: 0,
        symmetric,
        one_to_one: symmetric,
        one_to_one_flip: flip,
        covered: 0.5,
        n_regions_a: 8,
        n_regions_b: 8,
        seconds: 1.0,
    }
}

#[test]
fn the_table_averages_per_mode_noise_and_density_and_the_figure_is_a_png() {
    let results = vec![
        trial(MESH_TO_CLOUD, 500, 0.0, 0.8, Some(0.7)),
        trial(MESH_TO_CLOUD, 500, 0.0, 0.6, Some(0.5)),
        trial(MESH_TO_CLOUD, 1500, 0.0, 0.9, Some(0.9)),
        trial(CLOUD_TO_CLOUD, 500, 0.02, 0.4, None),
        trial(CLOUD_TO_CLOUD, 1500, 0.0, 1.0, Some(1.0)),
    ];
    let table = cloud_table(&results, Some(0.95));
    println!("{table}");
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(
        lines[0], "| symmetric accuracy | noise | 1500 | 500 |",
        "densities descending"
    );
    assert!(lines.contains(&"| mesh-to-cloud | 0% | 0.900 | 0.700 |"));
    assert!(lines.contains(&"| mesh-to-cloud | 2% | n/a | n/a |"));
    assert!(lines.contains(&"| cloud-to-cloud | 2% | n/a | 0.400 |"));
    assert!(lines.contains(&"| cloud-to-cloud | 0% | 1.000 | n/a |"));
    // Second table: one-to-one with flips; a trial without a mirror map gives n/a.
    let second = lines
        .iter()
        .position(|l| l.starts_with("| one-to-one accuracy (flip ok)"))
        .unwrap();
    assert!(lines[second..].contains(&"| mesh-to-cloud | 0% | 0.900 | 0.600 |"));
    assert!(lines[second..].contains(&"| cloud-to-cloud | 2% | n/a | n/a |"));
    assert!(table.contains("mesh-to-mesh symmetric accuracy: 0.950"));

    let dir = std::env::temp_dir().join(format!("shapecorr-clouds-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("pointclouds.png");
    cloud_figure(&path, &results, Some(0.95)).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert!(cloud_figure(&dir.join("empty.png"), &[], None).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Ground-truth vertex pairs `(vertex of A, vertex of B)`.
type Truth = Vec<(u32, u32)>;

/// Mesh A (rest pose) and mesh B (another pose) of the generated humanoid, with the
/// identity ground truth and its mirror image.
fn humanoid_pair(vertices: usize) -> (Shape, Shape, Truth, Truth) {
    let meshes = synth::figure_poses(
        FigureKind::Humanoid,
        vertices,
        Proportions::default(),
        &[0, 2],
    )
    .unwrap();
    let mirror = synth::mirror_map(&meshes[0]);
    let a = Shape::mesh(meshes[0].vertices.clone(), &meshes[0].triangles).unwrap();
    let b = Shape::mesh(meshes[1].vertices.clone(), &meshes[1].triangles).unwrap();
    let truth: Vec<(u32, u32)> = (0..a.n_vertices() as u32).map(|v| (v, v)).collect();
    let flipped = truth
        .iter()
        .map(|&(x, y)| (x, mirror[y as usize]))
        .collect();
    (a, b, truth, flipped)
}

#[test]
fn a_small_protocol_run_on_two_humanoid_poses() {
    let (a, b, truth, flipped) = humanoid_pair(3000);
    let pair = Pair {
        source: "rest".into(),
        target: "pose2".into(),
        category: "humanoid".into(),
    };
    let protocol = CloudProtocol {
        densities: vec![1500, 500],
        noise: vec![0.0, 0.02],
        trials: 1,
        seed: 7,
    };
    let params = Params::default();
    let reported = Cell::new(0);
    let results = cloud_trials(
        &pair,
        &a,
        &b,
        &truth,
        Some(&flipped),
        &protocol,
        &params,
        &|_, _, _, _| false,
        &mut |t| {
            reported.set(reported.get() + 1);
            println!(
                "{} {} pts {:.0}%: symmetric {:.3}, one-to-one {:.3}, flip {:?}, covered {:.3}, regions {}/{}, {:.2} s",
                t.mode,
                t.density,
                100.0 * t.noise,
                t.symmetric,
                t.one_to_one,
                t.one_to_one_flip,
                t.covered,
                t.n_regions_a,
                t.n_regions_b,
                t.seconds
            );
        },
    )
    .unwrap();
    assert_eq!(results.len(), 8);
    assert_eq!(reported.get(), 8);
    println!("{}", cloud_table(&results, None));
    let order: Vec<(&str, usize, f64)> = results
        .iter()
        .map(|r| (r.mode.as_str(), r.density, r.noise))
        .collect();
    assert_eq!(order[0], (MESH_TO_CLOUD, 1500, 0.0));
    assert_eq!(order[3], (MESH_TO_CLOUD, 500, 0.02));
    assert_eq!(order[4], (CLOUD_TO_CLOUD, 1500, 0.0));
    for r in &results {
        let flip = r.one_to_one_flip.unwrap();
        for v in [r.symmetric, r.one_to_one, flip, r.covered] {
            assert!((0.0..=1.0).contains(&v), "{r:?}");
        }
        assert!(flip >= r.one_to_one);
        assert!(r.n_regions_a >= 2 && r.n_regions_b >= 2, "{r:?}");
        assert!(r.covered > 0.0, "{r:?}");
        if r.mode == MESH_TO_CLOUD {
            // 1500 points on 3000 vertices cover at most half of B's vertices.
            assert!(r.covered <= r.density as f64 / b.n_vertices() as f64 + 1e-12);
        }
    }
    let clean = &results[0];
    assert!(clean.symmetric >= 0.8, "{clean:?}");
    assert!(results[4].symmetric >= 0.7, "{:?}", results[4]);
    // Cloud-to-cloud covers fewer pairs than mesh-to-cloud at the same density.
    assert!(results[4].covered < results[0].covered);

    // The same trial by hand, then with the cloud's labels scrambled: the protocol's
    // accuracy is the real one and is far above chance.
    let seed = cloud_seed(7, "rest", "pose2", "B", 1500, 0.0, 0);
    let (cloud, nearest) = sample_cloud(&b, 1500, 0.0, seed).unwrap();
    let result = Correspondence::compute(&a, &cloud, &params, &mut NoProgress).unwrap();
    let mass_a = vec![1.0; a.n_vertices()];
    let labels_a: Vec<Option<u32>> = result.regions_a().iter().map(|&r| Some(r)).collect();
    let n = (result.graph_a.n_nodes(), result.graph_b.n_nodes());
    let score_with = |cloud_labels: &[u32]| {
        let labels_b = transfer_labels(b.vertices(), cloud.vertices(), &nearest, cloud_labels);
        score_transferred(
            &labels_a,
            &labels_b,
            n.0,
            n.1,
            &mass_a,
            &result.matches,
            &result.matches_one_to_one,
            &truth,
            Some(&flipped),
        )
    };
    let real = score_with(result.regions_b());
    assert!((real.covered - clean.covered).abs() < 1e-12);
    assert!(
        (real.symmetric - clean.symmetric).abs() < 0.05,
        "unit weights {} vs mass weights {}",
        real.symmetric,
        clean.symmetric
    );
    let mut scrambled = result.regions_b().to_vec();
    scrambled.shuffle(&mut ChaCha8Rng::seed_from_u64(1));
    let chance = score_with(&scrambled);
    println!("real {real:?}\nscrambled {chance:?}");
    assert!(
        real.symmetric > chance.symmetric + 0.3,
        "real {} vs scrambled {}",
        real.symmetric,
        chance.symmetric
    );

    // Resuming: skipping all but one trial reruns exactly that trial.
    let again = cloud_trials(
        &pair,
        &a,
        &b,
        &truth,
        Some(&flipped),
        &protocol,
        &params,
        &|mode, density, noise, trial| {
            !(mode == MESH_TO_CLOUD && density == 500 && noise == 0.0 && trial == 0)
        },
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(again.len(), 1);
    assert_eq!(again[0].symmetric, results[2].symmetric);
    assert_eq!(again[0].one_to_one_flip, results[2].one_to_one_flip);
    assert_eq!(again[0].covered, results[2].covered);
}

/// FAUST tr_reg_000 -> tr_reg_009 (identity ground truth, mirror map
/// `faust/template_mirror.txt`) at 3000 and 500 points, noise 0 and 2%, one trial:
/// `cargo test --release -p shapecorr-eval --test it bench_clouds:: -- --ignored --nocapture`.
#[test]
#[ignore = "needs shared/data/faust; about 12 s in release"]
fn faust_pair_quick_check() {
    let root = shapecorr_eval::datasets::default_data_root().join("faust");
    if !root.exists() {
        println!("no {}", root.display());
        return;
    }
    let read = |name: &str| Shape::read(&root.join(format!("{name}.ply")), ReadAs::Auto).unwrap();
    let (a, b) = (read("tr_reg_000"), read("tr_reg_009"));
    let mirror: Vec<u32> = std::fs::read_to_string(root.join("template_mirror.txt"))
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.trim().parse().unwrap())
        .collect();
    assert_eq!(mirror.len(), b.n_vertices());
    let truth: Vec<(u32, u32)> = (0..a.n_vertices() as u32).map(|v| (v, v)).collect();
    let flipped: Vec<(u32, u32)> = truth
        .iter()
        .map(|&(x, y)| (x, mirror[y as usize]))
        .collect();
    let pair = Pair {
        source: "tr_reg_000".into(),
        target: "tr_reg_009".into(),
        category: "faust".into(),
    };
    let params = Params::default();
    let started = std::time::Instant::now();
    let mesh = Correspondence::compute(&a, &b, &params, &mut NoProgress).unwrap();
    let mass = shapecorr::Eigenbasis::compute(&a, &params.eigen, &mut NoProgress)
        .unwrap()
        .mass;
    let mass_b = shapecorr::Eigenbasis::compute(&b, &params.eigen, &mut NoProgress)
        .unwrap()
        .mass;
    let mesh_scores =
        shapecorr::evaluation::score_correspondence(&mesh, &mass, &mass_b, &truth, Some(&flipped));
    println!(
        "mesh-to-mesh: {mesh_scores:?} ({:.1} s)",
        started.elapsed().as_secs_f64()
    );
    let protocol = CloudProtocol {
        densities: vec![3000, 500],
        noise: vec![0.0, 0.02],
        trials: 1,
        seed: 0,
    };
    let results = cloud_trials(
        &pair,
        &a,
        &b,
        &truth,
        Some(&flipped),
        &protocol,
        &params,
        &|_, _, _, _| false,
        &mut |t| {
            println!(
                "{} {} pts {:.0}%: symmetric {:.3}, one-to-one {:.3}, flip {:?}, covered {:.3}, regions {}/{}, {:.2} s",
                t.mode, t.density, 100.0 * t.noise, t.symmetric, t.one_to_one,
                t.one_to_one_flip, t.covered, t.n_regions_a, t.n_regions_b, t.seconds
            )
        },
    )
    .unwrap();
    println!("{}", cloud_table(&results, Some(mesh_scores.symmetric)));
    println!("total {:.1} s", started.elapsed().as_secs_f64());
    for r in &results {
        assert!((0.0..=1.0).contains(&r.symmetric));
    }
}
