//! The library's errors as Python exceptions: a file that cannot be read or written is an
//! `OSError` (`FileNotFoundError`, `PermissionError`, ... by its errno), a file whose content is
//! wrong is a [`MeshFileError`] (a `ValueError`); both carry the library's message, which starts
//! with the path, and the path as `filename`.

use fairmesh::io::IoError;
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    fairmesh,
    MeshFileError,
    PyValueError,
    include_str!(concat!(env!("OUT_DIR"), "/doc/MeshFileError.txt"))
);

/// `error` as the exception a Python caller expects.
pub fn io_error(py: Python<'_>, error: &IoError) -> PyErr {
    let path = error.path().display().to_string();
    let message = error.to_string();
    let os_error = match error {
        IoError::Read { source, .. } | IoError::Write { source, .. } => source.raw_os_error(),
        _ => None,
    };
    if let Some(errno) = os_error {
        // OSError(errno, message, filename) picks the subclass (FileNotFoundError, ...).
        return PyOSError::new_err((errno, message, path));
    }
    if matches!(error, IoError::Read { .. } | IoError::Write { .. }) {
        return PyOSError::new_err(message);
    }
    let exception = MeshFileError::new_err(message);
    // The attribute is a convenience: the message already names the file.
    let _ = exception.value(py).setattr("filename", path);
    exception
}
