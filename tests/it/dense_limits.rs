//! The limits of a job on dense shapes at a scale that runs in seconds (docs/decisions.md,
//! "Dense shapes: limits"; the 1.9M-vertex figures are measured by
//! tests/bench/dense_limits.sh): a cancel lands inside reading, the repairs and the proxy
//! stage, and a memory ceiling that the files' declared sizes cannot meet is refused before
//! their bodies are read.

use std::path::Path;
use std::time::Instant;

use shapecorr::pipeline::budget::Budget;
use shapecorr::pipeline::{Correspondence, PairJob, Params};
use shapecorr::shape::io::{declared_size, write_ply};
use shapecorr::shape::proxy::{Proxy, PIECE_TRIANGLES};
use shapecorr::{Error, ReadAs, Repairs, Shape, Stage};

use crate::common::icosphere;

/// A progress that cancels at the `nth` report (from 1) of `stage` at or past `from`, and
/// remembers when.
struct CancelAt {
    stage: Stage,
    from: f32,
    nth: usize,
    asked: Option<Instant>,
}

impl CancelAt {
    fn new(stage: Stage, from: f32, nth: usize) -> Self {
        CancelAt {
            stage,
            from,
            nth,
            asked: None,
        }
    }

    fn report(&mut self, stage: Stage, fraction: f32) -> bool {
        if self.asked.is_none() && stage == self.stage && fraction >= self.from {
            self.nth -= 1;
            if self.nth == 0 {
                self.asked = Some(Instant::now());
            }
        }
        self.asked.is_none()
    }

    /// Seconds from the cancel to now.
    fn latency(&self) -> f64 {
        self.asked
            .expect("the stage was reported")
            .elapsed()
            .as_secs_f64()
    }
}

/// A 655K-triangle sphere (328K vertices) written as binary PLY.
fn dense_file(dir: &Path) -> std::path::PathBuf {
    let (vertices, triangles) = icosphere(8);
    let path = dir.join("dense.ply");
    write_ply(&path, &vertices, &triangles, None).unwrap();
    path
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("shapecorr-dense-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn a_cancel_lands_within_reading_and_within_the_repairs() {
    let dir = scratch("read");
    let path = dense_file(&dir);
    let repairs = Repairs::default();
    // Read to the end, the same file is a shape: only the cancel stops it.
    let whole = Shape::read_watched(&path, ReadAs::Auto, &repairs, &mut |_, _| true).unwrap();
    assert_eq!(whole.n_vertices(), icosphere(8).0.len());
    // From 0.05 of the parse, and from the start of the repairs (0.5).
    for from in [0.05, 0.5] {
        let mut cancel = CancelAt::new(Stage::Reading, from, 1);
        let read = Shape::read_watched(&path, ReadAs::Auto, &repairs, &mut |s, f| {
            cancel.report(s, f)
        });
        assert!(
            matches!(read, Err(Error::Cancelled)),
            "from {from}: {read:?}"
        );
        assert!(
            cancel.latency() < 0.5,
            "from {from}: {} s",
            cancel.latency()
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_ceiling_the_declared_sizes_cannot_meet_is_refused_before_reading() {
    let dir = scratch("declared");
    let path = dense_file(&dir);
    let size = declared_size(&path).unwrap();
    assert_eq!(
        (size.vertices, size.faces),
        (icosphere(8).0.len(), icosphere(8).1.len())
    );
    let mut params = Params {
        budget: Budget {
            memory_limit_mib: 100,
            ..Budget::default()
        },
        ..Params::default()
    };
    let job = PairJob {
        params: &params,
        map: None,
    };
    let t = Instant::now();
    let refused = job.check_files([&path, &path]);
    assert!(t.elapsed().as_secs_f64() < 0.5);
    match refused {
        Err(Error::ResourceLimit { limit, .. }) => assert_eq!(limit, "memory_limit_mib"),
        other => panic!("{other:?}"),
    }
    // The estimate covers the reading: above the job's on the shapes once read.
    params.budget.memory_limit_mib = 0;
    let job = PairJob {
        params: &params,
        map: None,
    };
    let files = job.check_files([&path, &path]).unwrap();
    let shape = Shape::read(&path, ReadAs::Auto).unwrap();
    let read = params
        .budget
        .check(&job.budget_job([&shape, &shape]))
        .unwrap();
    assert!(files.bytes > read.bytes, "{files:?} {read:?}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_cancel_lands_within_the_proxy_of_a_dense_mesh() {
    let (vertices, triangles) = icosphere(8);
    assert!(triangles.len() > 4 * PIECE_TRIANGLES);
    let shape = Shape::mesh(vertices, &triangles).unwrap();
    // Simplified in pieces, the proxy is still one closed piece of about the target size.
    let proxy = Proxy::build(&shape, 4000).unwrap();
    assert_eq!(proxy.shape.n_pieces(), 1);
    let n = proxy.shape.n_vertices();
    assert!((3000..=4400).contains(&n), "{n} vertices");
    // The third report comes about 50 ms into the simplification (reports every 25 ms,
    // the fraction stays 0 until the input vertices are located on the proxy).
    let mut cancel = CancelAt::new(Stage::Proxy, 0.0, 3);
    let result = Correspondence::compute(&shape, &shape, &Params::default(), &mut |s, f| {
        cancel.report(s, f)
    });
    assert!(matches!(result, Err(Error::Cancelled)), "{result:?}");
    // Pieces of 50K triangles (100K took 0.62 s on 2 shared cores).
    assert!(cancel.latency() < 0.5, "{} s", cancel.latency());
}
