//! What one frame of the view shows (hand frame, metres, newtons): taken
//! from a running daemon's status, or from a recorded trace's sample. A
//! trace records the commanded state only, so a frame from a trace has no
//! measurements, no tick time and no tracking errors (`None`): the view
//! leaves those out rather than draw zeros.

use gaitd_client::{FingerPhase, Status};
use shm_schema::status::measured;
use trace_mcap::file::{Trace, TraceSample};

/// One finger in a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerFrame {
    /// Touching the object (grasping or rolling).
    pub touching: bool,
    /// Commanded fingertip centre.
    pub tip: [f64; 3],
    /// Measured fingertip centre.
    pub measured_tip: Option<[f64; 3]>,
    /// Contact point on the object's surface, hand frame (touching only).
    pub contact_hand: [f64; 3],
    /// The same point in the object's frame.
    pub contact_object: [f64; 3],
    /// Commanded normal force.
    pub force: f64,
    /// Measured normal force.
    pub measured_force: Option<f64>,
    /// Measured fingertip's distance from its setpoint.
    pub tip_error: Option<f64>,
}

/// One frame of the view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Time \[s\]: the daemon's clock, or the trace's `t`.
    pub time: f64,
    /// The daemon's tick (a trace's: its time over its period).
    pub tick: Option<u64>,
    /// Commanded object orientation [w, x, y, z].
    pub object: [f64; 4],
    /// Measured object orientation [w, x, y, z].
    pub measured_object: Option<[f64; 4]>,
    /// The fingers.
    pub fingers: [FingerFrame; 3],
    /// Force-closure margin of the grasp.
    pub fc_margin: Option<f64>,
    /// Load margin \[N\].
    pub load_margin: Option<f64>,
    /// Angle still to turn to the goal \[rad\].
    pub remaining: Option<f64>,
    /// The tick's compute time \[µs\].
    pub compute_us: Option<f64>,
    /// Measured object orientation's distance from its setpoint \[rad\].
    pub object_error: Option<f64>,
}

impl Frame {
    /// The frame of a daemon's status: measured values where its mask
    /// says they are valid.
    pub fn from_status(s: &Status) -> Self {
        let has = |bit: u32| s.measured_mask & bit != 0;
        let finger = |f: &shm_schema::status::FingerStatus| FingerFrame {
            touching: matches!(
                FingerPhase::try_from(f.state),
                Ok(FingerPhase::Grasping | FingerPhase::Rolling)
            ),
            tip: f.commanded_tip_position,
            measured_tip: has(measured::TIPS).then_some(f.measured_tip_position),
            contact_hand: f.contact_hand,
            contact_object: f.contact_object,
            force: f.commanded_normal_force,
            measured_force: has(measured::FORCES).then_some(f.measured_normal_force),
            tip_error: has(measured::TIPS).then_some(f.tip_error),
        };
        Self {
            time: s.time_ns as f64 * 1e-9,
            tick: Some(s.tick),
            object: s.commanded_object_q,
            measured_object: has(measured::OBJECT).then_some(s.measured_object_q),
            fingers: [0, 1, 2].map(|k| finger(&s.fingers[k])),
            fc_margin: Some(s.grasp_margin),
            load_margin: Some(s.load_margin),
            remaining: Some(s.goal.remaining_angle),
            compute_us: Some(s.timing.compute_last_ns as f64 * 1e-3),
            object_error: has(measured::OBJECT).then_some(s.object_error),
        }
    }

    /// The frame of one of `trace`'s samples: a touching fingertip's
    /// contact lies on the segment from the object's centre to the tip's,
    /// R from the centre (the object and the tip are spheres touching).
    pub fn from_sample(trace: &Trace, s: &TraceSample) -> Self {
        let (big_r, r) = (trace.object_radius, trace.fingertip_radius);
        let q = s.object.quaternion();
        let object = [q.w, q.i, q.j, q.k];
        let finger = |f: &trace_mcap::file::TraceFinger| {
            let (contact_hand, contact_object) = if f.contact {
                let c = f.p * (big_r / (big_r + r));
                (c.into(), (s.object.inverse() * c).into())
            } else {
                ([0.0; 3], [0.0; 3])
            };
            FingerFrame {
                touching: f.contact,
                tip: f.p.into(),
                measured_tip: None,
                contact_hand,
                contact_object,
                force: f.grip,
                measured_force: None,
                tip_error: None,
            }
        };
        Self {
            time: s.t,
            tick: trace
                .dt
                .filter(|dt| *dt > 0.0)
                .map(|dt| (s.t / dt).round() as u64),
            object,
            measured_object: None,
            fingers: [0, 1, 2].map(|k| finger(&s.fingers[k])),
            fc_margin: s.fc_margin,
            load_margin: s.load_margin,
            remaining: s.remaining_angle,
            compute_us: None,
            object_error: None,
        }
    }

    /// The object's orientation to draw: as the plant measures it, the
    /// commanded one until it does.
    pub fn shown_object(&self) -> [f64; 4] {
        self.measured_object.unwrap_or(self.object)
    }

    /// The object's and fingertips' radii from a frame where a finger
    /// touches: |contact| and |tip centre − contact|.
    pub fn radii(&self) -> Option<(f64, f64)> {
        self.fingers.iter().find(|f| f.touching).and_then(|f| {
            let (c, t) = (f.contact_hand, f.tip);
            let big_r = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            let d = [t[0] - c[0], t[1] - c[1], t[2] - c[2]];
            let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            (big_r > 0.0 && r > 0.0).then_some((big_r, r))
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use nalgebra::{UnitQuaternion, Vector3};
    use trace_mcap::file::TraceFinger;

    /// A trace of the paper's hand (R 0.5, r 0.1, 1 kHz) with `samples`.
    pub(crate) fn trace_of(samples: Vec<TraceSample>) -> Trace {
        Trace {
            object_radius: 0.5,
            fingertip_radius: 0.1,
            workspace_half_angle_deg: 60.0,
            finger_azimuth_deg: [0.0, 120.0, 240.0],
            dt: Some(0.001),
            hand_description: None,
            samples,
        }
    }

    fn trace() -> Trace {
        trace_of(vec![])
    }

    fn sample(object: UnitQuaternion<f64>, contact: [bool; 3]) -> TraceSample {
        let at = |k: usize| {
            let a = (120.0 * k as f64).to_radians();
            Vector3::new(a.cos(), a.sin(), 0.3).normalize() * 0.6
        };
        TraceSample {
            t: 2.5,
            object,
            fingers: [0, 1, 2].map(|k| TraceFinger {
                p: at(k),
                q: UnitQuaternion::identity(),
                contact: contact[k],
                grip: 3.0 + k as f64,
                roll: 0.0,
                joints: None,
            }),
            fc_margin: Some(0.2),
            load_margin: Some(7.0),
            remaining_angle: Some(1.0),
            phase: None,
        }
    }

    #[test]
    fn a_samples_contacts_lie_on_the_ball_under_the_tips() {
        let turn = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 0.7);
        let t = trace();
        let f = Frame::from_sample(&t, &sample(turn, [true, false, true]));
        assert_eq!(f.tick, Some(2500));
        let (big_r, r) = f.radii().expect("a finger touches");
        assert!((big_r - 0.5).abs() < 1e-12 && (r - 0.1).abs() < 1e-12);
        for (k, g) in f.fingers.iter().enumerate() {
            assert_eq!(g.touching, k != 1);
            assert_eq!(g.force, 3.0 + k as f64);
            if !g.touching {
                assert_eq!(g.contact_hand, [0.0; 3]);
                continue;
            }
            let c = Vector3::from(g.contact_hand);
            let tip = Vector3::from(g.tip);
            assert!((c.norm() - 0.5).abs() < 1e-12);
            assert!((tip - c).norm() - 0.1 < 1e-12);
            // The object frame's point, turned by the object, is the hand
            // frame's.
            let back = turn * Vector3::from(g.contact_object);
            assert!((back - c).norm() < 1e-12, "{back} vs {c}");
        }
        assert_eq!(f.measured_object, None);
        assert_eq!(f.compute_us, None);
        let w = turn.quaternion();
        assert_eq!(f.shown_object(), [w.w, w.i, w.j, w.k]);
    }

    #[test]
    fn a_status_measures_only_what_its_mask_says() {
        let mut s = Status {
            commanded_object_q: [1.0, 0.0, 0.0, 0.0],
            measured_object_q: [0.0, 1.0, 0.0, 0.0],
            measured_mask: measured::OBJECT,
            ..Default::default()
        };
        s.fingers[0].measured_normal_force = 4.0;
        let f = Frame::from_status(&s);
        assert_eq!(f.shown_object(), [0.0, 1.0, 0.0, 0.0]);
        assert_eq!(f.fingers[0].measured_force, None);
        assert_eq!(f.fingers[0].measured_tip, None);
        s.measured_mask = measured::FORCES;
        let f = Frame::from_status(&s);
        assert_eq!(f.shown_object(), [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(f.fingers[0].measured_force, Some(4.0));
    }
}
