//! The exact check of a plan on TriFingerPro's chains (SPEC §14.1): it
//! passes a plan that keeps every limit, with margins the test reads
//! itself at finer samples, and names the limit and the place of the first
//! sample that breaks one — a carry turned past its range (the same limit
//! the kinematics' own scan finds, within one sample), a finger lifted off
//! a grasp whose last pair cannot hold the ball, a finger driven through
//! the ball — and refuses a rigid turn (contacts sticking) as no motion
//! of a chain.

#[path = "../../kinematics/tests/common/mod.rs"]
mod common;

use gait::planner::carry_path::{CarriedFinger, CarryPath};
use gait::planner::chains::certify::{CheckParams, ViolationKind, check};
use gait::planner::chains::{ChainHand, ChainHandError};
use gait::planner::plan::Reorientation;
use gait::planner::{FreeMove, FreePath, Motion, Step, StepKind};
use gait::{FingerMode, HandState};
use kinematics::{Bound, GraspLimits, Margins, carry_range};
use nalgebra::Vector3;

use common::LIMITS;

/// Samples every 1° or 1 mm; 2 rad/s² at most; 0.05 N least grip.
const PARAMS: CheckParams = CheckParams {
    carry_step: std::f64::consts::PI / 180.0,
    free_step: 0.001,
    branch_jump: 0.25,
    max_acceleration: 2.0,
    min_grip: 0.05,
};

fn hand() -> ChainHand {
    ChainHand::new(&common::hand(), LIMITS).expect("TriFingerPro is a chain hand")
}

/// The three tips on the ball's equator at the azimuths 75°, −45°, −165°
/// (each in front of its finger), as a planner state.
fn equator(h: &ChainHand) -> HandState {
    let mut s = HandState::paper_start(&gait::HandConfig::default());
    for (k, f) in s.fingers.iter_mut().enumerate() {
        let az = (75.0 - 120.0 * k as f64).to_radians();
        let r = h.object().radius + h.chain(k).tip_radius;
        f.mode = FingerMode::Grasping;
        f.center = Vector3::new(az.cos(), az.sin(), 0.0) * r;
    }
    s
}

fn joints(h: &ChainHand, s: &HandState) -> [Vector3<f64>; 3] {
    std::array::from_fn(|k| h.joints(k, &s.fingers[k].center, None).expect("reached"))
}

fn carry_step(h: &ChainHand, s: &HandState, axis: Vector3<f64>, angle: f64) -> Step {
    carry_from(h, s, &joints(h, s), axis, angle)
}

/// A turn in pieces of at most a radian, each fitted from the joints the
/// one before ends at.
fn carry_steps(h: &ChainHand, s: &HandState, axis: Vector3<f64>, angle: f64) -> Vec<Step> {
    let pieces = angle.ceil().max(1.0) as usize;
    let chains = [h.chain(0), h.chain(1), h.chain(2)];
    let mut q = joints(h, s);
    let mut at = *s;
    let mut out = Vec::new();
    for _ in 0..pieces {
        let st = carry_from(h, &at, &q, axis, angle / pieces as f64);
        kinematics::carry(
            &chains,
            &mut q,
            h.object(),
            &axis,
            angle / pieces as f64,
            1e-3,
        )
        .unwrap();
        at = st.eval(&st.dofs().length, &[0.0; 3]).state;
        out.push(st);
    }
    out
}

fn carry_from(
    h: &ChainHand,
    s: &HandState,
    q: &[Vector3<f64>; 3],
    axis: Vector3<f64>,
    angle: f64,
) -> Step {
    let fingers: [CarriedFinger<'_>; 3] = std::array::from_fn(|k| (k, h.chain(k), q[k]));
    let (path, _) = CarryPath::fit(&fingers, h.object(), &axis, angle, 1e-7).expect("fits");
    Step {
        kind: StepKind::Rotate,
        start: *s,
        motion: Motion::Carry { axis, angle, path },
        duration: 1.0,
        handover: None,
    }
}

/// Finger `k` straight out along its normal by `height` (or back in).
fn radial(s: &HandState, k: usize, height: f64, out: bool) -> Step {
    let c = s.fingers[k].center;
    let (near, far) = if out {
        (c.norm(), c.norm() + height)
    } else {
        (c.norm() - height, c.norm())
    };
    let (from, to) = if out { (near, far) } else { (far, near) };
    Step {
        kind: if out { StepKind::Lift } else { StepKind::Place },
        start: *s,
        motion: Motion::Free(FreeMove {
            finger: k,
            path: FreePath::Radial {
                dir: c.normalize(),
                from,
                to,
            },
            turn: Reorientation::NONE,
            contact_at_end: !out,
        }),
        duration: 1.0,
        handover: None,
    }
}

/// The test's own tightest joint and patch margins over `samples` + 1
/// even samples of a carry step (the patch from its definition: the
/// contact on the tip, Rᵀ(−n), against the pole).
fn own_margins(h: &ChainHand, st: &Step, samples: usize) -> (f64, f64) {
    let (mut joint, mut patch) = (f64::INFINITY, f64::INFINITY);
    let mut q = joints(h, &st.start);
    for i in 0..=samples {
        let lam = i as f64 / samples as f64;
        let s = st.eval(&st.dofs().length.map(|l| l * lam), &[0.0; 3]).state;
        for (k, q) in q.iter_mut().enumerate() {
            let c = h.chain(k);
            *q = h.joints(k, &s.fingers[k].center, Some(q)).unwrap();
            for (j, l) in c.limits.iter().enumerate() {
                joint = joint
                    .min(q[j] - l.lower - c.margin)
                    .min(l.upper - q[j] - c.margin);
            }
            let tip = c.forward(q).tip.rotation;
            let u = -(tip.transpose() * s.fingers[k].center.normalize());
            patch =
                patch.min(c.patch.alpha - u.angle(c.patch.pole.as_ref()) - LIMITS.margins.patch);
        }
    }
    (joint, patch)
}

#[test]
fn a_plan_within_every_limit_passes_with_its_margins() {
    let h = hand();
    let s0 = equator(&h);
    let turn = carry_step(&h, &s0, Vector3::z(), 20f64.to_radians());
    let m = check(&h, &s0, &[turn], &PARAMS).expect("a 20° turn about the vertical passes");
    let (joint, patch) = own_margins(&h, &turn, 400);
    eprintln!(
        "20° about z: joint {:.4} rad (own {joint:.4}), patch {:.4} rad (own {patch:.4}), \
         clearance {:.4} m, gap {:.4} m, torque share {:.3}, {} samples",
        m.joint, m.patch, m.clearance, m.gap, m.torque_share, m.samples
    );
    assert!(m.joint >= 0.0 && m.patch >= 0.0 && m.clearance >= 0.0 && m.gap >= 0.0);
    assert!(m.torque_share > 0.0 && m.torque_share <= 1.0);
    // Sampled at 1° against the test's 0.05°: the same minimum to within
    // what a degree of turn moves it.
    assert!(
        (m.joint - joint).abs() < 2e-3,
        "joint margin {} vs {joint}",
        m.joint
    );
    assert!(
        (m.patch - patch).abs() < 2e-3,
        "patch margin {} vs {patch}",
        m.patch
    );
}

/// The limits one at a time, so that each binds some turn (with all of
/// them the links' clearance binds first nearly always).
fn one_at_a_time() -> [(&'static str, GraspLimits); 4] {
    let none = GraspLimits {
        margins: Margins {
            patch: f64::NEG_INFINITY,
            clearance: f64::NEG_INFINITY,
        },
        finger_gap: f64::NEG_INFINITY,
    };
    let mut patch = none;
    patch.margins.patch = LIMITS.margins.patch;
    let mut gap = none;
    gap.finger_gap = LIMITS.finger_gap;
    [
        ("all", LIMITS),
        ("tip patch only", patch),
        ("finger gap only", gap),
        ("joint limits only", none),
    ]
}

#[test]
fn a_carry_past_its_range_fails_where_the_range_ends() {
    let axes = [
        Vector3::x(),
        Vector3::y(),
        -Vector3::x(),
        -Vector3::y(),
        Vector3::new(1.0, 1.0, 0.5).normalize(),
        Vector3::new(-0.3, 0.8, -0.5).normalize(),
        Vector3::new(0.2, -0.9, 0.4).normalize(),
    ];
    for (name, limits) in one_at_a_time() {
        let mut d = common::hand();
        // Weightless: the limits of reach decide, not the load.
        d.gravity = Vector3::zeros();
        if name == "joint limits only" {
            // The workspace's grasps sit far inside the joint limits (the
            // patch and the links stop a turn sooner): the test narrows
            // each joint to 0.2 rad either side of its start.
            let q = joints(&ChainHand::new(&d, limits).unwrap(), &equator(&hand()));
            let m = d.joint_limit_margin;
            for (f, q) in d.fingers.iter_mut().zip(&q) {
                for (j, q) in f.joints.iter_mut().zip(q.iter()) {
                    (j.limits.lower, j.limits.upper) = (q - 0.2 - m, q + 0.2 + m);
                }
            }
        }
        let h = ChainHand::new(&d, limits).unwrap();
        let s0 = equator(&h);
        let q = joints(&h, &s0);
        let chains = [h.chain(0), h.chain(1), h.chain(2)];
        let mut seen = 0;
        for axis in axes {
            let range = carry_range(&chains, &q, h.object(), &axis, 3.0, &limits, 0.01);
            if !matches!(
                range.bound,
                Bound::JointLimit { .. }
                    | Bound::TipPatch { .. }
                    | Bound::ObjectClearance { .. }
                    | Bound::FingerGap { .. }
            ) || range.angle < 0.05
            {
                continue;
            }
            seen += 1;
            let too_far = range.angle + 0.1;
            let steps = carry_steps(&h, &s0, axis, too_far);
            let v = check(&h, &s0, &steps, &PARAMS).expect_err("past its range");
            let angle = (v.step as f64 + v.at) * too_far / steps.len() as f64;
            eprintln!(
                "{name}, axis {:?}: range {:.2}° ({:?}); check {:?} at {:.2}°",
                axis.as_slice(),
                range.angle.to_degrees(),
                range.bound,
                v.kind,
                angle.to_degrees()
            );
            assert!(
                (angle - range.angle).abs() <= PARAMS.carry_step + 1e-3,
                "{name}: check at {angle}, range {}",
                range.angle
            );
            let same = matches!(
                (range.bound, v.kind),
                (Bound::JointLimit { .. }, ViolationKind::JointLimit(_))
                    | (Bound::TipPatch { .. }, ViolationKind::TipPatch(_))
                    | (
                        Bound::ObjectClearance { .. },
                        ViolationKind::ObjectClearance(_)
                    )
                    | (Bound::FingerGap { .. }, ViolationKind::FingerGap { .. })
            );
            assert!(
                same,
                "{name}: range bound {:?}, check {:?}",
                range.bound, v.kind
            );
        }
        assert!(seen >= 1, "{name}: no turn met a limit");
    }
}

#[test]
fn lifting_a_finger_the_pair_left_cannot_hold_fails_on_the_load() {
    let h = hand();
    let s0 = equator(&h);
    let lift = radial(&s0, 0, 0.015, true);
    let v = check(&h, &s0, &[lift], &PARAMS).expect_err("two fingers 120° apart");
    eprintln!("lift finger 0: {v:?}");
    assert!(matches!(v.kind, ViolationKind::Load(u) if u > 1.0), "{v:?}");
}

#[test]
fn a_finger_pushed_into_the_ball_or_carried_rigidly_is_refused() {
    // Weightless, so that the pair left holds and the finger's way decides.
    let mut d = common::hand();
    d.gravity = Vector3::zeros();
    let h = ChainHand::new(&d, LIMITS).unwrap();
    let s0 = equator(&h);
    let mut inside = s0;
    inside.fingers[1].mode = FingerMode::Free;
    // A free finger driven 5 mm into the ball.
    let c = inside.fingers[1].center;
    let into = Step {
        kind: StepKind::Transfer,
        start: inside,
        motion: Motion::Free(FreeMove {
            finger: 1,
            path: FreePath::Radial {
                dir: c.normalize(),
                from: c.norm(),
                to: c.norm() - 0.005,
            },
            turn: Reorientation::NONE,
            contact_at_end: false,
        }),
        duration: 1.0,
        handover: None,
    };
    let v = check(&h, &inside, &[into], &PARAMS).expect_err("through the ball");
    assert!(
        matches!(v.kind, ViolationKind::ObjectClearance(g) if g < 0.0),
        "{v:?}"
    );
    assert_eq!(v.finger, Some(1));
    // A turn that carries the contacts rigidly (sticking) is not a chain's.
    let rigid = Step {
        motion: Motion::Rotate {
            axis: Vector3::z(),
            angle: 0.1,
            free: None,
        },
        ..carry_step(&h, &s0, Vector3::z(), 0.1)
    };
    let v = check(&h, &s0, &[rigid], &PARAMS).expect_err("not a chain's motion");
    assert_eq!(v.kind, ViolationKind::Unsupported);
}

#[test]
fn a_description_that_is_not_a_chain_hand_is_refused() {
    let mut d = common::hand();
    d.fingers.pop();
    assert_eq!(
        ChainHand::new(&d, LIMITS).err(),
        Some(ChainHandError::FingerCount(2))
    );
}
