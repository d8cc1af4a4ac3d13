//! A chain hand's joints on the plant link (shm_schema `PLANT-GUIDE.md`,
//! "A hand of finger chains"): what the daemon reads from a joint-level
//! plant and what it commands it, per finger (SPEC §14.1).
//!
//! - **Measured**: the joint positions; forward kinematics makes the tip
//!   (its centre relative to the object's centre O, as the model holds
//!   it, and its orientation), so the controller's feedback and checks
//!   read a chain hand as they read fingertips.
//! - **Commanded**, the shape of a TriFinger action: the joints that put
//!   the tip at the setpoint; the joint velocities that move it at the
//!   setpoint's tip velocity, $\dot q = J_v^{-1} v$ (0 at a singular
//!   configuration); the feed-forward torque
//!   $\tau_{ff} = J_p^\top f + g(q)$ — the grip's whole contact force $f$
//!   on the object (its normal push and the tangential share of the load)
//!   at the contact point, the links' weight where configured, and the
//!   hand's own viscous damping $b \circ \dot q^*$ at the commanded rate —
//!   clipped to the motors' limits (the executor chooses grips within
//!   them); the configured PD gains.
//!
//! Allocation-free: it runs on the loop thread.

use gait::planner::chains::ChainHand;
use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use shm_schema::{MAX_JOINTS, PlantFingerCommand};

/// Joints per finger of the chain hands gaitd runs.
pub const JOINTS: usize = 3;

/// The gains and feed-forward a joint-level plant is commanded with
/// (`[hand]` `joint_kp`, `joint_kd`, `compensate_link_weight`,
/// `joint_damping`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointGains {
    /// Position gains, base to tip \[N·m/rad\].
    pub kp: [f64; JOINTS],
    /// Velocity gains, base to tip \[N·m·s/rad\].
    pub kd: [f64; JOINTS],
    /// Whether the feed-forward torque holds the links' weight, g(q).
    pub compensate_weight: bool,
    /// The hand's own viscous damping per joint, supplied at the commanded
    /// rate \[N·m·s/rad\].
    pub damping: [f64; JOINTS],
}

impl From<&crate::config::hand::HandSection> for JointGains {
    fn from(h: &crate::config::hand::HandSection) -> Self {
        Self {
            kp: h.joint_kp,
            kd: h.joint_kd,
            compensate_weight: h.compensate_link_weight,
            damping: h.joint_damping,
        }
    }
}

/// The chain hand behind a joint-level plant (module docs).
#[derive(Debug, Clone)]
pub struct JointLink {
    hand: ChainHand,
    gains: JointGains,
}

/// A finger as its measured joints put it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredTip {
    /// Tip centre relative to the object's centre O \[m\].
    pub center: Vector3<f64>,
    /// Tip orientation (tip → hand).
    pub orientation: UnitQuaternion<f64>,
}

/// A finger's setpoint, as the command's joint fields need it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerSetpoint {
    /// The commanded joints \[rad\].
    pub joints: Vector3<f64>,
    /// Tip centre relative to O \[m\].
    pub center: Vector3<f64>,
    /// Tip centre velocity \[m/s\].
    pub velocity: Vector3<f64>,
    /// The contact force the tip pushes the object with, hand frame \[N\]
    /// (zero: free, or carrying nothing).
    pub force: Vector3<f64>,
}

impl JointLink {
    /// `hand`'s joints, commanded with `gains`.
    pub fn new(hand: ChainHand, gains: JointGains) -> Self {
        Self { hand, gains }
    }

    /// The hand.
    pub fn hand(&self) -> &ChainHand {
        &self.hand
    }

    /// Finger `k`'s tip at joints `q` (module docs).
    pub fn tip(&self, k: usize, q: &Vector3<f64>) -> MeasuredTip {
        let s = self.hand.chain(k).forward(q);
        MeasuredTip {
            center: s.tip_centre() - self.hand.object().centre,
            orientation: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
                s.tip.rotation,
            )),
        }
    }

    /// Fills finger `k`'s joint fields of a command for the setpoint `sp`
    /// (module docs).
    pub fn command(&self, k: usize, sp: &FingerSetpoint, out: &mut PlantFingerCommand) {
        let chain = self.hand.chain(k);
        let q = &sp.joints;
        let s = chain.forward(q);
        let qd = s
            .jacobian_v()
            .try_inverse()
            .map_or_else(Vector3::zeros, |inv| inv * sp.velocity);
        // The torque box's statics: the contact point's Jᵀ and g(q).
        let n = sp.center.normalize();
        let statics = self.hand.statics(k, q, &n);
        let mut tau = if self.gains.compensate_weight {
            statics.bias
        } else {
            Vector3::zeros()
        };
        tau += statics.force_to_torque * sp.force;
        for i in 0..JOINTS {
            tau[i] += self.gains.damping[i] * qd[i];
        }
        let limit = chain.effort();
        out.joint_count = JOINTS as u32;
        out.joint_position = [0.0; MAX_JOINTS];
        out.joint_velocity = [0.0; MAX_JOINTS];
        out.joint_torque = [0.0; MAX_JOINTS];
        out.kp = [0.0; MAX_JOINTS];
        out.kd = [0.0; MAX_JOINTS];
        for i in 0..JOINTS {
            out.joint_position[i] = q[i];
            out.joint_velocity[i] = qd[i];
            out.joint_torque[i] = tau[i].clamp(-limit[i], limit[i]);
            out.kp[i] = self.gains.kp[i];
            out.kd[i] = self.gains.kd[i];
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The shipped TriFingerPro, commanded with TriFinger's gains.
    pub(crate) fn trifingerpro(compensate_weight: bool) -> JointLink {
        let d = kinematics::HandDescription::parse(
            include_str!("../../../deploy/hands/trifingerpro/trifingerpro.urdf"),
            include_str!("../../../deploy/hands/trifingerpro/hand.toml"),
        )
        .unwrap();
        let limits = kinematics::GraspLimits {
            margins: kinematics::Margins {
                patch: 0.0,
                clearance: 0.0,
            },
            finger_gap: 0.0,
        };
        let gains = JointGains {
            kp: [9.0; 3],
            kd: [0.01; 3],
            compensate_weight,
            // TriFinger's safety damping where the weight is compensated
            // (the shipped configuration); none otherwise.
            damping: if compensate_weight {
                [0.09, 0.09, 0.05]
            } else {
                [0.0; 3]
            },
        };
        JointLink::new(ChainHand::new(&d, limits).unwrap(), gains)
    }

    /// The tip centre of finger `k` at `q` in the hand frame.
    fn tip_at(link: &JointLink, k: usize, q: &Vector3<f64>) -> Vector3<f64> {
        link.hand.chain(k).forward(q).tip_centre()
    }

    /// The command's joints, velocities and torques against the test's own
    /// numbers: velocities that move the tip (by numeric differentiation
    /// of forward kinematics) at the setpoint's velocity; torques whose
    /// virtual work on a small joint motion equals that of the grip
    /// pressing at the contact point plus the links' weight and the hand's
    /// damping at the commanded rate (numeric
    /// differentiation of the contact point and of the links' potential
    /// energy, the masses and centres from the URDF).
    #[test]
    fn joint_commands_move_the_tip_and_press_with_the_grip() {
        let link = trifingerpro(true);
        let h = &link.hand;
        let q = Vector3::new(0.3, 0.9, -1.8);
        let g = *h.gravity();
        for k in 0..3 {
            let chain = h.chain(k);
            let center = tip_at(&link, k, &q) - h.object().centre;
            let sp = FingerSetpoint {
                joints: q,
                center,
                velocity: Vector3::new(0.01, -0.02, 0.005),
                force: Vector3::zeros(),
            };
            let mut out = PlantFingerCommand::default();
            link.command(k, &sp, &mut out);
            assert_eq!(out.joint_count, 3);
            assert_eq!(out.joint_position[..3], [q.x, q.y, q.z]);
            assert_eq!(out.joint_position[3], 0.0);
            assert_eq!(
                (out.kp, out.kd),
                ([9.0, 9.0, 9.0, 0.0], [0.01, 0.01, 0.01, 0.0])
            );
            let qd = Vector3::new(
                out.joint_velocity[0],
                out.joint_velocity[1],
                out.joint_velocity[2],
            );
            let eps = 1e-7;
            let moved = (tip_at(&link, k, &(q + qd * eps)) - tip_at(&link, k, &(q - qd * eps)))
                / (2.0 * eps);
            assert!(
                (moved - sp.velocity).norm() < 1e-6,
                "{moved} vs {}",
                sp.velocity
            );
            // Virtual work per joint: τ_i = ∂(contact point)/∂q_i · f
            // + ∂V/∂q_i, V = −Σ m_j g·c_j the links' potential energy; the
            // contact point is the tip's material point there, and the
            // force a push of 0.8 N with a tangential part.
            let n = center.normalize();
            let side = n.cross(&Vector3::z()).normalize();
            let f = -n * 0.8 + side * 0.3;
            let sp = FingerSetpoint { force: f, ..sp };
            let mut out = PlantFingerCommand::default();
            link.command(k, &sp, &mut out);
            let local = chain.forward(&q).tip.rotation.transpose() * (-n * chain.tip_radius);
            let contact = |q: &Vector3<f64>| {
                let s = chain.forward(q);
                s.tip_centre() + s.tip.rotation * local
            };
            let potential = |q: &Vector3<f64>| {
                let s = chain.forward(q);
                (0..3)
                    .map(|j| {
                        -chain.bodies[j].mass * g.dot(&s.joints[j].point(&chain.bodies[j].com))
                    })
                    .sum::<f64>()
            };
            for i in 0..3 {
                let mut d = Vector3::zeros();
                d[i] = eps;
                let dc = (contact(&(q + d)) - contact(&(q - d))) / (2.0 * eps);
                let dv = (potential(&(q + d)) - potential(&(q - d))) / (2.0 * eps);
                // The hand's damping at the commanded rate.
                let damping = [0.09, 0.09, 0.05][i] * qd[i];
                let want = (dc.dot(&f) + dv + damping).clamp(-chain.effort()[i], chain.effort()[i]);
                assert!(
                    (out.joint_torque[i] - want).abs() < 1e-6,
                    "finger {k} joint {i}: {} vs {want}",
                    out.joint_torque[i]
                );
            }
        }
        // Free, uncompensated: no torque at all; a singular finger (the
        // lower link straight) gets no velocity rather than a huge one.
        let link = trifingerpro(false);
        let straight = Vector3::new(0.0, 0.5, 0.0);
        let sp = FingerSetpoint {
            joints: straight,
            center: tip_at(&link, 0, &straight) - link.hand.object().centre,
            velocity: Vector3::new(0.0, 0.0, 0.01),
            force: Vector3::zeros(),
        };
        let mut out = PlantFingerCommand::default();
        link.command(0, &sp, &mut out);
        assert_eq!(out.joint_torque, [0.0; 4]);
        assert!(
            out.joint_velocity
                .iter()
                .all(|v| v.is_finite() && v.abs() < 10.0)
        );
    }

    /// A grip larger than the motors give is clipped at their limits.
    #[test]
    fn feed_forward_torques_stay_within_the_motors() {
        let link = trifingerpro(true);
        let q = Vector3::new(0.3, 0.9, -1.8);
        let center = tip_at(&link, 1, &q) - link.hand.object().centre;
        let sp = FingerSetpoint {
            joints: q,
            center,
            velocity: Vector3::zeros(),
            force: -center.normalize() * 1000.0,
        };
        let mut out = PlantFingerCommand::default();
        link.command(1, &sp, &mut out);
        let limit = link.hand.chain(1).effort();
        assert!((0..3).all(|i| out.joint_torque[i].abs() <= limit[i]));
        assert!((0..3).any(|i| out.joint_torque[i].abs() == limit[i]));
    }

    /// The measured tip is forward kinematics, relative to the object's
    /// centre.
    #[test]
    fn a_measured_tip_is_where_its_joints_put_it() {
        let link = trifingerpro(true);
        let q = Vector3::new(0.2, 1.0, -1.5);
        for k in 0..3 {
            let t = link.tip(k, &q);
            let s = link.hand.chain(k).forward(&q);
            assert!((t.center + link.hand.object().centre - s.tip_centre()).norm() < 1e-15);
            let r = t.orientation.to_rotation_matrix();
            assert!((r.matrix() - s.tip.rotation).norm() < 1e-12);
        }
    }
}
