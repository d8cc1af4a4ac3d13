//! The hand-off rings move values, boxes included, between threads without
//! touching the allocator on either side: no allocation and no free in
//! `push`, `pop`, `free` or `is_empty` (per-thread counting allocator), and
//! each value arrives once, in order.

use gaitd::sys::handoff;
use test_support::counting::{self, Counting, Tally};

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn boxes_cross_without_allocation_or_free() {
    const N: u64 = 100_000;
    assert!(counting::is_installed());
    let (mut tx, mut rx) = handoff::channel::<Box<u64>>(16);
    let producer = std::thread::spawn(move || {
        // Boxes are made before counting, as plans are on the planner thread.
        let mut boxes: Vec<Box<u64>> = (0..N).rev().map(Box::new).collect();
        let heap = Tally::default();
        while let Some(b) = boxes.pop() {
            let mut b = Some(b);
            while let Some(v) = b.take() {
                if let Err(v) = heap.count(|| {
                    let _ = tx.free();
                    tx.push(v)
                }) {
                    b = Some(v);
                    std::thread::yield_now();
                }
            }
        }
        heap.total()
    });
    let heap = Tally::default();
    // Preallocated: the received boxes are kept, to be freed after counting.
    let mut received = Vec::with_capacity(N as usize);
    while received.len() < N as usize {
        match heap.count(|| {
            let _ = rx.is_empty();
            rx.pop()
        }) {
            Some(b) => received.push(b),
            None => std::thread::yield_now(),
        }
    }
    let sent = producer.join().unwrap();
    assert!(sent.is_zero(), "push allocated or freed: {sent}");
    assert!(
        heap.total().is_zero(),
        "pop allocated or freed: {}",
        heap.total()
    );
    assert!(received.iter().zip(0..).all(|(b, i)| **b == i), "in order");
}
