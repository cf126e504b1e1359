//! The fairmesh editor: an eframe/egui app with a wgpu viewport, built on the `fairmesh` library.
//!
//! An artist loads a mesh, the editor builds its volume-preserving decimation hierarchy in the
//! background, and a slider picks the level from which coarse-to-fine fairing starts; noise can
//! be injected, before and after compared, the result exported in its own format.
//!
//! - [`app`]: the editor's state, its panels, the background work and [`app::run`], which opens
//!   the window;
//! - [`render`]: the 3D viewport's own wgpu pipeline behind an `egui_wgpu` paint callback; it
//!   takes positions, triangles and per-vertex values and knows nothing of fairing.
//!
//! The library (`fairmesh`) knows nothing of this crate: every algorithm the editor runs is a
//! public function of the library, called from the editor's worker threads.

pub mod app;
pub mod render;
