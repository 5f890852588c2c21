//! `parallel::dealt` and `costliest_first`: every item once, results in
//! item order whatever the threads, no more at once than asked, and the
//! costliest items started first.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use lightquad::parallel::{costliest_first, dealt};

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a pool")
}

#[test]
fn every_item_once_in_item_order_on_any_number_of_threads() {
    for threads in [1, 2, 3, 8] {
        for n in [0, 1, 2, 7, 100] {
            // A permutation of 0..n, by a stride prime to n.
            let order: Vec<usize> = (0..n).map(|i| (i * 37 + 5) % n.max(1)).collect();
            let calls = AtomicUsize::new(0);
            let out = pool(threads).install(|| {
                dealt(&order, usize::MAX, |k| {
                    calls.fetch_add(1, Ordering::Relaxed);
                    k * k
                })
            });
            let want: Vec<usize> = (0..n).map(|k| k * k).collect();
            assert_eq!(out, want, "{threads} threads, n = {n}");
            assert_eq!(calls.into_inner(), n);
        }
    }
}

#[test]
fn no_more_items_run_at_once_than_the_workers_asked() {
    for (threads, workers) in [(4, 1), (4, 2), (4, 3), (2, 8)] {
        let (now, most) = (AtomicUsize::new(0), AtomicUsize::new(0));
        let order: Vec<usize> = (0..24).collect();
        pool(threads).install(|| {
            dealt(&order, workers, |_| {
                let running = now.fetch_add(1, Ordering::SeqCst) + 1;
                most.fetch_max(running, Ordering::SeqCst);
                std::thread::sleep(Duration::from_millis(2));
                now.fetch_sub(1, Ordering::SeqCst);
            })
        });
        let most = most.into_inner();
        assert!(
            most <= workers.min(threads),
            "{threads} threads, {workers} workers: {most}"
        );
    }
}

#[test]
fn one_thread_takes_the_items_in_the_order_given_costliest_first() {
    let costs = [3, 9, 0, 9, 5, 1];
    let started = Mutex::new(Vec::new());
    let out = pool(1).install(|| {
        costliest_first(&costs, |k| {
            started.lock().expect("lock").push(k);
            costs[k]
        })
    });
    assert_eq!(out, costs);
    // Largest first, ties in ascending index.
    assert_eq!(started.into_inner().expect("lock"), [1, 3, 4, 0, 5, 2]);
}

#[test]
fn nested_deals_finish() {
    let order: Vec<usize> = (0..6).collect();
    let out = pool(2).install(|| {
        dealt(&order, usize::MAX, |k| {
            dealt(&order, usize::MAX, |j| j + k).iter().sum::<usize>()
        })
    });
    let want: Vec<usize> = (0..6).map(|k| 15 + 6 * k).collect();
    assert_eq!(out, want);
}

#[test]
fn after_a_failure_no_item_is_started_and_the_first_failure_in_order_is_returned() {
    let order: Vec<usize> = (0..40).collect();
    for threads in [1, 2, 4] {
        let started = AtomicUsize::new(0);
        let out: Result<Vec<usize>, usize> = pool(threads).install(|| {
            lightquad::parallel::try_dealt(&order, usize::MAX, |k| {
                started.fetch_add(1, Ordering::SeqCst);
                // The items after the failure take long: the threads start
                // few of them before it is known.
                if k > 7 {
                    std::thread::sleep(Duration::from_millis(20));
                }
                if k == 7 || k == 9 || k == 30 {
                    Err(k)
                } else {
                    Ok(k)
                }
            })
        });
        assert_eq!(out, Err(7), "{threads} threads");
        let started = started.into_inner();
        if threads == 1 {
            assert_eq!(started, 8);
        } else {
            assert!(started < 40, "{threads} threads: every item started");
        }
        let all: Result<Vec<usize>, usize> =
            pool(threads).install(|| lightquad::parallel::try_dealt(&order, 2, Ok));
        assert_eq!(all, Ok(order.clone()));
    }
}
