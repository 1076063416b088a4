//! Progress of a long computation, for a front end to show (the CLI's progress bars):
//! the computation opens named tasks and advances them.

/// One task's progress: advanced a step at a time, finished once.
pub trait Task: Send + Sync {
    /// `n` more steps done.
    fn inc(&self, n: u64);
    /// The task is done.
    fn finish(&self);
}

/// Where a computation opens its tasks.
pub trait Progress: Sync {
    /// A task called `name` of `len` steps.
    fn task(&self, name: &str, len: u64) -> Box<dyn Task>;
}

/// A boxed task is a task (what [`Progress::task`] gives can be lent as `&dyn Task`).
impl<T: Task + ?Sized> Task for Box<T> {
    fn inc(&self, n: u64) {
        (**self).inc(n);
    }
    fn finish(&self) {
        (**self).finish();
    }
}
