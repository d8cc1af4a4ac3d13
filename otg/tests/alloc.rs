//! `update` and `calculate` never allocate (counting global allocator).

use otg::{ControlInterface, Input, Otg, Output, Synchronization, Trajectory};
use test_support::counting;

#[global_allocator]
static GLOBAL: counting::Counting = counting::Counting;

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

    assert!(counting::is_installed());
    let mut cycles = 0;
    let (_, heap) = counting::count(|| {
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
    });
    assert!(heap.is_zero(), "{heap} in {cycles} cycles");
}
