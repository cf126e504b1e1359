//! The `fairmesh` Python package's extension module, `fairmesh._fairmesh` (PyO3): the library's
//! fairing, noise, comparison, hierarchy and file I/O on numpy arrays. `fairmesh/__init__.py`
//! re-exports it; `fairmesh/__init__.pyi` gives editors its signatures and docs.
//!
//! - `arrays.rs`: numpy arrays in (checked, read where they lie) and out (handed over, no copy).
//! - `mesh.rs`: meshes from arrays, and `Mesh`, a loaded file kept for saving it back.
//! - `fair.rs`: `fair`, the command line's `fair` with its `--json` report as a dict.
//! - `levels.rs`: `hierarchy` and its `Hierarchy` object, which runs `multires` again and again.
//! - `measure.rs`: `noise` and `compare`.
//! - `texture.rs`: `follow_texture`, texture coordinates that follow the vertices' slide.
//! - `run.rs`: long calls without the GIL, with a progress callback and Ctrl+C.
//! - `pool.rs`: the rayon pool every call runs in, one per process (so a forked child works).
//! - `options.rs`, `errors.rs`: keyword arguments checked, the library's errors as exceptions.

mod arrays;
mod errors;
mod fair;
mod levels;
mod measure;
mod mesh;
mod options;
mod pool;
mod run;
mod texture;

use pyo3::prelude::*;

#[pymodule]
fn _fairmesh(module: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = module.py();
    module.add_function(wrap_pyfunction!(fair::fair, module)?)?;
    module.add_function(wrap_pyfunction!(measure::noise, module)?)?;
    module.add_function(wrap_pyfunction!(measure::compare, module)?)?;
    module.add_function(wrap_pyfunction!(levels::hierarchy, module)?)?;
    module.add_function(wrap_pyfunction!(texture::follow_texture, module)?)?;
    module.add_function(wrap_pyfunction!(mesh::load, module)?)?;
    module.add_function(wrap_pyfunction!(mesh::save, module)?)?;
    module.add_function(wrap_pyfunction!(mesh::load_pickled, module)?)?;
    module.add_class::<mesh::Mesh>()?;
    module.add_class::<levels::Hierarchy>()?;
    module.add("MeshFileError", py.get_type::<errors::MeshFileError>())?;
    module.add("MeshWarning", py.get_type::<mesh::MeshWarning>())?;
    module.add("Cancelled", py.get_type::<run::Cancelled>())?;
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
