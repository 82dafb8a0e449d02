//! What one job may use: a memory ceiling and a time limit (docs/decisions.md, "Budget").
//! Both are checked against an estimate before any work, so a job that cannot fit is
//! refused at once with the reason; the time limit is also enforced while the job runs,
//! through the same checks that honour a cancel (within a fraction of a second in every
//! long stage).
//!
//! The estimates are models of what the pipeline allocates and computes, with constants
//! measured on generated humanoids (docs/decisions.md, "Budget"): the peak memory of the
//! eigensolver (the Lanczos vectors and the Cholesky factor), of the eigenbases kept for
//! the pair, and of the full-resolution conversions of functional maps to vertex maps; the
//! time of the eigensolves and of those conversions, which are quadratic in the vertex
//! count (`n_a n_b k` products) and so decide what a large pair costs.

use std::time::{Duration, Instant};

use crate::progress::{Progress, Stage};
use crate::shape::io::DeclaredSize;
use crate::spectral::eigen::{effective_threads, eigensolver_bytes, EigenParams, CONCURRENT_BELOW};
use crate::{Error, Result};

/// The limits of one job.
#[derive(Debug, Clone, PartialEq)]
pub struct Budget {
    /// Largest estimated peak memory, in MiB; 0 (the default) is the memory the system has
    /// available when the job starts (`MemAvailable`; no limit where the system does not
    /// say).
    pub memory_limit_mib: u64,
    /// Longest a job may run, in seconds; 0 is no limit. Default [`DEFAULT_TIME_LIMIT_S`].
    pub time_limit_s: f64,
    /// When the time limit's clock started; `None` (the default): when the job starts. A
    /// front end that reads the shapes as part of the job sets it before reading
    /// ([`Budget::run`] on the reading too).
    pub started: Option<Instant>,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

/// Default [`Budget::time_limit_s`]: half an hour. A 100K-vertex pair takes minutes here
/// and a 2M-vertex pair hours (its vertex maps alone are 4e14 products), which a user should
/// hear at once rather than after waiting.
pub const DEFAULT_TIME_LIMIT_S: f64 = 1800.0;

impl Default for Budget {
    fn default() -> Self {
        Budget {
            memory_limit_mib: 0,
            time_limit_s: DEFAULT_TIME_LIMIT_S,
            started: None,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

/// What a job will take, estimated before it starts.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Estimate {
    /// Peak memory, in bytes.
    pub bytes: u64,
    /// Wall time on the reference machine (2 cores), in seconds.
    pub seconds: f64,
}

impl Estimate {
    /// The estimated peak memory in MiB.
    pub fn mib(&self) -> f64 {
        self.bytes as f64 / MIB
    }
}

/// The work of one job: the two shapes' sizes and what is computed on them.
#[derive(Debug, Clone, Copy)]
pub struct Job {
    /// Active vertices of shape A and shape B (the same shape twice for a symmetry job): of
    /// their proxies when they have one.
    pub vertices: [usize; 2],
    /// Vertices of the input shapes A and B, which the job holds throughout; where one is
    /// larger than [`Job::vertices`], the shape is replaced by its proxy.
    pub inputs: [usize; 2],
    /// Eigenpairs computed per shape.
    pub eigenpairs: usize,
    /// Full-resolution conversions of a functional map to a vertex map (each `n_a n_b k`
    /// products), and the size `k` of those maps.
    pub conversions: usize,
    /// Functional map size of the conversions.
    pub conversion_size: usize,
    /// Threads of the dense products.
    pub threads: usize,
    /// Sides the pair may try again without the objects touching their figure
    /// ([`crate::Shape::may_have_touching_objects`]): a try holds the first answer's
    /// shapes and bases beside its own work. The tries add no time: the time limit ends
    /// them, not the job.
    pub objects_tried: [bool; 2],
}

const MIB: f64 = 1024.0 * 1024.0;

/// Memory of the process before any shape: code, thread stacks, allocator pools. Chosen so
/// that the 3K-5K-vertex pairs' measured peaks (63-153 MiB) stay under the estimate.
const BASE_BYTES: u64 = 90 << 20;

/// Bytes per vertex of everything else a job holds per shape: positions, faces, neighbours,
/// repair maps, the Laplacian, descriptors, the regions' indicator and operator matrices,
/// and what the allocator keeps of the parallel stages' scratch. Measured: the peak of the
/// same 20K-vertex `match` varied from 224 to 532 MiB between runs (thread timing and the
/// allocator's per-thread arenas) until `nearest_rows` reused its distance blocks; this
/// constant keeps the estimate above every peak measured on generated humanoids of
/// 3K-100K vertices (docs/decisions.md, "Budget").
const SHAPE_BYTES_PER_VERTEX: u64 = 4500;

/// Nonzeros of the Cholesky factor per vertex: an allowance for the fill of nested
/// dissection on surface meshes, not measured on its own (the whole estimate is what the
/// measured peaks were compared with).
const FACTOR_NONZEROS_PER_VERTEX: u64 = 60;

/// Queries per block of the dense nearest-neighbour search (`maps::fmap`'s `NN_BLOCK`):
/// each thread holds one `n_a x block` distance block in single precision.
const CONVERSION_BLOCK: u64 = 256;

/// Multiply-adds per second and thread of the single-precision products of a conversion,
/// measured with `p2p` at 50K vertices on a 2-core AMD EPYC (2.5e11 products a conversion
/// at 100 eigenpairs; 48 s for three of them with the hypotheses' sample refinements).
const CONVERSION_PRODUCTS_PER_SECOND: f64 = 8e9;

/// Seconds per vertex, eigenpair and doubling of the size for one eigensolve (shift-invert
/// Lanczos): 0.9 s for 20K vertices and 50 eigenpairs, 6-15 s for 50K and 50-100.
const EIGEN_SECONDS: f64 = 1e-7;

/// Address space a thread takes beyond the estimate, counted under an address-space limit:
/// the matrix products' scratch (2 x one core's L3 share: 32 MiB on the 2-core reference
/// machine) and its stack (2 MiB). With one allocator arena
/// ([`crate::system::fit_allocator_to_address_space_limit`]) a 5K-vertex `match` there
/// peaked at 162 MiB of address space against an estimate of 180 MiB (docs/decisions.md,
/// "Address space").
const ADDRESS_SPACE_PER_THREAD: u64 = 40 << 20;

/// Bytes per vertex of an input shape held while the job runs on its proxy: the positions
/// (24), about two triangles (24), the active and representative indices (8), and where
/// every vertex lies on the proxy (40). Counted, not fitted.
const INPUT_BYTES_PER_VERTEX: u64 = 96;

/// Bytes per input vertex while a proxy is built (on top of the held input): single
/// precision positions (12), the triangles' indices (24), meshoptimizer's tables for a
/// piece of at most [`crate::shape::proxy::PIECE_TRIANGLES`] triangles (bounded, counted in
/// [`PROXY_FIXED_BYTES`]), the order of the triangles (4) and the k-d tree of the
/// proxy's answers brought back (48 per vertex of A, with the lifted map). Rounded up from
/// the measured peaks on a 1.9M-vertex figure (docs/decisions.md, "Dense shapes: limits").
const PROXY_BYTES_PER_VERTEX: u64 = 120;

/// The proxy stage's memory that does not grow with the input: meshoptimizer's tables for
/// pieces of [`crate::shape::proxy::PIECE_TRIANGLES`] triangles on every thread.
const PROXY_FIXED_BYTES: u64 = 64 << 20;

/// Seconds per input vertex of building a proxy and bringing the answers back, measured on
/// a 1.9M-vertex figure on the 2-core reference machine (docs/decisions.md, "Dense
/// shapes: limits").
const PROXY_SECONDS_PER_VERTEX: f64 = 2e-6;

/// Bytes per declared vertex while a file is read and repaired: the vertex as read (24),
/// as kept (24 and 8 of indices), and the repairs' tables (weld targets, flags, the k-d
/// tree of the weld). Fitted with [`READ_BYTES_PER_FACE`] to the peak of reading a
/// 1.9M-vertex PLY (docs/decisions.md, "Dense shapes: limits").
const READ_BYTES_PER_VERTEX: u64 = 160;

/// Bytes per declared face while a file is read and repaired: the polygon as read (its own
/// allocation: 24 and 32), its slice (16), its triangle (12) and the repairs' copies.
const READ_BYTES_PER_FACE: u64 = 110;

/// Seconds per byte of reading and repairing a shape file on the 2-core reference
/// machine (docs/decisions.md, "Dense shapes: limits").
const READ_SECONDS_PER_BYTE: f64 = 1e-7;

/// Peak bytes of reading and repairing a file of this size (its bytes included).
pub fn reading_bytes(size: &DeclaredSize) -> u64 {
    size.bytes
        + size.vertices as u64 * READ_BYTES_PER_VERTEX
        + size.faces as u64 * READ_BYTES_PER_FACE
}

/// Seconds of reading and repairing a file of this size.
pub fn reading_seconds(size: &DeclaredSize) -> f64 {
    size.bytes as f64 * READ_SECONDS_PER_BYTE
}

/// The job's estimated peak memory and time.
pub fn estimate(job: &Job) -> Estimate {
    let [n_a, n_b] = job.vertices.map(|n| n as u64);
    let k = job.eigenpairs as u64;
    let largest = n_a.max(n_b);
    let eigen = EigenParams {
        n_eigenpairs: job.eigenpairs.max(1),
        ..Default::default()
    };
    // Both shapes and their bases are kept for the pair; the two eigensolves run together
    // up to `CONCURRENT_BELOW` vertices, else one at a time.
    let kept = (n_a + n_b) * (SHAPE_BYTES_PER_VERTEX + 8 * k.min(largest));
    let solve =
        |n: u64| eigensolver_bytes(n as usize, &eigen) + n * FACTOR_NONZEROS_PER_VERTEX * 12;
    let eigensolve = if largest as usize <= CONCURRENT_BELOW {
        solve(n_a) + solve(n_b)
    } else {
        solve(largest)
    };
    let conversion = if job.conversions > 0 {
        let c = job.conversion_size as u64;
        // The embedding of A (double and single precision, row-major copy) and B's rows,
        // then one distance block per thread.
        (n_a + n_b) * c * 20 + job.threads as u64 * n_a * CONVERSION_BLOCK * 4
    } else {
        0
    };
    // Input shapes replaced by proxies are held at full size, and a proxy's construction
    // comes before the working shapes' own memory.
    let (inputs, proxy_stage, proxy_seconds) = proxied_inputs(job);
    // A try without objects holds what the first answer kept and the trimmed copies of the
    // inputs it runs on (measured: peaks 1.17-1.20 of the estimate without this, on 20K-
    // and 50K-vertex humanoids with a box at a foot; docs/scans.md, "Props").
    let trimmed: u64 = (0..2)
        .filter(|&i| job.objects_tried[i])
        .map(|i| job.inputs[i] as u64 * INPUT_BYTES_PER_VERTEX)
        .sum();
    let tries = if trimmed > 0 { kept + trimmed } else { 0 };
    let bytes = BASE_BYTES + inputs + tries + (kept + eigensolve.max(conversion)).max(proxy_stage);
    let doublings = |n: u64| (n.max(2) as f64).log2();
    let eigen_seconds = [n_a, n_b]
        .map(|n| EIGEN_SECONDS * (n * k) as f64 * doublings(n))
        .iter()
        .sum::<f64>();
    let products = job.conversions as f64 * (n_a * n_b * job.conversion_size as u64) as f64;
    let conversion_seconds = products / (CONVERSION_PRODUCTS_PER_SECOND * job.threads as f64);
    Estimate {
        bytes,
        seconds: eigen_seconds + conversion_seconds + proxy_seconds,
    }
}

/// What the input shapes that get a proxy add to a job: the held inputs' bytes, the proxy
/// stage's bytes and its seconds.
fn proxied_inputs(job: &Job) -> (u64, u64, f64) {
    let proxied: Vec<u64> = (0..2)
        .filter(|&i| job.inputs[i] > job.vertices[i])
        .map(|i| job.inputs[i] as u64)
        .collect();
    if proxied.is_empty() {
        return (0, 0, 0.0);
    }
    let held = proxied.iter().sum::<u64>() * INPUT_BYTES_PER_VERTEX;
    let largest = proxied.iter().copied().max().unwrap_or(0);
    let stage = PROXY_FIXED_BYTES + largest * PROXY_BYTES_PER_VERTEX;
    let seconds = proxied.iter().sum::<u64>() as f64 * PROXY_SECONDS_PER_VERTEX;
    (held, stage, seconds)
}

impl Budget {
    /// The memory ceiling in bytes: the configured one, or what the system has available.
    pub fn memory_limit_bytes(&self) -> Option<u64> {
        if self.memory_limit_mib > 0 {
            Some(self.memory_limit_mib.saturating_mul(1 << 20))
        } else {
            crate::system::available_bytes()
        }
    }

    /// Refuses a job whose estimate exceeds the memory ceiling or the time limit with
    /// [`Error::ResourceLimit`], naming the option and what to do.
    pub fn check(&self, job: &Job) -> Result<Estimate> {
        self.check_estimate(job, estimate(job))
    }

    /// [`Budget::check`] for a job that first reads its two shape files, from what the files
    /// declare ([`crate::shape::io::declared_size`]; `job` on those counts): the peak of
    /// reading A, of holding A while reading B, or of the job.
    pub fn check_with_reading(&self, job: &Job, files: [&DeclaredSize; 2]) -> Result<Estimate> {
        let [a, b] = files;
        let work = estimate(job);
        let held_a = a.vertices as u64 * INPUT_BYTES_PER_VERTEX;
        let estimate = Estimate {
            bytes: work
                .bytes
                .max(BASE_BYTES + reading_bytes(a))
                .max(BASE_BYTES + held_a + reading_bytes(b)),
            seconds: work.seconds + reading_seconds(a) + reading_seconds(b),
        };
        self.check_estimate(job, estimate)
    }

    fn check_estimate(&self, job: &Job, estimate: Estimate) -> Result<Estimate> {
        let [n_a, n_b] = job.inputs;
        let pair = if n_a == n_b {
            format!("{n_a}-vertex shapes")
        } else {
            format!("{n_a}- and {n_b}-vertex shapes")
        };
        if let Some(limit) = self.memory_limit_bytes() {
            if estimate.bytes > limit {
                return Err(Error::ResourceLimit {
                    limit: "memory_limit_mib",
                    reason: format!(
                        "the job on {pair} needs about {:.0} MiB, more than the {} {:.0} MiB; \
                         simplify the shapes, ask for fewer eigenpairs or raise \
                         memory_limit_mib",
                        estimate.mib(),
                        if self.memory_limit_mib > 0 {
                            "ceiling of"
                        } else {
                            "memory available,"
                        },
                        limit as f64 / MIB
                    ),
                });
            }
        }
        if let Some(left) = crate::system::address_space_left() {
            let threads = job.threads as u64 + 2;
            let needs = estimate.bytes + threads * ADDRESS_SPACE_PER_THREAD;
            if needs > left {
                return Err(Error::ResourceLimit {
                    limit: "address_space",
                    reason: format!(
                        "the job on {pair} needs about {:.0} MiB of address space ({:.0} MiB \
                         and {threads} threads), more than the {:.0} MiB the process may \
                         still map under its address-space limit (ulimit -v); raise the \
                         limit, use fewer threads, simplify the shapes or ask for fewer \
                         eigenpairs",
                        needs as f64 / MIB,
                        estimate.mib(),
                        left as f64 / MIB
                    ),
                });
            }
        }
        if self.time_limit_s > 0.0 && estimate.seconds > self.time_limit_s {
            return Err(Error::ResourceLimit {
                limit: "time_limit_s",
                reason: format!(
                    "the job on {pair} would take about {:.0} s on a 2-core machine, more \
                     than time_limit_s = {} s; simplify the shapes or raise time_limit_s \
                     (0: no limit)",
                    estimate.seconds, self.time_limit_s
                ),
            });
        }
        Ok(estimate)
    }

    /// When the time limit passes for a job that starts `now` (or started at
    /// [`Budget::started`], when set); `None` without a limit (0, or not a number of
    /// seconds an [`Instant`] can hold).
    pub fn deadline(&self, now: Instant) -> Option<Instant> {
        if self.time_limit_s.is_nan() || self.time_limit_s <= 0.0 {
            return None;
        }
        let limit = Duration::try_from_secs_f64(self.time_limit_s).ok()?;
        self.started.unwrap_or(now).checked_add(limit)
    }

    /// Runs `work` with `progress` wrapped so that it also stops the work once the time
    /// limit has passed; the work's cancel then becomes [`Error::ResourceLimit`] naming
    /// `time_limit_s`.
    pub fn run<T>(
        &self,
        progress: &mut dyn Progress,
        work: impl FnOnce(&mut dyn Progress) -> Result<T>,
    ) -> Result<T> {
        let Some(deadline) = self.deadline(Instant::now()) else {
            return work(progress);
        };
        let mut watched = Deadline {
            inner: progress,
            deadline,
            passed_in: None,
        };
        let result = work(&mut watched);
        match (result, watched.passed_in) {
            (Err(Error::Cancelled), Some(stage)) => Err(Error::ResourceLimit {
                limit: "time_limit_s",
                reason: format!(
                    "the job ran past time_limit_s = {} s (in stage {stage:?}) and was \
                     stopped; raise time_limit_s (0: no limit) or simplify the shapes",
                    self.time_limit_s
                ),
            }),
            (result, _) => result,
        }
    }
}

/// A progress that says stop once its deadline has passed.
struct Deadline<'a> {
    inner: &'a mut dyn Progress,
    deadline: Instant,
    passed_in: Option<Stage>,
}

impl Progress for Deadline<'_> {
    fn report(&mut self, stage: Stage, fraction: f32) -> bool {
        if Instant::now() >= self.deadline {
            self.passed_in.get_or_insert(stage);
            return false;
        }
        self.inner.report(stage, fraction)
    }
}

/// The job of a region correspondence (`Correspondence::compute`; `verify` when its
/// hypotheses are verified by maps, which converts up to three of them at full resolution).
pub fn regions_job(vertices: [usize; 2], eigen: &EigenParams, verify: bool) -> Job {
    Job {
        vertices,
        inputs: vertices,
        eigenpairs: eigen.n_eigenpairs,
        conversions: if verify { 3 } else { 0 },
        conversion_size: eigen.n_eigenpairs,
        threads: effective_threads(eigen.threads),
        objects_tried: [false; 2],
    }
}
