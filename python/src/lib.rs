//! mirrorball for Python: numpy arrays in and out, through the workspace's crates (core's
//! `Resampler` and `Remap` for conversions, io for files, filter for prefiltering and SH9,
//! bake for engines' bakes, the library's `views` for rigs of views). This crate holds no conversion logic of its own: it checks
//! Python's arguments, moves texels between numpy and `Image`, releases the GIL while the
//! work runs, and turns errors into Python's exceptions by whose fault they are.
//!
//! Built by maturin (`python/pyproject.toml`) as the module `mirrorball._native`; the
//! package `mirrorball` re-exports it (`python/mirrorball/__init__.py`).

mod arrays;
mod convert;
mod errors;
mod files;
mod lighting;
mod threads;
mod views;

use pyo3::prelude::*;

/// The native module, re-exported by the `mirrorball` package.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("InputError", m.py().get_type::<errors::InputError>())?;
    m.add_function(wrap_pyfunction!(threads::set_threads, m)?)?;
    m.add_function(wrap_pyfunction!(threads::get_threads, m)?)?;
    m.add_function(wrap_pyfunction!(convert::convert, m)?)?;
    m.add_function(wrap_pyfunction!(convert::projections, m)?)?;
    m.add_class::<convert::Remap>()?;
    m.add_function(wrap_pyfunction!(files::read, m)?)?;
    m.add_function(wrap_pyfunction!(files::write, m)?)?;
    m.add_function(wrap_pyfunction!(lighting::prefilter, m)?)?;
    m.add_function(wrap_pyfunction!(lighting::sh9, m)?)?;
    m.add_function(wrap_pyfunction!(lighting::bake, m)?)?;
    m.add_function(wrap_pyfunction!(views::views, m)?)?;
    m.add_function(wrap_pyfunction!(views::cut_views, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
