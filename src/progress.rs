//! Progress reports and cancellation: one trait for every long-running stage.

/// A stage of the pipeline, as reported to [`Progress::report`]. The numbers are part of
/// the C API (later) and never change meaning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum Stage {
    /// Building the Laplacian of a shape.
    Laplacian = 1,
    /// Computing a shape's eigenbasis.
    Eigenbasis = 2,
    /// Computing descriptors.
    Descriptors = 3,
    /// Joint segmentation and shape graphs over the range of k.
    Segmentation = 4,
    /// Spectral graph matching.
    Matching = 5,
    /// Symmetry breaking (one-to-one region correspondence).
    SymmetryBreaking = 6,
    /// Point-to-point map (functional map and its refinement).
    PointwiseMap = 7,
    /// Making the working shape (a dense shape's proxy, a low-poly mesh's refined copy) and
    /// bringing the answers back to every input vertex ([`crate::multiresolution`]).
    Proxy = 8,
    /// Carrying data from A to B: the surface map and the transfer ([`crate::transfer`]).
    Transfer = 9,
    /// Reading a shape file and validating and repairing the shape
    /// ([`crate::Shape::read_watched`]).
    Reading = 10,
}

/// Receives progress and may cancel: `report` returns `false` to stop the work, which then
/// ends promptly with [`crate::Error::Cancelled`].
pub trait Progress {
    /// `fraction` runs from 0 to 1 within `stage`. Return `false` to cancel.
    fn report(&mut self, stage: Stage, fraction: f32) -> bool;
}

/// Ignores reports and never cancels.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn report(&mut self, _stage: Stage, _fraction: f32) -> bool {
        true
    }
}

impl<F: FnMut(Stage, f32) -> bool> Progress for F {
    fn report(&mut self, stage: Stage, fraction: f32) -> bool {
        self(stage, fraction)
    }
}

/// Reports the work of `inner` as `stage` (a stage that runs another stage's operation,
/// such as the one-to-one step verifying its answer with pointwise maps).
pub(crate) struct AsStage<'a> {
    /// The caller's progress.
    pub(crate) inner: &'a mut dyn Progress,
    /// The stage every report is made as.
    pub(crate) stage: Stage,
}

impl Progress for AsStage<'_> {
    fn report(&mut self, _stage: Stage, fraction: f32) -> bool {
        self.inner.report(self.stage, fraction)
    }
}

/// Reports and turns a cancel request into [`crate::Error::Cancelled`].
pub(crate) fn check(progress: &mut dyn Progress, stage: Stage, fraction: f32) -> crate::Result<()> {
    if progress.report(stage, fraction.clamp(0.0, 1.0)) {
        Ok(())
    } else {
        Err(crate::Error::Cancelled)
    }
}

/// A cancel flag shared with work running away from the caller's thread: the work polls
/// [`Cancel::check`] in its loops and may publish how far it is with [`Cancel::set_fraction`].
/// `Cancel::default()` is never set: pass it to run an operation to its end.
#[derive(Debug, Default)]
pub struct Cancel {
    stop: std::sync::atomic::AtomicBool,
    fraction: std::sync::atomic::AtomicU32,
}

impl Cancel {
    /// [`crate::Error::Cancelled`] once the caller asked to stop.
    pub fn check(&self) -> crate::Result<()> {
        if self.stop.load(std::sync::atomic::Ordering::Relaxed) {
            Err(crate::Error::Cancelled)
        } else {
            Ok(())
        }
    }

    /// [`Cancel::check`] when `i` is a multiple of [`CHECK_EVERY`]: for the loops over
    /// millions of elements (the repairs), at about a millisecond between looks.
    pub fn check_every(&self, i: usize) -> crate::Result<()> {
        if i.is_multiple_of(CHECK_EVERY) {
            self.check()
        } else {
            Ok(())
        }
    }

    /// Publishes the fraction done (0 to 1) for the next report.
    pub fn set_fraction(&self, fraction: f32) {
        self.fraction
            .store(fraction.to_bits(), std::sync::atomic::Ordering::Relaxed);
    }
}

/// Elements between two looks at the flag in [`Cancel::check_every`].
pub const CHECK_EVERY: usize = 4096;

/// How often [`polled`] reports while the work runs: a cancel is seen within this time (plus
/// the work's own polling interval). The target is 0.2 s (docs/decisions.md, "Cancellation
/// within 0.2 s").
pub(crate) const POLL_INTERVAL: std::time::Duration = std::time::Duration::from_millis(25);

/// Runs `work` on a helper thread (in a rayon pool of the caller's size) while the caller's
/// thread reports to `progress` every [`POLL_INTERVAL`], from `start` to `end` of `stage`
/// by the fraction the work publishes; a cancel sets the work's [`Cancel`] flag. The
/// callback is only ever called from the caller's thread.
pub(crate) fn polled<T: Send>(
    progress: &mut dyn Progress,
    stage: Stage,
    (start, end): (f32, f32),
    work: impl FnOnce(&Cancel) -> crate::Result<T> + Send,
) -> crate::Result<T> {
    check(progress, stage, start)?;
    let cancel = Cancel::default();
    let threads = rayon::current_num_threads();
    // A caller that is itself a worker of a pool only polls while it waits: the work gets a
    // pool of its own, or a one-thread pool would never run it.
    let caller_in_pool = rayon::current_thread_index().is_some();
    let outcome = std::thread::scope(|scope| {
        let cancel = &cancel;
        let caller = std::thread::current();
        let worker = scope.spawn(move || {
            let result = in_pool_of(threads, caller_in_pool, || work(cancel));
            caller.unpark();
            result
        });
        let mut cancelled = false;
        while !worker.is_finished() {
            std::thread::park_timeout(POLL_INTERVAL);
            // Nothing is reported after a cancel, while the work winds down.
            if worker.is_finished() || cancelled {
                continue;
            }
            let done = f32::from_bits(cancel.fraction.load(std::sync::atomic::Ordering::Relaxed));
            let fraction = start + (end - start) * done.clamp(0.0, 1.0);
            if !progress.report(stage, fraction.clamp(0.0, 1.0)) {
                cancelled = true;
                cancel
                    .stop
                    .store(true, std::sync::atomic::Ordering::Relaxed);
            }
        }
        worker.join()
    });
    match outcome {
        Ok(result) => result,
        Err(panic) => std::panic::resume_unwind(panic),
    }
}

/// Runs `f` in a rayon pool of `threads` threads: the global pool when it has that size and
/// the caller is not a worker of a pool, else a pool made for the call (so the caller's
/// `ThreadPool::install` size is kept and a waiting caller never blocks the work).
fn in_pool_of<T: Send>(threads: usize, caller_in_pool: bool, f: impl FnOnce() -> T + Send) -> T {
    if !caller_in_pool && rayon::current_num_threads() == threads {
        return f();
    }
    match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(pool) => pool.install(f),
        Err(_) => f(),
    }
}
