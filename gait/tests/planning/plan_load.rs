//! A plan's load, sample by sample, by the independent check
//! ([`LoadCheck`], SPEC §1.3 I1'): every rotation every 2.5°, every roll
//! at 8 points (a spinning contact frictionless), every still grasp.

use super::load::{Kind, LoadCheck};
use gait::HandState;
use gait::planner::{Motion, Plan};
use nalgebra::Vector3;

/// Rotation between two load samples of a Rotate step (the test's own).
pub const ROTATION_STEP_DEG: f64 = 2.5;
/// Samples of a roll step.
pub const ROLL_SAMPLES: usize = 8;

/// The largest F* over the plan's samples, and the first sample that does
/// not hold (step index, F*), by the independent check.
pub fn plan_load(check: &LoadCheck, plan: &Plan) -> (f64, Option<(usize, f64)>) {
    let mut worst = 0.0f64;
    let mut bad = None;
    let grasping = |s: &HandState| -> Vec<Vector3<f64>> {
        s.fingers
            .iter()
            .filter(|f| f.mode == gait::FingerMode::Grasping)
            .map(|f| f.center.normalize())
            .collect()
    };
    // `spinning`: the index among `normals` of a contact spinning on the
    // object — frictionless (its cone is used up by the spin's torsion);
    // the others then are soft (they neither roll nor spin).
    let mut test = |normals: &[Vector3<f64>],
                    axis: Option<&Vector3<f64>>,
                    step: usize,
                    spinning: Option<usize>| {
        let kind = if normals.len() == 3 && spinning.is_none() {
            Kind::Hard
        } else {
            Kind::Soft
        };
        let slick = spinning.map_or(0, |i| 1u8 << i);
        let (ok, f) = check.holds_with(normals, kind, axis, slick);
        worst = worst.max(f);
        if !ok && bad.is_none() {
            bad = Some((step, f));
        }
    };
    for (i, st) in plan.steps.iter().enumerate() {
        let d = st.dofs();
        let at = |lam: f64| st.eval(&d.length.map(|l| l * lam), &[0.0; 3]).state;
        match st.motion {
            Motion::Rotate { axis, angle, .. } if angle > 0.0 => {
                let n = (angle.to_degrees() / ROTATION_STEP_DEG).ceil().max(1.0) as usize;
                for k in 0..=n {
                    test(&grasping(&at(k as f64 / n as f64)), Some(&axis), i, None);
                }
            }
            Motion::Roll { .. } | Motion::RollSegment { .. } => {
                // The spinning finger's place among the grasping ones.
                let spinning = match st.motion {
                    Motion::RollSegment {
                        finger, segment, ..
                    } if segment.kind == gait::rolling::SegmentKind::Spin => Some(
                        (0..finger)
                            .filter(|&k| st.start.fingers[k].mode == gait::FingerMode::Grasping)
                            .count(),
                    ),
                    _ => None,
                };
                for k in 0..=ROLL_SAMPLES {
                    test(
                        &grasping(&at(k as f64 / ROLL_SAMPLES as f64)),
                        None,
                        i,
                        spinning,
                    );
                }
            }
            _ => {
                // A still grasp while a finger moves: the fingers touching
                // before and after (a handover's ends are the still grasps
                // of the placement before it and the lift after it).
                let end = at(1.0);
                let normals: Vec<Vector3<f64>> = (0..3)
                    .filter(|&k| {
                        st.start.fingers[k].mode == gait::FingerMode::Grasping
                            && end.fingers[k].mode == gait::FingerMode::Grasping
                    })
                    .map(|k| st.start.fingers[k].center.normalize())
                    .collect();
                test(&normals, None, i, None);
            }
        }
    }
    (worst, bad)
}

/// Asserts that `plan` holds the load at every sample by the independent
/// check, within `load.max_grip`, and keeps the kinematic invariants
/// (`what` names it in a failure); its largest F* \[N\].
pub fn assert_held(
    check: &LoadCheck,
    checker: &super::verify::Checker,
    cfg: &gait::HandConfig,
    plan: &Plan,
    what: &str,
) -> f64 {
    let (f, bad) = plan_load(check, plan);
    assert_eq!(bad, None, "{what}: a sample that does not hold (step, F*)");
    assert!(f <= cfg.load.max_grip * (1.0 + 1e-6), "{what}: F* {f} N");
    assert!(checker.check_plan(plan, 20).is_empty(), "{what}");
    f
}
