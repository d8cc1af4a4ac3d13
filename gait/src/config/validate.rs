//! The checks of [`HandConfig::validate`], one function per TOML section
//! with its keys' names. The order of the calls decides which key is named
//! when several are wrong, and is kept as it always was.

use super::{
    ConfigError, FeedbackConfig, HandConfig, LimitsConfig, LoadConfig, ModelConfig, MotionLimit,
    PlannerConfig,
};

fn finite(key: &'static str, value: f64) -> Result<f64, ConfigError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ConfigError::NotFinite { key, value })
    }
}

/// `lo < value <= hi` (open below, closed above).
fn in_range(
    key: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    expected: &'static str,
) -> Result<(), ConfigError> {
    finite(key, value)?;
    if value > lo && value <= hi {
        Ok(())
    } else {
        Err(ConfigError::OutOfRange {
            key,
            value,
            expected,
        })
    }
}

/// `lo <= value <= hi`.
fn in_closed(
    key: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    expected: &'static str,
) -> Result<(), ConfigError> {
    finite(key, value)?;
    if (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(ConfigError::OutOfRange {
            key,
            value,
            expected,
        })
    }
}

impl MotionLimit {
    fn validate(&self, keys: [&'static str; 3]) -> Result<(), ConfigError> {
        let expected = "> 0 and at most 1e6";
        in_range(keys[0], self.velocity, 0.0, 1e6, expected)?;
        in_range(keys[1], self.acceleration, 0.0, 1e6, expected)?;
        in_range(keys[2], self.jerk, 0.0, 1e6, expected)
    }
}

impl HandConfig {
    /// Checks every key; the first failure is returned, naming its key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.model.validate()?;
        self.load.validate_load()?;
        self.planner.validate(&self.model)?;
        self.feedback.validate()?;
        self.load.validate_grip()?;
        self.limits.validate()
    }
}

impl ModelConfig {
    /// `[model]`: geometry, friction, workspace, margins, tolerances.
    fn validate(&self) -> Result<(), ConfigError> {
        self.validate_geometry()?;
        self.validate_margins()?;
        self.validate_consistency()
    }

    /// Sizes, friction, finger directions, workspace, free space, roll
    /// limit, clearance.
    fn validate_geometry(&self) -> Result<(), ConfigError> {
        let m = self;
        in_range(
            "model.object_radius",
            m.object_radius,
            0.0,
            100.0,
            "> 0 m and at most 100 m",
        )?;
        in_range(
            "model.fingertip_radius",
            m.fingertip_radius,
            0.0,
            m.object_radius,
            "> 0 m and at most model.object_radius",
        )?;
        in_range(
            "model.friction_angle_deg",
            m.friction_angle_deg,
            0.0,
            60.0,
            "in (0°, 60°]",
        )?;
        in_range(
            "model.torsion_ratio",
            m.torsion_ratio,
            0.0,
            10.0,
            "in (0, 10]",
        )?;
        for a in m.finger_azimuth_deg {
            in_closed(
                "model.finger_azimuth_deg",
                a,
                -360.0,
                360.0,
                "each in [-360°, 360°]",
            )?;
        }
        in_range(
            "model.workspace_half_angle_deg",
            m.workspace_half_angle_deg,
            0.0,
            90.0,
            "in (0°, 90°]",
        )?;
        in_range(
            "model.free_space_height",
            m.free_space_height,
            0.0,
            m.object_radius,
            "> 0 m and at most model.object_radius",
        )?;
        in_range(
            "model.roll_limit_deg",
            m.roll_limit_deg,
            0.0,
            180.0,
            "in (0°, 180°]",
        )?;
        in_closed(
            "model.fingertip_clearance",
            m.fingertip_clearance,
            0.0,
            m.object_radius,
            "in [0, model.object_radius] m",
        )?;
        Ok(())
    }

    /// Margins kept inside the limits, contact and slip tolerances.
    fn validate_margins(&self) -> Result<(), ConfigError> {
        let m = self;
        in_closed(
            "model.fc_margin_deg",
            m.fc_margin_deg,
            0.0,
            10.0,
            "in [0°, 10°]",
        )?;
        in_closed(
            "model.workspace_margin_deg",
            m.workspace_margin_deg,
            0.0,
            m.workspace_half_angle_deg,
            "in [0°, model.workspace_half_angle_deg)",
        )?;
        in_closed(
            "model.roll_margin_deg",
            m.roll_margin_deg,
            0.0,
            m.roll_limit_deg,
            "in [0°, model.roll_limit_deg)",
        )?;
        in_range(
            "model.contact_tolerance",
            m.contact_tolerance,
            0.0,
            m.fingertip_radius,
            "> 0 m and at most model.fingertip_radius",
        )?;
        in_range(
            "model.slip_tolerance",
            m.slip_tolerance,
            0.0,
            m.fingertip_radius,
            "> 0 m and at most model.fingertip_radius",
        )?;
        Ok(())
    }

    /// Keys that must agree with each other.
    fn validate_consistency(&self) -> Result<(), ConfigError> {
        let m = self;
        if m.workspace_margin_deg >= m.workspace_half_angle_deg {
            return Err(ConfigError::Inconsistent {
                key: "model.workspace_margin_deg",
                other: "model.workspace_half_angle_deg",
                why: "the margin leaves no workspace",
            });
        }
        if m.roll_margin_deg >= m.roll_limit_deg {
            return Err(ConfigError::Inconsistent {
                key: "model.roll_margin_deg",
                other: "model.roll_limit_deg",
                why: "the margin leaves no roll range",
            });
        }
        // Fact 3 needs two contacts at least π − 2θ + margin apart.
        if 180.0 - 2.0 * m.friction_angle_deg + m.fc_margin_deg >= 180.0 {
            return Err(ConfigError::Inconsistent {
                key: "model.fc_margin_deg",
                other: "model.friction_angle_deg",
                why: "no two-finger grasp can be force-closure with this margin",
            });
        }
        Ok(())
    }
}

impl LoadConfig {
    /// `[load]`: mass, gravity and the disturbance to resist.
    fn validate_load(&self) -> Result<(), ConfigError> {
        let l = self;
        in_closed(
            "load.object_mass",
            l.object_mass,
            0.0,
            1e3,
            "in [0, 1000] kg",
        )?;
        for g in l.gravity {
            in_closed(
                "load.gravity",
                g,
                -100.0,
                100.0,
                "each component in [-100, 100] m/s²",
            )?;
        }
        in_closed(
            "load.disturbance_force",
            l.disturbance_force,
            0.0,
            1e4,
            "in [0, 1e4] N",
        )?;
        in_closed(
            "load.disturbance_torque",
            l.disturbance_torque,
            0.0,
            1e4,
            "in [0, 1e4] N·m",
        )?;
        Ok(())
    }

    /// `[load]`: the grip force range.
    fn validate_grip(&self) -> Result<(), ConfigError> {
        let l = self;
        in_closed("load.min_grip", l.min_grip, 0.0, 1e4, "in [0, 1e4] N")?;
        in_range(
            "load.max_grip",
            l.max_grip,
            l.min_grip,
            1e5,
            "> load.min_grip and at most 1e5 N",
        )?;
        in_closed(
            "load.handover_time",
            l.handover_time,
            0.0,
            10.0,
            "in [0, 10] s",
        )?;
        Ok(())
    }
}

impl PlannerConfig {
    /// `[planner]`; the transfer height must fit `model`'s free space.
    fn validate(&self, m: &ModelConfig) -> Result<(), ConfigError> {
        let p = self;
        in_range(
            "planner.transfer_height",
            p.transfer_height,
            0.0,
            m.free_space_height,
            "> 0 m and at most model.free_space_height",
        )?;
        in_range(
            "planner.candidate_spacing_deg",
            p.candidate_spacing_deg,
            0.5,
            20.0,
            "in (0.5°, 20°]",
        )?;
        in_range(
            "planner.branching",
            f64::from(p.branching),
            0.0,
            16.0,
            "in [1, 16]",
        )?;
        in_range(
            "planner.max_expansions",
            f64::from(p.max_expansions),
            0.0,
            1e6,
            "in [1, 1000000]",
        )?;
        in_range(
            "planner.budget_ms",
            p.budget_ms,
            0.0,
            6e5,
            "in (0, 600000] ms",
        )?;
        in_range(
            "planner.detour_axes",
            f64::from(p.detour_axes),
            -1.0,
            1024.0,
            "in [0, 1024]",
        )?;
        in_range(
            "planner.escape_axes",
            f64::from(p.escape_axes),
            3.0,
            4096.0,
            "in [4, 4096]",
        )?;
        // > 0: the roll from a three-finger start must end strictly inside
        // the force-closure margin (SPEC §4.3).
        in_range(
            "planner.pair_margin_deg",
            p.pair_margin_deg,
            0.0,
            30.0,
            "in (0°, 30°]",
        )?;
        Ok(())
    }
}

impl FeedbackConfig {
    /// `[feedback]`: tolerances, replans, guard, stall, gain.
    fn validate(&self) -> Result<(), ConfigError> {
        let fb = self;
        in_range(
            "feedback.object_tolerance_deg",
            fb.object_tolerance_deg,
            0.0,
            90.0,
            "in (0°, 90°]",
        )?;
        in_range(
            "feedback.finger_tolerance",
            fb.finger_tolerance,
            0.0,
            1.0,
            "in (0, 1] m",
        )?;
        in_range(
            "feedback.contact_tolerance",
            fb.contact_tolerance,
            0.0,
            1.0,
            "in (0, 1] m",
        )?;
        in_closed(
            "feedback.limit_guard",
            fb.limit_guard,
            0.0,
            1.0,
            "in [0, 1]",
        )?;
        in_closed(
            "feedback.stall_ratio",
            fb.stall_ratio,
            0.0,
            1.0,
            "in [0, 1]",
        )?;
        if fb.max_replans > 100 {
            return Err(ConfigError::OutOfRange {
                key: "feedback.max_replans",
                value: fb.max_replans as f64,
                expected: "at most 100",
            });
        }
        in_closed(
            "feedback.orientation_gain",
            fb.orientation_gain,
            0.0,
            1000.0,
            "in [0, 1000] 1/s",
        )?;
        in_closed(
            "feedback.max_correction_deg",
            fb.max_correction_deg,
            0.0,
            10.0,
            "in [0°, 10°]",
        )?;
        in_closed(
            "feedback.max_place_offset",
            fb.max_place_offset,
            0.0,
            0.01,
            "in [0, 0.01] m",
        )?;
        if !(1..=100_000).contains(&fb.contact_grace_ticks) {
            return Err(ConfigError::OutOfRange {
                key: "feedback.contact_grace_ticks",
                value: f64::from(fb.contact_grace_ticks),
                expected: "in [1, 100000] ticks",
            });
        }
        in_closed(
            "feedback.min_contact_force",
            fb.min_contact_force,
            0.0,
            1000.0,
            "in [0, 1000] N",
        )?;
        in_range(
            "feedback.tracker_gain",
            fb.tracker_gain,
            0.0,
            1.0,
            "in (0, 1]",
        )?;
        Ok(())
    }
}

impl LimitsConfig {
    /// `[limits.object]`, `[limits.fingertip]`, `[limits.rolling]`.
    fn validate(&self) -> Result<(), ConfigError> {
        let lim = self;
        lim.object.validate([
            "limits.object.velocity",
            "limits.object.acceleration",
            "limits.object.jerk",
        ])?;
        lim.fingertip.validate([
            "limits.fingertip.velocity",
            "limits.fingertip.acceleration",
            "limits.fingertip.jerk",
        ])?;
        lim.rolling.validate([
            "limits.rolling.velocity",
            "limits.rolling.acceleration",
            "limits.rolling.jerk",
        ])
    }
}
