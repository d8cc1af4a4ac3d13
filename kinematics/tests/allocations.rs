//! The per-tick calls allocate nothing (counting allocator, this thread only).

mod common;

use kinematics::{
    Carrier, ClosedFormIk, DlsParams, gravity_torques, joint_torques, max_force_scale,
    rolling_rates,
};
use nalgebra::Vector3;
use test_support::counting::{Counting, count};

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn per_tick_calls_do_not_allocate() {
    let h = common::hand();
    let chains = common::chains();
    let iks = chains.map(|c| ClosedFormIk::new(&c).unwrap());
    let g = h.gravity;
    let grasp = [Vector3::new(0.366, 0.890, -1.854); 3];
    let fingers = [&chains[0], &chains[1], &chains[2]];
    let mut carrier = Carrier::new(&fingers, &grasp, &h.object, &Vector3::z(), 0.02);
    let (_, heap) = count(|| {
        let mut acc = 0.0;
        for t in 0..1000 {
            let k = t % 3;
            let c = &chains[k];
            let q = Vector3::new(0.366, 0.890 + 1e-4 * t as f64, -1.854);
            let s = c.forward(&q);
            let sol = iks[k].solve(&s.tip_centre(), &q).unwrap();
            let d = c.ik_dls(&s.tip_centre(), &(q * 0.99), &DlsParams::default());
            let n = (s.tip_centre() - h.object.centre).normalize();
            let rr = rolling_rates(&s, &Vector3::z(), &n, h.object.radius, c.tip_radius).unwrap();
            let gt = gravity_torques(c, &s, &g);
            let tau = joint_torques(&s, &(-n), &gt);
            let scale = max_force_scale(&s, &(-n), &gt, &c.effort()).unwrap();
            let caps = c.capsules(&s);
            let gap = caps
                .as_slice()
                .iter()
                .map(|cap| cap.sphere_gap(&h.object.centre, h.object.radius))
                .fold(f64::INFINITY, f64::min);
            let carried = carrier.advance_to(1e-3 * t as f64).unwrap()[k][0];
            let rate = carrier.rates(1.0).unwrap()[k][0];
            acc += sol[0]
                + carried
                + rate
                + d.q[0]
                + rr.spin
                + tau[0]
                + scale
                + gap
                + c.patch.margin(&s.tip.rotation, &n)
                + c.limit_margin(&q);
        }
        acc
    });
    assert!(heap.is_zero(), "{heap:?}");
}
