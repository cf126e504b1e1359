//! The clock the library times its stages with (the reports' durations): the standard library's
//! `Instant`, except on `wasm32` targets, whose standard library has no clock (`Instant::now`
//! panics there); the `web-time` crate's `Instant` stands in for it with the same interface.

#[cfg(not(target_arch = "wasm32"))]
pub(crate) use std::time::Instant;
#[cfg(target_arch = "wasm32")]
pub(crate) use web_time::Instant;
