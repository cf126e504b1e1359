//! The rayon pool every call runs in: one per process, this extension's own, never rayon's
//! global one.
//!
//! A process made by `fork` (what `multiprocessing` used by default on Linux before Python 3.14)
//! is a copy of its parent with only the thread that forked: a pool started in the parent is in
//! the child's memory, but none of its threads run there, so the first parallel section a child
//! starts on it waits for ever. rayon's global pool cannot be started again once it exists, so
//! the library's parallel sections run inside [`shared`]'s pool (`ThreadPool::install`), which is
//! keyed on the process id: a process that is not the one that made the pool makes its own, and
//! the parent's copy is left alone (freeing it would wait for threads that are not there).
//!
//! Every call into the library that may reach a parallel section goes through [`run`] (short
//! calls on the calling thread) or `run::run_detached` (long ones, which also install a pool of
//! their own for `threads=`), so that rayon's global pool is never started in the first place.
//! The pointer is swapped without a lock, so a fork while another thread of the parent is here
//! leaves the child nothing to wait on.

use pyo3::exceptions::PyRuntimeError;
use pyo3::PyResult;
use rayon::{ThreadPool, ThreadPoolBuilder};
use std::sync::atomic::{AtomicPtr, Ordering};

/// A pool and the process that made it.
struct ProcessPool {
    process: u32,
    pool: ThreadPool,
}

/// The current process's pool once made (never freed: at most one per process lives on, and a
/// forked child's copy of its parent's is dead weight of a few hundred bytes).
static POOL: AtomicPtr<ProcessPool> = AtomicPtr::new(std::ptr::null_mut());

/// This process's pool, made on first use (as many threads as rayon's global pool would have:
/// `RAYON_NUM_THREADS`, else one a core).
pub fn shared() -> PyResult<&'static ThreadPool> {
    let process = std::process::id();
    loop {
        let current = POOL.load(Ordering::Acquire);
        // SAFETY: a pointer stored in POOL comes from `Box::into_raw` and is never freed.
        if let Some(made) = unsafe { current.as_ref() } {
            if made.process == process {
                return Ok(&made.pool);
            }
        }
        let pool = build(None, "fairmesh")?;
        let fresh = Box::into_raw(Box::new(ProcessPool { process, pool }));
        if POOL
            .compare_exchange(current, fresh, Ordering::AcqRel, Ordering::Acquire)
            .is_err()
        {
            // Another thread made this process's pool first: use that one.
            // SAFETY: `fresh` was never shared.
            drop(unsafe { Box::from_raw(fresh) });
        }
    }
}

/// A pool of `threads` threads (None: rayon's default count), named `{name}-{i}`.
pub fn build(threads: Option<usize>, name: &'static str) -> PyResult<ThreadPool> {
    let mut builder = ThreadPoolBuilder::new().thread_name(move |i| format!("{name}-{i}"));
    if let Some(n) = threads {
        builder = builder.num_threads(n);
    }
    builder.build().map_err(|e| {
        PyRuntimeError::new_err(format!(
            "cannot start {} threads: {e}",
            threads.map_or_else(|| "the pool's".to_string(), |n| n.to_string())
        ))
    })
}

/// Runs `work` in this process's pool, waiting for it (the caller should not hold the GIL:
/// see `py.detach`).
pub fn run<T: Send>(work: impl FnOnce() -> T + Send) -> PyResult<T> {
    Ok(shared()?.install(work))
}
