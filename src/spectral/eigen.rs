//! The smallest generalized eigenpairs `L phi = lambda M phi` of the unit-area shape
//! (docs/design.md, step 4), computed once per shape and reused by every later stage.
//!
//! Method: shift-invert. `A = L + sigma M` (sigma > 0, so A is positive definite even for
//! several connected pieces) is factored once by faer's supernodal sparse Cholesky; the
//! largest eigenvalues `theta = 1 / (lambda + sigma)` of the operator `A^{-1} M`,
//! self-adjoint in the M inner product, are found by a **block Lanczos** iteration with full block
//! reorthogonalisation (classical Gram-Schmidt applied twice), then Rayleigh-Ritz on the
//! block tridiagonal projection. Blocks turn the triangular solves and the
//! reorthogonalisation into matrix-matrix work (BLAS-3), which is where the time goes; the
//! start block comes from a fixed seed, so results are deterministic.
//! Small shapes use a dense eigensolver instead.

use std::sync::atomic::{AtomicU32, Ordering};

use faer::dyn_stack::MemBuffer;
use faer::linalg::matmul::matmul;
use faer::reborrow::ReborrowMut;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::progress::{check, polled, Progress, Stage};
use crate::shape::Shape;
use crate::spectral::laplacian::Laplacian;
use crate::spectral::sparse::SparseCholesky;
use crate::{Error, Result};

/// Parameters of the eigensolver. The defaults are the documented ones.
#[derive(Debug, Clone, PartialEq)]
pub struct EigenParams {
    /// Number of eigenpairs (the authors use 100).
    pub n_eigenpairs: usize,
    /// Shift `sigma` of `A = L + sigma M` on the unit-area shape. The smallest eigenvalues
    /// of a unit-area shape are O(1), so sigma = 1 keeps A well conditioned (a shift near 0
    /// made faer's solver return inaccurate and repeated eigenpairs:
    /// docs/decisions.md, "Eigensolver").
    pub shift: f64,
    /// Convergence: a Ritz pair is accepted when its residual in the shift-inverted operator
    /// is below `tolerance * theta`.
    pub tolerance: f64,
    /// Vectors per Lanczos block.
    pub block_size: usize,
    /// Seed of the random start block.
    pub seed: u64,
    /// Threads for the dense matrix products (0 = all available). The result does not depend
    /// on it.
    pub threads: usize,
    /// Largest shape accepted, in vertices ([`DEFAULT_MAX_VERTICES`]): a larger shape is
    /// refused before the Laplacian is built.
    pub max_vertices: usize,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for EigenParams {
    fn default() -> Self {
        EigenParams {
            n_eigenpairs: 100,
            shift: 1.0,
            tolerance: 1e-13,
            block_size: 4,
            seed: 0x5eed,
            threads: 0,
            max_vertices: DEFAULT_MAX_VERTICES,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

/// Largest shape, in vertices, whose eigenbasis [`Eigenbasis::pair`] computes at the same
/// time as the other shape's. The solver's products gain little from a second thread
/// (FAUST, 6,890 vertices: 0.255 s on one thread, 0.246 s on two, 2-core AMD EPYC), so two
/// solves side by side take the time of one; above this size they run one after the other
/// so that the peak memory stays one solve's. Not tuned: a size where two solves hold
/// under 250 MiB.
pub const CONCURRENT_BELOW: usize = 20_000;

/// Default [`EigenParams::max_vertices`]: 2 million vertices. Measured (docs/decisions.md,
/// "Size limits"): a 300K-vertex pair took 289 s and 1.47 GB on a 2-core machine, so 2M is
/// about 10 GB and half an hour, the most a desktop can do; larger shapes should be
/// simplified first.
pub const DEFAULT_MAX_VERTICES: usize = 2_000_000;

/// The threads the dense products use: `threads` (0: all) clamped to the machine's cores,
/// so that a huge value neither spins nor oversubscribes.
pub fn effective_threads(threads: usize) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if threads == 0 {
        cores
    } else {
        threads.min(cores)
    }
}

/// Fixes faer's global parallelism (its matrix products and dense decompositions) to
/// [`FAER_SPLIT`] tasks, once per process. faer splits work by its `Par`'s thread count and
/// the split changes the rounding; its default, `Par::rayon(0)`, takes the size of the
/// current rayon pool, so results differed in the last digits between RAYON_NUM_THREADS=1
/// and 2 (docs/decisions.md, "Determinism across thread counts"). A constant split (not the
/// machine's cores) keeps them bit-identical for any pool size on any machine; the tasks
/// run on however many threads the pool has.
pub fn fix_faer_parallelism() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| faer::set_global_parallelism(Par::rayon(FAER_SPLIT)));
}

/// The number of tasks faer's parallel kernels split into ([`fix_faer_parallelism`]).
pub const FAER_SPLIT: usize = 8;

/// Most eigenpairs computed (the range of the options `eigenpairs` and `p2p_eigenpairs`):
/// an n x 1000 basis of a 2M-vertex shape is 16 GB.
pub const MAX_EIGENPAIRS: usize = 1000;

/// Below this many active vertices the dense eigensolver is used.
const DENSE_LIMIT: usize = 600;

/// A shape with its eigenbasis: what every stage after the eigensolver takes.
#[derive(Debug, Clone, Copy)]
pub struct ShapeBasis<'a> {
    /// The shape.
    pub shape: &'a Shape,
    /// Its eigenbasis ([`Eigenbasis::compute`]).
    pub basis: &'a Eigenbasis,
}

impl<'a> ShapeBasis<'a> {
    /// The shape and its basis side by side.
    pub fn new(shape: &'a Shape, basis: &'a Eigenbasis) -> Self {
        ShapeBasis { shape, basis }
    }
}

/// Eigenvalues and M-orthonormal eigenvectors of a shape's Laplacian (unit-area shape).
#[derive(Debug, Clone)]
pub struct Eigenbasis {
    /// Eigenvalues, ascending (the first is 0 up to round-off for each connected piece).
    pub values: Vec<f64>,
    /// Eigenvectors as columns, one row per *input* vertex (rows of unreferenced vertices are
    /// copies of their representative's), M-orthonormal: `Phi^T M Phi = I`.
    pub vectors: Mat<f64>,
    /// Lumped mass per input vertex on the unit-area shape (0 for unreferenced vertices).
    pub mass: Vec<f64>,
    /// The shape's area in the caller's units (the scale that was divided out).
    pub input_area: f64,
}

impl Eigenbasis {
    /// Laplacian and eigenpairs of a shape, reporting progress and honouring cancellation
    /// ([`crate::NoProgress`] for neither).
    pub fn compute(
        shape: &Shape,
        params: &EigenParams,
        progress: &mut dyn Progress,
    ) -> Result<Eigenbasis> {
        check(progress, Stage::Laplacian, 0.0)?;
        check_size(shape, params)?;
        let laplacian = Laplacian::new(shape)?;
        check(progress, Stage::Laplacian, 1.0)?;
        let (values, compact) =
            eigenpairs(&laplacian, params, progress).map_err(|e| with_shape_hint(e, shape))?;
        let k = values.len();
        let active = shape.active_vertices();
        let mut row_of = vec![usize::MAX; shape.n_vertices()];
        for (row, &v) in active.iter().enumerate() {
            row_of[v as usize] = row;
        }
        let representative = shape.representative();
        let vectors = Mat::from_fn(shape.n_vertices(), k, |v, j| {
            compact[(row_of[representative[v] as usize], j)]
        });
        let mut mass = vec![0.0; shape.n_vertices()];
        for (row, &v) in active.iter().enumerate() {
            mass[v as usize] = laplacian.mass[row];
        }
        Ok(Eigenbasis {
            values,
            vectors,
            mass,
            input_area: laplacian.input_area,
        })
    }

    /// The eigenbases of shapes A and B and the seconds each took, errors naming the shape.
    /// Shapes of at most [`CONCURRENT_BELOW`] vertices are solved at the same time, one per
    /// thread; progress is then the mean of the two.
    pub fn pair(
        (a, b): (&Shape, &Shape),
        params: &EigenParams,
        progress: &mut dyn Progress,
    ) -> Result<([Eigenbasis; 2], [f64; 2])> {
        let timed = |shape: &Shape, name: char, progress: &mut dyn Progress| {
            let started = std::time::Instant::now();
            let basis =
                Eigenbasis::compute(shape, params, progress).map_err(|e| e.in_shape(name))?;
            Ok::<_, Error>((basis, started.elapsed().as_secs_f64()))
        };
        let largest = a.active_vertices().len().max(b.active_vertices().len());
        if largest > CONCURRENT_BELOW || rayon::current_num_threads() < 2 {
            let (basis_a, t_a) = timed(a, 'A', progress)?;
            let (basis_b, t_b) = timed(b, 'B', progress)?;
            return Ok(([basis_a, basis_b], [t_a, t_b]));
        }
        polled(progress, Stage::Eigenbasis, (0.0, 1.0), |cancel| {
            let halves = [AtomicU32::new(0), AtomicU32::new(0)];
            let half = |i: usize| {
                let halves = &halves;
                move |_: Stage, fraction: f32| {
                    halves[i].store(fraction.to_bits(), Ordering::Relaxed);
                    let done = halves
                        .iter()
                        .map(|h| f32::from_bits(h.load(Ordering::Relaxed)));
                    cancel.set_fraction(done.sum::<f32>() / 2.0);
                    cancel.check().is_ok()
                }
            };
            let (result_a, result_b) = rayon::join(
                || timed(a, 'A', &mut half(0)),
                || timed(b, 'B', &mut half(1)),
            );
            let ((basis_a, t_a), (basis_b, t_b)) = (result_a?, result_b?);
            Ok(([basis_a, basis_b], [t_a, t_b]))
        })
    }

    /// Number of eigenpairs.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// True when there are no eigenpairs.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

impl EigenParams {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<()> {
        validate(self)
    }
}

/// Bytes the eigensolver needs at most for `n` vertices: the Lanczos basis (up to
/// `6k + 20b` vectors) and the eigenvectors, 8 bytes a value.
pub fn eigensolver_bytes(n: usize, params: &EigenParams) -> u64 {
    let k = params.n_eigenpairs.min(n) as u64;
    let vectors = (6 * k + 20 * params.block_size as u64).min(n as u64) + 2 * k;
    n as u64 * vectors * 8
}

/// Refuses a shape above [`EigenParams::max_vertices`], or one whose eigenbasis needs more
/// memory than the system has, before anything is allocated ([`Error::ResourceLimit`]).
fn check_size(shape: &Shape, params: &EigenParams) -> Result<()> {
    let n = shape.active_vertices().len();
    let needed = eigensolver_bytes(n, params);
    if let Some(available) = crate::system::available_bytes().filter(|&a| needed > a) {
        let gb = |b: u64| b as f64 / 1e9;
        return Err(Error::ResourceLimit {
            limit: "available_memory",
            reason: format!(
                "{} eigenpairs of a {n}-vertex shape need about {:.1} GB, more than the \
                 {:.1} GB available; ask for fewer eigenpairs or simplify the shape",
                params.n_eigenpairs,
                gb(needed),
                gb(available)
            ),
        });
    }
    check_max_vertices(shape, params)
}

/// Refuses a shape above [`EigenParams::max_vertices`] with [`Error::ResourceLimit`] (also
/// checked on a dense input before its proxy is built: docs/design.md, step 16).
pub(crate) fn check_max_vertices(shape: &Shape, params: &EigenParams) -> Result<()> {
    let n = shape.active_vertices().len();
    if n > params.max_vertices {
        return Err(Error::ResourceLimit {
            limit: "max_vertices",
            reason: format!(
                "the shape has {n} vertices, more than max_vertices = {}; simplify it or \
                 raise max_vertices",
                params.max_vertices
            ),
        });
    }
    Ok(())
}

fn validate(params: &EigenParams) -> Result<()> {
    let bad = |name, reason: &str| {
        Err(Error::InvalidParameter {
            name,
            reason: reason.to_string(),
        })
    };
    if params.n_eigenpairs == 0 || params.n_eigenpairs > MAX_EIGENPAIRS {
        return bad(
            "n_eigenpairs",
            "must lie in [1, 1000] (the `eigenpairs` option's range)",
        );
    }
    if !(params.shift > 0.0 && params.shift.is_finite()) {
        return bad("shift", "must be a positive finite number");
    }
    if !(params.tolerance > 0.0 && params.tolerance < 1.0) {
        return bad("tolerance", "must lie in (0, 1)");
    }
    if params.block_size == 0 || params.block_size > 64 {
        return bad("block_size", "must lie in 1..=64");
    }
    Ok(())
}

/// The `params.n_eigenpairs` smallest eigenpairs of `(L, M)` (fewer if the operator is
/// smaller), eigenvalues ascending, eigenvectors M-orthonormal, on the Laplacian's rows.
pub fn eigenpairs(
    laplacian: &Laplacian,
    params: &EigenParams,
    progress: &mut dyn Progress,
) -> Result<(Vec<f64>, Mat<f64>)> {
    validate(params)?;
    fix_faer_parallelism();
    let n = laplacian.len();
    let k = params.n_eigenpairs.min(n);
    let par = match effective_threads(params.threads) {
        1 => Par::Seq,
        threads => Par::rayon(threads),
    };
    let (mut values, mut vectors) = if n <= DENSE_LIMIT || 3 * k + 4 * params.block_size >= n {
        dense_eigenpairs(laplacian, k)?
    } else {
        let solver = ShiftInvert::new(laplacian, params.shift, par)?;
        block_lanczos(&solver, laplacian, k, params, par, progress)?
    };
    // Fix the sign of every eigenvector (largest-magnitude entry positive), so results do not
    // depend on arithmetic details.
    for j in 0..vectors.ncols() {
        let col = vectors.col(j);
        let mut best = 0;
        for i in 0..n {
            if col[i].abs() > col[best].abs() + 1e-12 {
                best = i;
            }
        }
        if col[best] < 0.0 {
            for i in 0..n {
                vectors[(i, j)] = -vectors[(i, j)];
            }
        }
    }
    values.truncate(k);
    Ok((values, vectors))
}

/// Dense path for small shapes: eigenpairs of `M^{-1/2} L M^{-1/2}`.
fn dense_eigenpairs(laplacian: &Laplacian, k: usize) -> Result<(Vec<f64>, Mat<f64>)> {
    let n = laplacian.len();
    let inv_sqrt_mass: Vec<f64> = laplacian.mass.iter().map(|m| 1.0 / m.sqrt()).collect();
    let mut dense = Mat::<f64>::zeros(n, n);
    for (col, column) in laplacian.stiffness.outer_iterator().enumerate() {
        for (row, &value) in column.iter() {
            dense[(row, col)] += value * inv_sqrt_mass[row] * inv_sqrt_mass[col];
        }
    }
    let evd = dense
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::Numerical {
            stage: "dense eigensolver",
            reason: format!("{e:?}"),
        })?;
    let values: Vec<f64> = (0..k).map(|j| evd.S()[j]).collect();
    let vectors = Mat::from_fn(n, k, |i, j| evd.U()[(i, j)] * inv_sqrt_mass[i]);
    Ok((values, vectors))
}

/// The operator `x -> (L + sigma M)^{-1} M x`, self-adjoint in the M inner product, with
/// the factorisation kept. Working in the M inner product (rather than with the symmetric
/// `M^{1/2} A^{-1} M^{1/2}`) never divides by `sqrt(mass)`, which would amplify rounding
/// errors at vertices with tiny mass (measured: residuals 4e-10 instead of 1e-11 on a
/// 52K-vertex TOSCA shape).
struct ShiftInvert {
    factor: SparseCholesky,
    mass: Vec<f64>,
}

impl ShiftInvert {
    fn new(laplacian: &Laplacian, shift: f64, par: Par) -> Result<ShiftInvert> {
        let diagonal: Vec<f64> = laplacian.mass.iter().map(|m| shift * m).collect();
        let factor = SparseCholesky::new(
            &laplacian.stiffness,
            1.0,
            &diagonal,
            par,
            "sparse Cholesky of L + sigma M",
        )?;
        Ok(ShiftInvert {
            factor,
            mass: laplacian.mass.clone(),
        })
    }

    fn len(&self) -> usize {
        self.mass.len()
    }

    /// `out = A^{-1} M x` for a block of columns.
    fn apply(&self, x: MatRef<'_, f64>, mut out: MatMut<'_, f64>, buffer: &mut MemBuffer) {
        for j in 0..x.ncols() {
            for i in 0..self.len() {
                out[(i, j)] = x[(i, j)] * self.mass[i];
            }
        }
        self.factor.solve_in_place(out.rb_mut(), buffer);
    }

    fn scratch(&self, ncols: usize) -> Result<MemBuffer> {
        self.factor.scratch(ncols)
    }

    /// `M x` for a block of columns.
    fn mass_times(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        Mat::from_fn(x.nrows(), x.ncols(), |i, j| self.mass[i] * x[(i, j)])
    }
}

/// Block Lanczos with full reorthogonalisation (M inner product) for the `k` largest
/// eigenvalues `theta = 1 / (lambda + sigma)` of `A^{-1} M`; returns the eigenpairs of
/// `(L, M)`, eigenvalues ascending, eigenvectors M-orthonormal.
fn block_lanczos(
    op: &ShiftInvert,
    laplacian: &Laplacian,
    k: usize,
    params: &EigenParams,
    par: Par,
    progress: &mut dyn Progress,
) -> Result<(Vec<f64>, Mat<f64>)> {
    let n = op.len();
    let b = params.block_size;
    // The Krylov space grows until the k wanted pairs converge; shift-invert makes that
    // quick (typically 2k-3.5k vectors), the cap only guards against stagnation.
    let max_dim = (6 * k + 20 * b).min(n - b);
    let max_blocks = max_dim / b;
    // Room for the usual 4k vectors first; grown (copied) only if convergence needs more.
    let mut capacity = ((4 * k).div_ceil(b) + 1).min(max_blocks + 1) * b;
    let mut basis = Mat::<f64>::zeros(n, capacity);
    let mut projected = Mat::<f64>::zeros(capacity, capacity);
    let mut buffer = op.scratch(b)?;

    // Random start block, M-orthonormalised.
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let start = Mat::from_fn(n, b, |_, _| rng.random::<f64>() - 0.5);
    let (q, _) = orthonormalize_block(op, basis.as_ref().subcols(0, 0), start, par, &mut rng);
    basis.as_mut().subcols_mut(0, b).copy_from(&q);

    let mut w = Mat::<f64>::zeros(n, b);
    // Convergence is checked (a dense eigensolve of the projection) from 2k vectors on. After
    // a failed check the next one is placed where the worst residual, decaying geometrically
    // since the previous check, should meet the tolerance (at most k/4 vectors later).
    let check_every = (k / 4).div_ceil(b).max(1) * b;
    let mut next_check = 2 * k;
    let mut previous: Option<(usize, f64)> = None;
    for block in 0..max_blocks {
        let m = (block + 1) * b;
        if m + b > capacity {
            capacity = (max_blocks + 1) * b;
            let mut grown = Mat::<f64>::zeros(n, capacity);
            grown
                .as_mut()
                .subcols_mut(0, m)
                .copy_from(basis.as_ref().subcols(0, m));
            basis = grown;
            let mut grown = Mat::<f64>::zeros(capacity, capacity);
            grown
                .as_mut()
                .submatrix_mut(0, 0, m, m)
                .copy_from(projected.as_ref().submatrix(0, 0, m, m));
            projected = grown;
        }
        check(
            progress,
            Stage::Eigenbasis,
            (m as f32 / (3.0 * k as f32)).min(0.95),
        )?;
        op.apply(
            basis.as_ref().subcols(block * b, b),
            w.as_mut(),
            &mut buffer,
        );
        let (q, coefficients) =
            orthonormalize_block(op, basis.as_ref().subcols(0, m), w.clone(), par, &mut rng);
        projected
            .as_mut()
            .submatrix_mut(0, block * b, m + b, b)
            .copy_from(&coefficients);
        basis.as_mut().subcols_mut(m, b).copy_from(&q);

        if m >= next_check || block + 1 == max_blocks {
            match rayleigh_ritz(&basis, &projected, m, b, k, params, laplacian, par)? {
                Ritz::Converged(result) => {
                    check(progress, Stage::Eigenbasis, 1.0)?;
                    return Ok(result);
                }
                Ritz::NotYet { excess } => {
                    let mut step = check_every;
                    if let Some((m_before, excess_before)) = previous {
                        let rate = (excess_before.ln() - excess.ln()) / (m - m_before) as f64;
                        if rate > 0.0 {
                            let needed = (1.1 * excess.ln() / rate).ceil() as usize;
                            step = needed.div_ceil(b).clamp(1, check_every / b) * b;
                        }
                    }
                    previous = Some((m, excess));
                    next_check = m + step;
                }
            }
        }
    }
    Err(Error::Numerical {
        stage: "eigensolver",
        reason: format!(
            "block Lanczos did not converge to {k} eigenpairs within {max_dim} vectors"
        ),
    })
}

/// An eigensolver failure with what about the shape likely caused it and how to fix it.
fn with_shape_hint(error: Error, shape: &Shape) -> Error {
    let Error::Numerical { stage, reason } = error else {
        return error;
    };
    let pieces = shape.n_pieces();
    let hint = if pieces > 1 {
        format!(
            "the shape has {pieces} disconnected pieces, each adding a zero eigenvalue: weld \
             its seams and leave out loose pieces (the default repairs do both unless they \
             were switched off), or match the pieces separately"
        )
    } else if shape
        .warnings()
        .iter()
        .any(|w| matches!(w, crate::Warning::NeedleOrZeroAreaFaces { .. }))
    {
        "the shape has (near) zero-area faces: remesh it or clean it up (e.g. merge close \
         vertices) and try again"
            .to_string()
    } else {
        "the shape may have a degenerate or nearly detached region: check it with \
         `shapecorr info`, or ask for fewer eigenpairs"
            .to_string()
    };
    Error::Numerical {
        stage,
        reason: format!("{reason}; {hint}"),
    }
}

/// The outcome of a convergence check.
enum Ritz {
    /// Eigenvalues ascending and M-orthonormal eigenvectors.
    Converged((Vec<f64>, Mat<f64>)),
    /// Largest ratio of a wanted pair's residual to its tolerance (> 1).
    NotYet { excess: f64 },
}

/// Ritz pairs from the first `m` basis vectors, once the `k` largest are all converged.
#[allow(clippy::too_many_arguments)]
fn rayleigh_ritz(
    basis: &Mat<f64>,
    projected: &Mat<f64>,
    m: usize,
    b: usize,
    k: usize,
    params: &EigenParams,
    laplacian: &Laplacian,
    par: Par,
) -> Result<Ritz> {
    let h = projected.as_ref().submatrix(0, 0, m, m);
    let t = Mat::from_fn(m, m, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
    let evd = t
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::Numerical {
            stage: "eigensolver (Rayleigh-Ritz)",
            reason: format!("{e:?}"),
        })?;
    // Residual of Ritz pair y: || coupling block * (last b entries of y) ||, the coupling
    // block to the next Lanczos block being rows m..m+b, columns m-b..m.
    let coupling = projected.as_ref().submatrix(m, m - b, b, b);
    let last_rows = evd.U().subrows(m - b, b);
    let mut residual = Mat::<f64>::zeros(b, m);
    matmul(
        residual.as_mut(),
        Accum::Replace,
        coupling,
        last_rows,
        1.0,
        Par::Seq,
    );
    // The largest theta are the last columns (ascending order).
    let mut excess: f64 = 0.0;
    for idx in (m - k)..m {
        let theta = evd.S()[idx];
        if !(theta > 0.0) {
            excess = f64::INFINITY;
        } else {
            excess = excess.max(residual.col(idx).norm_l2() / (params.tolerance * theta));
        }
    }
    if !(excess <= 1.0) {
        return Ok(Ritz::NotYet {
            excess: excess.min(1e300),
        });
    }
    let mut ritz = Mat::<f64>::zeros(m, k);
    for (out, idx) in (0..k).zip((m - k..m).rev()) {
        ritz.col_mut(out).copy_from(evd.U().col(idx));
    }
    let mut vectors = Mat::<f64>::zeros(basis.nrows(), k);
    matmul(
        vectors.as_mut(),
        Accum::Replace,
        basis.as_ref().subcols(0, m),
        ritz.as_ref(),
        1.0,
        par,
    );
    refine_in_original_problem(laplacian, vectors, par).map(Ritz::Converged)
}

/// Rayleigh-Ritz of the pencil `(L, M)` itself on the span of the converged vectors: the
/// Ritz values of the shift-inverted operator carry the rounding of the solves; projecting
/// `L` and `M` directly gives eigenvalues and M-orthonormal vectors as accurate as the
/// subspace. Returns eigenvalues ascending.
fn refine_in_original_problem(
    laplacian: &Laplacian,
    vectors: Mat<f64>,
    par: Par,
) -> Result<(Vec<f64>, Mat<f64>)> {
    let (n, k) = (vectors.nrows(), vectors.ncols());
    let mut l_phi = Mat::<f64>::zeros(n, k);
    for j in 0..k {
        let phi = vectors.col(j);
        let mut out = l_phi.col_mut(j);
        for (col, column) in laplacian.stiffness.outer_iterator().enumerate() {
            let x = phi[col];
            for (row, &value) in column.iter() {
                out[row] += value * x;
            }
        }
    }
    let m_phi = Mat::from_fn(n, k, |i, j| laplacian.mass[i] * vectors[(i, j)]);
    let mut stiffness = Mat::<f64>::zeros(k, k);
    matmul(
        stiffness.as_mut(),
        Accum::Replace,
        vectors.transpose(),
        l_phi.as_ref(),
        1.0,
        par,
    );
    let mut gram = Mat::<f64>::zeros(k, k);
    matmul(
        gram.as_mut(),
        Accum::Replace,
        vectors.transpose(),
        m_phi.as_ref(),
        1.0,
        par,
    );
    let symmetric = |a: &Mat<f64>| Mat::from_fn(k, k, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let failed = |e: faer::linalg::evd::EvdError| Error::Numerical {
        stage: "eigensolver (final Rayleigh-Ritz)",
        reason: format!("{e:?}"),
    };
    // G^{-1/2} from the eigendecomposition of the (nearly identity) Gram matrix.
    let gram_evd = symmetric(&gram)
        .self_adjoint_eigen(Side::Lower)
        .map_err(failed)?;
    if !(gram_evd.S()[0] > 0.5) {
        return Err(Error::Numerical {
            stage: "eigensolver (final Rayleigh-Ritz)",
            reason: "the converged vectors are not independent".into(),
        });
    }
    let q = gram_evd.U();
    let inv_sqrt = Mat::from_fn(k, k, |i, j| {
        (0..k)
            .map(|l| q[(i, l)] * q[(j, l)] / gram_evd.S()[l].sqrt())
            .sum::<f64>()
    });
    let projected = &inv_sqrt * &symmetric(&stiffness) * &inv_sqrt;
    let evd = symmetric(&projected)
        .self_adjoint_eigen(Side::Lower)
        .map_err(failed)?;
    let rotation = &inv_sqrt * evd.U();
    let mut refined = Mat::<f64>::zeros(n, k);
    matmul(
        refined.as_mut(),
        Accum::Replace,
        vectors.as_ref(),
        rotation.as_ref(),
        1.0,
        par,
    );
    let values = (0..k).map(|j| evd.S()[j]).collect();
    Ok((values, refined))
}

/// A Gram-Schmidt pass whose block norm falls below this fraction triggers another pass
/// (Daniel-Gragg-Kaufman-Stewart criterion).
const REORTHOGONALIZE_BELOW: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// M-orthonormalises the block `w` against the M-orthonormal columns of `basis` and within
/// itself. Returns the new block `Q` and the coefficients `[C; R]` with `w = basis C + Q R`.
///
/// Against the basis: classical Gram-Schmidt, first against the last two blocks (Lanczos
/// couples a block mostly to those), then against all of it, repeated only when a pass
/// removed a large part of the block. Within the block: Cholesky QR applied twice. Columns
/// that vanish (an invariant subspace was found) are replaced by fresh random directions.
fn orthonormalize_block(
    op: &ShiftInvert,
    basis: MatRef<'_, f64>,
    mut w: Mat<f64>,
    par: Par,
    rng: &mut ChaCha8Rng,
) -> (Mat<f64>, Mat<f64>) {
    let m = basis.ncols();
    let b = w.ncols();
    let mut coefficients = Mat::<f64>::zeros(m + b, b);
    let m_norm = |x: &Mat<f64>| {
        let mx = op.mass_times(x.as_ref());
        (0..x.ncols())
            .map(|j| (0..x.nrows()).map(|i| x[(i, j)] * mx[(i, j)]).sum::<f64>())
            .sum::<f64>()
            .sqrt()
    };
    let local = m.saturating_sub(2 * b);
    if m > 0 {
        project_out(
            op,
            basis.subcols(local, m - local),
            &mut w,
            &mut coefficients,
            local,
            par,
        );
        for _ in 0..2 {
            let before = m_norm(&w);
            project_out(op, basis, &mut w, &mut coefficients, 0, par);
            if m_norm(&w) > REORTHOGONALIZE_BELOW * before {
                break;
            }
        }
    }
    let mut r_total = Mat::<f64>::identity(b, b);
    for _ in 0..2 {
        match cholesky_qr_step(op, &mut w, par) {
            Some(r) => r_total = &r * &r_total,
            None => {
                let r = modified_gram_schmidt_with_restarts(op, basis, &mut w, rng, par);
                r_total = &r * &r_total;
            }
        }
    }
    coefficients
        .as_mut()
        .submatrix_mut(m, 0, b, b)
        .copy_from(&r_total);
    (w, coefficients)
}

/// `w -= V (V^T M w)`, adding the coefficients `V^T M w` to rows `offset..` of
/// `coefficients`.
fn project_out(
    op: &ShiftInvert,
    v: MatRef<'_, f64>,
    w: &mut Mat<f64>,
    coefficients: &mut Mat<f64>,
    offset: usize,
    _par: Par,
) {
    let (m, b) = (v.ncols(), w.ncols());
    let c = transpose_times_mass_times(v, w.as_ref(), &op.mass);
    subtract_product(w, v, c.as_ref());
    let mut rows = coefficients.as_mut().subrows_mut(offset, m);
    for j in 0..b {
        for i in 0..m {
            rows[(i, j)] += c[(i, j)];
        }
    }
}

/// Rows per chunk of the tall-skinny products below. The chunking is fixed (it does not
/// depend on the number of threads), so the sums, and the results, are identical on any
/// thread count.
const ROWS_PER_CHUNK: usize = 1024;

/// `V^T M W` for tall `V` (n x m) and skinny `W` (n x b): partial products over fixed row
/// chunks in parallel, summed in chunk order. faer's matmul runs this shape (a long inner
/// dimension) on one thread.
fn transpose_times_mass_times(v: MatRef<'_, f64>, w: MatRef<'_, f64>, mass: &[f64]) -> Mat<f64> {
    use rayon::prelude::*;
    let (n, m, b) = (v.nrows(), v.ncols(), w.ncols());
    let partials: Vec<Mat<f64>> = (0..n.div_ceil(ROWS_PER_CHUNK))
        .into_par_iter()
        .map(|chunk| {
            let start = chunk * ROWS_PER_CHUNK;
            let rows = ROWS_PER_CHUNK.min(n - start);
            let mw = Mat::from_fn(rows, b, |i, j| mass[start + i] * w[(start + i, j)]);
            let mut c = Mat::<f64>::zeros(m, b);
            matmul(
                c.as_mut(),
                Accum::Replace,
                v.subrows(start, rows).transpose(),
                mw.as_ref(),
                1.0,
                Par::Seq,
            );
            c
        })
        .collect();
    let mut total = Mat::<f64>::zeros(m, b);
    for c in &partials {
        total += c;
    }
    total
}

/// `W -= V C` for tall `V` and `W`, by independent row chunks in parallel.
fn subtract_product(w: &mut Mat<f64>, v: MatRef<'_, f64>, c: MatRef<'_, f64>) {
    use rayon::prelude::*;
    let n = w.nrows();
    let chunks: Vec<(usize, MatMut<'_, f64>)> = {
        let mut rest = w.as_mut();
        let mut out = Vec::new();
        let mut start = 0;
        while start < n {
            let rows = ROWS_PER_CHUNK.min(n - start);
            let (head, tail) = rest.split_at_row_mut(rows);
            out.push((start, head));
            rest = tail;
            start += rows;
        }
        out
    };
    chunks.into_par_iter().for_each(|(start, mut chunk)| {
        let rows = chunk.nrows();
        matmul(
            chunk.rb_mut(),
            Accum::Add,
            v.subrows(start, rows),
            c,
            -1.0,
            Par::Seq,
        );
    });
}

/// One Cholesky QR step in the M inner product: `G = w^T M w = R^T R`, `w <- w R^{-1}`.
/// Returns R, or None (w unchanged) when G is numerically singular.
fn cholesky_qr_step(op: &ShiftInvert, w: &mut Mat<f64>, par: Par) -> Option<Mat<f64>> {
    let b = w.ncols();
    let mw = op.mass_times(w.as_ref());
    let mut gram = Mat::<f64>::zeros(b, b);
    matmul(
        gram.as_mut(),
        Accum::Replace,
        w.transpose(),
        mw.as_ref(),
        1.0,
        par,
    );
    let largest = (0..b).map(|j| gram[(j, j)]).fold(0.0, f64::max);
    // Upper-triangular R with G = R^T R (Cholesky, by columns).
    let mut r = Mat::<f64>::zeros(b, b);
    for j in 0..b {
        for i in 0..=j {
            let dot: f64 = (0..i).map(|l| r[(l, i)] * r[(l, j)]).sum();
            let value = gram[(i, j)] - dot;
            if i == j {
                if !(value > 1e-20 * largest.max(f64::MIN_POSITIVE)) {
                    return None;
                }
                r[(j, j)] = value.sqrt();
            } else {
                r[(i, j)] = value / r[(i, i)];
            }
        }
    }
    let mut r_inverse = Mat::<f64>::zeros(b, b);
    for j in 0..b {
        r_inverse[(j, j)] = 1.0 / r[(j, j)];
        for i in (0..j).rev() {
            let sum: f64 = (i + 1..=j).map(|l| r[(i, l)] * r_inverse[(l, j)]).sum();
            r_inverse[(i, j)] = -sum / r[(i, i)];
        }
    }
    let mut q = Mat::<f64>::zeros(w.nrows(), b);
    matmul(
        q.as_mut(),
        Accum::Replace,
        w.as_ref(),
        r_inverse.as_ref(),
        1.0,
        par,
    );
    *w = q;
    Some(r)
}

/// Column-by-column M-orthonormalisation for the rare rank-deficient block: a column that
/// vanishes gets a random direction (orthogonal to the basis and the earlier columns) and a
/// zero column in R.
fn modified_gram_schmidt_with_restarts(
    op: &ShiftInvert,
    basis: MatRef<'_, f64>,
    w: &mut Mat<f64>,
    rng: &mut ChaCha8Rng,
    par: Par,
) -> Mat<f64> {
    let (n, b) = (w.nrows(), w.ncols());
    let mut r = Mat::<f64>::zeros(b, b);
    let m_dot = |x: MatRef<'_, f64>, y: MatRef<'_, f64>| -> f64 {
        (0..n).map(|i| x[(i, 0)] * op.mass[i] * y[(i, 0)]).sum()
    };
    let scale = (0..b)
        .map(|j| m_dot(w.as_ref().subcols(j, 1), w.as_ref().subcols(j, 1)).sqrt())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    for j in 0..b {
        let mut restarted = false;
        loop {
            for i in 0..j {
                let c = m_dot(w.as_ref().subcols(i, 1), w.as_ref().subcols(j, 1));
                if !restarted {
                    r[(i, j)] += c;
                }
                for row in 0..n {
                    let value = w[(row, i)];
                    w[(row, j)] -= c * value;
                }
            }
            let norm = m_dot(w.as_ref().subcols(j, 1), w.as_ref().subcols(j, 1)).sqrt();
            if norm > 1e-10 * scale {
                if !restarted {
                    r[(j, j)] = norm;
                }
                for row in 0..n {
                    w[(row, j)] /= norm;
                }
                break;
            }
            // Vanished: a random direction, M-orthogonal to the basis, then to the others.
            restarted = true;
            let mut fresh = Mat::from_fn(n, 1, |_, _| rng.random::<f64>() - 0.5);
            let mut unused = Mat::<f64>::zeros(basis.ncols(), 1);
            for _ in 0..2 {
                project_out(op, basis, &mut fresh, &mut unused, 0, par);
            }
            w.col_mut(j).copy_from(fresh.col(0));
        }
    }
    r
}
