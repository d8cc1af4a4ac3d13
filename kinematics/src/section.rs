//! The gaitd hand section (TOML): what a URDF does not say.
//!
//! ```toml
//! urdf = "trifingerpro.urdf"      # for the caller, who reads the file
//! frame = "base_link"             # hand frame link (default: the URDF root)
//! joint_limit_margin = 0.05       # [rad], kept from every joint limit
//! gravity = [0.0, 0.0, -9.81]     # [m/s²] in the hand frame
//!
//! [object]                        # the sphere held (SPEC §14.1)
//! radius = 0.0335                 # R [m]
//! mass = 0.058                    # [kg]
//! centre = [0.0, 0.0, 0.08]       # O in the hand frame [m]
//!
//! [friction]
//! mu = 0.6                        # Coulomb coefficient of tip on object
//! torsion = 0.0006                # μ_t [m]: torque ≤ μ_t · normal force
//!
//! [[finger]]
//! name = "finger_0"
//! base = "finger_base_link_0"
//! tip = "finger_tip_link_0"
//! tip_radius = 0.010              # optional where the tip link has a sphere
//! tip_pole = [0.0, 0.0, -1.0]     # p in tip coordinates (default −z)
//! tip_patch_deg = 90.0            # α: contacts within α of the pole
//! ```
//!
//! Unknown keys are errors (a misspelt key must not silently fall back to
//! a default).

use serde::Deserialize;

/// The hand section as written (before checking it against the URDF).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandSection {
    /// The URDF file, relative to the section's file. Not read here: the
    /// caller reads it and hands its text to [`crate::HandDescription::parse`].
    #[serde(default)]
    pub urdf: Option<String>,
    /// The link whose frame is the hand frame (default: the URDF root).
    #[serde(default)]
    pub frame: Option<String>,
    /// Margin kept inside every joint's position limits \[rad\] (default 0.05).
    #[serde(default = "default_margin")]
    pub joint_limit_margin: f64,
    /// Gravity in the hand frame \[m/s²\] (default (0, 0, −9.81)).
    #[serde(default = "default_gravity")]
    pub gravity: [f64; 3],
    /// The object.
    pub object: ObjectSection,
    /// Friction between tips and object.
    pub friction: FrictionSection,
    /// The fingers, in order.
    #[serde(default)]
    pub finger: Vec<FingerSection>,
}

/// The object: a sphere at a fixed point of the hand frame (SPEC §14.1).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSection {
    /// Radius R \[m\].
    pub radius: f64,
    /// Mass \[kg\].
    pub mass: f64,
    /// Centre O in the hand frame \[m\].
    pub centre: [f64; 3],
}

/// Friction at a tip contact (SPEC §1.2).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSection {
    /// Coulomb coefficient μ.
    pub mu: f64,
    /// Torsional coefficient μ_t \[m\] of the soft-finger model.
    pub torsion: f64,
}

/// One finger.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FingerSection {
    /// Name (unique).
    pub name: String,
    /// Link the chain starts from (fixed in the hand frame).
    pub base: String,
    /// Link whose frame is the tip frame (the tip sphere's centre).
    pub tip: String,
    /// Tip radius r \[m\]; optional when the tip link has a collision sphere
    /// centred at its origin.
    #[serde(default)]
    pub tip_radius: Option<f64>,
    /// The tip's pole p in tip coordinates (default (0, 0, −1)).
    #[serde(default = "default_pole")]
    pub tip_pole: [f64; 3],
    /// Half-angle α of the contactable patch around the pole \[deg\] (default 90).
    #[serde(default = "default_patch")]
    pub tip_patch_deg: f64,
}

fn default_margin() -> f64 {
    0.05
}

fn default_gravity() -> [f64; 3] {
    [0.0, 0.0, -9.81]
}

fn default_pole() -> [f64; 3] {
    [0.0, 0.0, -1.0]
}

fn default_patch() -> f64 {
    90.0
}
