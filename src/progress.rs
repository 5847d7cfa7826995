//! A progress bar for long runs (issue 14: "Long runs show a progress bar on a terminal and
//! stay quiet when not on one"): drawn on stderr with `indicatif` when stderr is a terminal,
//! hidden otherwise (piped, redirected, under a test harness or CI), so that logs and captured
//! output hold only the results.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;

/// A bar of `len` steps, each named by what it is doing.
#[derive(Debug, Clone)]
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar of `len` steps with `prefix` in front (e.g. the scene); hidden unless stderr is a
    /// terminal.
    pub fn new(len: usize, prefix: &str) -> Self {
        let bar = if std::io::stderr().is_terminal() {
            ProgressBar::new(len as u64)
        } else {
            ProgressBar::hidden()
        };
        if let Ok(style) =
            ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {msg} ({elapsed})")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_prefix(prefix.to_string());
        Self { bar }
    }

    /// Step `what` begins: the steps before it are done.
    pub fn start(&self, what: &str) {
        if !self.bar.message().is_empty() {
            self.bar.inc(1);
        }
        self.bar.set_message(what.to_string());
    }

    /// `n` more steps are done (for bars counting work items rather than named steps; safe
    /// to call from several threads).
    pub fn advance(&self, n: u64) {
        self.bar.inc(n);
    }

    /// Every step is done: the bar disappears, leaving the terminal to the results.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
