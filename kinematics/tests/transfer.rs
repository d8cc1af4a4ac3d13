//! A free TriFingerPro finger moved from one contact on the tennis ball to
//! another while the other two hold it (SPEC §14.3): the way starts and
//! ends on the contacts, and every point of it — sampled four times finer
//! than the code checks, by the test's own reading of the limits — keeps
//! the joints inside their limits, the links off the ball, the tip off the
//! ball while travelling, and the finger off the other two.

mod common;

use kinematics::{
    Chain, ClosedFormIk, FingerGap, Margins, Obstacle, TransferError, TransferLimits, Workspace,
    finger_gap, sphere_grid, transfer, workspace::object_clearance,
};
use nalgebra::Vector3;
use rand::Rng;

/// The test's choices: 15 mm above the ball, 5 mm from ball and fingers,
/// samples 1° apart; and a wary one, 20 mm above, 10 mm from the ball
/// (contacts whose links keep that much at the start and at the end),
/// where the links come into play.
const CHOICES: [TransferLimits; 2] = [
    TransferLimits {
        hover: 0.015,
        clearance: 0.005,
        finger_gap: 0.005,
        resolution: std::f64::consts::PI / 180.0,
    },
    TransferLimits {
        hover: 0.02,
        clearance: 0.01,
        finger_gap: 0.005,
        resolution: std::f64::consts::PI / 180.0,
    },
];

/// What the test allows between the code's samples \[m\].
const BETWEEN: f64 = 1e-3;

#[test]
fn a_free_finger_moves_clear_of_the_ball_and_the_others() {
    for limits in CHOICES {
        moves(&limits);
    }
}

fn moves(limits: &TransferLimits) {
    let chains = common::chains();
    let object = common::hand().object;
    let g = common::hand().gravity;
    let iks = chains.each_ref().map(|c| ClosedFormIk::new(c).unwrap());
    let margins = Margins {
        patch: 5f64.to_radians(),
        clearance: limits.clearance,
    };
    let grid = sphere_grid(800);
    let ws: Vec<Workspace> = (0..3)
        .map(|k| Workspace::new(&chains[k], &iks[k], &object, &g, &grid, &margins))
        .collect();
    let mut rng = common::rng(5);
    let (mut moved, mut blocked, mut unreachable, mut higher) = (0, 0, 0, 0);
    let mut cases = 0;
    while cases < 60 {
        let q: [Vector3<f64>; 3] =
            std::array::from_fn(|k| ws[k].reached[rng.random_range(0..ws[k].reached.len())].1.q);
        let s: [_; 3] = std::array::from_fn(|k| chains[k].forward(&q[k]));
        let gap = |a: usize, b: usize| finger_gap((&chains[a], &s[a]), (&chains[b], &s[b]));
        if gap(0, 1) < limits.finger_gap
            || gap(0, 2) < limits.finger_gap
            || gap(1, 2) < limits.finger_gap
        {
            continue; // not a grasp to start from
        }
        cases += 1;
        let to = ws[0].reached[rng.random_range(0..ws[0].reached.len())].0;
        let others = [1, 2].map(|k| Obstacle {
            chain: &chains[k],
            state: s[k],
            gap: FingerGap::new(&chains[0], &chains[k]),
        });
        match transfer(&chains[0], &iks[0], &object, &q[0], &to, &others, limits) {
            Ok(t) => {
                moved += 1;
                if t.height > limits.hover {
                    higher += 1;
                }
                check(&chains, &object, &q[0], &to, &t, &s, limits);
            }
            Err(TransferError::Blocked) => blocked += 1,
            Err(TransferError::Unreachable { .. }) => unreachable += 1,
        }
    }
    eprintln!(
        "{} mm above, {} mm clear: {cases} transfers of finger 0: {moved} found ({higher} above the first height), {blocked} blocked, {unreachable} unreachable",
        limits.hover * 1e3,
        limits.clearance * 1e3
    );
    assert!(moved >= cases / 2, "only {moved} of {cases} found");
    assert!(
        higher > 0,
        "no transfer needed a higher route: the sample misses a case"
    );
}

/// The test's own reading of every point of `t`.
fn check(
    chains: &[Chain<3>; 3],
    object: &kinematics::Object,
    from: &Vector3<f64>,
    to: &Vector3<f64>,
    t: &kinematics::Transfer,
    s: &[kinematics::ChainState<3>; 3],
    limits: &TransferLimits,
) {
    let c = &chains[0];
    let w = t.waypoints();
    assert_eq!(w[0], *from, "starts where the finger is");
    let end = c.forward(&w[w.len() - 1]).tip_centre();
    let want = object.centre + to * (object.radius + c.tip_radius);
    assert!(
        (end - want).norm() < 1e-9,
        "ends {} m off the contact",
        (end - want).norm()
    );
    let half = w.len() / 2;
    for i in 0..w.len() - 1 {
        let n = ((w[i + 1] - w[i]).amax() / (limits.resolution / 4.0))
            .ceil()
            .max(1.0) as usize;
        for j in 0..=n {
            let q = w[i] + (w[i + 1] - w[i]) * (j as f64 / n as f64);
            for k in 0..3 {
                assert!(
                    q[k] >= c.limits[k].lower + c.margin - 1e-12
                        && q[k] <= c.limits[k].upper - c.margin + 1e-12,
                    "segment {i}: joint {k} at {} outside its limits",
                    q[k]
                );
            }
            let st = c.forward(&q);
            let links = object_clearance(c, &st, object);
            assert!(
                links >= limits.clearance - BETWEEN,
                "segment {i}: a link {links} m from the ball"
            );
            let tip = (st.tip_centre() - object.centre).norm() - object.radius - c.tip_radius;
            if i + 1 == half {
                assert!(
                    tip >= limits.clearance - BETWEEN,
                    "travelling: tip {tip} m from the ball"
                );
            } else {
                assert!(tip >= -1e-9, "on a normal: tip {tip} m into the ball");
            }
            for k in [1, 2] {
                let g = finger_gap((c, &st), (&chains[k], &s[k]));
                assert!(
                    g >= limits.finger_gap - BETWEEN,
                    "segment {i}: {g} m from finger {k}"
                );
            }
        }
    }
}

/// A finger whose links are already within the clearance of the ball (a
/// grasp the wary limits would not make) has no way out that keeps it:
/// the links are checked, not only the tip.
#[test]
fn links_within_the_clearance_block_the_way() {
    let chains = common::chains();
    let object = common::hand().object;
    let g = common::hand().gravity;
    let ik = ClosedFormIk::new(&chains[0]).unwrap();
    let margins = Margins {
        patch: 5f64.to_radians(),
        clearance: 0.005,
    };
    let ws = Workspace::new(&chains[0], &ik, &object, &g, &sphere_grid(800), &margins);
    let close: Vec<_> = ws
        .reached
        .iter()
        .filter(|(_, r)| r.clearance < 0.008)
        .collect();
    assert!(!close.is_empty(), "no contact with a link within 8 mm");
    let limits = TransferLimits {
        clearance: 0.01,
        ..CHOICES[0]
    };
    let to = ws
        .reached
        .iter()
        .max_by(|a, b| a.1.clearance.total_cmp(&b.1.clearance))
        .unwrap()
        .0;
    for (_, r) in &close {
        let way = transfer(&chains[0], &ik, &object, &r.q, &to, &[], &limits);
        assert!(
            way.is_err(),
            "a link {} m from the ball, and a way out: {way:?}",
            r.clearance
        );
    }
    eprintln!(
        "{} contacts with a link within 8 mm of the ball: no way out keeps 10 mm",
        close.len()
    );
}
