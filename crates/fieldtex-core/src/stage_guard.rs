//! A progress stage as a scope: [`StageGuard`] reports the stage to a [`Progress`] when
//! it begins, times it, nests (a child's name is `parent / child`), checks for
//! cancellation, and finishes the stage when dropped, so an early `?` return cannot
//! leave a stage open. Built only on `Progress`'s existing methods.
//!
//! ```
//! use fieldtex_core::{NoProgress, StageGuard, StageTimings};
//! let timings = StageTimings::default();
//! {
//!     let outer = StageGuard::begin(&NoProgress, "bake", 2).timed(&timings);
//!     {
//!         let inner = outer.child("rasterise", 10);
//!         inner.advance(10);
//!     }
//!     outer.advance(2);
//! }
//! let names: Vec<String> = timings.entries().into_iter().map(|e| e.name).collect();
//! assert_eq!(names, ["bake / rasterise", "bake"]);
//! ```

use std::sync::Mutex;
use std::time::Instant;

use crate::Progress;

/// The caller asked to stop ([`Progress::cancelled`]) while the named stage ran.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Cancelled {
    /// Full name of the stage that noticed (`parent / child`).
    pub stage: String,
}

impl std::fmt::Display for Cancelled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cancelled during stage '{}'", self.stage)
    }
}

impl std::error::Error for Cancelled {}

/// One finished stage: its full name, nesting depth (0 = top) and wall time.
#[derive(Clone, Debug, PartialEq)]
pub struct StageTiming {
    pub name: String,
    pub depth: usize,
    pub ms: f64,
}

/// Wall times of finished stages, in the order they finished (a child before its
/// parent). Shareable between threads.
#[derive(Debug, Default)]
pub struct StageTimings(Mutex<Vec<StageTiming>>);

impl StageTimings {
    /// A copy of the entries so far.
    pub fn entries(&self) -> Vec<StageTiming> {
        self.0.lock().map(|v| v.clone()).unwrap_or_default()
    }

    fn push(&self, t: StageTiming) {
        if let Ok(mut v) = self.0.lock() {
            v.push(t);
        }
    }
}

/// A running stage (see the module doc). Dropping it calls
/// [`Progress::finish_stage`] and records its time in the attached [`StageTimings`].
pub struct StageGuard<'a> {
    progress: &'a dyn Progress,
    name: String,
    depth: usize,
    start: Instant,
    timings: Option<&'a StageTimings>,
}

impl<'a> StageGuard<'a> {
    /// Begins the top-level stage `name` of `total` work units (0: unknown).
    pub fn begin(progress: &'a dyn Progress, name: &str, total: u64) -> Self {
        progress.stage(name, total);
        Self { progress, name: name.to_owned(), depth: 0, start: Instant::now(), timings: None }
    }

    /// Records this stage's (and its children's) wall times in `timings`.
    pub fn timed(mut self, timings: &'a StageTimings) -> Self {
        self.timings = Some(timings);
        self
    }

    /// Begins a nested stage `parent / name`, reported to the same progress and timed
    /// into the same [`StageTimings`]. The progress sees the child as the current
    /// stage until the child is dropped.
    pub fn child(&self, name: &str, total: u64) -> StageGuard<'a> {
        let full = format!("{} / {name}", self.name);
        self.progress.stage(&full, total);
        StageGuard {
            progress: self.progress,
            name: full,
            depth: self.depth + 1,
            start: Instant::now(),
            timings: self.timings,
        }
    }

    /// `n` more units of this stage are done.
    pub fn advance(&self, n: u64) {
        self.progress.advance(n);
    }

    /// `Err(Cancelled)` when the caller asked to stop.
    pub fn check_cancelled(&self) -> Result<(), Cancelled> {
        if self.progress.cancelled() { Err(Cancelled { stage: self.name.clone() }) } else { Ok(()) }
    }

    /// Full name (`parent / child` when nested).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Wall time since the stage began, milliseconds.
    pub fn elapsed_ms(&self) -> f64 {
        self.start.elapsed().as_secs_f64() * 1e3
    }
}

impl Drop for StageGuard<'_> {
    fn drop(&mut self) {
        self.progress.finish_stage();
        if let Some(t) = self.timings {
            t.push(StageTiming {
                name: std::mem::take(&mut self.name),
                depth: self.depth,
                ms: self.elapsed_ms(),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicBool, Ordering};

    /// Records every call as a line; cancels when told to.
    #[derive(Default)]
    struct Log {
        lines: Mutex<Vec<String>>,
        cancel: AtomicBool,
    }

    impl Progress for Log {
        fn stage(&self, name: &str, total: u64) {
            self.lines.lock().unwrap().push(format!("stage {name} {total}"));
        }
        fn advance(&self, n: u64) {
            self.lines.lock().unwrap().push(format!("advance {n}"));
        }
        fn finish_stage(&self) {
            self.lines.lock().unwrap().push("finish".into());
        }
        fn cancelled(&self) -> bool {
            self.cancel.load(Ordering::Relaxed)
        }
    }

    fn run(log: &Log, timings: &StageTimings, fail_inside: bool) -> Result<(), Cancelled> {
        let outer = StageGuard::begin(log, "align", 3).timed(timings);
        outer.advance(1);
        {
            let inner = outer.child("bake", 0);
            inner.advance(5);
            if fail_inside {
                log.cancel.store(true, Ordering::Relaxed);
            }
            inner.check_cancelled()?;
        }
        outer.check_cancelled()
    }

    #[test]
    fn stages_report_time_nest_and_close_on_early_return() {
        let (log, timings) = (Log::default(), StageTimings::default());
        run(&log, &timings, false).unwrap();
        assert_eq!(
            *log.lines.lock().unwrap(),
            ["stage align 3", "advance 1", "stage align / bake 0", "advance 5", "finish", "finish"]
        );
        let e = timings.entries();
        assert_eq!(
            e.iter().map(|t| (t.name.as_str(), t.depth)).collect::<Vec<_>>(),
            [("align / bake", 1), ("align", 0)]
        );
        assert!(e[1].ms >= e[0].ms && e[0].ms >= 0.0);

        // Cancelled inside the child: the error names it and both stages still finish.
        let (log, timings) = (Log::default(), StageTimings::default());
        let err = run(&log, &timings, true).unwrap_err();
        assert_eq!(err.stage, "align / bake");
        assert_eq!(log.lines.lock().unwrap().iter().filter(|l| *l == "finish").count(), 2);
        assert_eq!(timings.entries().len(), 2);
    }
}
