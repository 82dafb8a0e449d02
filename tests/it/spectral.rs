//! Identities of the Laplacian, the eigenbasis and the descriptors (STYLE.md: identities,
//! not single values).

use crate::common;

use common::{icosphere, permutation, rel};
use faer::Mat;
use shapecorr::spectral::descriptors::{hks, wks, HksParams, WksParams};
use shapecorr::spectral::eigen::eigenpairs;
use shapecorr::spectral::laplacian::Laplacian;
use shapecorr::{EigenParams, Eigenbasis, NoProgress, Shape};

fn sphere(levels: u32) -> Shape {
    let (v, f) = icosphere(levels);
    Shape::mesh(v, &f).unwrap()
}

/// max_j ||L phi_j - lambda_j M phi_j|| / (max(lambda_j, 1) ||M phi_j||) and
/// max |Phi^T M Phi - I|.
fn residual_and_orthonormality(lap: &Laplacian, values: &[f64], vectors: &Mat<f64>) -> (f64, f64) {
    let n = lap.len();
    let k = values.len();
    let mut worst_residual: f64 = 0.0;
    for j in 0..k {
        let phi: Vec<f64> = (0..n).map(|i| vectors[(i, j)]).collect();
        let mut l_phi = vec![0.0; n];
        for (col, column) in lap.stiffness.outer_iterator().enumerate() {
            for (row, &value) in column.iter() {
                l_phi[row] += value * phi[col];
            }
        }
        let mut r2 = 0.0;
        let mut m2 = 0.0;
        for i in 0..n {
            let m_phi = lap.mass[i] * phi[i];
            r2 += (l_phi[i] - values[j] * m_phi).powi(2);
            m2 += m_phi * m_phi;
        }
        worst_residual = worst_residual.max(r2.sqrt() / (values[j].max(1.0) * m2.sqrt()));
    }
    let mut worst_orth: f64 = 0.0;
    for a in 0..k {
        for b in 0..=a {
            let dot: f64 = (0..n)
                .map(|i| vectors[(i, a)] * lap.mass[i] * vectors[(i, b)])
                .sum();
            let expected = if a == b { 1.0 } else { 0.0 };
            worst_orth = worst_orth.max((dot - expected).abs());
        }
    }
    (worst_residual, worst_orth)
}

#[test]
fn laplacian_is_symmetric_rows_sum_to_zero_and_mass_is_the_area() {
    let shape = sphere(4);
    let lap = Laplacian::new(&shape).unwrap();
    let l = &lap.stiffness;
    let mut max_entry: f64 = 0.0;
    for (col, column) in l.outer_iterator().enumerate() {
        let mut sum = 0.0;
        for (row, &value) in column.iter() {
            let transposed = l.get(col, row).copied().unwrap_or(f64::NAN);
            assert!((value - transposed).abs() <= 1e-12 * value.abs().max(1.0));
            sum += value;
            max_entry = max_entry.max(value.abs());
        }
        // Symmetric, so column sums are row sums.
        assert!(
            sum.abs() < 1e-10 * max_entry.max(1.0),
            "row {col} sums to {sum}"
        );
    }
    let total: f64 = lap.mass.iter().sum();
    assert!(
        (total - 1.0).abs() < 1e-12,
        "unit-area mass sums to {total}"
    );
    assert!(lap.mass.iter().all(|&m| m > 0.0));
    assert!(rel(lap.input_area, shape.mesh_area(), 0.0) < 1e-9);
    // The icosphere's area approaches the sphere's from below.
    let sphere_area = 4.0 * std::f64::consts::PI;
    assert!(lap.input_area < sphere_area && lap.input_area > 0.99 * sphere_area);
}

#[test]
fn eigenpairs_satisfy_the_generalized_problem_and_are_m_orthonormal() {
    let shape = sphere(4); // 2,562 vertices: the Lanczos path
    let lap = Laplacian::new(&shape).unwrap();
    let params = EigenParams {
        n_eigenpairs: 60,
        ..Default::default()
    };
    let (values, vectors) = eigenpairs(&lap, &params, &mut NoProgress).unwrap();
    assert_eq!(values.len(), 60);
    assert!(values.windows(2).all(|w| w[0] <= w[1]), "ascending");
    assert!(values[0].abs() < 1e-9);
    let (residual, orth) = residual_and_orthonormality(&lap, &values, &vectors);
    assert!(residual < 1e-8, "relative residual {residual}");
    assert!(orth < 1e-8, "M-orthonormality defect {orth}");
}

#[test]
fn lanczos_agrees_with_the_dense_solver() {
    // 642 vertices: above the dense limit, so eigenpairs() takes the Lanczos path; compare
    // with a dense solve of the same matrices.
    let shape = sphere(3);
    let lap = Laplacian::new(&shape).unwrap();
    let params = EigenParams {
        n_eigenpairs: 30,
        block_size: 4,
        ..Default::default()
    };
    let (values, _) = eigenpairs(&lap, &params, &mut NoProgress).unwrap();
    let n = lap.len();
    let mut dense = Mat::<f64>::zeros(n, n);
    for (col, column) in lap.stiffness.outer_iterator().enumerate() {
        for (row, &value) in column.iter() {
            dense[(row, col)] = value / (lap.mass[row] * lap.mass[col]).sqrt();
        }
    }
    let reference = dense.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
    for j in 1..30 {
        assert!(
            rel(values[j], reference[j], 1e-9) < 1e-9,
            "eigenvalue {j}: {} vs dense {}",
            values[j],
            reference[j]
        );
    }
}

#[test]
fn sphere_spectrum_has_multiplicities_1_3_5_7_and_values_l_l_plus_1() {
    let shape = sphere(5); // 10,242 vertices
    let basis = Eigenbasis::compute(
        &shape,
        &EigenParams {
            n_eigenpairs: 20,
            ..Default::default()
        },
        &mut NoProgress,
    )
    .unwrap();
    // Unit-area scaling multiplies the unit sphere's l(l+1) by its area.
    let area = basis.input_area;
    let mut index = 0;
    for l in 0..4usize {
        let expected = (l * (l + 1)) as f64 * area;
        for _ in 0..(2 * l + 1) {
            let value = basis.values[index];
            if l == 0 {
                assert!(value.abs() < 1e-8, "lambda_0 = {value}");
            } else {
                assert!(
                    rel(value, expected, 0.0) < 0.01,
                    "lambda_{index} = {value}, expected {expected} (l = {l})"
                );
            }
            index += 1;
        }
    }
    // The next eigenvalue belongs to l = 4: a clear gap after the 16 above.
    assert!(basis.values[16] > 1.5 * basis.values[15]);
}

#[test]
fn hks_is_constant_on_the_sphere() {
    let shape = sphere(5);
    let basis = Eigenbasis::compute(&shape, &EigenParams::default(), &mut NoProgress).unwrap();
    let h = hks(&basis, &HksParams::default()).unwrap();
    assert_eq!((h.nrows(), h.ncols()), (shape.n_vertices(), 15));
    for t in 0..h.ncols() {
        let column: Vec<f64> = (0..h.nrows()).map(|v| h[(v, t)]).collect();
        let mean = column.iter().sum::<f64>() / column.len() as f64;
        let spread = column.iter().map(|x| (x - mean).abs()).fold(0.0, f64::max);
        assert!(
            spread / mean < 1e-3,
            "time {t}: relative spread {}",
            spread / mean
        );
    }
}

/// A non-symmetric test mesh: a sphere with a bump, so eigenvalues are simple.
fn bumpy_sphere() -> Shape {
    let (mut v, f) = icosphere(4);
    for p in &mut v {
        let s = 1.0 + 0.3 * (2.0 * p[0] + 0.5).sin() * (p[1] + 0.2).cos() + 0.2 * p[2] * p[2];
        let stretch = [1.3, 1.0, 0.8];
        for k in 0..3 {
            p[k] *= s * stretch[k];
        }
    }
    Shape::mesh(v, &f).unwrap()
}

fn small_params() -> EigenParams {
    EigenParams {
        n_eigenpairs: 30,
        ..Default::default()
    }
}

#[test]
fn eigenvalues_and_hks_do_not_change_under_permutation_rigid_motion_and_scaling() {
    let shape = bumpy_sphere();
    let reference = Eigenbasis::compute(&shape, &small_params(), &mut NoProgress).unwrap();
    let reference_hks = hks(&reference, &HksParams::default()).unwrap();

    // Vertex permutation: new vertex i is old vertex perm[i].
    let n = shape.n_vertices();
    let perm = permutation(n, 7);
    let mut inverse = vec![0u32; n];
    for (new, &old) in perm.iter().enumerate() {
        inverse[old] = new as u32;
    }
    let vertices: Vec<[f64; 3]> = perm.iter().map(|&old| shape.vertices()[old]).collect();
    let triangles: Vec<[u32; 3]> = shape
        .triangles()
        .iter()
        .map(|t| t.map(|v| inverse[v as usize]))
        .collect();
    let permuted = Shape::mesh(vertices, &triangles).unwrap();

    // Rigid motion and uniform scaling by 3.7.
    let (c, s) = (0.6f64.cos(), 0.6f64.sin());
    let moved: Vec<[f64; 3]> = shape
        .vertices()
        .iter()
        .map(|p| {
            let q = [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
            [3.7 * q[0] + 10.0, 3.7 * q[2] - 4.0, -3.7 * q[1] + 1.5]
        })
        .collect();
    let moved = shape.with_vertices(moved).unwrap();

    for (name, other, map) in [
        ("permuted", &permuted, perm.clone()),
        ("moved and scaled", &moved, (0..n).collect::<Vec<_>>()),
    ] {
        let basis = Eigenbasis::compute(other, &small_params(), &mut NoProgress).unwrap();
        for j in 1..basis.len() {
            let r = rel(basis.values[j], reference.values[j], 0.0);
            assert!(r < 1e-8, "{name}: eigenvalue {j} differs by {r}");
        }
        let h = hks(&basis, &HksParams::default()).unwrap();
        for (new, &old) in map.iter().enumerate() {
            for t in 0..h.ncols() {
                let r = rel(h[(new, t)], reference_hks[(old, t)], 0.0);
                assert!(
                    r < 1e-6,
                    "{name}: HKS of vertex {old} at time {t} differs by {r}"
                );
            }
        }
    }
}

#[test]
fn eigenbasis_is_identical_on_any_thread_count() {
    let shape = bumpy_sphere();
    let compute_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            Eigenbasis::compute(
                &shape,
                &EigenParams {
                    threads,
                    ..small_params()
                },
                &mut NoProgress,
            )
            .unwrap()
        })
    };
    let one = compute_on(1);
    for threads in [2, 3] {
        let other = compute_on(threads);
        assert_eq!(one.values, other.values, "{threads} threads");
        assert!(one.vectors == other.vectors, "{threads} threads");
    }
}

#[test]
fn wks_rows_are_normalised_distributions_and_log_hks_is_the_log() {
    let shape = bumpy_sphere();
    let basis = Eigenbasis::compute(&shape, &small_params(), &mut NoProgress).unwrap();
    let w = wks(&basis, &WksParams::default()).unwrap();
    assert_eq!(w.ncols(), 100);
    // Each energy's weights sum to 1, and sum_v M_v phi_i(v)^2 = 1, so the mass-weighted
    // integral of every WKS column is 1.
    for e in 0..w.ncols() {
        let integral: f64 = (0..w.nrows()).map(|v| basis.mass[v] * w[(v, e)]).sum();
        assert!(
            (integral - 1.0).abs() < 1e-9,
            "energy {e}: integral {integral}"
        );
    }
    let raw = hks(&basis, &HksParams::default()).unwrap();
    let log = hks(
        &basis,
        &HksParams {
            log: true,
            ..Default::default()
        },
    )
    .unwrap();
    for v in (0..raw.nrows()).step_by(97) {
        assert!((log[(v, 3)] - raw[(v, 3)].ln()).abs() < 1e-12);
    }
}

#[test]
fn two_pieces_and_unreferenced_vertices_are_handled() {
    // Two spheres far apart, plus three vertices used by no face.
    let (v, f) = icosphere(3);
    let offset = v.len() as u32;
    let mut vertices = v.clone();
    vertices.extend(v.iter().map(|p| [p[0] + 5.0, p[1], p[2]]));
    vertices.extend([[0.0, 0.0, 2.0], [5.0, 0.0, 2.0], [0.0, 0.0, 0.0]]);
    let mut faces = f.clone();
    faces.extend(f.iter().map(|t| t.map(|i| i + offset)));
    // The repairs would leave the second sphere out as a separate object.
    let keep_pieces = shapecorr::shape::Repairs {
        debris_fraction: 0.0,
        ..Default::default()
    };
    let polygons: Vec<Vec<u32>> = faces.iter().map(|t| t.to_vec()).collect();
    let shape = Shape::mesh_with(vertices, &polygons, &keep_pieces).unwrap();
    assert_eq!(shape.n_pieces(), 2);
    assert!(shape
        .warnings()
        .contains(&shapecorr::Warning::UnreferencedVertices { count: 3 }));
    let basis = Eigenbasis::compute(&shape, &small_params(), &mut NoProgress).unwrap();
    // One zero eigenvalue per piece.
    assert!(basis.values[0].abs() < 1e-8 && basis.values[1].abs() < 1e-8);
    assert!(basis.values[2] > 1.0);
    // An unreferenced vertex takes the values of its nearest used vertex.
    let extra = 2 * offset as usize;
    let rep = shape.representative()[extra] as usize;
    assert!(rep < offset as usize);
    for j in 0..basis.len() {
        assert_eq!(basis.vectors[(extra, j)], basis.vectors[(rep, j)]);
    }
    assert_eq!(basis.mass[extra], 0.0);
}

#[test]
fn cancelling_from_the_progress_callback_stops_the_eigensolver() {
    let shape = sphere(4);
    let mut calls = 0;
    let mut cancel_after_three = |stage: shapecorr::Stage, _fraction: f32| {
        if stage == shapecorr::Stage::Eigenbasis {
            calls += 1;
        }
        calls < 3
    };
    let result = Eigenbasis::compute(&shape, &EigenParams::default(), &mut cancel_after_three);
    assert!(
        matches!(result, Err(shapecorr::Error::Cancelled)),
        "{result:?}"
    );
    assert_eq!(
        calls, 3,
        "the solver stops at the first report answered with false"
    );
}

#[test]
fn a_pair_of_eigenbases_is_the_two_computed_alone_and_can_be_cancelled() {
    let (a, b) = (bumpy_sphere(), sphere(4));
    let params = small_params();
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| Eigenbasis::pair((&a, &b), &params, &mut NoProgress).unwrap())
    };
    let alone = [&a, &b].map(|s| Eigenbasis::compute(s, &params, &mut NoProgress).unwrap());
    // Two threads solve the two side by side, one thread one after the other.
    for threads in [1, 2] {
        let (pair, seconds) = on(threads);
        for (side, basis) in pair.iter().enumerate() {
            assert_eq!(basis.values, alone[side].values, "{threads} threads");
            assert!(basis.vectors == alone[side].vectors, "{threads} threads");
            assert!(seconds[side] > 0.0);
        }
    }

    // The first report comes before the solves start, the second while they run (the
    // pair takes about 0.1 s, a report comes every 25 ms).
    let mut reports = Vec::new();
    let mut cancel_at_the_second = |stage: shapecorr::Stage, fraction: f32| {
        reports.push((stage, fraction));
        reports.len() < 2
    };
    let result = Eigenbasis::pair((&a, &b), &EigenParams::default(), &mut cancel_at_the_second);
    assert!(
        matches!(result, Err(shapecorr::Error::Cancelled)),
        "{:?}",
        result.map(|_| ())
    );
    assert_eq!(reports.len(), 2, "nothing is reported after the cancel");
    assert!(reports.iter().all(|r| (0.0..=1.0).contains(&r.1)));
}
