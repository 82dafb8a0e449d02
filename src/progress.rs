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

/// Reports and turns a cancel request into [`crate::Error::Cancelled`].
pub(crate) fn check(progress: &mut dyn Progress, stage: Stage, fraction: f32) -> crate::Result<()> {
    if progress.report(stage, fraction.clamp(0.0, 1.0)) {
        Ok(())
    } else {
        Err(crate::Error::Cancelled)
    }
}
