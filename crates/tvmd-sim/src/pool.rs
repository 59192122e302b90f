//! A scoped worker pool: independent jobs on a few threads, results in input order (the batch
//! runs and the AFS atlas share it).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Worker threads for `jobs` jobs: `requested` or the available cores, at least 1, at most
/// `jobs`.
pub fn worker_count(requested: Option<usize>, jobs: usize) -> usize {
    requested
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .clamp(1, jobs.max(1))
}

/// `f(k, item)` for every item on `workers` threads (the calling thread is one of them), the
/// results in input order; `None` for a job that did not finish (its worker panicked). A
/// thread that cannot be spawned leaves its share to the others.
pub fn map_in_order<T: Sync, R: Send>(
    items: &[T],
    workers: usize,
    f: impl Fn(usize, &T) -> R + Sync,
) -> Vec<Option<R>> {
    let next = AtomicUsize::new(0);
    let slots: Vec<Mutex<Option<R>>> = items.iter().map(|_| Mutex::new(None)).collect();
    let work = || loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        let (Some(item), Some(slot)) = (items.get(k), slots.get(k)) else {
            break;
        };
        let result = f(k, item);
        if let Ok(mut slot) = slot.lock() {
            *slot = Some(result);
        }
    };
    std::thread::scope(|scope| {
        for _ in 1..workers {
            let _ = std::thread::Builder::new().spawn_scoped(scope, work);
        }
        work();
    });
    slots
        .into_iter()
        .map(|slot| slot.into_inner().ok().flatten())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_keep_the_input_order_whatever_the_workers() {
        let items: Vec<u64> = (0..100).collect();
        for workers in [1, 2, 7] {
            let out = map_in_order(&items, workers, |k, x| (k as u64) * 1000 + x * x);
            let want: Vec<Option<u64>> = items.iter().map(|x| Some(x * 1000 + x * x)).collect();
            assert_eq!(out, want);
        }
        assert_eq!(worker_count(Some(0), 5), 1);
        assert_eq!(worker_count(Some(9), 5), 5);
        assert!(map_in_order::<u8, u8>(&[], 3, |_, x| *x).is_empty());
    }
}
