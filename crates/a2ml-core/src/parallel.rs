//! Work shared out between the calling thread and the thread pool (rayon's global pool, or
//! the pool a caller installs): one planned task's independent pieces, Opt1/Opt2's starts,
//! a plan's segments, the output's samples. Each piece is computed alone and the results
//! come back in the pieces' order, so that which thread ran a piece changes no bit. rayon
//! enters the library here.
//!
//! The caller takes pieces itself and the pool's threads help as they come free. Many tasks
//! at once run on the same pool (the CLI's batches, `a2ml.plan_many`): a task's pieces then
//! mostly run on its own thread, and its helpers, found with nothing left, end at once.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

/// `f(i, &items[i])` for every item, side by side, in the items' order.
pub(crate) fn map<T: Sync, R: Send>(items: &[T], f: impl Fn(usize, &T) -> R + Sync) -> Vec<R> {
    in_turn(items.iter(), items.len(), f)
}

/// `f(i, &mut items[i])` for every item, side by side, in the items' order.
pub(crate) fn map_mut<T: Send, R: Send>(
    items: &mut [T],
    f: impl Fn(usize, &mut T) -> R + Sync,
) -> Vec<R> {
    let count = items.len();
    in_turn(items.iter_mut(), count, f)
}

/// `a()` and `b()`, side by side: `a` on this thread, `b` on the pool's.
pub(crate) fn join<A: Send, B: Send>(
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    let mut b_result = None;
    let a_result = rayon::in_place_scope(|scope| {
        scope.spawn(|_| b_result = Some(b()));
        a()
    });
    // The scope returns once `b` has run, or passes on its panic.
    (a_result, b_result.expect("the scope ran b"))
}

/// `f(i, item)` for each of the `count` items `items` gives, in the items' order: the
/// calling thread and up to one thread of the pool per item more take the next item in
/// turn when done with one. The caller works rather than waits (it may be the one thread
/// a plan's critical path runs on), and a helper that comes late finds the items taken.
fn in_turn<I, R>(items: I, count: usize, f: impl Fn(usize, I::Item) -> R + Sync) -> Vec<R>
where
    I: Iterator + Send,
    I::Item: Send,
    R: Send,
{
    let source = Mutex::new(items.enumerate());
    let done = Mutex::new(Vec::with_capacity(count));
    let take = || {
        let mut mine = Vec::new();
        loop {
            let next = source.lock().unwrap_or_else(PoisonError::into_inner).next();
            let Some((i, item)) = next else { break };
            mine.push((i, f(i, item)));
        }
        done.lock().unwrap_or_else(PoisonError::into_inner).append(&mut mine);
    };
    let helpers = rayon::current_num_threads().min(count).saturating_sub(1);
    rayon::in_place_scope(|scope| {
        for _ in 0..helpers {
            scope.spawn(|_| take());
        }
        take();
    });
    let mut done = done.into_inner().unwrap_or_else(PoisonError::into_inner);
    done.sort_unstable_by_key(|&(i, _)| i);
    done.into_iter().map(|(_, result)| result).collect()
}

/// `f(i, &items[i], abandoned)` for the items in turn until the first call that says its
/// item is the last wanted (`(_, true)`): the calling thread and the pool's take the lowest
/// item not yet taken, so the items are begun in order, and none after the last wanted one
/// is begun once it is known; `abandoned()` tells a call still running on a later item that
/// its result will be thrown away, so that it may stop early. Returns the results of the
/// items up to the last wanted one (every item's when none is), in order: the same as
/// calling `f` on one item after the other and stopping after the last wanted one, so long
/// as `f` gives the same result whichever thread calls it and `abandoned()` is only
/// consulted to stop.
pub(crate) fn in_turn_until<T: Sync, R: Send>(
    items: &[T],
    f: impl Fn(usize, &T, &dyn Fn() -> bool) -> (R, bool) + Sync,
) -> Vec<R> {
    // The lowest item known to be the last wanted.
    let last = AtomicUsize::new(usize::MAX);
    let results = map(items, |i, item| {
        let abandoned = || i > last.load(Ordering::Relaxed);
        if abandoned() {
            return None;
        }
        let (result, is_last) = f(i, item, &abandoned);
        if is_last {
            last.fetch_min(i, Ordering::Relaxed);
        }
        Some(result)
    });
    let wanted = last.into_inner().saturating_add(1);
    // Every item up to the last wanted one was begun (in order) and none was abandoned.
    results.into_iter().take(wanted).map_while(|result| result).collect()
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

    #[test]
    fn items_in_turn_stop_after_the_last_wanted_one_on_any_pool() {
        let items: Vec<u64> = (0..50).collect();
        // A slow item, so that later ones run beside it, and items that are the last wanted.
        let work = |i: usize, x: &u64, abandoned: &dyn Fn() -> bool, last: &[usize]| {
            let spins = if i == 3 { 200_000 } else { 1_000 };
            let mut sum = 0u64;
            for k in 0..spins {
                if k % 100 == 0 && abandoned() {
                    return (u64::MAX, false);
                }
                sum = sum.wrapping_add(k ^ x);
            }
            (sum, last.contains(&i))
        };
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
            for last in [vec![], vec![0], vec![3], vec![7, 5], vec![49]] {
                let alone: Vec<u64> = (items.iter().enumerate())
                    .map(|(i, x)| work(i, x, &|| false, &last))
                    .scan(false, |stop, (r, is_last)| {
                        (!std::mem::replace(stop, is_last)).then_some(r)
                    })
                    .collect();
                let in_turn = pool.install(|| {
                    in_turn_until(&items, |i, x, abandoned| work(i, x, abandoned, &last))
                });
                assert_eq!(in_turn, alone, "{threads} threads, last wanted {last:?}");
                assert_eq!(in_turn.len(), last.iter().min().map_or(items.len(), |l| l + 1));
            }
        }
    }
}
