//! Work shared out on the thread pool (rayon's global pool, or the pool a caller installs):
//! one planned task's independent pieces, Opt1/Opt2's starts, a plan's segments, the
//! output's samples. Each piece is computed alone and the results come back in the pieces'
//! order, so that which thread ran a piece changes no bit. rayon enters the library here.
//!
//! Many tasks at once run on the same pool (the CLI's batches, `a2ml.plan_many`): a task's
//! pieces then mostly run on its own thread, and nothing waits for a thread that is busy.

use rayon::prelude::*;

/// `f(i, &items[i])` for every item, on the pool, in the items' order.
pub(crate) fn map<T: Sync, R: Send>(items: &[T], f: impl Fn(usize, &T) -> R + Sync) -> Vec<R> {
    items.par_iter().enumerate().map(|(i, item)| f(i, item)).collect()
}

/// `f(i, &mut items[i])` for every item, on the pool, in the items' order.
pub(crate) fn map_mut<T: Send, R: Send>(
    items: &mut [T],
    f: impl Fn(usize, &mut T) -> R + Sync,
) -> Vec<R> {
    items.par_iter_mut().enumerate().map(|(i, item)| f(i, item)).collect()
}

/// `a()` and `b()`, side by side.
pub(crate) fn join<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    rayon::join(a, b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_back_in_order_on_any_pool() {
        let items: Vec<u64> = (0..1000).collect();
        let square = |i: usize, x: &u64| (i as u64) * 1000 + x * x;
        let alone: Vec<u64> = items.iter().enumerate().map(|(i, x)| square(i, x)).collect();
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
            assert_eq!(pool.install(|| map(&items, square)), alone);
            let mut doubled = items.clone();
            let old = pool.install(|| {
                map_mut(&mut doubled, |i, x| {
                    let old = *x;
                    *x = 2 * *x + i as u64;
                    old
                })
            });
            assert_eq!(old, items);
            assert!(doubled.iter().enumerate().all(|(i, x)| *x == 3 * i as u64));
            assert_eq!(pool.install(|| join(|| 1, || 2)), (1, 2));
        }
    }
}
