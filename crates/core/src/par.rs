//! Parallel reductions that give the same bits on every run.
//!
//! rayon's `reduce` and `sum` associate the partial results as the work happened to be
//! split between threads, which varies from run to run; floating-point addition is not
//! associative, so a sum of `f32`/`f64` made that way can differ in its last digits between
//! two runs on the same input. [`fold_in_order`] keeps the parallel map and folds the
//! per-item results on one thread, in the iterator's order.

use rayon::iter::IndexedParallelIterator;

/// Maps in parallel, then folds the results in order with `op`, starting from `identity`:
/// the result depends only on the items, not on the thread count or the scheduling.
///
/// Meant for reductions of a few values per item (a row's partial sums): the per-item
/// results are collected before the fold.
///
/// ```
/// use mirrorball_core::par::fold_in_order;
/// use rayon::prelude::*;
/// let parts = (0..1000).into_par_iter().map(|i| 1.0 / (1.0 + i as f64));
/// let a = fold_in_order(parts, 0.0, |a, b| a + b);
/// let b = (0..1000).map(|i| 1.0 / (1.0 + i as f64)).fold(0.0, |a, b| a + b);
/// assert_eq!(a.to_bits(), b.to_bits());
/// ```
pub fn fold_in_order<T, I, F>(items: I, identity: T, op: F) -> T
where
    T: Send,
    I: IndexedParallelIterator<Item = T>,
    F: Fn(T, T) -> T,
{
    items.collect::<Vec<T>>().into_iter().fold(identity, op)
}
