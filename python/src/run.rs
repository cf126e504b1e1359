//! Running long library calls without the GIL: the work runs on a thread of its own while the
//! calling thread waits with the GIL released, waking every few hundredths of a second to check
//! for Ctrl+C (Python handles signals on its main thread, in the interpreter) and to call the
//! `progress` callback. Either one stops the work at its next progress report, through the
//! library's [`fairmesh::Progress`] hook; a panic in the library comes back as an exception.

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// How often the waiting thread looks for Ctrl+C and reports progress.
const POLL: Duration = Duration::from_millis(40);

pyo3::create_exception!(
    fairmesh,
    Cancelled,
    pyo3::exceptions::PyException,
    "The progress callback returned False: the call stopped and gave no result."
);

/// What the working thread and the waiting one share.
struct Shared {
    /// The last fraction reported, as f32 bits.
    fraction: AtomicU32,
    cancel: AtomicBool,
}

/// The [`fairmesh::Progress`] the work reports to.
pub struct Hook<'a> {
    shared: &'a Shared,
}

impl fairmesh::Progress for Hook<'_> {
    fn report(&mut self, fraction: f32) -> bool {
        self.shared
            .fraction
            .store(fraction.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
        !self.shared.cancel.load(Ordering::Relaxed)
    }
}

/// Runs `work` without the GIL; `progress` (a Python callable taking the fraction done, or
/// None) is called on the calling thread as the work reports. `work` returns `None` when it
/// stopped because its hook asked it to. Ctrl+C raises `KeyboardInterrupt`, a callback that
/// returns False raises [`Cancelled`], one that raises passes its exception on; in each case
/// the work is stopped first. With `threads`, the work runs in a rayon pool of that many threads
/// of its own instead of the shared one (for running several calls side by side).
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
        fraction: AtomicU32::new(0f32.to_bits()),
        cancel: AtomicBool::new(false),
    };
    let pool = threads
        .map(|n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .thread_name(|i| format!("fairmesh-python-{i}"))
                .build()
                .map_err(|e| PyRuntimeError::new_err(format!("cannot start {n} threads: {e}")))
        })
        .transpose()?;
    // Set by the worker when it ends, panicking or not.
    let finished = (Mutex::new(false), Condvar::new());
    std::thread::scope(|scope| {
        let worker = std::thread::Builder::new()
            .name("fairmesh-python".into())
            .spawn_scoped(scope, || {
                let _signal = FinishedSignal(&finished);
                let mut hook = Hook { shared: &shared };
                match &pool {
                    Some(pool) => pool.install(|| work(&mut hook)),
                    None => work(&mut hook),
                }
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
        let mut stopped_by: Option<PyErr> = None;
        let mut reported = f32::NAN;
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
            if ended {
                break;
            }
            if stopped_by.is_some() {
                continue;
            }
            let outcome = py.check_signals().and_then(|()| match progress {
                Some(callback) => {
                    let fraction = f32::from_bits(shared.fraction.load(Ordering::Relaxed));
                    if fraction == reported {
                        return Ok(true);
                    }
                    reported = fraction;
                    keep_going(callback, fraction)
                }
                None => Ok(true),
            });
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
        let result = py.detach(|| worker.join()).map_err(panic_error)?;
        if let Some(error) = stopped_by {
            return Err(error);
        }
        if let (Some(callback), Some(_)) = (progress, &result) {
            if !keep_going(callback, 1.0)? {
                return Err(Cancelled::new_err("cancelled by the progress callback"));
            }
        }
        result.ok_or_else(|| Cancelled::new_err("cancelled"))
    })
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

/// Runs `work` on the calling thread, turning a panic into an exception (short calls that keep
/// the GIL, such as building a mesh from arrays).
pub fn catching<T>(work: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(work))
        .unwrap_or_else(|p| Err(panic_error(p)))
}
