//! fairmesh: removing noise and unwanted detail from triangle meshes without shrinking them,
//! after Liu, Bao, Heng, Wong and Peng, "Constrained Fairing for Meshes".
//!
//! Map of the library (data flows top to bottom):
//! - [`mesh`]: `TriMesh`, `Topology` (one-ring CSR, boundary loops, components), welding, clean-up.
//! - [`io`]: load and save OBJ, glTF/GLB, PLY, STL, OFF; `load(path)` / `save(path)` by extension.
//! - [`fairing`]: constrained fairing (paper 3.2), boundary curves (3.3), Laplacian/Taubin/HC.
//! - [`hierarchy`]: volume-preserving decimation hierarchy (4.1) and moving between its levels.
//! - [`multires`]: multiresolution fairing from a chosen coarse level (4.2).
//! - [`noise`], [`metrics`]: seeded noise; volume, area, surface distance and other comparisons.
//! - `app`, `render` (feature `gui`): the editor; nothing else imports egui or wgpu.
//!
//! The library never prints and never spawns long-lived threads (rayon's pool aside); long
//! operations take a [`Progress`] hook to report progress and to be cancelled.

pub mod fairing;
pub mod hierarchy;
pub mod io;
pub mod mesh;
pub mod metrics;
pub mod multires;
pub mod noise;

#[cfg(feature = "gui")]
pub mod app;
#[cfg(feature = "gui")]
pub mod render;

pub use mesh::{Topology, TriMesh};

/// Progress-and-cancel hook for long operations. `report` is called now and then with the fraction
/// done, in `0.0..=1.0`; returning `false` asks the operation to stop as soon as it can. `Send`,
/// so that operations can run their whole body on a worker of the rayon pool.
pub trait Progress: Send {
    fn report(&mut self, fraction: f32) -> bool;
}

impl<F: FnMut(f32) -> bool + Send> Progress for F {
    fn report(&mut self, fraction: f32) -> bool {
        self(fraction)
    }
}

/// A [`Progress`] that ignores reports and never cancels.
pub struct NoProgress;

impl Progress for NoProgress {
    fn report(&mut self, _fraction: f32) -> bool {
        true
    }
}
