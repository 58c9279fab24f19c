//! Work items shared by a few threads, each taking the next item when it is done with one
//! (the camera's row chunks, the LiDAR's ray runs). Taken as they go, not dealt in advance: a
//! thread the system holds back (another sensor's, another process) does not hold up the
//! others. Callers make each item's result depend on the item alone, so the outcome is the
//! same for any number of threads.

use std::sync::Mutex;

/// Runs `work(index, item)` on every item of `items` on `threads` threads (the caller's
/// among them); returns the sum of what it returns.
pub fn on_threads<T: Send>(
    threads: usize,
    items: impl Iterator<Item = T> + Send,
    work: impl Fn(usize, T) -> usize + Sync,
) -> usize {
    let queue = Mutex::new(items.enumerate());
    let drain = || {
        let mut sum = 0;
        loop {
            let next = queue.lock().expect("work queue").next();
            match next {
                Some((i, t)) => sum += work(i, t),
                None => return sum,
            }
        }
    };
    if threads <= 1 {
        return drain();
    }
    std::thread::scope(|s| {
        let others: Vec<_> = (1..threads).map(|_| s.spawn(drain)).collect();
        let mine = drain();
        mine + others.into_iter().map(|r| r.join().expect("worker thread")).sum::<usize>()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_item_once_whatever_the_threads() {
        for threads in [1, 2, 3, 8] {
            let mut seen = [0u8; 100];
            let sum = on_threads(threads, seen.iter_mut(), |i, s| {
                *s += 1;
                i
            });
            assert_eq!(sum, (0..100).sum::<usize>(), "{threads} threads");
            assert!(seen.iter().all(|&s| s == 1), "{threads} threads");
        }
    }
}
