//! The per-tick API of the kinematics allocates nothing: path evaluation,
//! both integrators, the rate functions, and (though it runs off the
//! real-time thread) the single-finger planner. Proven with a counting
//! global allocator.

mod common;

use gait::HandConfig;
use gait::contact::{
    BodyRates, ChartIntegrator, ContactGeometry, ContactState, ContactTwist, VectorIntegrator,
    contact_rates,
};
use gait::rolling::{RollGoal, RollLimits, plan_roll};
use gait::sphere::best_chart;
use nalgebra::Vector3;

use test_support::counting;

#[global_allocator]
static GLOBAL: counting::Counting = counting::Counting;

#[test]
fn kinematics_hot_paths_do_not_allocate() {
    let cfg = HandConfig::default();
    let g = ContactGeometry::from_config(&cfg);
    let lim = RollLimits::from_config(&cfg, true);
    let mut rng = common::rng(900);
    // Inputs prepared before counting.
    let mut cases = Vec::new();
    for _ in 0..200 {
        let n = common::unit(&mut rng);
        let m = common::hemisphere_point(&mut rng);
        let rel = gait::contact::RelativeContact {
            contact: n,
            fingertip: common::touching(&mut rng, &n, &m),
            roll: 0.2,
        };
        cases.push((rel, common::unit(&mut rng), common::rotation(&mut rng)));
    }
    let (_, setup) = counting::count(|| Vec::<u8>::with_capacity(8));
    assert_eq!(
        setup.allocs, 1,
        "the counting allocator must see allocations"
    );
    let (checksum, heap) = counting::count(|| {
        let mut checksum = 0.0;
        for (rel, target, object) in &cases {
            let goal = RollGoal {
                target: *target,
                final_roll: Some(0.1),
            };
            let path = plan_roll(&g, rel, &goal, &lim).unwrap();
            for i in 0..=1000 {
                let e = path.eval(path.length() * i as f64 / 1000.0);
                checksum += e.roll + e.contact.x;
            }
            checksum += path.margins().min_hemisphere + path.max_angle_from(&Vector3::x());
            let s = ContactState::from_relative(rel, *object);
            let b = BodyRates {
                object: Vector3::new(0.1, 0.2, 0.3),
                fingertip: Vector3::new(-1.0, 0.5, 0.2),
                slip: Vector3::zeros(),
            };
            let mut vi = VectorIntegrator::new(g, s);
            let mut ci = ChartIntegrator::new(
                g,
                s.chart_contact(
                    best_chart(&s.fingertip_contact()),
                    best_chart(&s.object_contact()),
                ),
            );
            for k in 0..100 {
                vi.step(k as f64 * 1e-3, 1e-3, |_, _| b);
                vi.advance_constant(&b, 1e-3);
                ci.step(k as f64 * 1e-3, 1e-3, |_| ContactTwist {
                    linear: Vector3::zeros(),
                    angular: Vector3::new(1.0, -0.5, 0.1),
                });
                checksum += contact_rates(&g, &vi.state, &b).roll;
            }
            checksum += ci.state.psi + vi.state.roll;
        }
        checksum
    });
    assert!(checksum.is_finite());
    assert_eq!(heap.allocs, 0, "allocations on the hot path");
}
