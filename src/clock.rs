//! The clock the library times its stages with (the reports' durations): the standard library's
//! `Instant`, except on `wasm32` targets, whose standard library has no clock (`Instant::now`
//! panics there); the `web-time` crate's `Instant` stands in for it with the same interface.
//!
//! The library's own unit tests can make the clock tick instead ([`Ticking`]): while a test
//! holds one, every reading on its thread moves the clock on by a fixed step, so a report's
//! durations count the readings and the test can work out by hand what each must be.

#[cfg(all(not(target_arch = "wasm32"), not(test)))]
pub(crate) use std::time::Instant;
#[cfg(target_arch = "wasm32")]
pub(crate) use web_time::Instant;

#[cfg(all(not(target_arch = "wasm32"), test))]
pub(crate) use ticking::{Instant, Ticking};

#[cfg(all(not(target_arch = "wasm32"), test))]
mod ticking {
    use std::cell::Cell;
    use std::time::Duration;

    thread_local! {
        /// This thread's ticking clock: its step and its reading, in milliseconds; `None`: the
        /// wall clock.
        static CLOCK: Cell<Option<(u64, u64)>> = const { Cell::new(None) };
    }

    /// While held, the clock on this thread ticks: every reading (`now`, `elapsed`) moves it on
    /// by `step_ms`, so a stretch timed by two readings lasts exactly `step_ms`.
    pub(crate) struct Ticking;

    impl Ticking {
        pub(crate) fn start(step_ms: u64) -> Self {
            CLOCK.with(|c| c.set(Some((step_ms, 0))));
            Ticking
        }
    }

    impl Drop for Ticking {
        fn drop(&mut self) {
            CLOCK.with(|c| c.set(None));
        }
    }

    /// The ticking clock's next reading on this thread, if it ticks.
    fn tick() -> Option<u64> {
        CLOCK.with(|c| {
            let (step, at) = c.get()?;
            c.set(Some((step, at + step)));
            Some(at + step)
        })
    }

    /// An instant of the wall clock, or a reading of the ticking one.
    #[derive(Clone, Copy, Debug)]
    pub(crate) enum Instant {
        Wall(std::time::Instant),
        Tick(u64),
    }

    impl Instant {
        pub(crate) fn now() -> Self {
            tick().map_or_else(|| Self::Wall(std::time::Instant::now()), Self::Tick)
        }

        pub(crate) fn elapsed(&self) -> Duration {
            match *self {
                Self::Wall(started) => started.elapsed(),
                Self::Tick(started) => {
                    let now = tick().expect("a ticking reading is read again on its thread");
                    Duration::from_millis(now - started)
                }
            }
        }
    }
}
