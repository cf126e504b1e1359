//! Running long library calls without the GIL: the work runs on a thread of its own, inside a
//! rayon pool (this process's, or one of its own for `threads=`: see [`crate::pool`]), while the
//! calling thread waits with the GIL released, waking every few hundredths of a second to check
//! for Ctrl+C (Python handles signals on its main thread, in the interpreter) and to call the
//! `progress` callback with every fraction the work reported since. Either one stops the work at
//! its next progress report, through the library's [`fairmesh::Progress`] hook; a panic in the
//! library comes back as an exception.

use crate::pool;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// How often the waiting thread looks for Ctrl+C and reports progress.
const POLL: Duration = Duration::from_millis(40);

pyo3::create_exception!(
    fairmesh,
    Cancelled,
    pyo3::exceptions::PyException,
    include_str!(concat!(env!("OUT_DIR"), "/doc/Cancelled.txt"))
);

/// What the working thread and the waiting one share.
struct Shared {
    /// The fractions reported and not yet given to the callback (only kept with a callback).
    reported: Option<Mutex<Reported>>,
    cancel: AtomicBool,
}

/// Fractions reported by the work, in order.
#[derive(Default)]
struct Reported {
    waiting: Vec<f32>,
    /// The last fraction queued, so that a repeated one is not given twice.
    last: Option<f32>,
}

/// The [`fairmesh::Progress`] the work reports to.
pub struct Hook<'a> {
    shared: &'a Shared,
}

impl fairmesh::Progress for Hook<'_> {
    fn report(&mut self, fraction: f32) -> bool {
        if let Some(reported) = &self.shared.reported {
            let fraction = fraction.clamp(0.0, 1.0);
            let mut reported = reported
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            if reported.last != Some(fraction) {
                reported.last = Some(fraction);
                reported.waiting.push(fraction);
            }
        }
        !self.shared.cancel.load(Ordering::Relaxed)
    }
}

/// Runs `work` without the GIL; `progress` (a Python callable taking the fraction done, or
/// None) is called on the calling thread with every new fraction the work reports, in order
/// (the work does not wait for it), and with 1.0 at the end unless the work reported it last.
/// `work` returns `None` when it stopped because its hook asked it to. Ctrl+C raises
/// `KeyboardInterrupt`, a callback that returns False raises [`Cancelled`], one that raises
/// passes its exception on; in each case the work is stopped first. The work runs in this
/// process's pool, or with `threads` in a rayon pool of that many threads of its own (for
/// running several calls side by side).
pub fn run_detached<T, W>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    threads: Option<usize>,
    work: W,
) -> PyResult<T>
where
    T: Send,
    W: FnOnce(&mut Hook<'_>) -> Option<T> + Send,
{
    let shared = Shared {
        reported: progress.map(|_| Mutex::new(Reported::default())),
        cancel: AtomicBool::new(false),
    };
    let own_pool = threads
        .map(|n| pool::build(Some(n), "fairmesh-call"))
        .transpose()?;
    let pool = match &own_pool {
        Some(pool) => pool,
        None => pool::shared()?,
    };
    // Set by the worker when it ends, panicking or not.
    let finished = (Mutex::new(false), Condvar::new());
    std::thread::scope(|scope| {
        let worker = std::thread::Builder::new()
            .name("fairmesh-python".into())
            .spawn_scoped(scope, || {
                let _signal = FinishedSignal(&finished);
                let mut hook = Hook { shared: &shared };
                pool.install(|| work(&mut hook))
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
        let mut stopped_by: Option<PyErr> = None;
        let mut delivered: Option<f32> = None;
        loop {
            let ended = py.detach(|| {
                let (done, signal) = &finished;
                let guard = done
                    .lock()
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
                let (guard, _) = signal
                    .wait_timeout_while(guard, POLL, |done| !*done)
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
                *guard
            });
            if stopped_by.is_none() {
                let outcome = py
                    .check_signals()
                    .and_then(|()| deliver(progress, &shared, &mut delivered));
                match outcome {
                    Ok(true) => {}
                    Ok(false) => {
                        stopped_by = Some(Cancelled::new_err("cancelled by the progress callback"));
                        shared.cancel.store(true, Ordering::Relaxed);
                    }
                    Err(error) => {
                        stopped_by = Some(error);
                        shared.cancel.store(true, Ordering::Relaxed);
                    }
                }
            }
            if ended {
                break;
            }
        }
        let result = py.detach(|| worker.join()).map_err(panic_error)?;
        if let Some(error) = stopped_by {
            return Err(error);
        }
        if let (Some(callback), Some(_)) = (progress, &result) {
            if delivered != Some(1.0) && !keep_going(callback, 1.0)? {
                return Err(Cancelled::new_err("cancelled by the progress callback"));
            }
        }
        result.ok_or_else(|| Cancelled::new_err("cancelled"))
    })
}

/// Gives `progress` every fraction reported since the last call, in order; false once it
/// returned False (the rest are dropped).
fn deliver(
    progress: Option<&Bound<'_, PyAny>>,
    shared: &Shared,
    delivered: &mut Option<f32>,
) -> PyResult<bool> {
    let (Some(callback), Some(reported)) = (progress, &shared.reported) else {
        return Ok(true);
    };
    let waiting = std::mem::take(
        &mut reported
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .waiting,
    );
    for fraction in waiting {
        *delivered = Some(fraction);
        if !keep_going(callback, fraction)? {
            return Ok(false);
        }
    }
    Ok(true)
}

/// Tells the waiting thread that the worker ended, when dropped (so also when the work panics).
struct FinishedSignal<'a>(&'a (Mutex<bool>, Condvar));

impl Drop for FinishedSignal<'_> {
    fn drop(&mut self) {
        let (done, signal) = self.0;
        *done
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = true;
        signal.notify_all();
    }
}

/// Calls `callback(fraction)`: anything but False (None included) goes on.
fn keep_going(callback: &Bound<'_, PyAny>, fraction: f32) -> PyResult<bool> {
    let answer = callback.call1((fraction,))?;
    Ok(!answer.is_instance_of::<pyo3::types::PyBool>() || answer.is_truthy()?)
}

/// A panic in the library, as an exception (it is a bug: the message asks for a report).
pub fn panic_error(payload: Box<dyn std::any::Any + Send>) -> PyErr {
    let message = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_string());
    PyRuntimeError::new_err(format!(
        "fairmesh failed inside the library (a bug; please report it with the mesh): {message}"
    ))
}

/// Runs `work` in this process's pool without the GIL, waiting for it and turning a panic into
/// an exception (short calls, such as building a mesh from arrays).
pub fn catching<T: Send>(py: Python<'_>, work: impl FnOnce() -> PyResult<T> + Send) -> PyResult<T> {
    py.detach(|| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| pool::run(work)))
            .unwrap_or_else(|p| Err(panic_error(p)))
            .and_then(|result| result)
    })
}
