//! A progress bar for long runs (issue 14: "Long runs show a progress bar on a terminal and
//! stay quiet when not on one"): drawn on stderr with `indicatif` when stderr is a terminal,
//! hidden otherwise (piped, redirected, under a test harness or CI), so that logs and captured
//! output hold only the results. A run that is usually short (loading a scene) takes a
//! [`Progress::delayed`] bar, which appears only once the run has taken longer than its delay.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressFinish, ProgressStyle};
use std::io::IsTerminal;
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

/// A bar of `len` steps, each named by what it is doing.
#[derive(Debug, Clone)]
pub struct Progress {
    bar: ProgressBar,
    /// The thread that shows a [`Progress::delayed`] bar once its delay has passed.
    reveal: Option<Arc<Reveal>>,
}

/// The waiting thread of a delayed bar, and the channel whose closing stops it.
#[derive(Debug)]
struct Reveal {
    stop: Mutex<Option<Sender<()>>>,
    thread: Mutex<Option<JoinHandle<()>>>,
}

impl Reveal {
    /// Stops the thread (it shows nothing if its delay has not passed) and waits for it.
    fn stop(&self) {
        if let Ok(mut stop) = self.stop.lock() {
            stop.take();
        }
        let thread = self.thread.lock().ok().and_then(|mut t| t.take());
        if let Some(t) = thread {
            let _ = t.join();
        }
    }
}

impl Drop for Reveal {
    fn drop(&mut self) {
        self.stop();
    }
}

/// The bar's look: prefix, bar, steps, message, time so far.
fn styled(bar: ProgressBar, prefix: &str) -> ProgressBar {
    if let Ok(style) =
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {msg} ({elapsed})")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_prefix(prefix.to_string());
    bar
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
        Self {
            bar: styled(bar, prefix),
            reveal: None,
        }
    }

    /// Like [`Progress::new`], but the bar is drawn only once `delay` has passed without
    /// [`Progress::finish`] (a run that ends sooner shows nothing), then redrawn ten times a
    /// second until the end; it is cleared when finished or dropped (an error ends the run).
    /// Hidden unless stderr is a terminal, and then no thread is started.
    pub fn delayed(len: usize, prefix: &str, delay: Duration) -> Self {
        let bar = styled(
            ProgressBar::with_draw_target(Some(len as u64), ProgressDrawTarget::hidden())
                .with_finish(ProgressFinish::AndClear),
            prefix,
        );
        let reveal = std::io::stderr().is_terminal().then(|| {
            let (stop, wait) = mpsc::channel::<()>();
            let shown = bar.clone();
            let thread = std::thread::spawn(move || {
                if let Err(RecvTimeoutError::Timeout) = wait.recv_timeout(delay) {
                    shown.set_draw_target(ProgressDrawTarget::stderr());
                    shown.enable_steady_tick(Duration::from_millis(100));
                }
            });
            Arc::new(Reveal {
                stop: Mutex::new(Some(stop)),
                thread: Mutex::new(Some(thread)),
            })
        });
        Self { bar, reveal }
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
        if let Some(reveal) = &self.reveal {
            reveal.stop();
        }
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A delayed bar starts its waiting thread only for a terminal (never under a test harness
    /// or CI, where stderr is captured or redirected), and finishing stops it.
    #[test]
    fn a_delayed_bar_waits_only_on_a_terminal() {
        let p = Progress::delayed(2, "loading", Duration::from_secs(60));
        assert_eq!(p.reveal.is_some(), std::io::stderr().is_terminal());
        p.start("reading");
        p.start("validating");
        p.finish();
        assert!(p.bar.is_finished());
        if let Some(r) = &p.reveal {
            assert!(r.thread.lock().unwrap().is_none(), "the thread was joined");
        }
    }
}
