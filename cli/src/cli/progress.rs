//! A progress line on standard error for the long steps of a command (load, hierarchy build,
//! fairing, save), drawn only when standard error is a terminal: piped, redirected or under a
//! test, a command writes nothing here.
//!
//! A step that takes less than [`QUIET_FOR`] never shows. Past that, a small thread redraws one
//! line (`label  12.3 s  45%`) every [`REDRAW`], so steps without progress reports (loading,
//! saving) still show that they are alive; steps that report a fraction through
//! [`fairmesh::Progress`] show it. When the step ends the line is replaced by `label: 12.3 s`.

use std::io::{IsTerminal, Write};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Steps shorter than this print nothing.
const QUIET_FOR: Duration = Duration::from_millis(300);
/// How often the line is redrawn.
const REDRAW: Duration = Duration::from_millis(100);

/// One step of a command; see the module docs. Ends (and clears its line) when dropped.
pub struct Step {
    shared: Option<Arc<Mutex<Line>>>,
    stop: Option<mpsc::Sender<()>>,
    drawer: Option<JoinHandle<()>>,
}

struct Line {
    label: String,
    started: Instant,
    /// Fraction reported so far, if the step reports one.
    fraction: Option<f32>,
    drawn: bool,
}

impl Line {
    fn draw(&mut self) {
        let seconds = self.started.elapsed().as_secs_f64();
        let fraction = self
            .fraction
            .map(|f| format!("  {:>3.0}%", 100.0 * f))
            .unwrap_or_default();
        let mut stderr = std::io::stderr().lock();
        // \r and "erase line" so the line is redrawn in place.
        let _ = write!(stderr, "\r\x1b[2K{}  {seconds:.1} s{fraction}", self.label);
        let _ = stderr.flush();
        self.drawn = true;
    }
}

impl Step {
    /// Starts a step named `label` ("loading big.ply").
    pub fn start(label: impl Into<String>) -> Step {
        Step::start_if(std::io::stderr().is_terminal(), label)
    }

    fn start_if(shown: bool, label: impl Into<String>) -> Step {
        if !shown {
            return Step {
                shared: None,
                stop: None,
                drawer: None,
            };
        }
        let shared = Arc::new(Mutex::new(Line {
            label: label.into(),
            started: Instant::now(),
            fraction: None,
            drawn: false,
        }));
        let (stop, stopped) = mpsc::channel::<()>();
        let line = Arc::clone(&shared);
        let drawer = std::thread::Builder::new()
            .name("progress".into())
            .spawn(move || {
                if !matches!(
                    stopped.recv_timeout(QUIET_FOR),
                    Err(RecvTimeoutError::Timeout)
                ) {
                    return;
                }
                loop {
                    if let Ok(mut line) = line.lock() {
                        line.draw();
                    }
                    if !matches!(stopped.recv_timeout(REDRAW), Err(RecvTimeoutError::Timeout)) {
                        return;
                    }
                }
            })
            .ok();
        Step {
            shared: Some(shared),
            stop: Some(stop),
            drawer,
        }
    }

    /// Runs `work` as a step named `label`.
    pub fn run<T>(label: impl Into<String>, work: impl FnOnce() -> T) -> T {
        let _step = Step::start(label);
        work()
    }
}

impl fairmesh::Progress for Step {
    fn report(&mut self, fraction: f32) -> bool {
        if let Some(Ok(mut line)) = self.shared.as_ref().map(|s| s.lock()) {
            line.fraction = Some(fraction.clamp(0.0, 1.0));
        }
        true
    }
}

impl Drop for Step {
    fn drop(&mut self) {
        drop(self.stop.take());
        if let Some(drawer) = self.drawer.take() {
            let _ = drawer.join();
        }
        if let Some(Ok(line)) = self.shared.as_ref().map(|s| s.lock()) {
            if line.drawn {
                eprintln!(
                    "\r\x1b[2K{}: {:.1} s",
                    line.label,
                    line.started.elapsed().as_secs_f64()
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fairmesh::Progress;

    #[test]
    fn a_step_that_is_not_shown_starts_no_thread_and_keeps_no_state() {
        let mut step = Step::start_if(false, "loading");
        assert!(step.report(0.5));
        assert!(step.shared.is_none() && step.drawer.is_none());
    }

    #[test]
    fn a_shown_step_records_the_fraction_and_its_thread_ends_with_it() {
        let mut step = Step::start_if(true, "building");
        assert!(step.report(1.5), "a progress line never cancels");
        let shared = step.shared.clone().unwrap();
        assert_eq!(shared.lock().unwrap().fraction, Some(1.0));
        drop(step);
        // The drawing thread held the other reference; it has been joined.
        assert_eq!(Arc::strong_count(&shared), 1);
        assert!(!shared.lock().unwrap().drawn, "a quick step never draws");
    }
}
