//! The one configuration struct of the model (SPEC.md §1.1, §3.3, §5).
//!
//! Defaults are the paper's simulation values (paper §4). Angles are given in
//! degrees (keys ending in `_deg`), everything else in SI units. A
//! [`HandConfig`] is only used after [`HandConfig::validate`] accepted it; the
//! error names the offending key exactly as it is spelt in the TOML file
//! (`section.key`), so a user can find it.
//!
//! The types and their defaults live here; the checks, one function per
//! section with its keys' names, in `validate.rs`.

use serde::{Deserialize, Serialize};

mod validate;

/// Why a configuration was refused. Every variant names the key.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ConfigError {
    /// A number is NaN or infinite.
    #[error("config key `{key}` must be a finite number (got {value})")]
    NotFinite {
        /// Key, as written in the TOML file.
        key: &'static str,
        /// The value found.
        value: f64,
    },
    /// A number lies outside its allowed range.
    #[error("config key `{key}` = {value} is out of range: {expected}")]
    OutOfRange {
        /// Key, as written in the TOML file.
        key: &'static str,
        /// The value found.
        value: f64,
        /// The allowed range, in words.
        expected: &'static str,
    },
    /// Two keys contradict each other.
    #[error("config keys `{key}` and `{other}` are inconsistent: {why}")]
    Inconsistent {
        /// First key.
        key: &'static str,
        /// Second key.
        other: &'static str,
        /// What is wrong, in words.
        why: &'static str,
    },
}

/// Geometry, friction, workspace and margins of the hand and object
/// (SPEC §1.1; TOML section `[model]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ModelConfig {
    /// Object sphere radius R \[m\] (paper: 0.5).
    pub object_radius: f64,
    /// Fingertip sphere radius r \[m\] (paper: 0.1).
    pub fingertip_radius: f64,
    /// Friction angle θ, μ = tan θ \[deg\] (paper: 20°).
    pub friction_angle_deg: f64,
    /// Torsional friction ratio: μ_t = ratio · r · μ (SPEC §1.2, default 0.1).
    pub torsion_ratio: f64,
    /// Azimuths φ_k of the finger base directions d_k in the xy-plane \[deg\].
    pub finger_azimuth_deg: [f64; 3],
    /// Half angle β of each finger's workspace cone on the object \[deg\] (paper: 60°).
    pub workspace_half_angle_deg: f64,
    /// Height δR of the free-space shell above the object surface \[m\].
    pub free_space_height: f64,
    /// Fingertip roll limit γ about its pole axis \[deg\] (paper: 60°).
    pub roll_limit_deg: f64,
    /// Minimum gap between two fingertip spheres \[m\].
    pub fingertip_clearance: f64,
    /// Angle margin kept inside the force-closure boundary (Fact 3) \[deg\].
    pub fc_margin_deg: f64,
    /// Angle margin kept inside the workspace cones \[deg\].
    pub workspace_margin_deg: f64,
    /// Margin kept inside the roll limit \[deg\].
    pub roll_margin_deg: f64,
    /// How far a grasping fingertip centre may be from the contact sphere
    /// |p| = R + r before the contact counts as broken (SPEC §1.3 I5,
    /// object centre fixed) \[m\].
    pub contact_tolerance: f64,
    /// Largest per-step difference |R Δ_o − r Δ_f| between the arcs
    /// travelled by the two contact points of a grasping finger, and
    /// (divided by r) the largest spin about the normal per step in a
    /// two-finger grasp, before the step counts as slipping (SPEC §1.3 I5) \[m\].
    pub slip_tolerance: f64,
}

impl Default for ModelConfig {
    fn default() -> Self {
        Self {
            object_radius: 0.5,
            fingertip_radius: 0.1,
            friction_angle_deg: 20.0,
            torsion_ratio: 0.1,
            finger_azimuth_deg: [0.0, 120.0, 240.0],
            workspace_half_angle_deg: 60.0,
            free_space_height: 0.05,
            roll_limit_deg: 60.0,
            fingertip_clearance: 0.005,
            fc_margin_deg: 2.0,
            workspace_margin_deg: 1.0,
            roll_margin_deg: 1.0,
            contact_tolerance: 1e-4,
            slip_tolerance: 1e-4,
        }
    }
}

/// Object load for grasp-force optimisation (SPEC §3.3; TOML section `[load]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LoadConfig {
    /// Object mass m \[kg\].
    pub object_mass: f64,
    /// Gravity vector g in the hand frame [m/s²].
    pub gravity: [f64; 3],
    /// Extra force \[N\] the grasp must resist in any direction on top of the
    /// weight (the disturbance margin of SPEC §3.3).
    pub disturbance_force: f64,
    /// Extra torque [N·m] the grasp must resist about any axis.
    pub disturbance_torque: f64,
    /// Least normal force a grasping finger presses with \[N\] (keeps the
    /// contact sensed and loaded).
    pub min_grip: f64,
    /// Largest normal force a fingertip can apply \[N\]: no grasp the
    /// planner makes needs more to hold the load (SPEC §1.3 I1'), and no
    /// commanded grip exceeds it. Default 20 N, a typical fingertip force
    /// of a dexterous hand and the limit SPEC §3.3's load figures are given
    /// for (a 0.1 kg object then needs near-antipodal pairs in planes
    /// close to vertical).
    pub max_grip: f64,
    /// Time for the grip to pass from one finger to another with the
    /// object still \[s\]: after a placement the new finger's force ramps
    /// in while the one that lifts next ramps out (and before any other
    /// lift), so no contact force jumps. 0: no ramp (forces jump at each
    /// gait).
    pub handover_time: f64,
}

impl Default for LoadConfig {
    fn default() -> Self {
        Self {
            object_mass: 0.1,
            gravity: [0.0, 0.0, -9.81],
            disturbance_force: 0.5,
            disturbance_torque: 0.0,
            min_grip: 1.0,
            max_grip: 20.0,
            handover_time: 0.15,
        }
    }
}

/// Velocity, acceleration and jerk limit of one motion kind (SPEC §5).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionLimit {
    /// Maximum velocity (> 0).
    pub velocity: f64,
    /// Maximum acceleration (> 0).
    pub acceleration: f64,
    /// Maximum jerk (> 0).
    pub jerk: f64,
}

/// Motion limits (SPEC §5; TOML section `[limits]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LimitsConfig {
    /// Object rotation [rad/s, rad/s², rad/s³].
    pub object: MotionLimit,
    /// Fingertip centre translation in free space [m/s, m/s², m/s³].
    pub fingertip: MotionLimit,
    /// Rolling: fingertip angular velocity relative to the object [rad/s, …].
    pub rolling: MotionLimit,
}

impl Default for LimitsConfig {
    fn default() -> Self {
        Self {
            object: MotionLimit {
                velocity: 1.0,
                acceleration: 4.0,
                jerk: 40.0,
            },
            fingertip: MotionLimit {
                velocity: 0.5,
                acceleration: 4.0,
                jerk: 40.0,
            },
            // "same acc/jerk ratios" as the object: a/v = 4 /s, j/a = 10 /s.
            rolling: MotionLimit {
                velocity: 2.0,
                acceleration: 8.0,
                jerk: 80.0,
            },
        }
    }
}

/// Planner tuning (SPEC §4; TOML section `[planner]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerConfig {
    /// Height above the contact surface at which free fingertips hover and
    /// travel \[m\]; at most `model.free_space_height`.
    pub transfer_height: f64,
    /// Spacing of the candidate contact grid in each workspace cone \[deg\].
    pub candidate_spacing_deg: f64,
    /// Children kept per relocation pattern in the search.
    pub branching: u32,
    /// Search budget in node expansions, over every pass of a request:
    /// what bounds planning where no clock may (lockstep runs, offline
    /// planning); a request that spends it is refused as `PlanTimeout`.
    pub max_expansions: u32,
    /// Wall-clock budget of one request \[ms\], for a caller that has a
    /// clock (the daemon in real time): planning never runs longer, and a
    /// request that needs longer is refused as `PlanTimeout`. The library
    /// reads no clock; its caller enforces this (with `max_expansions`).
    pub budget_ms: f64,
    /// Directions a pair may first turn about: from a root, as far as it
    /// can and half as far (0: never); from a grasp no gait can leave
    /// (paper Theory 1 fails, SPEC §4.3), the least turn that lets one.
    pub detour_axes: u32,
    /// Directions tried from a grasp no gait can leave.
    pub escape_axes: u32,
    /// Extra separation \[deg\] beyond the force-closure boundary (with its
    /// margin) of every pair the planner makes, and the extra the roll
    /// from a three-finger start aims for. Pairs near the boundary need
    /// huge grip forces to hold any load (SPEC §3.3; the MuJoCo oracle's
    /// pitfall 5), so wider pairs make executable plans.
    pub pair_margin_deg: f64,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            transfer_height: 0.03,
            candidate_spacing_deg: 6.0,
            branching: 3,
            max_expansions: 30_000,
            budget_ms: 2000.0,
            detour_axes: 48,
            escape_axes: 64,
            pair_margin_deg: 1.0,
        }
    }
}

/// Feedback and fault detection of the controller (SPEC §6.3; TOML section
/// `[feedback]`). The defaults suit the embedded kinematic hand, which
/// follows setpoints exactly; a physical plant needs looser tolerances.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FeedbackConfig {
    /// Largest measured-vs-commanded object orientation error before a
    /// fault \[deg\].
    pub object_tolerance_deg: f64,
    /// Largest measured-vs-commanded fingertip position error before a
    /// fault \[m\].
    pub finger_tolerance: f64,
    /// Largest drift of a grasping contact point over the object surface
    /// (slip) \[m\]. Beyond it the motion stops smoothly and the goal is
    /// replanned from the measured state (SPEC §6.3); a fault once
    /// `max_replans` is used up, or if the drift goes on during the stop.
    pub contact_tolerance: f64,
    /// Replans after contact drift or an invariant near its limit allowed
    /// per goal (0: either is a fault).
    pub max_replans: u32,
    /// While moving, the *measured* state must keep at least this fraction
    /// of each margin (workspace cone, two-finger force closure, fingertip
    /// clearance) to the invariant's true limit; closer for a few ticks in
    /// a row, the motion stops smoothly and the goal is replanned (SPEC
    /// §6.3 "an invariant near its limit"; `executor::guard`). 0 disables
    /// the check. Only a plant whose measurement differs from the command
    /// pays for it.
    pub limit_guard: f64,
    /// A fingertip that moves less than this fraction of its commanded
    /// motion in one tick (while commanded to move) is stuck; 0 disables
    /// the check.
    pub stall_ratio: f64,
    /// Gain of the object orientation error (measured against planned)
    /// fed back into the fingertip setpoints: the commanded grasp is turned
    /// about the object centre by a correction that integrates the error at
    /// this rate, so a hand that lags or creeps still brings the object to
    /// the plan (SPEC §6.3) [1/s]; 0 disables it.
    pub orientation_gain: f64,
    /// Largest correction of the commanded grasp \[deg\]: it uses up
    /// workspace margin, so it stays well inside `model.workspace_margin_deg`.
    pub max_correction_deg: f64,
    /// Longest offset by which a fingertip is placed where the object is
    /// measured rather than where the model puts it (a plant that measures
    /// the object centre; `executor::placement`) \[m\]; 0 disables it.
    pub max_place_offset: f64,
    /// A grasping contact measured as not touching (its contact flag, or a
    /// measured normal force below `min_contact_force`) this many ticks in
    /// a row is lost: a fault (a plant's flags lag a placement or lift by a
    /// few ticks).
    pub contact_grace_ticks: u32,
    /// Measured normal force below which a contact counts as not touching
    /// (plants that measure forces) \[N\].
    pub min_contact_force: f64,
    /// Share of each new sample of the object's pose taken into the
    /// object's estimate (a tracking system's noise averaged over samples;
    /// `executor::tracking`): 1 takes each sample as it is, 0.25 averages
    /// the error over about 7 samples. Each sample is compared with the
    /// plan at the tick it was taken (`object_age_us` of the plant's
    /// measurement) whatever the gain.
    pub tracker_gain: f64,
}

impl Default for FeedbackConfig {
    fn default() -> Self {
        Self {
            object_tolerance_deg: 0.1,
            finger_tolerance: 0.0005,
            contact_tolerance: 0.0005,
            max_replans: 3,
            limit_guard: 0.5,
            stall_ratio: 0.1,
            orientation_gain: 10.0,
            max_correction_deg: 0.5,
            max_place_offset: 0.002,
            contact_grace_ticks: 50,
            min_contact_force: 0.05,
            tracker_gain: 1.0,
        }
    }
}

/// Everything the model, planner and controller need (SPEC §1.1, §3.3, §5).
///
/// Deserialises from TOML with sections `[model]`, `[load]`, `[limits]`;
/// missing keys take the paper's defaults, unknown keys are refused.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HandConfig {
    /// Geometry, friction, workspace, margins.
    pub model: ModelConfig,
    /// Object load for grasp forces.
    pub load: LoadConfig,
    /// Motion limits.
    pub limits: LimitsConfig,
    /// Planner tuning.
    pub planner: PlannerConfig,
    /// Feedback and fault detection.
    pub feedback: FeedbackConfig,
}

impl HandConfig {
    /// Friction coefficient μ = tan θ.
    pub fn mu(&self) -> f64 {
        self.model.friction_angle_deg.to_radians().tan()
    }

    /// Torsional friction coefficient μ_t = ratio · r · μ (SPEC §1.2) \[m\].
    pub fn mu_torsion(&self) -> f64 {
        self.model.torsion_ratio * self.model.fingertip_radius * self.mu()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_papers_and_valid() {
        let c = HandConfig::default();
        c.validate().unwrap();
        assert!((c.mu() - 0.36397).abs() < 1e-5);
        assert_eq!(c.model.object_radius, 0.5);
        assert_eq!(c.model.fingertip_radius, 0.1);
    }

    #[test]
    fn bad_values_name_their_key() {
        let mut c = HandConfig::default();
        c.model.roll_limit_deg = f64::NAN;
        let e = c.validate().unwrap_err();
        assert!(e.to_string().contains("model.roll_limit_deg"), "{e}");

        let mut c = HandConfig::default();
        c.limits.fingertip.jerk = 0.0;
        let e = c.validate().unwrap_err();
        assert!(e.to_string().contains("limits.fingertip.jerk"), "{e}");

        let mut c = HandConfig::default();
        c.model.fingertip_radius = 0.6;
        let e = c.validate().unwrap_err();
        assert!(e.to_string().contains("model.fingertip_radius"), "{e}");

        for g in [0.0, 1.5, f64::NAN] {
            let mut c = HandConfig::default();
            c.feedback.tracker_gain = g;
            let e = c.validate().unwrap_err();
            assert!(e.to_string().contains("feedback.tracker_gain"), "{e}");
        }
    }

    #[test]
    fn toml_partial_and_unknown_keys() {
        let c: HandConfig = toml::from_str("[model]\nroll_limit_deg = 45\n").unwrap();
        assert_eq!(c.model.roll_limit_deg, 45.0);
        assert_eq!(c.model.object_radius, 0.5);
        let e = toml::from_str::<HandConfig>("[model]\nroll_limt_deg = 45\n").unwrap_err();
        assert!(e.to_string().contains("roll_limt_deg"), "{e}");
    }
}
