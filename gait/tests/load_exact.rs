//! The planner's exact load tier (`PairLoad::with_exact`), checked
//! independently: it accepts every pair the sufficient test accepts, more
//! pairs besides, and only pairs that the test's own SOCP (`planning::load`,
//! Clarabel, 26 disturbance directions) finds held within `load.max_grip`
//! (SPEC §1.3 I1'). A tier that accepted a pair the physics cannot hold
//! would plan drops.

mod planning;

use gait::HandConfig;
use gait::planner::load::PairLoad;
use planning::load::{Kind, LoadCheck};
use planning::unit;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Two random unit normals of a pair the planner could make: 140°–180°
/// apart (force closure needs more than 180° − 2·20°).
fn wide_pair(rng: &mut ChaCha8Rng) -> (nalgebra::Vector3<f64>, nalgebra::Vector3<f64>) {
    loop {
        let n1 = unit(rng);
        let n2 = unit(rng);
        if n1.dot(&n2) <= (140f64).to_radians().cos() {
            return (n1, n2);
        }
    }
}

#[test]
fn the_exact_tier_accepts_more_pairs_and_only_pairs_that_hold() {
    let cfg = HandConfig::default();
    let quick = PairLoad::new(&cfg);
    let exact = quick.with_exact(&cfg);
    let check = LoadCheck::new(&cfg);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (mut n_quick, mut n_exact, mut tried) = (0, 0, 0);
    while tried < 400 {
        let (n1, n2) = wide_pair(&mut rng);
        tried += 1;
        let axis = (tried % 2 == 0).then(|| unit(&mut rng));
        let q = quick.holds(&n1, &n2, axis.as_ref());
        let e = exact.holds(&n1, &n2, axis.as_ref());
        assert!(
            !q || e,
            "the exact tier refused a pair the sufficient test holds"
        );
        n_quick += q as usize;
        n_exact += e as usize;
        if e {
            let (ok, f) = check.holds(&[n1, n2], Kind::Soft, axis.as_ref());
            assert!(
                ok,
                "accepted a pair the independent SOCP does not hold: F* {f:.3} N \
                 > {} N ({n1:?}, {n2:?}, axis {axis:?})",
                cfg.load.max_grip
            );
        }
    }
    println!("of {tried} pairs 140–180° apart: sufficient test {n_quick}, exact tier {n_exact}");
    assert!(
        n_exact > n_quick,
        "the exact tier accepts no pair the sufficient test refuses"
    );
}

/// A pair turned as far as `PairLoad::exit` allows holds the load at every
/// sample of the turn, by the same test at the turned contacts — the test
/// the plan's check applies (its disturbance directions are fixed in the
/// hand frame, not in the pair's). With gravity and without it (the
/// disturbance alone), exact tier on.
#[test]
fn a_pair_holds_at_every_sample_of_the_turn_its_exit_allows() {
    let limit = std::f64::consts::FRAC_PI_2;
    for gravity in [true, false] {
        let mut cfg = HandConfig::default();
        if !gravity {
            cfg.load.gravity = [0.0; 3];
        }
        let exact = PairLoad::new(&cfg).with_exact(&cfg);
        let mut rng = ChaCha8Rng::seed_from_u64(29);
        let (mut tried, mut turned, mut samples) = (0, 0, 0);
        while tried < 300 {
            let (n1, n2) = wide_pair(&mut rng);
            tried += 1;
            let axis = unit(&mut rng);
            let exit = exact.exit(&n1, &n2, &axis, limit);
            if exit <= 0.0 {
                continue;
            }
            turned += 1;
            // The check's density: every 3°, and the end.
            let n = (exit / 3f64.to_radians()).ceil() as usize;
            for k in 0..=n {
                let t = exit * k as f64 / n.max(1) as f64;
                let q = nalgebra::UnitQuaternion::from_axis_angle(
                    &nalgebra::Unit::new_normalize(axis),
                    t,
                );
                samples += 1;
                assert!(
                    exact.holds(&(q * n1), &(q * n2), Some(&axis)),
                    "gravity {gravity}: the pair's exit is {:.2}° but it does not hold at \
                     {:.2}° ({n1:?}, {n2:?}, axis {axis:?})",
                    exit.to_degrees(),
                    t.to_degrees()
                );
            }
        }
        println!("gravity {gravity}: {tried} pairs, {turned} turn at all, {samples} samples held");
        assert!(
            turned >= 30,
            "too few pairs turn to test anything: {turned}"
        );
    }
}
