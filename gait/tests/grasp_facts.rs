//! The closed forms of paper §3.1 against the exact conic test of SPEC §3.2,
//! over seeded random sweeps (no golden numbers).

mod common;

use core::f64::consts::PI;

use gait::HandConfig;
use gait::grasp::contact::grasp_columns;
use gait::grasp::facts::{
    fact1_region_contains, fact2_contains, fact2_regions, fact3_bound, fact3_force_closure,
    fact3_shortest_fix, fact3_slack, fact4_force_closure, fact4_slack, friction_region_contains,
};
use gait::grasp::planar::three_hard_certificate;
use gait::grasp::{ClosureMargin, ConicSolver, Contact, ContactKind, Friction, GraspError};
use nalgebra::Vector6;
use rand::Rng;

fn friction(theta_deg: f64, ratio: f64) -> Friction {
    let mut c = HandConfig::default();
    c.model.friction_angle_deg = theta_deg;
    c.model.torsion_ratio = ratio;
    Friction::from_config(&c)
}

/// The solver's internal force really is one: G f = 0, Σ f_n = 1, every
/// cone holds with margin t*.
fn check_certificate(solver: &ConicSolver, contacts: &[Contact], m: &ClosureMargin) {
    let x = solver.last_solution().unwrap();
    let fr = solver.friction();
    let t = m.t_star.unwrap();
    let mut wrench = Vector6::zeros();
    let mut sum_n = 0.0;
    let mut off = 0;
    for c in contacts {
        let cols = grasp_columns(c, &fr);
        let d = c.kind.dim();
        for j in 0..d {
            wrench += cols[j] * x[off + j];
        }
        sum_n += x[off];
        let tang: f64 = (1..d).map(|j| x[off + j] * x[off + j]).sum::<f64>().sqrt();
        assert!(
            tang <= fr.mu * x[off] - t + 1e-6,
            "cone violated: {tang} vs {}",
            fr.mu * x[off] - t
        );
        off += d;
    }
    assert!(wrench.norm() < 1e-6, "not internal: {}", wrench.norm());
    assert!((sum_n - 1.0).abs() < 1e-6);
}

#[test]
fn fact3_iff_conic_on_random_soft_pairs() {
    let mut rng = common::rng(3);
    let mut solver = ConicSolver::new(friction(20.0, 0.1));
    let (mut checked, mut fc, mut skipped, mut max_iter) = (0usize, 0usize, 0usize, 0u32);
    while checked < 12_000 {
        let theta_deg = if checked.is_multiple_of(2) {
            20.0
        } else {
            rng.random_range(8.0..40.0)
        };
        let fr = friction(theta_deg, rng.random_range(0.02..1.0));
        let theta = theta_deg.to_radians();
        solver.set_friction(fr);
        let a = common::unit(&mut rng);
        // Half uniform pairs, half concentrated around the boundary.
        let b = if checked % 4 < 2 {
            common::unit(&mut rng)
        } else {
            let alpha = fact3_bound(theta, 0.0) + rng.random_range(-0.5..0.5);
            common::at_angle(&mut rng, &a, alpha.clamp(0.0, PI))
        };
        if fact3_slack(&a, &b, theta, 0.0).abs() < 0.25f64.to_radians() {
            skipped += 1;
            continue;
        }
        let contacts = [Contact::soft(a), Contact::soft(b)];
        let m = solver.margin(&contacts).unwrap();
        if m.t_star.is_some() {
            check_certificate(&solver, &contacts, &m);
        }
        let closed = fact3_force_closure(&a, &b, theta, 0.0);
        assert_eq!(
            closed,
            m.is_force_closure(),
            "θ={theta_deg} angle={} {m:?}",
            common::angle(&a, &b).to_degrees()
        );
        fc += usize::from(closed);
        max_iter = max_iter.max(m.iterations);
        checked += 1;
    }
    println!(
        "Fact 3 ⇔ conic: {checked} pairs ({fc} force-closure), {skipped} skipped near the boundary, max {max_iter} iterations"
    );
}

#[test]
fn two_hard_contacts_are_never_force_closure() {
    let mut rng = common::rng(4);
    let mut solver = ConicSolver::new(friction(20.0, 0.1));
    for _ in 0..500 {
        let a = common::unit(&mut rng);
        let c = [Contact::hard(a), Contact::hard(common::unit(&mut rng))];
        let m = solver.margin(&c).unwrap();
        assert!(m.rank < 6 && !m.is_force_closure());
    }
}

/// Triples uniform on the sphere, and triples near a random great circle
/// (where Fact 4 has a chance).
fn random_triple(rng: &mut rand_chacha::ChaCha8Rng, i: usize) -> [nalgebra::Vector3<f64>; 3] {
    if i.is_multiple_of(2) {
        [common::unit(rng), common::unit(rng), common::unit(rng)]
    } else {
        let axis = common::unit(rng);
        let tilt = rng.random_range(0.0..0.6);
        [0; 3].map(|_| {
            let p = common::perpendicular(rng, &axis);
            let off = rng.random_range(-tilt..tilt);
            common::at_angle(rng, &p, off)
        })
    }
}

#[test]
fn fact4_implies_conic_on_random_hard_triples() {
    let mut rng = common::rng(5);
    let mut solver = ConicSolver::new(friction(20.0, 0.1));
    // Per sample family: [uniform triples at θ = 20°, near-great-circle
    // triples at θ ∈ [8°, 40°]].
    let (mut fact4, mut conic_fc, mut missed) = ([0usize; 2], [0usize; 2], [0usize; 2]);
    let mut max_iter = 0u32;
    let n = 12_000usize;
    for i in 0..n {
        let theta_deg = if i.is_multiple_of(2) {
            20.0
        } else {
            rng.random_range(8.0..40.0)
        };
        let theta = f64::to_radians(theta_deg);
        solver.set_friction(friction(theta_deg, 0.1));
        let p = random_triple(&mut rng, i);
        let contacts = p.map(Contact::hard);
        let m = solver.margin(&contacts).unwrap();
        assert_eq!(m.rank, 6);
        check_certificate(&solver, &contacts, &m);
        let closed = fact4_force_closure(&p[0], &p[1], &p[2], theta);
        let fam = i % 2;
        if closed {
            fact4[fam] += 1;
            assert!(
                m.is_force_closure(),
                "Fact 4 false positive: slack {} {m:?}",
                fact4_slack(&p[0], &p[1], &p[2], theta)
            );
        }
        if m.is_force_closure() {
            conic_fc[fam] += 1;
            missed[fam] += usize::from(!closed);
        }
        max_iter = max_iter.max(m.iterations);
    }
    for (fam, name) in [
        "uniform triples, θ = 20°",
        "near-great-circle triples, θ ∈ [8°, 40°]",
    ]
    .iter()
    .enumerate()
    {
        println!(
            "Fact 4 ⇒ conic ({name}): {} triples, {} force-closure, Fact 4 found {} (no false \
             positive), missed {} = {:.1} % of the force-closure triples",
            n / 2,
            conic_fc[fam],
            fact4[fam],
            missed[fam],
            100.0 * missed[fam] as f64 / conic_fc[fam] as f64
        );
    }
    println!("Fact 4 sweep: max {max_iter} conic iterations");
}

#[test]
fn fact1_is_the_direct_region() {
    let mut rng = common::rng(6);
    let mut n = 0;
    while n < 10_000 {
        let theta = rng.random_range(5f64..40.0).to_radians();
        let p = common::unit(&mut rng);
        let q = common::unit(&mut rng);
        // Away from the boundary: angle(q, −p) ≠ 2θ.
        if (common::angle(&q, &(-p)) - 2.0 * theta).abs() < 1e-6 {
            continue;
        }
        assert_eq!(
            friction_region_contains(&p, &q, theta),
            fact1_region_contains(&p, &q, theta)
        );
        n += 1;
    }
}

#[test]
fn fact2_caps_are_independent_and_maximal() {
    let mut rng = common::rng(7);
    for _ in 0..10_000 {
        let theta = rng.random_range(5f64..40.0).to_radians();
        let axis = common::unit(&mut rng);
        let [a, b] = fact2_regions(&axis, theta);
        let (d1, d2) = (rng.random_range(0.0..theta), rng.random_range(0.0..theta));
        let p1 = common::at_angle(&mut rng, &a.centre, d1);
        let p2 = common::at_angle(&mut rng, &b.centre, d2);
        assert!(fact2_contains(&axis, theta, &p1, &p2));
        // Independent: every such pair satisfies Fact 3 (boundary included).
        assert!(fact3_slack(&p1, &p2, theta, 0.0) >= -1e-12);
        // Maximal: a point just outside one cap has a partner in the other
        // cap that is not force-closure with it.
        let eps = 1e-3;
        let q = common::at_angle(&mut rng, &a.centre, theta + eps);
        // b.centre turned by θ towards q: on the rim of cap b.
        let axis2 = nalgebra::Unit::new_normalize(b.centre.cross(&q));
        let worst = nalgebra::Rotation3::from_axis_angle(&axis2, theta) * b.centre;
        assert!(common::angle(&worst, &b.centre) <= theta + 1e-12);
        assert!(
            !fact3_force_closure(&q, &worst, theta, 0.0),
            "{}",
            fact3_slack(&q, &worst, theta, 0.0)
        );
    }
}

#[test]
fn shortest_fix_reaches_fact3_and_moves_least() {
    let mut rng = common::rng(8);
    let theta = 20f64.to_radians();
    let margin = 2f64.to_radians();
    for _ in 0..10_000 {
        let a = common::unit(&mut rng);
        let b = common::unit(&mut rng);
        let [a2, b2] = fact3_shortest_fix(&a, &b, theta, margin);
        let s = fact3_slack(&a, &b, theta, margin);
        assert!(fact3_slack(&a2, &b2, theta, margin) >= -1e-9);
        let moved = common::angle(&a, &a2) + common::angle(&b, &b2);
        // Separation grows by at most the moved angle, so −s is the least
        // total motion; the fix achieves it exactly.
        assert!((moved - (-s).max(0.0)).abs() < 1e-9, "{moved} vs {s}");
    }
}

#[test]
fn margin_is_deterministic_across_histories() {
    let mut rng = common::rng(9);
    let fr = friction(20.0, 0.1);
    let target = [
        common::unit(&mut rng),
        common::unit(&mut rng),
        common::unit(&mut rng),
    ]
    .map(Contact::hard);
    let fresh = ConicSolver::new(fr).margin(&target).unwrap();
    let mut used = ConicSolver::new(fr);
    for _ in 0..50 {
        let c = [
            common::unit(&mut rng),
            common::unit(&mut rng),
            common::unit(&mut rng),
        ]
        .map(Contact::hard);
        used.margin(&c).unwrap();
        used.margin(&[Contact::soft(c[0].normal), Contact::soft(c[1].normal)])
            .unwrap();
    }
    let again = used.margin(&target).unwrap();
    assert_eq!(
        fresh.t_star.map(f64::to_bits),
        again.t_star.map(f64::to_bits)
    );
}

#[test]
fn bad_input_is_rejected_not_panicking() {
    let mut s = ConicSolver::new(friction(20.0, 0.1));
    assert_eq!(s.margin(&[]), Err(GraspError::NoContacts));
    let nan = nalgebra::Vector3::new(f64::NAN, 0.0, 1.0);
    assert_eq!(
        s.margin(&[Contact::hard(nan); 3]),
        Err(GraspError::BadInput)
    );
    let zero = nalgebra::Vector3::zeros();
    assert_eq!(
        s.margin(&[Contact::hard(zero); 3]),
        Err(GraspError::BadInput)
    );
    assert_eq!(ContactKind::Soft.dim(), 4);
}

#[test]
fn planar_certificate_agrees_with_conic_on_random_hard_triples() {
    let mut rng = common::rng(10);
    let mut solver = ConicSolver::new(friction(20.0, 0.1));
    let mut neither = 0usize;
    let (mut certified, mut conic_fc, mut missed, mut worst_missed) =
        (0usize, 0usize, 0usize, 0.0f64);
    let n = 12_000usize;
    for i in 0..n {
        let theta_deg = if i.is_multiple_of(2) {
            20.0
        } else {
            rng.random_range(8.0..40.0)
        };
        let theta = f64::to_radians(theta_deg);
        solver.set_friction(friction(theta_deg, 0.1));
        let p = random_triple(&mut rng, i);
        let m = solver.margin(&p.map(Contact::hard)).unwrap();
        let cert = three_hard_certificate(&p, theta);
        if let Some(margin) = cert {
            certified += 1;
            assert!(margin > 0.0 && margin <= theta);
            assert!(
                m.is_force_closure(),
                "certificate false positive: {margin} {m:?}"
            );
        }
        if m.is_force_closure() {
            conic_fc += 1;
            let pair = [(0, 1), (0, 2), (1, 2)]
                .iter()
                .any(|&(a, b)| fact3_force_closure(&p[a], &p[b], theta, 0.0));
            if !pair && !fact4_force_closure(&p[0], &p[1], &p[2], theta) {
                neither += 1;
            }
            if cert.is_none() {
                missed += 1;
                worst_missed = worst_missed.max(m.t_star.unwrap());
            }
        }
    }
    println!(
        "planar certificate vs conic: {n} triples, {conic_fc} force-closure, {certified} certified, \
         {missed} missed (largest t* missed {worst_missed:.2e}); \
         force-closure triples with neither Fact 4 nor a Fact 3 pair: {neither}"
    );
    // Misses only within solver precision of the boundary.
    assert!(
        worst_missed < 1e-6,
        "missed a force-closure triple with t* = {worst_missed}"
    );
}
