//! The core's [`scatterloc::Error`] as Python exceptions: every bad input is a
//! `scatterloc.ScatterlocError` (a `ValueError`) carrying the core's field name (`field`) and
//! the error's kind (`kind`, the core variant's name); a cancelled run is the
//! `KeyboardInterrupt` that cancelled it; a panic inside the library (a bug, caught by
//! [`crate::run::guarded`]) is a `ScatterlocError` of kind `"Panic"`, never
//! `pyo3_runtime.PanicException`.

use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;

use scatterloc::Error;

pyo3::create_exception!(
    _scatterloc,
    ScatterlocError,
    PyValueError,
    "Bad input to scatterloc (a ValueError). `field` names the input at fault as the core \
     names it (e.g. 'receivers[2].position_m', 'runs'), or is None; `kind` is the error's kind \
     (e.g. 'OutOfRange', 'InvalidDelay')."
);

/// A [`ScatterlocError`] with message `message`, `field` and `kind`.
pub fn error_with(py: Python<'_>, message: String, field: Option<&str>, kind: &str) -> PyErr {
    let err = ScatterlocError::new_err(message);
    let value = err.value(py);
    // Setting two attributes on a fresh exception instance cannot fail in practice; if it did,
    // the error would still carry its message.
    let _ = value.setattr("field", field);
    let _ = value.setattr("kind", kind);
    err
}

/// The core error `e` as a Python exception (see the module doc).
pub fn core_error(e: Error) -> PyErr {
    if matches!(e, Error::Cancelled) {
        return PyKeyboardInterrupt::new_err("cancelled");
    }
    Python::attach(|py| error_with(py, e.to_string(), e.field(), e.kind()))
}

/// A panic inside the library (a bug) with its `message`: a [`ScatterlocError`] of kind
/// `"Panic"` (no `field`), so `except ValueError` / `except Exception` catch it as any other
/// error of the package.
pub fn panic_error(message: &str) -> PyErr {
    Python::attach(|py| {
        error_with(
            py,
            format!("internal error (a bug in scatterloc, please report it): {message}"),
            None,
            "Panic",
        )
    })
}

/// A bad argument of the binding itself (a wrong shape, an unknown option), named `field`.
pub fn arg_error(field: &str, message: impl std::fmt::Display) -> PyErr {
    Python::attach(|py| {
        error_with(
            py,
            format!("{field}: {message}"),
            Some(field),
            "InvalidArgument",
        )
    })
}

/// `Result<T, Error>` → `PyResult<T>`.
pub trait Core<T> {
    /// The core error as a Python exception ([`core_error`]).
    fn py(self) -> PyResult<T>;
}

impl<T> Core<T> for scatterloc::Result<T> {
    fn py(self) -> PyResult<T> {
        self.map_err(core_error)
    }
}
