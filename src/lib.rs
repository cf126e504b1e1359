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
//! - [`bundled`]: the Stanford bunny compiled into the library, so the binary needs no files.
//!
//! The library never prints and never spawns long-lived threads (rayon's pool aside); long
//! operations take a [`Progress`] hook to report progress and to be cancelled.
//!
//! The repository's `docs/architecture.md` describes how data flows, where each section of the
//! paper lives and how the editor is tested without a GPU; `docs/paper.md` is the reading of the
//! paper that the code follows; `docs/measurements.md` holds the measurements behind the defaults.
//!
//! # The workspace around it
//! The library has no GUI and no command-line dependency. Beside it, in the same repository:
//! the editor (crate `fairmesh-editor`, eframe, egui and wgpu), the `fairmesh` binary (crate
//! `fairmesh-cli`: the command-line tool, and the editor when given no subcommand) and the
//! Python package (`python/`). Each of them uses this library's public API only.
//!
//! # Public dependencies
//! Points and vectors in the API are [glam](https://docs.rs/glam/0.34) 0.34 types (`DVec3` in
//! [`metrics`], `Vec3A` in the fairing kernels); the crate re-exports it as [`fairmesh::glam`](glam)
//! so that callers use the same version.
//!
//! # Example
//! Load a mesh, add noise, fair it, and measure how close it comes back:
//!
//! ```
//! use fairmesh::fairing::{fair_constrained, FairOptions};
//! use fairmesh::noise::{add_noise, NoiseOptions};
//!
//! let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/bunny00.obj"));
//! let loaded = fairmesh::io::load(path)?;
//! let clean = loaded.mesh.clone();
//!
//! let mut mesh = loaded.mesh;
//! add_noise(&mut mesh, &NoiseOptions::default()); // 0.3 mean edge lengths along the normals
//! let noisy = mesh.clone();
//! fair_constrained(&mut mesh, &loaded.topology, &FairOptions::default());
//!
//! let before = fairmesh::metrics::compare(&clean, &noisy);
//! let after = fairmesh::metrics::compare(&clean, &mesh);
//! assert!(after.mean_surface_distance < 0.7 * before.mean_surface_distance);
//! # Ok::<(), fairmesh::io::IoError>(())
//! ```

/// `with_*` setters for an options struct. The options structs are `#[non_exhaustive]` (they will
/// grow), so code outside the crate starts from `Default` and sets what it needs:
/// `FairOptions::default().with_rounds(3)`.
macro_rules! with_setters {
    ($type:ident { $($setter:ident => $field:ident: $field_type:ty),* $(,)? }) => {
        impl $type {
            $(
                #[doc = concat!("`self` with [`", stringify!($field), "`](Self::",
                    stringify!($field), ") set to `value`.")]
                #[must_use]
                pub fn $setter(mut self, value: $field_type) -> Self {
                    self.$field = value;
                    self
                }
            )*
        }
    };
}

pub mod bundled;
mod clock;
pub mod fairing;
pub mod hierarchy;
pub mod io;
pub mod mesh;
pub mod metrics;
pub mod multires;
pub mod noise;

pub use mesh::{Topology, TriMesh};

/// The glam version the API uses (0.34), for callers that build or read its points.
pub use glam;

/// Progress-and-cancel hook for long operations. `report` is called now and then with the fraction
/// done, in `0.0..=1.0`; returning `false` asks the operation to stop as soon as it can. `Send`,
/// so that operations can run their whole body on a worker of the rayon pool.
pub trait Progress: Send {
    fn report(&mut self, fraction: f32) -> bool;

    /// [`report`](Self::report) as a `Result`: `Err(Cancelled)` when the hook asks to stop, so
    /// that an operation passes the stop on with `?`.
    fn check(&mut self, fraction: f32) -> Result<(), Cancelled> {
        if self.report(fraction) {
            Ok(())
        } else {
            Err(Cancelled)
        }
    }
}

/// A long operation stopped part-way because its [`Progress`] hook asked it to. What it was
/// changing in place is left part-way: the caller drops it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cancelled;

impl std::fmt::Display for Cancelled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("cancelled")
    }
}

impl std::error::Error for Cancelled {}

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
