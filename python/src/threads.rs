//! The thread count: every call's parallel work runs in one rayon pool, which
//! `set_threads` replaces (rayon's global pool, all cores, until it is first called).

use pyo3::prelude::*;
use std::sync::{Arc, RwLock};

static POOL: RwLock<Option<Arc<rayon::ThreadPool>>> = RwLock::new(None);

/// The pool work runs in, if one was set.
fn pool() -> Option<Arc<rayon::ThreadPool>> {
    POOL.read().unwrap_or_else(|e| e.into_inner()).clone()
}

/// Runs `f` in the pool `set_threads` made (else rayon's global one).
pub fn run<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    match pool() {
        Some(p) => p.install(f),
        None => f(),
    }
}

/// Sets how many threads mirrorball's calls use: `n` ≥ 1, or None for one per core.
#[pyfunction]
#[pyo3(signature = (n=None))]
pub fn set_threads(n: Option<i64>) -> PyResult<()> {
    let made = match n {
        None => None,
        Some(n) if !(1..=4096).contains(&n) => {
            return Err(crate::errors::request(
                "n",
                format!("{n} threads; give 1 to 4096, or None for one per core"),
            ))
        }
        Some(n) => Some(Arc::new(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n as usize)
                .thread_name(|i| format!("mirrorball-{i}"))
                .build()
                .map_err(|e| pyo3::exceptions::PyOSError::new_err(e.to_string()))?,
        )),
    };
    *POOL.write().unwrap_or_else(|e| e.into_inner()) = made;
    Ok(())
}

/// How many threads mirrorball's calls use.
#[pyfunction]
pub fn get_threads() -> usize {
    run(rayon::current_num_threads)
}
