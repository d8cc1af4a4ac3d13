//! Pre-allocated lock-free single-producer single-consumer ring (SPEC §7.2).
//!
//! The real-time loop exchanges objects with other threads through these
//! rings: `push` and `pop` are wait-free, never allocate, never block and
//! never free memory. Values are moved in and out; in particular a `Box`
//! moves through without touching the allocator, which is how plans reach
//! the loop and old plans leave it to be dropped elsewhere.
//!
//! Memory ordering: the producer writes a slot, then publishes it with a
//! Release store of `tail`; the consumer reads `tail` with Acquire before
//! reading the slot, and gives the slot back with a Release store of `head`
//! that the producer reads with Acquire before reusing it.

use std::cell::UnsafeCell;
use std::mem::MaybeUninit;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// An atomic on its own cache line, so producer and consumer indices do not
/// false-share.
#[repr(align(64))]
struct Padded(AtomicUsize);

struct Ring<T> {
    slots: Box<[UnsafeCell<MaybeUninit<T>>]>,
    /// Count of values popped (owned by the consumer).
    head: Padded,
    /// Count of values pushed (owned by the producer).
    tail: Padded,
}

// SAFETY: a slot is accessed by one side at a time, handed over through the
// acquire/release protocol above; T itself must be Send to cross threads.
unsafe impl<T: Send> Sync for Ring<T> {}
unsafe impl<T: Send> Send for Ring<T> {}

impl<T> Drop for Ring<T> {
    fn drop(&mut self) {
        let head = self.head.0.load(Ordering::Relaxed);
        let tail = self.tail.0.load(Ordering::Relaxed);
        let cap = self.slots.len();
        for i in head..tail {
            // SAFETY: slots in [head, tail) hold initialised values; we own
            // the ring exclusively in drop.
            unsafe { (*self.slots[i % cap].get()).assume_init_drop() };
        }
    }
}

/// The sending end.
pub struct Producer<T> {
    ring: Arc<Ring<T>>,
}

/// The receiving end.
pub struct Consumer<T> {
    ring: Arc<Ring<T>>,
}

impl<T> std::fmt::Debug for Producer<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Producer")
            .field("capacity", &self.ring.slots.len())
            .finish()
    }
}

impl<T> std::fmt::Debug for Consumer<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Consumer")
            .field("capacity", &self.ring.slots.len())
            .finish()
    }
}

/// A ring holding at most `capacity` values (allocated here, once).
pub fn channel<T: Send>(capacity: usize) -> (Producer<T>, Consumer<T>) {
    assert!(capacity > 0, "capacity must be positive");
    let slots = (0..capacity)
        .map(|_| UnsafeCell::new(MaybeUninit::uninit()))
        .collect();
    let ring = Arc::new(Ring {
        slots,
        head: Padded(AtomicUsize::new(0)),
        tail: Padded(AtomicUsize::new(0)),
    });
    (Producer { ring: ring.clone() }, Consumer { ring })
}

impl<T: Send> Producer<T> {
    /// Moves `value` into the ring; gives it back if the ring is full.
    pub fn push(&mut self, value: T) -> Result<(), T> {
        let r = &*self.ring;
        let tail = r.tail.0.load(Ordering::Relaxed);
        let head = r.head.0.load(Ordering::Acquire);
        if tail.wrapping_sub(head) == r.slots.len() {
            return Err(value);
        }
        // SAFETY: the slot at tail is free (the consumer released it).
        unsafe { (*r.slots[tail % r.slots.len()].get()).write(value) };
        r.tail.0.store(tail.wrapping_add(1), Ordering::Release);
        Ok(())
    }

    /// Free slots right now (the consumer may free more concurrently).
    pub fn free(&self) -> usize {
        let r = &*self.ring;
        r.slots.len()
            - r.tail
                .0
                .load(Ordering::Relaxed)
                .wrapping_sub(r.head.0.load(Ordering::Acquire))
    }
}

impl<T: Send> Consumer<T> {
    /// Moves the oldest value out, if any.
    pub fn pop(&mut self) -> Option<T> {
        let r = &*self.ring;
        let head = r.head.0.load(Ordering::Relaxed);
        let tail = r.tail.0.load(Ordering::Acquire);
        if head == tail {
            return None;
        }
        // SAFETY: the slot at head was initialised by the producer (published by tail).
        let v = unsafe { (*r.slots[head % r.slots.len()].get()).assume_init_read() };
        r.head.0.store(head.wrapping_add(1), Ordering::Release);
        Some(v)
    }

    /// Whether the ring is empty right now.
    pub fn is_empty(&self) -> bool {
        let r = &*self.ring;
        r.head.0.load(Ordering::Relaxed) == r.tail.0.load(Ordering::Acquire)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

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
        }
        assert_eq!(Arc::strong_count(&probe), 1);
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
