//! The parts-travel bound (`kinematics::parts_travel`) against the travel
//! itself: material points on every part's surface (capsule ends pushed
//! out by the radius in random directions, the tip sphere's surface),
//! followed by forward kinematics along a joint path between two random
//! configurations up to 0.1 rad apart, 10⁴ pairs over the three fingers.
//! And what the bound is for: a capsule's distance to a ball never drops
//! below (d_a + d_b − D)/2 between the path's ends.

mod common;

use kinematics::{Chain, ChainState, Frame, Object, parts_travel};
use nalgebra::Vector3;
use rand::Rng;

/// Surface points of every part in the part's own frame: (segment, point);
/// segment 0 is the base, N + 1 the tip frame.
fn material_points(
    chain: &Chain<3>,
    rng: &mut rand_chacha::ChaCha8Rng,
) -> Vec<(usize, Vector3<f64>)> {
    let mut out = Vec::new();
    for lc in chain.link_capsules() {
        for end in [lc.capsule.a, lc.capsule.b] {
            for _ in 0..4 {
                out.push((lc.segment, end + common::unit(rng) * lc.capsule.radius));
            }
        }
    }
    for _ in 0..8 {
        out.push((4, common::unit(rng) * chain.tip_radius));
    }
    out
}

fn frame_of<'a>(chain: &'a Chain<3>, s: &'a ChainState<3>, segment: usize) -> &'a Frame {
    match segment {
        0 => &chain.base,
        4 => &s.tip,
        j => &s.joints[j - 1],
    }
}

#[test]
fn no_surface_point_travels_further_than_the_bound() {
    let chains = common::chains();
    let mut rng = common::rng(0x5eed_5eed);
    let mut tightest = f64::INFINITY;
    for trial in 0..10_000 {
        let chain = &chains[trial % 3];
        let qa = common::random_q(chain, &mut rng);
        let dq = Vector3::from_fn(|_, _| rng.random_range(-0.1..=0.1));
        let qb = qa + dq;
        let (sa, sb) = (chain.forward(&qa), chain.forward(&qb));
        let points = material_points(chain, &mut rng);
        // Every configuration on the joint path from qa: its travel from
        // qa is bounded by the bound from qa to it (a sub-path).
        for t in [0.25, 0.5, 0.75, 1.0] {
            let q = qa + dq * t;
            let s = chain.forward(&q);
            let bound = parts_travel(chain, (&qa, &sa), (&q, &s));
            for (seg, p) in &points {
                let travel = (frame_of(chain, &s, *seg).point(p)
                    - frame_of(chain, &sa, *seg).point(p))
                .norm();
                assert!(
                    travel <= bound + 1e-12,
                    "finger {} from {qa:?} by {dq:?} (t = {t}): a point of part {seg} \
                     travels {travel} m, bound {bound} m",
                    trial % 3
                );
                tightest = tightest.min(bound - travel);
            }
        }
        let _ = sb;
    }
    // The bound is not vacuous: somewhere it is nearly met.
    assert!(
        tightest < 1e-3,
        "the bound is never within 1 mm of the travel: {tightest}"
    );
}

#[test]
fn a_capsule_stays_clear_by_half_the_ends_sum_less_the_travel() {
    let chains = common::chains();
    let mut rng = common::rng(0xc1ea_0001);
    let ball = Object {
        centre: Vector3::new(0.0, 0.0, 0.1),
        radius: 0.035,
        mass: 0.06,
    };
    for trial in 0..3_000 {
        let chain = &chains[trial % 3];
        let qa = common::random_q(chain, &mut rng);
        let qb = qa + Vector3::from_fn(|_, _| rng.random_range(-0.05..=0.05));
        let (sa, sb) = (chain.forward(&qa), chain.forward(&qb));
        let clear = |s: &ChainState<3>| kinematics::workspace::object_clearance(chain, s, &ball);
        let floor = (clear(&sa) + clear(&sb) - parts_travel(chain, (&qa, &sa), (&qb, &sb))) / 2.0;
        for i in 1..50 {
            let q = qa + (qb - qa) * (i as f64 / 50.0);
            let d = clear(&chain.forward(&q));
            assert!(d >= floor - 1e-12, "clearance {d} below the floor {floor}");
        }
    }
}
