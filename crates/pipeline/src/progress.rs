//! Progress reporting hooks, so that the library stays quiet and the binary decides
//! how (and whether) to show progress.

/// Receives progress of the long stages.
pub trait Progress: Sync {
    /// A stage with `total` steps begins.
    fn start(&self, stage: &str, total: usize);
    /// One step of the current stage is done.
    fn advance(&self);
    /// The current stage is over.
    fn finish(&self);
}

/// Shows nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _stage: &str, _total: usize) {}
    fn advance(&self) {}
    fn finish(&self) {}
}
