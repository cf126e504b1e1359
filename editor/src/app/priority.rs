//! Background work yields to the window. The editor's workers (loading, the hierarchy, fairing,
//! measures) run at a lower scheduling priority than the UI thread, in a rayon pool of their own
//! whose threads have that priority too, so that on a machine with few cores the window and the
//! renderer's threads (a software renderer such as lavapipe rasterizes on the CPU) are served
//! first and input is answered while a big mesh is being built or faired. The work itself is the
//! same; it only waits while the window is drawing.
//!
//! Only Linux lowers a single thread's priority (`setpriority` with `PRIO_PROCESS` and 0 applies
//! to the calling thread there; elsewhere it would apply to the whole process), so other systems
//! run the workers at normal priority.

use std::sync::OnceLock;

/// The nice value of background threads (0 is normal, 19 the lowest): with the scheduler's
/// weights a thread at 5 gets about a third of the share of a normal thread that wants the same
/// core (10 and 15 answered input a little better but made results wait twice as long:
/// `docs/measurements.md`).
#[cfg_attr(not(target_os = "linux"), allow(dead_code))]
pub const BACKGROUND_NICE: i32 = 5;

/// Lowers the calling thread's scheduling priority to [`BACKGROUND_NICE`] (Linux only; a
/// failure leaves it as it was: it only makes the window less quick to answer).
pub fn lower_this_thread() {
    #[cfg(target_os = "linux")]
    // SAFETY: setpriority only reads its arguments; on Linux `who = 0` with PRIO_PROCESS is the
    // calling thread.
    unsafe {
        libc::setpriority(libc::PRIO_PROCESS, 0, BACKGROUND_NICE);
    }
}

/// The editor's worker threads (io, compute, measure), whose jobs run in [`background_pool`]:
/// `Workers::spawn` starts one of each.
pub(in crate::app) const WORKER_NAMES: [&str; 3] =
    ["fairmesh-io", "fairmesh-compute", "fairmesh-measure"];

/// The rayon pool background jobs run in, each at background priority: one thread per core plus
/// one per worker, because a job holds the pool thread it runs on (a long measure must not keep
/// an export waiting for a free thread); the extra threads only run while there is work.
/// `None` if it could not be started, in which case jobs run on their worker's thread.
pub fn background_pool() -> Option<&'static rayon::ThreadPool> {
    static POOL: OnceLock<Option<rayon::ThreadPool>> = OnceLock::new();
    POOL.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(rayon::current_num_threads() + WORKER_NAMES.len())
            .thread_name(|i| format!("fairmesh-background-{i}"))
            .start_handler(|_| lower_this_thread())
            .build()
            .ok()
    })
    .as_ref()
}

/// Runs `job` at background priority: on a thread of [`background_pool`] (the caller waits for
/// it), its parallel loops in that pool too; on the calling thread if there is no pool.
pub fn run_in_background<R>(job: impl FnOnce() -> R + Send) -> R
where
    R: Send,
{
    match background_pool() {
        Some(pool) => pool.install(job),
        None => job(),
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// The calling thread's nice value (`getpriority` returns it; -1 is also a valid value, so
    /// errno is cleared first).
    fn nice_of_this_thread() -> i32 {
        // SAFETY: plain libc calls on the calling thread.
        unsafe {
            *libc::__errno_location() = 0;
            libc::getpriority(libc::PRIO_PROCESS, 0)
        }
    }

    #[test]
    fn background_work_runs_at_lower_priority_and_the_caller_keeps_its_own() {
        let before = std::thread::spawn(nice_of_this_thread).join().unwrap();
        let (worker, pool_threads) = std::thread::spawn(|| {
            lower_this_thread();
            let pool_threads = run_in_background(|| {
                use rayon::prelude::*;
                (0..64)
                    .into_par_iter()
                    .map(|_| nice_of_this_thread())
                    .collect::<Vec<_>>()
            });
            (nice_of_this_thread(), pool_threads)
        })
        .join()
        .unwrap();
        let expected = (before + BACKGROUND_NICE).min(19).max(before);
        assert_eq!(worker, expected);
        assert!(
            pool_threads.iter().all(|&nice| nice == expected),
            "{pool_threads:?}"
        );
        // A thread that did not ask keeps its priority (it is per thread, not per process).
        assert_eq!(
            std::thread::spawn(nice_of_this_thread).join().unwrap(),
            before
        );
    }
}
