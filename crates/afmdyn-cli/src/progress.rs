//! The progress bar of a long analysis: a [`Progress`] the library counts in, read every
//! 100 ms by a thread that draws an indicatif bar on stderr (only on a terminal, and only once
//! the run has taken a second), cleared when the run ends.

use afmdyn::error::SimError;
use afmdyn::request::Progress;
use afmdyn::request::{self, Analysis, Document, Resolved};
use indicatif::{ProgressBar, ProgressStyle};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Run `work` with a bar counting `unit`s (e.g. "starts", "points").
pub fn with_bar<T>(unit: &'static str, work: impl FnOnce(&Progress) -> T) -> T {
    let progress = Progress::new();
    let finished = AtomicBool::new(false);
    std::thread::scope(|s| {
        let poller = s.spawn(|| draw(&progress, &finished, unit));
        // the bar ends however the work ends (a panic too: the scope joins the poller first)
        let _done = Finished(&finished, poller.thread().clone());
        work(&progress)
    })
}

/// Ends the poller when dropped.
struct Finished<'a>(&'a AtomicBool, std::thread::Thread);

impl Drop for Finished<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
        self.1.unpark();
    }
}

fn draw(progress: &Progress, finished: &AtomicBool, unit: &'static str) {
    let start = Instant::now();
    let mut bar: Option<(ProgressBar, bool)> = None;
    while !finished.load(Ordering::Relaxed) {
        std::thread::park_timeout(Duration::from_millis(100));
        // a signal caught for a run that cleans up (`simulate`) cancels it
        if crate::error::interrupted().is_err() {
            progress.cancel();
        }
        if start.elapsed() < Duration::from_secs(1) || finished.load(Ordering::Relaxed) {
            continue;
        }
        let (done, total) = (progress.done(), progress.total());
        let counted = total.is_some();
        let b = match &mut bar {
            Some((b, c)) if *c == counted => b,
            _ => {
                if let Some((old, _)) = bar.take() {
                    old.finish_and_clear();
                }
                let b = ProgressBar::new(0);
                let template = if counted {
                    format!("{{bar:40}} {{pos}}/{{len}} {unit}  {{elapsed}} / ~{{duration}}")
                } else {
                    format!("{{spinner}} {{pos}} {unit}  {{elapsed}}")
                };
                b.set_style(ProgressStyle::with_template(&template).expect("template"));
                &mut bar.insert((b, counted)).0
            }
        };
        // a run that learns its size as it goes can be ahead of the total for a while
        b.set_length(total.unwrap_or(0).max(done) as u64);
        b.set_position(done as u64);
        b.tick();
    }
    if let Some((b, _)) = bar {
        b.finish_and_clear();
    }
}

/// [`request::run_admitted`] with a bar counting `unit`s: a request the caller admitted.
///
/// # Errors
/// As [`request::run_admitted`].
pub fn run_admitted<A: Analysis + ?Sized>(
    analysis: &A,
    model: &Resolved,
    unit: &'static str,
) -> Result<Document<A::Output>, SimError> {
    with_bar(unit, |progress| {
        request::run_admitted(analysis, model, progress)
    })
}
