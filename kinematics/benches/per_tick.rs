//! Per-finger, per-tick kinematics of TriFingerPro: forward kinematics,
//! Jacobians, closed-form IK and the rolling law, timed call by call
//! beside a reference measured in the same run (a loop of 3×3 matrix
//! products), so that the numbers say how fast this machine is.
//!
//! `cargo bench -p kinematics --bench per_tick` prints p50 / p99 / max [ns]
//! per finger per tick. Target: p99 ≤ 2 µs. Then the same for a grasp of
//! three fingers carried by the ball's turn ([`kinematics::Carrier`]: one
//! RK4 sub-step of the rolling law per tick, 1 rad/s at 1 kHz).

use std::hint::black_box;
use std::time::Instant;

use kinematics::{Carrier, Chain, ClosedFormIk, HandDescription, rolling_rates};
use nalgebra::{Matrix3, Vector3};

const URDF: &str = include_str!("../../deploy/hands/trifingerpro/trifingerpro.urdf");
const SECTION: &str = include_str!("../../deploy/hands/trifingerpro/hand.toml");
const TICKS: usize = 200_000;

fn percentiles(mut ns: Vec<u64>) -> (u64, u64, u64) {
    ns.sort_unstable();
    let at = |p: f64| ns[((ns.len() - 1) as f64 * p) as usize];
    (at(0.5), at(0.99), *ns.last().unwrap())
}

fn main() {
    let h = HandDescription::parse(URDF, SECTION).expect("description");
    let chains: Vec<Chain<3>> = h
        .fingers
        .iter()
        .map(|f| Chain::from_description(f, h.joint_limit_margin).unwrap())
        .collect();
    let iks: Vec<ClosedFormIk> = chains
        .iter()
        .map(|c| ClosedFormIk::new(c).unwrap())
        .collect();
    let (o, big_r) = (h.object.centre, h.object.radius);
    let omega = Vector3::new(0.3, -0.2, 0.5);
    // The feasible grasp of deploy/hands/trifingerpro/README.md, moved a little each tick.
    let q0 = Vector3::new(0.366, 0.890, -1.854);
    let mut q = [q0; 3];
    let tick = |k: usize, t: usize, q: &mut Vector3<f64>| {
        let c = &chains[k];
        let wobble = Vector3::new(
            0.05 * (t as f64 * 1e-3).sin(),
            0.05 * (t as f64 * 7e-4).cos(),
            0.0,
        );
        let s = c.forward(&(q0 + wobble));
        let target = s.tip_centre();
        let sol = iks[k].solve(&target, q).unwrap_or(*q);
        let s = c.forward(&sol);
        let n = (s.tip_centre() - o).normalize();
        let rr = rolling_rates(&s, &omega, &n, big_r, c.tip_radius);
        *q = sol;
        black_box((s.jacobian_v(), s.jacobian_w(), rr));
    };
    let reference = |m: &mut Matrix3<f64>| {
        for _ in 0..16 {
            *m = black_box(*m) * Matrix3::new(0.9, 0.1, 0.0, -0.1, 0.9, 0.05, 0.0, -0.05, 0.9);
        }
    };
    // Warm-up.
    for t in 0..10_000 {
        tick(t % 3, t, &mut q[t % 3]);
    }
    let (mut ours, mut refs) = (Vec::with_capacity(TICKS), Vec::with_capacity(TICKS));
    let mut m = Matrix3::identity();
    for t in 0..TICKS {
        let k = t % 3;
        let t0 = Instant::now();
        tick(k, t, &mut q[k]);
        ours.push(t0.elapsed().as_nanos() as u64);
        let t0 = Instant::now();
        reference(&mut m);
        refs.push(t0.elapsed().as_nanos() as u64);
    }
    let (p50, p99, max) = percentiles(ours);
    let (r50, r99, rmax) = percentiles(refs);
    println!(
        "per finger per tick (FK + J_v + J_omega + closed-form IK + FK + rolling law), {TICKS} ticks:"
    );
    println!(
        "  ours       p50 {p50:>6} ns  p99 {p99:>6} ns  max {rmax_o:>8} ns",
        rmax_o = max
    );
    println!(
        "  reference  p50 {r50:>6} ns  p99 {r99:>6} ns  max {rmax:>8} ns  (16 products of 3x3 matrices)"
    );
    println!(
        "  target p99 <= 2000 ns: {}",
        if p99 <= 2000 { "met" } else { "missed" }
    );

    // Three fingers carried by a turn of the ball about the vertical from
    // that grasp (30° from the top): one advance per tick.
    let grasp = [q0; 3];
    let fingers = [&chains[0], &chains[1], &chains[2]];
    let axis = Vector3::z();
    let mut carrier = Carrier::new(&fingers, &grasp, &h.object, &axis, 0.02);
    let (mut ours, mut refs) = (Vec::with_capacity(TICKS), Vec::with_capacity(TICKS));
    for t in 1..=TICKS {
        // 1 rad/s there and back, so the joints stay in their range.
        let angle = 0.3 * (t as f64 * 1e-3 / 0.3).sin();
        let t0 = Instant::now();
        let q = carrier.advance_to(angle).expect("the grasp stays regular")[0];
        let rates = carrier.rates(1.0).expect("the grasp stays regular");
        black_box((q, rates));
        ours.push(t0.elapsed().as_nanos() as u64 / 3);
        let t0 = Instant::now();
        reference(&mut m);
        refs.push(t0.elapsed().as_nanos() as u64);
    }
    let (p50, p99, max) = percentiles(ours);
    let (r50, r99, rmax) = percentiles(refs);
    println!(
        "per finger per tick of a carried grasp (Carrier: RK4 sub-step of the rolling law + joint rates, three fingers / 3), {TICKS} ticks:"
    );
    println!("  ours       p50 {p50:>6} ns  p99 {p99:>6} ns  max {max:>8} ns");
    println!("  reference  p50 {r50:>6} ns  p99 {r99:>6} ns  max {rmax:>8} ns");
}
