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

#[test]
fn the_exact_tier_accepts_more_pairs_and_only_pairs_that_hold() {
    let cfg = HandConfig::default();
    let quick = PairLoad::new(&cfg);
    let exact = quick.with_exact(&cfg);
    let check = LoadCheck::new(&cfg);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (mut n_quick, mut n_exact, mut tried) = (0, 0, 0);
    while tried < 400 {
        let n1 = unit(&mut rng);
        let n2 = unit(&mut rng);
        // Pairs the planner could make: 140°–180° apart (force closure
        // needs more than 180° − 2·20°).
        if n1.dot(&n2) > (140f64).to_radians().cos() {
            continue;
        }
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
