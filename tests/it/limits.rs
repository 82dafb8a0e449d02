//! Never kill or hang the host (docs/decisions.md, "Option ranges", "Size limits",
//! "Budget"): every option has a range checked before any
//! work, a huge but accepted value is cancellable within a fraction of a second, and a
//! shape above `max_vertices` is refused at once, as is a job over its memory ceiling or
//! time limit: with `Error::ResourceLimit`, not the error of a bad value.

use std::time::{Duration, Instant};

use shapecorr::options::{OptionType, OptionValue, Options, OPTIONS};
use shapecorr::pipeline::multiresolution::Multiresolution;
use shapecorr::pipeline::Params;
use shapecorr::synth::{self, FigureKind, FigureSpec};
use shapecorr::NoProgress;
use shapecorr::{Error, PointwiseCorrespondence, Shape, Stage};

fn humanoid(pose: usize, vertices: usize) -> Shape {
    let mesh = synth::figure(&FigureSpec {
        kind: FigureKind::Humanoid,
        pose,
        target_vertices: vertices,
        ..Default::default()
    })
    .unwrap();
    Shape::mesh(mesh.vertices, &mesh.triangles).unwrap()
}

/// Values outside every range: each must be refused naming the option and its range.
#[test]
fn every_option_refuses_values_outside_its_range_and_names_it() {
    for info in OPTIONS.iter().filter(|o| o.name != "seed") {
        let values: Vec<OptionValue> = match info.option_type {
            OptionType::Int => [
                -1,
                info.max as i64 + 1,
                1_000_000_000_000,
                i64::MAX,
                i64::MIN,
            ]
            .into_iter()
            .chain((info.min >= 1.0).then_some(info.min as i64 - 1))
            .map(OptionValue::Int)
            .collect(),
            OptionType::Float => [f64::NAN, f64::INFINITY, -1e300, 1e300, info.max * 2.0 + 1.0]
                .into_iter()
                .map(OptionValue::Float)
                .collect(),
            OptionType::Bool => continue,
        };
        for value in values {
            let mut options = Options::default();
            match options.set_option(info.name, value) {
                Err(Error::InvalidParameter { name, reason }) => {
                    assert_eq!(name, info.name, "{value:?}");
                    let finite = !matches!(value, OptionValue::Float(v) if !v.is_finite());
                    if finite && info.choices.is_empty() {
                        assert!(
                            reason.contains(&info.range_text()),
                            "{}: {reason}",
                            info.name
                        );
                    }
                }
                other => panic!("{} = {value:?} gave {other:?}", info.name),
            }
        }
    }
}

/// A progress callback that cancels from `after` past its first report on.
struct CancelAfter {
    first_report: Option<Instant>,
    after: Duration,
}

impl CancelAfter {
    fn new(after: Duration) -> Self {
        CancelAfter {
            first_report: None,
            after,
        }
    }

    fn report(&mut self, _stage: Stage, _fraction: f32) -> bool {
        self.first_report.get_or_insert_with(Instant::now).elapsed() < self.after
    }

    /// Seconds from the moment the cancel was due to now (0 when it was not reached).
    fn latency(&self) -> f64 {
        self.first_report.map_or(0.0, |t| {
            (t.elapsed().as_secs_f64() - self.after.as_secs_f64()).max(0.0)
        })
    }
}

/// Every option at the largest value of its range, one at a time, on a small pair: the
/// job ends cleanly (a result or a typed error, never a panic or an abort) and a cancel
/// after 0.5 s is honoured within 2 s (generous, for a loaded 2-core machine).
#[test]
fn every_option_at_its_largest_value_ends_cleanly_and_cancels() {
    let a = humanoid(0, 700);
    let b = humanoid(3, 700);
    for info in OPTIONS.iter().filter(|o| o.option_type != OptionType::Bool) {
        let mut options = Options::default();
        // The pair as it is (a refined copy of 2.8K vertices with `eigenpairs` at its
        // largest is a dense eigensolve that does not look at the cancel), except for
        // `refine_below` itself.
        options
            .set_option("refine_below", OptionValue::Int(0))
            .unwrap();
        let value = match info.option_type {
            OptionType::Int => OptionValue::Int(info.max as i64),
            _ => OptionValue::Float(info.max),
        };
        options.set_option(info.name, value).unwrap();
        let mut cancel = CancelAfter::new(Duration::from_millis(500));
        let mut progress = |stage, fraction| cancel.report(stage, fraction);
        let started = Instant::now();
        let result = PointwiseCorrespondence::compute(
            &a,
            &b,
            &options.params,
            options.pointwise(),
            &mut progress,
        );
        let latency = cancel.latency();
        println!(
            "{} = {value:?}: {:.2} s, cancel latency {latency:.3} s, {}",
            info.name,
            started.elapsed().as_secs_f64(),
            result
                .as_ref()
                .map_or_else(|e| e.to_string(), |_| "ok".into())
        );
        assert!(
            latency < 2.0,
            "{}: stopped {latency:.2} s after the cancel",
            info.name
        );
    }
}

/// `kmeans_restarts` at its largest kept running 100 s after a cancel.
#[test]
fn huge_kmeans_restarts_is_cancelled_within_a_fraction_of_a_second() {
    let a = humanoid(0, 3000);
    let b = humanoid(3, 3000);
    let mut options = Options::default();
    options
        .set_option("kmeans_restarts", OptionValue::Int(1000))
        .unwrap();
    // Cancel 0.3 s into the segmentation, which takes minutes with 1000 restarts.
    let mut cancel = CancelAfter::new(Duration::from_millis(300));
    let mut progress =
        |stage, fraction| stage != Stage::Segmentation || cancel.report(stage, fraction);
    let result = shapecorr::Correspondence::compute(&a, &b, &options.params, &mut progress);
    let latency = cancel.latency();
    println!("cancel latency {latency:.3} s");
    assert!(matches!(result, Err(Error::Cancelled)), "{result:?}");
    assert!(latency < 2.0, "stopped {latency:.2} s after the cancel");
}

#[test]
fn a_shape_above_max_vertices_is_refused_before_any_work() {
    let a = humanoid(0, 700);
    let mut options = Options::default();
    options
        .set_option("max_vertices", OptionValue::Int(500))
        .unwrap();
    let started = Instant::now();
    let err =
        shapecorr::Eigenbasis::compute(&a, &options.params.eigen, &mut NoProgress).unwrap_err();
    assert!(
        matches!(
            err,
            Error::ResourceLimit {
                limit: "max_vertices",
                ..
            }
        ),
        "{err}"
    );
    assert!(
        err.to_string().contains("more than max_vertices = 500"),
        "{err}"
    );
    assert!(started.elapsed() < Duration::from_millis(100));
    assert_eq!(
        Options::default().option("max_vertices").unwrap(),
        OptionValue::Int(2_000_000)
    );
}

#[test]
fn threads_above_the_cores_are_clamped() {
    let cores = std::thread::available_parallelism().unwrap().get();
    use shapecorr::spectral::eigen::effective_threads;
    assert_eq!(effective_threads(0), cores);
    assert_eq!(effective_threads(1), 1);
    assert_eq!(effective_threads(1_000_000_000_000), cores);
}

/// An error about one shape of a pair says which.
#[test]
fn an_error_about_one_shape_of_a_pair_names_it() {
    let a = humanoid(0, 700);
    let b = humanoid(3, 1400);
    let mut options = Options::default();
    options
        .set_option("max_vertices", OptionValue::Int(1000))
        .unwrap();
    let err =
        shapecorr::Correspondence::compute(&a, &b, &options.params, &mut shapecorr::NoProgress)
            .unwrap_err();
    assert!(matches!(err, Error::InShape { side: 'B', .. }), "{err}");
    assert!(matches!(
        err.innermost(),
        Error::ResourceLimit {
            limit: "max_vertices",
            ..
        }
    ));
    assert!(err.to_string().starts_with("shape B: "), "{err}");
}

/// A valid shape scaled by 1e-100 (its area, 1e-200, is representable
/// but its squared lengths are not) gives the same Laplacian and the same regions.
#[test]
fn a_shape_scaled_by_1e_minus_100_gives_the_same_answer() {
    let mesh = synth::figure(&FigureSpec {
        kind: FigureKind::Humanoid,
        target_vertices: 700,
        ..Default::default()
    })
    .unwrap();
    let tiny: Vec<[f64; 3]> = mesh
        .vertices
        .iter()
        .map(|v| v.map(|x| x * 1e-100))
        .collect();
    let plain = Shape::mesh(mesh.vertices.clone(), &mesh.triangles).unwrap();
    let small = Shape::mesh(tiny, &mesh.triangles).unwrap();
    let (lp, ls) = (
        shapecorr::spectral::laplacian::Laplacian::new(&plain).unwrap(),
        shapecorr::spectral::laplacian::Laplacian::new(&small).unwrap(),
    );
    let relative = (ls.input_area / (lp.input_area * 1e-200) - 1.0).abs();
    assert!(
        relative < 1e-9,
        "area {} vs {}",
        ls.input_area,
        lp.input_area
    );
    let close = lp
        .mass
        .iter()
        .zip(&ls.mass)
        .all(|(a, b)| (a - b).abs() <= 1e-9 * a);
    assert!(close, "masses differ");
    let b = humanoid(3, 700);
    let params = Options::default().params;
    let with_plain =
        shapecorr::Correspondence::compute(&plain, &b, &params, &mut shapecorr::NoProgress)
            .unwrap();
    let with_small =
        shapecorr::Correspondence::compute(&small, &b, &params, &mut shapecorr::NoProgress)
            .unwrap();
    assert_eq!(with_plain.graph_a.labels, with_small.graph_a.labels);
    assert_eq!(with_plain.matches, with_small.matches);
    // The orientation test of the map's verification works at that scale too (its normals
    // underflowed to 0 and the confidence with them).
    assert_eq!(with_plain.matches_one_to_one, with_small.matches_one_to_one);
    let (c_plain, c_small) = (with_plain.confidence(), with_small.confidence());
    assert!(c_plain.unwrap() > 0.0, "{c_plain:?}");
    // On the refined copies (700 vertices are below `refine_below`) the confidence agrees
    // to 1.5e-4 (measured: 0.85413 vs 0.85427); on the shapes as they are, to round-off.
    assert!(
        (c_plain.unwrap() - c_small.unwrap()).abs() < 1e-3,
        "{c_plain:?} vs {c_small:?}"
    );
    let as_they_are = Params {
        multiresolution: Multiresolution {
            refine_below: 0,
            ..Default::default()
        },
        ..params
    };
    let confidence = |a: &Shape| {
        shapecorr::Correspondence::compute(a, &b, &as_they_are, &mut shapecorr::NoProgress)
            .unwrap()
            .confidence()
            .unwrap()
    };
    let (c_plain, c_small) = (confidence(&plain), confidence(&small));
    assert!(
        (c_plain - c_small).abs() < 1e-6,
        "as they are: {c_plain} vs {c_small}"
    );
}

/// The memory check before the eigensolve: 1000 eigenpairs of a 2M-vertex shape need
/// over 100 GB (refused on a machine with less), the defaults on 3,000 vertices a few MB.
#[test]
fn the_eigensolver_memory_estimate_scales_with_size_and_eigenpairs() {
    use shapecorr::spectral::eigen::eigensolver_bytes;
    let big = shapecorr::EigenParams {
        n_eigenpairs: 1000,
        ..Default::default()
    };
    assert!(eigensolver_bytes(2_000_000, &big) > 100_000_000_000);
    let small = Options::default().params.eigen;
    assert!(eigensolver_bytes(3000, &small) < 20_000_000);
}

/// A caller that is the only worker of the global pool (RAYON_NUM_THREADS=1, inside a
/// parallel loop) must not deadlock while it polls for progress. Runs itself again as a
/// child process with one global thread.
#[test]
fn a_job_started_from_the_only_global_pool_worker_finishes() {
    const CHILD: &str = "SHAPECORR_TEST_ONE_THREAD_CHILD";
    if std::env::var_os(CHILD).is_some() {
        assert_eq!(rayon::current_num_threads(), 1);
        let (a, b) = (humanoid(0, 700), humanoid(3, 700));
        let params = Options::default().params;
        let result = rayon::scope(|_| {
            shapecorr::Correspondence::compute(&a, &b, &params, &mut shapecorr::NoProgress)
        });
        assert!(result.is_ok(), "{result:?}");
        return;
    }
    let mut child = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "limits::a_job_started_from_the_only_global_pool_worker_finishes",
        ])
        .env(CHILD, "1")
        .env("RAYON_NUM_THREADS", "1")
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while started.elapsed() < Duration::from_secs(60) {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success(), "the child failed: {status}");
            return;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    panic!("the job deadlocked with one global thread");
}

/// The pointwise map (its functional maps, ZoomOut, the hypotheses'
/// verification and the full-resolution conversions) honours a cancel inside itself. With
/// 300 eigenpairs, ZoomOut to 300 and a heavy commutativity term it runs for seconds; it
/// stopped 0.9 s after a cancel when it checked only between stages.
#[test]
fn the_pointwise_map_is_cancelled_within_a_fraction_of_a_second() {
    let a = humanoid(0, 3000);
    let b = humanoid(3, 3000);
    let mut options = Options::default();
    for (name, value) in [
        ("p2p_eigenpairs", OptionValue::Int(300)),
        ("p2p_zoomout_end", OptionValue::Int(300)),
        ("p2p_zoomout_step", OptionValue::Int(1)),
        ("p2p_descriptor_commutativity", OptionValue::Float(1e3)),
    ] {
        options.set_option(name, value).unwrap();
    }
    for after_ms in [100, 400, 1000] {
        let mut cancel = CancelAfter::new(Duration::from_millis(after_ms));
        let mut progress =
            |stage, fraction| stage != Stage::PointwiseMap || cancel.report(stage, fraction);
        let result = PointwiseCorrespondence::compute(
            &a,
            &b,
            &options.params,
            options.pointwise(),
            &mut progress,
        );
        let latency = cancel.latency();
        println!("cancel {after_ms} ms into the map: latency {latency:.3} s");
        assert!(matches!(result, Err(Error::Cancelled)), "{result:?}");
        // Measured 0.05-0.15 s; the bound leaves room for a loaded 2-core machine.
        assert!(latency < 1.0, "stopped {latency:.2} s after the cancel");
    }
}

/// A 2M-vertex `match` either finishes within the budget or is
/// refused at once with the reason. At full resolution (`proxy_above` 0) the default budget
/// refuses it before any work (its vertex maps alone are about 4e14 products), naming the
/// limit and what to do; by default (on proxies, docs/design.md, step 16) `max_vertices` refuses it.
#[test]
fn a_two_million_vertex_pair_is_refused_at_once_by_the_default_budget() {
    // A 1415 x 1415 grid of points: 2,002,225 vertices.
    let side = 1415;
    let points: Vec<[f64; 3]> = (0..side * side)
        .map(|i| [(i % side) as f64, (i / side) as f64, 0.0])
        .collect();
    let cloud = Shape::point_cloud_with(points, &shapecorr::Repairs::none()).unwrap();
    // By default the memory ceiling is what the machine has (under 100 GB here) and the
    // time limit half an hour; with the largest ceiling, the time limit refuses it.
    let started = Instant::now();
    let err = shapecorr::Correspondence::compute(
        &cloud,
        &cloud,
        &Options::default().params,
        &mut shapecorr::NoProgress,
    )
    .unwrap_err();
    assert!(started.elapsed().as_secs_f64() < 1.0);
    assert!(
        err.to_string()
            .contains("resource limit `max_vertices`: the shape has 2002225 vertices"),
        "{err}"
    );
    for (memory_limit_mib, refused_by) in [(0, None), (16_777_216, Some("time_limit_s"))] {
        let mut options = Options::default();
        options
            .set_option("memory_limit_mib", OptionValue::Int(memory_limit_mib))
            .unwrap();
        options
            .set_option("proxy_above", OptionValue::Int(0))
            .unwrap();
        let started = Instant::now();
        let result = shapecorr::Correspondence::compute(
            &cloud,
            &cloud,
            &options.params,
            &mut shapecorr::NoProgress,
        );
        let seconds = started.elapsed().as_secs_f64();
        let err = result.unwrap_err();
        println!("memory_limit_mib {memory_limit_mib}: {seconds:.3} s: {err}");
        assert!(seconds < 1.0, "took {seconds:.2} s to refuse");
        let Error::ResourceLimit { limit: name, .. } = &err else {
            panic!("{err}")
        };
        assert!(
            [Some(*name), None].contains(&refused_by)
                && ["time_limit_s", "memory_limit_mib"].contains(name),
            "{err}"
        );
        assert!(err.to_string().contains("raise"), "{err}");
    }
}

/// The time limit is also enforced while a job runs: a job whose estimate fits but which
/// runs long (1000 k-means restarts) stops at the limit with the error naming it.
#[test]
fn a_job_that_runs_past_its_time_limit_stops_there() {
    let a = humanoid(0, 3000);
    let b = humanoid(3, 3000);
    let mut options = Options::default();
    options
        .set_option("kmeans_restarts", OptionValue::Int(1000))
        .unwrap();
    options
        .set_option("time_limit_s", OptionValue::Float(1.0))
        .unwrap();
    let started = Instant::now();
    let result =
        shapecorr::Correspondence::compute(&a, &b, &options.params, &mut shapecorr::NoProgress);
    let seconds = started.elapsed().as_secs_f64();
    println!("stopped after {seconds:.2} s: {result:?}");
    assert!(
        matches!(
            result,
            Err(Error::ResourceLimit {
                limit: "time_limit_s",
                ..
            })
        ),
        "{result:?}"
    );
    assert!(seconds < 2.5, "stopped after {seconds:.2} s");
}

/// A job refused by the memory ceiling is a resource limit, not a bad value: every job
/// (regions, symmetry, pointwise map) on two small shapes with `memory_limit_mib = 1` is
/// refused at once with `Error::ResourceLimit` naming the limit, the estimate and what to
/// do, while a value out of the option's range stays `Error::InvalidParameter`.
#[test]
fn a_job_over_the_memory_ceiling_is_refused_with_a_resource_limit() {
    let a = humanoid(0, 700);
    let b = humanoid(3, 700);
    let mut options = Options::default();
    options
        .set_option("memory_limit_mib", OptionValue::Int(1))
        .unwrap();
    let started = Instant::now();
    let results = [
        shapecorr::Correspondence::compute(&a, &b, &options.params, &mut shapecorr::NoProgress)
            .map(drop),
        shapecorr::Symmetry::detect(&a, &options.params, &mut shapecorr::NoProgress).map(drop),
        PointwiseCorrespondence::compute(
            &a,
            &b,
            &options.params,
            options.pointwise(),
            &mut shapecorr::NoProgress,
        )
        .map(drop),
    ];
    assert!(started.elapsed() < Duration::from_millis(500));
    for result in results {
        let err = result.unwrap_err();
        let Error::ResourceLimit { limit, reason } = &err else {
            panic!("expected a resource limit, got {err:?}")
        };
        assert_eq!(*limit, "memory_limit_mib");
        assert!(reason.contains("needs about"), "{reason}");
        assert!(reason.contains("ceiling of 1 MiB"), "{reason}");
        assert!(reason.contains("raise memory_limit_mib"), "{reason}");
        assert!(
            err.to_string()
                .starts_with("resource limit `memory_limit_mib`: "),
            "{err}"
        );
    }
    // The same option out of its range is a bad value.
    assert!(matches!(
        options.set_option("memory_limit_mib", OptionValue::Int(-1)),
        Err(Error::InvalidParameter {
            name: "memory_limit_mib",
            ..
        })
    ));
}
