//! The workspace of a TriFingerPro finger (SPEC §14.1): every normal it
//! admits is reached within the margins, and no admissible configuration
//! that an independent search (damped least squares from many starts)
//! finds is missing from it.

mod common;

use kinematics::{
    Chain, ClosedFormIk, DlsParams, Margins, Object, Workspace, finger_gap, reach, sphere_grid,
    workspace::object_clearance,
};
use nalgebra::{Rotation3, Vector3};

/// 5° inside the tip patch, 5 mm between links and ball: margins a planner
/// would keep (the test's own choice, not the code's).
const MARGINS: Margins = Margins {
    patch: 5.0 * std::f64::consts::PI / 180.0,
    clearance: 0.005,
};

fn setup() -> ([Chain<3>; 3], [ClosedFormIk; 3], Object, Vector3<f64>) {
    let h = common::hand();
    let chains = common::chains();
    let iks = chains.map(|c| ClosedFormIk::new(&c).expect("TriFingerPro is closed form"));
    (chains, iks, h.object, h.gravity)
}

#[test]
fn every_normal_admitted_is_reached_within_the_margins() {
    let (chains, iks, object, gravity) = setup();
    let grid = sphere_grid(3000);
    for k in 0..3 {
        let w = Workspace::new(&chains[k], &iks[k], &object, &gravity, &grid, &MARGINS);
        println!("finger {k}: {:.1} % of the sphere", 100.0 * w.share());
        assert!(
            w.share() > 0.05 && w.share() < 0.95,
            "finger {k}: share {}",
            w.share()
        );
        let c = &chains[k];
        for (n, r) in &w.reached {
            let s = c.forward(&r.q);
            let want = object.centre + n * (object.radius + c.tip_radius);
            assert!((s.tip_centre() - want).norm() < 1e-9, "finger {k} n {n:?}");
            assert!(c.limit_margin(&r.q) >= 0.0, "finger {k}: joint limit");
            for i in 0..3 {
                assert!(r.q[i] >= c.limits[i].lower && r.q[i] <= c.limits[i].upper);
            }
            assert!(
                c.patch.margin(&s.tip.rotation, n) >= MARGINS.patch,
                "finger {k}: tip patch"
            );
            assert!(
                object_clearance(c, &s, &object) >= MARGINS.clearance,
                "finger {k}: a link within 5 mm of the ball"
            );
            assert!(r.max_push >= 0.0);
        }
    }
}

#[test]
fn an_independent_search_finds_nothing_the_workspace_misses() {
    let (chains, iks, object, gravity) = setup();
    let grid = sphere_grid(600);
    let mut rng = common::rng(7);
    let (mut agree, mut only_closed) = (0, 0);
    for k in 0..3 {
        let c = &chains[k];
        let starts: Vec<_> = (0..12).map(|_| common::random_q(c, &mut rng)).collect();
        for n in &grid {
            let target = object.centre + n * (object.radius + c.tip_radius);
            // Admissible with a little to spare, by the test's own reading
            // of the margins (limits, patch, clearance).
            let found = starts.iter().any(|q0| {
                let d = c.ik_dls(&target, q0, &DlsParams::default());
                if !d.converged {
                    return false;
                }
                let s = c.forward(&d.q);
                let inside = (0..3).all(|i| {
                    d.q[i] >= c.limits[i].lower + c.margin + 1e-6
                        && d.q[i] <= c.limits[i].upper - c.margin - 1e-6
                });
                inside
                    && c.patch.margin(&s.tip.rotation, n) >= MARGINS.patch + 1e-6
                    && object_clearance(c, &s, &object) >= MARGINS.clearance + 1e-6
            });
            let admitted = reach(c, &iks[k], &object, &gravity, n, &MARGINS).is_some();
            assert!(
                admitted || !found,
                "finger {k}: n {n:?} is reachable within the margins but not admitted"
            );
            match (admitted, found) {
                (true, true) => agree += 1,
                (true, false) => only_closed += 1,
                _ => {}
            }
        }
    }
    println!("admitted and found by DLS: {agree}; admitted, DLS missed: {only_closed}");
    // The search is a check, not an oracle of completeness: it may miss a
    // branch, but not most of them.
    assert!(agree > 10 * only_closed, "{agree} vs {only_closed}");
}

#[test]
fn the_equator_toward_each_finger_is_reached_and_the_bottom_is_not() {
    // hand.toml: the ball's centre sits where the three tips reach it on
    // its equator; finger_0 stands along +y, the others at −120°, −240°
    // about z. The fingers hang from above: none gets its tip under the
    // ball within the margins.
    let (chains, iks, object, gravity) = setup();
    for k in 0..3 {
        let turn =
            Rotation3::from_axis_angle(&Vector3::z_axis(), -(k as f64) * 120f64.to_radians());
        let toward = turn * Vector3::y();
        let r = reach(&chains[k], &iks[k], &object, &gravity, &toward, &MARGINS);
        let r = r.unwrap_or_else(|| panic!("finger {k}: its side of the equator"));
        assert!(r.max_push > 1.0, "finger {k}: presses {} N", r.max_push);
        let below = reach(
            &chains[k],
            &iks[k],
            &object,
            &gravity,
            &-Vector3::z(),
            &MARGINS,
        );
        assert!(below.is_none(), "finger {k}: the ball's bottom");
    }
}

#[test]
fn two_fingers_apart_have_a_gap_and_two_tips_on_one_spot_do_not() {
    let (chains, iks, object, gravity) = setup();
    let states: Vec<_> = (0..3)
        .map(|k| {
            let turn =
                Rotation3::from_axis_angle(&Vector3::z_axis(), -(k as f64) * 120f64.to_radians());
            let r = reach(
                &chains[k],
                &iks[k],
                &object,
                &gravity,
                &(turn * Vector3::y()),
                &MARGINS,
            )
            .expect("the equator toward the finger");
            chains[k].forward(&r.q)
        })
        .collect();
    for a in 0..3 {
        for b in (a + 1)..3 {
            let gap = finger_gap((&chains[a], &states[a]), (&chains[b], &states[b]));
            // Tips 120° apart on a 33.5 mm ball: centres 75 mm apart.
            assert!(gap > 0.01, "fingers {a}, {b}: gap {gap}");
        }
        // Never more than the gap of the two tip spheres alone.
        for b in (a + 1)..3 {
            let tips = (states[a].tip_centre() - states[b].tip_centre()).norm()
                - chains[a].tip_radius
                - chains[b].tip_radius;
            let gap = finger_gap((&chains[a], &states[a]), (&chains[b], &states[b]));
            assert!(gap <= tips + 1e-12, "{gap} > {tips}");
        }
    }
}

#[test]
fn tips_closer_than_their_diameter_overlap() {
    // The two normals, one in each of fingers 0 and 1's workspaces, that
    // are nearest each other: within 26.6° the tip centres (43.5 mm from
    // O) are nearer than the 20 mm the two tips need.
    let (chains, iks, object, gravity) = setup();
    let grid = sphere_grid(1500);
    let w: Vec<_> = (0..2)
        .map(|k| Workspace::new(&chains[k], &iks[k], &object, &gravity, &grid, &MARGINS))
        .collect();
    let mut best = (f64::INFINITY, 0, 0);
    for (i, (a, _)) in w[0].reached.iter().enumerate() {
        for (j, (b, _)) in w[1].reached.iter().enumerate() {
            let angle = a.angle(b);
            if angle < best.0 {
                best = (angle, i, j);
            }
        }
    }
    let (angle, i, j) = best;
    println!(
        "fingers 0 and 1 reach normals {:.1}° apart",
        angle.to_degrees()
    );
    assert!(angle.to_degrees() < 25.0, "{}°", angle.to_degrees());
    let s0 = chains[0].forward(&w[0].reached[i].1.q);
    let s1 = chains[1].forward(&w[1].reached[j].1.q);
    let gap = finger_gap((&chains[0], &s0), (&chains[1], &s1));
    assert!(gap < 0.0, "gap {gap}");
}

#[test]
fn a_narrower_tip_patch_shrinks_the_workspace_to_its_cap() {
    // TriFingerPro's hemisphere never binds before the joint limits and
    // the links do; a 30° cap around the same pole must.
    let (chains, iks, object, gravity) = setup();
    let grid = sphere_grid(1500);
    let mut narrow = chains[0];
    narrow.patch.alpha = 30f64.to_radians();
    let wide = Workspace::new(&chains[0], &iks[0], &object, &gravity, &grid, &MARGINS);
    let cap = Workspace::new(&narrow, &iks[0], &object, &gravity, &grid, &MARGINS);
    println!(
        "hemisphere {:.1} %, 30° cap {:.1} %",
        100.0 * wide.share(),
        100.0 * cap.share()
    );
    assert!(cap.share() < 0.8 * wide.share());
    for (n, r) in &cap.reached {
        let s = narrow.forward(&r.q);
        let u = -(s.tip.rotation.transpose() * n);
        let from_pole = u.angle(&narrow.patch.pole);
        assert!(
            from_pole <= 25f64.to_radians() + 1e-12,
            "{}°",
            from_pole.to_degrees()
        );
    }
}
