//! `update` and `calculate` never allocate (counting global allocator).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use otg::{ControlInterface, Input, Otg, Output, Synchronization, Trajectory};

struct Counting;

// Per thread: the test harness's own threads must not count (a
// process-wide counter is flaky on a loaded machine).
thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

fn note() {
    let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: forwards to the system allocator; only counts calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn update_and_calculate_do_not_allocate() {
    // Everything is constructed before counting starts.
    let mut otg = Box::new(Otg::<7>::new(0.001).unwrap());
    let mut out = Box::new(Output::<7>::default());
    let mut traj = Box::new(Trajectory::<7>::default());
    let mut inp = Input::<7>::new([1.0; 7], [4.0; 7], [40.0; 7]);
    inp.target_position = [0.3, -0.2, 0.5, 0.0, 1.0, -1.0, 0.1];
    inp.target_velocity = [0.1, 0.0, -0.2, 0.0, 0.0, 0.3, 0.0];
    let mut stop = inp;
    stop.control_interface = ControlInterface::Velocity;
    stop.target_velocity = [0.0; 7];
    // Outside the limits: the brake pre-trajectory runs.
    stop.current_velocity = [2.0, -3.0, 0.5, 0.0, 1.5, -0.7, 0.2];
    stop.current_acceleration = [9.0, -1.0, 0.0, 5.0, -6.0, 0.0, 1.0];
    let mut phase = inp;
    phase.synchronization = Synchronization::Phase;
    phase.target_position = [0.2, 0.4, -0.2, 0.0, 0.6, 0.1, -0.4];
    phase.target_velocity = [0.0; 7];

    let before = ALLOCS.with(Cell::get);
    let mut cycles = 0;
    for (k, base) in [inp, stop, phase].iter().enumerate() {
        let mut i = *base;
        for step in 0..3000 {
            // Move the target now and then: recalculation mid-motion.
            if step % 500 == 250 {
                i.target_position[0] += 0.05 * (k as f64 + 1.0);
            }
            let _ = otg.update(&i, &mut out).expect("update");
            out.pass_to_input(&mut i);
            cycles += 1;
        }
        otg.calculate(base, &mut traj).expect("calculate");
        let _ = traj.at_time(0.5 * traj.duration);
    }
    let after = ALLOCS.with(Cell::get);
    assert_eq!(
        after - before,
        0,
        "{} allocations in {cycles} cycles",
        after - before
    );
}
