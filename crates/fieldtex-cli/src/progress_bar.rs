//! Renders the library's [`Progress`] reports as indicatif progress bars.

use fieldtex::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::Mutex;

/// A terminal progress bar per stage; silent with `--quiet` or when stderr is not a TTY.
pub struct TerminalProgress {
    bar: Mutex<Option<ProgressBar>>,
    quiet: bool,
}

impl TerminalProgress {
    pub fn new(quiet: bool) -> Self {
        Self { bar: Mutex::new(None), quiet }
    }

    fn new_bar(&self, name: &str, total: u64) -> ProgressBar {
        let bar = if total > 0 { ProgressBar::new(total) } else { ProgressBar::new_spinner() };
        if self.quiet {
            bar.set_draw_target(ProgressDrawTarget::hidden());
        }
        let style = if total > 0 {
            ProgressStyle::with_template("{msg:>24} [{bar:32}] {pos}/{len} ({elapsed})")
        } else {
            ProgressStyle::with_template("{msg:>24} {spinner} ({elapsed})")
        };
        if let Ok(s) = style {
            bar.set_style(s.progress_chars("=> "));
        }
        bar.set_message(name.to_string());
        bar
    }
}

impl Progress for TerminalProgress {
    fn stage(&self, name: &str, total: u64) {
        let mut g = self.bar.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(old) = g.take() {
            old.finish_and_clear();
        }
        *g = Some(self.new_bar(name, total));
    }

    fn advance(&self, n: u64) {
        if let Some(b) = self.bar.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
            b.inc(n);
        }
    }

    fn finish_stage(&self) {
        if let Some(b) = self.bar.lock().unwrap_or_else(|e| e.into_inner()).take() {
            b.finish_and_clear();
        }
    }
}

impl Drop for TerminalProgress {
    fn drop(&mut self) {
        self.finish_stage();
    }
}
