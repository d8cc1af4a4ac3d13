//! The chain planner's quick load test against the torque box's cone
//! program (SPEC §14.1 "Forces"): on random grasps of TriFingerPro holding
//! the tennis ball (two or three fingers, at rest or turning about a
//! random axis at the acceleration limit), every grasp the closed-form
//! forces pass is one the program holds, their share of the motors'
//! effort never below the program's u* — the quick test is sufficient,
//! so the planner's verdicts are the program's — and it
//! passes most of the grasps the program holds, which is what makes it
//! worth asking first.

mod chain_hand;
#[path = "../../kinematics/tests/common/mod.rs"]
mod common;

use gait::planner::chains::certify::grasp_share;
use gait::planner::chains::quick_hold::closed_form_share;
use gait::{FingerMode, HandState};
use rand::Rng;

#[test]
fn grasps_the_closed_forms_pass_are_held_by_the_torque_box() {
    let m = chain_hand::model();
    let h = m.hand();
    let params = *m.check_params();
    let mut rng = test_support::random::rng(17);
    let (mut tried, mut held, mut passed) = (0, 0, 0);
    while tried < 3000 {
        let mut s = HandState::paper_start(m.config());
        let lifted = rng.random_range(0..4usize);
        let mut joints = [None; 3];
        let mut reach = true;
        for (k, f) in s.fingers.iter_mut().enumerate() {
            let n = test_support::random::unit(&mut rng);
            f.center = n * (h.object().radius + h.chain(k).tip_radius);
            f.mode = if k == lifted {
                FingerMode::Free
            } else {
                FingerMode::Grasping
            };
            if f.mode == FingerMode::Grasping {
                joints[k] = h.joints(k, &f.center, None);
                reach &= joints[k].is_some();
            }
        }
        if !reach {
            continue;
        }
        tried += 1;
        let axis = rng
            .random_bool(0.5)
            .then(|| test_support::random::unit(&mut rng));
        let share = grasp_share(h, &s, &joints, axis.as_ref(), &params);
        let bound = closed_form_share(h, &s, &joints, axis.as_ref(), &params);
        if let Some(b) = bound {
            assert!(
                b >= share - 1e-6,
                "grasp {tried}: the closed forms need {b} of the box, the program {share}: {s:?}"
            );
        }
        let fits = bound.is_some_and(|b| b <= 1.0);
        held += u64::from(share <= 1.0);
        passed += u64::from(fits);
    }
    println!(
        "{tried} reachable grasps: {held} held by the torque box, {passed} passed by the closed forms"
    );
    assert!(held > 100, "{held} held: the sample says little");
    assert!(
        passed * 2 > held,
        "the closed forms pass {passed} of the {held} held: not worth asking first"
    );
}
