//! The fairmesh editor in a web page: `start` runs on the page's load (wasm-bindgen's start
//! function) and starts the editor (`fairmesh-editor`) on the canvas `fairmesh-canvas` of
//! `web/index.html`, with eframe's web runner and wgpu (WebGPU where the browser has it,
//! WebGL2 otherwise; `?backend=webgl2` asks for WebGL2 alone).
//!
//! The page opens the bundled bunny, then the file of `?open=URL` if there is one. The editor's
//! own web glue (files from the page, exports as downloads, work between frames) lives in
//! `fairmesh_editor::app::web`. Built only for `wasm32`: on other targets this crate is empty.

#[cfg(target_arch = "wasm32")]
mod page;

#[cfg(target_arch = "wasm32")]
pub use page::{command, start, status};
