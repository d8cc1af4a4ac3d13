//! Pre-allocated lock-free single-producer single-consumer rings (SPEC §7.2).
//!
//! The real-time loop exchanges objects with other threads through these
//! rings: `push` and `pop` are wait-free, never allocate, never block and
//! never free memory. Values are moved in and out; in particular a `Box`
//! moves through without touching the allocator, which is how plans reach
//! the loop and old plans leave it to be dropped elsewhere. Values still in
//! a ring when both ends are gone are dropped once, with the ring.
//!
//! The ring is [`rtrb`]'s (its memory is allocated once, in [`channel`]);
//! this module is the seam the daemon names, with the small API it uses.

/// The sending end.
pub struct Producer<T>(rtrb::Producer<T>);

/// The receiving end.
pub struct Consumer<T>(rtrb::Consumer<T>);

impl<T> std::fmt::Debug for Producer<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Producer")
            .field("capacity", &self.0.buffer().capacity())
            .finish()
    }
}

impl<T> std::fmt::Debug for Consumer<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Consumer")
            .field("capacity", &self.0.buffer().capacity())
            .finish()
    }
}

/// A ring holding at most `capacity` values (allocated here, once).
pub fn channel<T: Send>(capacity: usize) -> (Producer<T>, Consumer<T>) {
    assert!(capacity > 0, "capacity must be positive");
    let (p, c) = rtrb::RingBuffer::new(capacity);
    (Producer(p), Consumer(c))
}

impl<T: Send> Producer<T> {
    /// Moves `value` into the ring; gives it back if the ring is full.
    pub fn push(&mut self, value: T) -> Result<(), T> {
        self.0.push(value).map_err(|rtrb::PushError::Full(v)| v)
    }

    /// Free slots right now (the consumer may free more concurrently).
    pub fn free(&self) -> usize {
        self.0.slots()
    }
}

impl<T: Send> Consumer<T> {
    /// Moves the oldest value out, if any.
    pub fn pop(&mut self) -> Option<T> {
        self.0.pop().ok()
    }

    /// Whether the ring is empty right now.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use std::sync::Arc;

    #[test]
    fn fifo_and_full() {
        let (mut p, mut c) = channel(3);
        assert_eq!(c.pop(), None::<u32>);
        for i in 0..3 {
            p.push(i).unwrap();
        }
        assert_eq!(p.push(9), Err(9));
        assert_eq!(p.free(), 0);
        assert_eq!(c.pop(), Some(0));
        p.push(3).unwrap();
        assert_eq!(
            (c.pop(), c.pop(), c.pop(), c.pop()),
            (Some(1), Some(2), Some(3), None)
        );
        assert!(c.is_empty());
        assert_eq!(p.free(), 3);
    }

    #[test]
    fn values_left_in_the_ring_are_dropped_once() {
        let probe = Arc::new(());
        {
            let (mut p, mut c) = channel(4);
            for _ in 0..3 {
                p.push(probe.clone()).unwrap();
            }
            drop(c.pop());
            assert_eq!(Arc::strong_count(&probe), 3);
            // Either end may go first: the values stay until both are gone.
            drop(p);
            assert_eq!(Arc::strong_count(&probe), 3);
        }
        assert_eq!(Arc::strong_count(&probe), 1);
    }

    #[test]
    fn a_value_refused_by_a_full_ring_is_given_back_not_dropped() {
        let probe = Arc::new(());
        let (mut p, _c) = channel(1);
        p.push(probe.clone()).unwrap();
        let back = p.push(probe.clone()).unwrap_err();
        assert_eq!(Arc::strong_count(&probe), 3);
        drop(back);
        assert_eq!(Arc::strong_count(&probe), 2);
    }

    /// Two threads, seeded random burst sizes: every value arrives once, in
    /// order, boxes included.
    #[test]
    fn threads_exchange_every_value_in_order() {
        const N: u64 = 200_000;
        let (mut p, mut c) = channel::<Box<u64>>(8);
        let producer = std::thread::spawn(move || {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
            let mut i = 0;
            while i < N {
                let burst = rng.random_range(1..16);
                for _ in 0..burst {
                    if i == N {
                        break;
                    }
                    match p.push(Box::new(i)) {
                        Ok(()) => i += 1,
                        Err(_) => std::thread::yield_now(),
                    }
                }
            }
        });
        let mut expect = 0;
        while expect < N {
            match c.pop() {
                Some(v) => {
                    assert_eq!(*v, expect);
                    expect += 1;
                }
                None => std::thread::yield_now(),
            }
        }
        producer.join().unwrap();
        assert_eq!(c.pop(), None);
    }
}
