//! `[hand]`: which hand model the daemon plans and checks for — the
//! paper's free fingertips (`[model]`), or a hand of finger joint chains
//! described by a URDF and its hand section (SPEC §14; the shipped
//! TriFingerPro: `deploy/hands/trifingerpro/`).

use super::KeyError;
use serde::{Deserialize, Serialize};

/// The hand model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum HandKind {
    /// Free 6-DoF fingertips at `[model]`'s geometry (the paper's).
    #[default]
    Fingertips,
    /// Finger joint chains: the geometry, friction, object and gravity
    /// come from `hand.description`, and `[model]`'s geometry keys are not
    /// used.
    Chains,
}

/// `[hand]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HandSection {
    /// `"fingertips"` (default) or `"chains"`.
    pub kind: HandKind,
    /// Chains: the hand section file (TOML) of the description, which
    /// names its URDF; relative paths are from the configuration file's
    /// folder.
    pub description: String,
    /// Chains: kept inside each tip's contact patch \[deg\].
    pub patch_margin_deg: f64,
    /// Chains: every link capsule kept this far off the object \[m\].
    pub link_clearance: f64,
    /// Chains: two fingers' capsules kept this far apart \[m\].
    pub finger_gap: f64,
    /// Chains: the grasp the embedded hand starts in — per finger, the
    /// contact's outward normal on the object (hand frame, object at its
    /// start orientation; any length). An external plant's first
    /// measurement gives the start instead.
    pub start_normals: Vec<[f64; 3]>,
    /// Chains on an external plant: each joint's position gain, base to
    /// tip, the same on every finger \[N·m/rad\].
    pub joint_kp: [f64; 3],
    /// Chains on an external plant: each joint's velocity gain \[N·m·s/rad\].
    pub joint_kd: [f64; 3],
    /// Chains on an external plant: the commanded feed-forward torque
    /// holds the links' weight (the hand does not).
    pub compensate_link_weight: bool,
    /// Chains on an external plant: the viscous damping the hand's own
    /// driver applies against each joint's rate, base to tip (TriFinger's
    /// safety damping); the feed-forward torque supplies it at the
    /// commanded rate, so that the joints move as commanded rather than
    /// lag until the position gain makes it up \[N·m·s/rad\].
    pub joint_damping: [f64; 3],
}

impl Default for HandSection {
    fn default() -> Self {
        Self {
            kind: HandKind::Fingertips,
            description: String::new(),
            patch_margin_deg: 5.0,
            link_clearance: 0.005,
            finger_gap: 0.005,
            start_normals: Vec::new(),
            // TriFingerPro's default position control (robot_fingers).
            joint_kp: [9.0; 3],
            joint_kd: [0.01; 3],
            compensate_link_weight: true,
            joint_damping: [0.0; 3],
        }
    }
}

impl HandSection {
    /// Whether the hand is a chain hand.
    pub fn chains(&self) -> bool {
        self.kind == HandKind::Chains
    }

    /// The margins kept beyond the joint limits' own (tip patch, link
    /// clearance, finger gap).
    pub fn grasp_limits(&self) -> kinematics::GraspLimits {
        kinematics::GraspLimits {
            margins: kinematics::Margins {
                patch: self.patch_margin_deg.to_radians(),
                clearance: self.link_clearance,
            },
            finger_gap: self.finger_gap,
        }
    }

    /// Checks the keys on their own (the description is read at start-up
    /// and by `--check-config`).
    pub fn validate(&self) -> Result<(), KeyError> {
        let bad = |key, why| Err(KeyError::Invalid { key, why });
        if !(0.0..90.0).contains(&self.patch_margin_deg) {
            return bad("hand.patch_margin_deg", "must be in [0, 90) degrees");
        }
        if !(self.link_clearance >= 0.0 && self.link_clearance.is_finite()) {
            return bad("hand.link_clearance", "must be ≥ 0 and finite [m]");
        }
        if !(self.finger_gap >= 0.0 && self.finger_gap.is_finite()) {
            return bad("hand.finger_gap", "must be ≥ 0 and finite [m]");
        }
        let gain = |g: &[f64; 3]| g.iter().all(|x| *x >= 0.0 && x.is_finite());
        if !gain(&self.joint_kp) {
            return bad(
                "hand.joint_kp",
                "every gain must be ≥ 0 and finite [N·m/rad]",
            );
        }
        if !gain(&self.joint_kd) {
            return bad(
                "hand.joint_kd",
                "every gain must be ≥ 0 and finite [N·m·s/rad]",
            );
        }
        if !gain(&self.joint_damping) {
            return bad(
                "hand.joint_damping",
                "every coefficient must be ≥ 0 and finite [N·m·s/rad]",
            );
        }
        if !self.chains() {
            return Ok(());
        }
        if self.description.is_empty() {
            return bad(
                "hand.description",
                "a chain hand needs its description: the hand section file (TOML) that names its URDF",
            );
        }
        if self.start_normals.len() != 3 {
            return bad(
                "hand.start_normals",
                "a chain hand needs its start grasp: one contact normal per finger, three",
            );
        }
        let usable = |n: &[f64; 3]| {
            n.iter().all(|x| x.is_finite()) && n.iter().map(|x| x * x).sum::<f64>() > 1e-12
        };
        if !self.start_normals.iter().all(usable) {
            return bad(
                "hand.start_normals",
                "every normal must be finite and not zero",
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chains(normals: Vec<[f64; 3]>) -> HandSection {
        HandSection {
            kind: HandKind::Chains,
            description: "hand.toml".into(),
            start_normals: normals,
            ..HandSection::default()
        }
    }

    #[test]
    fn a_chain_hand_needs_three_usable_start_normals() {
        let n = [0.0, 0.0, 1.0];
        assert_eq!(chains(vec![n; 3]).validate(), Ok(()));
        for bad in [
            vec![n; 2],
            vec![n, n, [0.0; 3]],
            vec![n, n, [f64::NAN, 0.0, 1.0]],
        ] {
            match chains(bad.clone()).validate() {
                Err(KeyError::Invalid { key, .. }) => assert_eq!(key, "hand.start_normals"),
                other => panic!("{bad:?}: {other:?}"),
            }
        }
        // The fingertips need none of it.
        assert_eq!(HandSection::default().validate(), Ok(()));
    }
}
