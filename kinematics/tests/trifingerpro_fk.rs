//! TriFingerPro forward kinematics against numbers stated here from the
//! upstream description (robot_properties_fingers, BSD-3-Clause):
//! `fingerpro_macro.xacro` (offsets, axes, soft limits),
//! `trifingerpro.urdf.xacro` (holder height 0.29 m, fingers at 0°, −120°,
//! −240° about z) and upstream's own test data
//! (`tests/trifingerpro_kinematics_data.json`, tip positions upstream
//! computed for its IK test).

mod common;

use nalgebra::{Rotation3, Vector3};

/// Upstream constants (fingerpro_macro.xacro; trifingerpro_ik.py names).
const BASE_HEIGHT: f64 = 0.29;
const MIDDLE_DX: f64 = 0.01685;
const MIDDLE_DY: f64 = 0.0505; // JOINT1_Y_OFFSET
const LOWER_DX: f64 = 0.05015;
const TIP_DX: f64 = 0.019;
const LINK: f64 = 0.16; // MIDDLE_LINK_LENGTH = LOWER_LINK_LENGTH

/// finger_0's tip at q = (0, q1, q2), by hand: the upper joint at 0 keeps the
/// finger in its y–z plane, x offsets add up to TIP_X_OFFSET = 0.086, and
/// each 0.16 m link hangs at its angle from the vertical, Rx(a)(0,0,−L) =
/// (0, L sin a, −L cos a).
fn by_hand(q1: f64, q2: f64) -> Vector3<f64> {
    Vector3::new(
        MIDDLE_DX + LOWER_DX + TIP_DX,
        MIDDLE_DY + LINK * q1.sin() + LINK * (q1 + q2).sin(),
        BASE_HEIGHT - LINK * q1.cos() - LINK * (q1 + q2).cos(),
    )
}

#[test]
fn tip_at_the_initial_pose() {
    let chains = common::chains();
    let q = Vector3::new(0.0, 0.9, -1.7);
    let expected0 = by_hand(0.9, -1.7);
    // The same numbers written out: (0.086, 0.061055, 0.079069) m.
    assert!((expected0 - Vector3::new(0.086, 0.061055, 0.079069)).norm() < 1e-6);
    for (k, yaw_deg) in [0.0, -120.0, -240.0].into_iter().enumerate() {
        let expected =
            Rotation3::from_axis_angle(&Vector3::z_axis(), f64::to_radians(yaw_deg)) * expected0;
        let got = chains[k].forward(&q).tip_centre();
        assert!(
            (got - expected).norm() < 1e-12,
            "finger {k}: {got} vs {expected}"
        );
    }
}

#[test]
fn zero_pose_points_straight_down() {
    // All joints 0: every link vertical, tip 0.32 m below the holder, tip
    // frame parallel to the base frame (upstream: "pointing straight down").
    let c = &common::chains()[0];
    let s = c.forward(&Vector3::zeros());
    assert!(
        (s.tip_centre() - Vector3::new(0.086, 0.0505, BASE_HEIGHT - 2.0 * LINK)).norm() < 1e-12
    );
    assert!((s.tip.rotation - nalgebra::Matrix3::identity()).norm() < 1e-12);
}

#[test]
fn matches_upstream_kinematics_data() {
    // Rows 0, 108 and 216 of upstream's trifingerpro_kinematics_data.json
    // (joint positions, the same for the three fingers; tip positions of
    // finger_0, finger_120, finger_240).
    let rows: [([f64; 3], [[f64; 3]; 3]); 3] = [
        (
            [0.1988521312508383, 0.8897835312111577, -2.019488080167178],
            [
                [
                    0.05091218020801411,
                    0.03012390215059141,
                    0.10730117080405478,
                ],
                [
                    0.0006319744195217858,
                    -0.05915319249748725,
                    0.10730117080405478,
                ],
                [
                    -0.05154415462753592,
                    0.029029290346895803,
                    0.10730117080405478,
                ],
            ],
        ),
        (
            [-0.2569975323034179, 0.4261576869452221, -0.8637283483853972],
            [
                [
                    0.1570434701661676,
                    0.048841590496930876,
                    0.030788698100669976,
                ],
                [
                    -0.036223676951504996,
                    -0.16042442991083017,
                    0.030788698100669976,
                ],
                [
                    -0.12081979321466266,
                    0.11158283941389922,
                    0.030788698100669976,
                ],
            ],
        ),
        (
            [0.1213502736235735, 0.9784947587022422, -1.8683582656133049],
            [
                [
                    0.06236193906874854,
                    0.058927543475282285,
                    0.09094064006005458,
                ],
                [
                    0.0198517800978322,
                    -0.08347079520043468,
                    0.09094064006005458,
                ],
                [
                    -0.08221371916658074,
                    0.0245432517251523,
                    0.09094064006005458,
                ],
            ],
        ),
    ];
    let chains = common::chains();
    for (q, tips) in rows {
        for k in 0..3 {
            let got = chains[k].forward(&Vector3::from(q)).tip_centre();
            let err = (got - Vector3::from(tips[k])).norm();
            assert!(
                err < 1e-9,
                "finger {k} q {q:?}: {got} vs {:?} ({err:e})",
                tips[k]
            );
        }
    }
}

#[test]
fn limits_are_upstreams_soft_limits() {
    // fingerpro_macro.xacro: upper [−0.33, 1.0], middle [0, 1.57], lower
    // [−2.7, 0] rad; torque 0.396 N·m; trifingerpro_limits.py: 10 rad/s.
    let h = common::hand();
    assert_eq!(h.fingers.len(), 3);
    for f in &h.fingers {
        let l: Vec<_> = f
            .joints
            .iter()
            .map(|j| {
                (
                    j.limits.lower,
                    j.limits.upper,
                    j.limits.effort,
                    j.limits.velocity,
                )
            })
            .collect();
        assert_eq!(
            l,
            [
                (-0.33, 1.0, 0.396, 10.0),
                (0.0, 1.57, 0.396, 10.0),
                (-2.7, 0.0, 0.396, 10.0)
            ]
        );
        assert_eq!(f.tip_radius, 0.010);
        let masses: Vec<_> = f.bodies.iter().map(|b| b.mass).collect();
        // The tip's 9.2 g rides on the lower link.
        assert_eq!(masses, [0.26689, 0.27163, 0.05569 + 0.0092]);
    }
    let c = &common::chains()[0];
    assert_eq!(c.limit_margin(&Vector3::new(0.0, 0.9, -1.7)), 0.33 - 0.05);
    assert!(c.limit_margin(&Vector3::new(0.0, 1.55, -1.7)) < 0.0);
}
