//! The hand-over between the stepping thread and the recorder's writer thread: a FIFO bounded
//! by the bytes it holds, so a writer that falls behind holds the stepping thread back rather
//! than letting the queue grow (camera images are megabytes each), and a killed run loses at
//! most what was queued besides the chunk being written.

use std::collections::VecDeque;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

/// What a queued item counts for against the limit.
pub(crate) trait Weight {
    fn bytes(&self) -> usize;
}

struct State<T> {
    items: VecDeque<T>,
    bytes: usize,
    /// The producer is done: the consumer drains what is left, then stops.
    closed: bool,
    /// The consumer failed: what it said; the producer's next push reports it.
    failed: Option<String>,
}

pub(crate) struct Queue<T> {
    state: Mutex<State<T>>,
    /// Signalled when an item arrives or the queue closes.
    filled: Condvar,
    /// Signalled when an item leaves or the consumer fails.
    drained: Condvar,
    limit: usize,
}

impl<T: Weight> Queue<T> {
    /// A queue that holds at most `limit` bytes (one larger item still passes alone).
    pub fn new(limit: usize) -> Queue<T> {
        let state = State { items: VecDeque::new(), bytes: 0, closed: false, failed: None };
        Queue { state: Mutex::new(state), filled: Condvar::new(), drained: Condvar::new(), limit }
    }

    fn lock(&self) -> MutexGuard<'_, State<T>> {
        // A panic on the other side while holding the lock leaves plain data behind: go on.
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Queues `item`, waiting while the queue is full; the consumer's failure, if any.
    pub fn push(&self, item: T) -> Result<(), String> {
        let n = item.bytes();
        let mut s = self.lock();
        while s.failed.is_none() && !s.items.is_empty() && s.bytes + n > self.limit {
            s = self.drained.wait(s).unwrap_or_else(|p| p.into_inner());
        }
        if let Some(e) = &s.failed {
            return Err(e.clone());
        }
        s.bytes += n;
        s.items.push_back(item);
        self.filled.notify_one();
        Ok(())
    }

    /// The next item, waiting for one; `None` once the queue is closed and empty.
    pub fn pop(&self) -> Option<T> {
        let mut s = self.lock();
        loop {
            if let Some(item) = s.items.pop_front() {
                s.bytes -= item.bytes();
                self.drained.notify_one();
                return Some(item);
            }
            if s.closed {
                return None;
            }
            s = self.filled.wait(s).unwrap_or_else(|p| p.into_inner());
        }
    }

    /// No more items will come.
    pub fn close(&self) {
        self.lock().closed = true;
        self.filled.notify_one();
    }

    /// The consumer failed with `e` (the first failure is kept): pushes report it from now on.
    pub fn fail(&self, e: String) {
        let mut s = self.lock();
        s.failed.get_or_insert(e);
        self.drained.notify_one();
    }

    /// The consumer's failure, if any.
    pub fn failure(&self) -> Option<String> {
        self.lock().failed.clone()
    }
}

/// A consumer's guard: if the consumer's thread panics, the queue is marked failed, so that a
/// producer waiting on a full queue gets an error instead of waiting for a consumer that is
/// gone.
pub(crate) struct FailOnPanic<T: Weight> {
    queue: Arc<Queue<T>>,
    why: &'static str,
}

impl<T: Weight> FailOnPanic<T> {
    pub fn new(queue: Arc<Queue<T>>, why: &'static str) -> FailOnPanic<T> {
        FailOnPanic { queue, why }
    }
}

impl<T: Weight> Drop for FailOnPanic<T> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.queue.fail(self.why.into());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Weight for Vec<u8> {
        fn bytes(&self) -> usize {
            self.len()
        }
    }

    /// Runs `body` as the consumer of `q` on a thread of its own, guarded as the recorder's
    /// writer thread is.
    fn consumer<R: Send + 'static>(
        q: &Arc<Queue<Vec<u8>>>,
        body: impl FnOnce(&Queue<Vec<u8>>) -> R + Send + 'static,
    ) -> std::thread::JoinHandle<R> {
        let q = q.clone();
        std::thread::spawn(move || {
            let _unblock = FailOnPanic::new(q.clone(), "consumer panicked");
            body(&q)
        })
    }

    /// Everything pushed comes out once, in order, and the queue never holds more than its
    /// limit (plus one item that is larger alone).
    #[test]
    fn order_kept_and_bytes_bounded() {
        let q = Arc::new(Queue::<Vec<u8>>::new(1000));
        let consumer = consumer(&q, |q| {
            let mut got = vec![];
            while let Some(item) = q.pop() {
                let s = q.lock();
                assert!(
                    s.bytes <= 1000 || s.items.len() == 1,
                    "queue over its limit: {} bytes in {} items",
                    s.bytes,
                    s.items.len()
                );
                drop(s);
                got.push(item);
                std::thread::yield_now();
            }
            got
        });
        let sizes: Vec<usize> = (0..500).map(|i| (i * 37) % 400 + usize::from(i == 250) * 5000).collect();
        for (i, &n) in sizes.iter().enumerate() {
            q.push(vec![i as u8; n]).unwrap();
        }
        q.close();
        let got = consumer.join().unwrap();
        assert_eq!(got.len(), sizes.len());
        for (i, (item, &n)) in got.iter().zip(&sizes).enumerate() {
            assert_eq!((item.len(), item.first().copied().unwrap_or(i as u8)), (n, i as u8));
        }
    }

    /// A consumer that panics (its guard marks the queue failed) does not leave the producer
    /// waiting on a full queue for ever.
    #[test]
    fn a_panicking_consumer_unblocks_the_producer() {
        let q = Arc::new(Queue::<Vec<u8>>::new(10));
        let consumer = consumer(&q, |_| {
            std::thread::sleep(std::time::Duration::from_millis(20));
            panic!("consumer gone");
        });
        q.push(vec![0; 10]).unwrap();
        assert_eq!(q.push(vec![0; 10]), Err("consumer panicked".into()));
        assert!(consumer.join().is_err());
    }

    /// A consumer's failure reaches the producer, even one waiting on a full queue.
    #[test]
    fn a_failure_reaches_a_waiting_producer() {
        let q = Arc::new(Queue::<Vec<u8>>::new(10));
        q.push(vec![0; 10]).unwrap();
        let failer = {
            let q = q.clone();
            std::thread::spawn(move || {
                std::thread::sleep(std::time::Duration::from_millis(20));
                q.fail("disk full".into());
            })
        };
        assert_eq!(q.push(vec![0; 5]), Err("disk full".into()));
        failer.join().unwrap();
        assert_eq!(q.failure().as_deref(), Some("disk full"));
    }
}
