//! Work dealt out on rayon's threads in an order of the caller's choosing.
//!
//! Rayon splits a parallel iterator into halves and steals the larger
//! pending half: a costly item near the end of a list runs last, with the
//! other threads idle meanwhile. Here a shared counter deals the items one
//! at a time, in the order given, to whichever thread is free (so with the
//! costliest first the last item to finish is among the cheapest: the
//! longest-processing-time-first schedule), and at most a given number run
//! at once.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

/// `work(k)` for every `k` of `order`, returned in ascending `k`: computed
/// on at most `workers` of rayon's threads (at least one), each taking the
/// next `k` of `order` when it is free. The results do not depend on the
/// threads, only the time they take does.
pub fn dealt<R: Send>(order: &[usize], workers: usize, work: impl Fn(usize) -> R + Sync) -> Vec<R> {
    let next = AtomicUsize::new(0);
    let workers = workers
        .min(rayon::current_num_threads())
        .min(order.len())
        .max(1);
    let mut done: Vec<(usize, R)> = (0..workers)
        .into_par_iter()
        .with_max_len(1)
        .flat_map_iter(|_| {
            // A worker that starts late finds the counter spent and stops.
            std::iter::from_fn(|| {
                let k = *order.get(next.fetch_add(1, Ordering::Relaxed))?;
                Some((k, work(k)))
            })
            .collect::<Vec<_>>()
        })
        .collect();
    done.sort_unstable_by_key(|(k, _)| *k);
    done.into_iter().map(|(_, r)| r).collect()
}

/// [`dealt`] on every thread over `0..costs.len()`, largest `costs[k]`
/// first (ties in ascending `k`).
pub fn costliest_first<R: Send>(costs: &[u64], work: impl Fn(usize) -> R + Sync) -> Vec<R> {
    let mut order: Vec<usize> = (0..costs.len()).collect();
    order.sort_by_key(|&k| (std::cmp::Reverse(costs[k]), k));
    dealt(&order, usize::MAX, work)
}

/// [`dealt`] for work that can fail: once an item has failed no new item
/// is started (the items under way finish), and the error returned is the
/// first in ascending `k`, the same as if every item had run: an item not
/// started comes after every item started in `order`, so, with `order`
/// ascending, after the one that failed.
pub fn try_dealt<T: Send, E: Send>(
    order: &[usize],
    workers: usize,
    work: impl Fn(usize) -> Result<T, E> + Sync,
) -> Result<Vec<T>, E> {
    let failed = AtomicBool::new(false);
    dealt(order, workers, |k| {
        if failed.load(Ordering::Relaxed) {
            return None;
        }
        let out = work(k);
        if out.is_err() {
            failed.store(true, Ordering::Relaxed);
        }
        Some(out)
    })
    .into_iter()
    .flatten()
    .collect()
}
