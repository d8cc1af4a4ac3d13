//! A hand description: the URDF's chains plus the gaitd hand section (SPEC §14.4).
//!
//! [`HandDescription::parse`] takes the URDF text and the hand section's
//! text ([`HandDescription::load`]: the files, read by the caller's
//! reader) and builds, per finger, the chain of
//! revolute joints from its base link to its tip link:
//!
//! - the base frame in the hand frame (only fixed joints between them);
//! - per revolute joint $i$: its origin in the frame of joint $i-1$ (the
//!   base for $i = 1$; fixed joints in between are folded in), its unit
//!   axis in its own frame, its limits;
//! - the tip frame in the last joint's frame;
//! - per moving link: the mass and centre of mass of everything rigidly
//!   attached to it (fixed children merged), and its collision primitives as
//!   capsules ([`crate::capsule`]).
//!
//! The description holds `Vec`s (it is built once); [`crate::Chain`] is
//! its fixed-size, per-tick form. The walk through the URDF tree is in
//! the private `urdf_chain` submodule.

use nalgebra::{Unit, Vector3};
use urdf_rs::Robot;

use crate::capsule::LinkCapsule;
use crate::error::DescriptionError;
use crate::frame::Frame;
use crate::section::HandSection;

mod files;
mod urdf_chain;

pub use files::LoadError;

use urdf_chain::{Tree, finger};

/// A joint's limits as the URDF gives them (SPEC §14.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimits {
    /// Lower position limit \[rad\].
    pub lower: f64,
    /// Upper position limit \[rad\].
    pub upper: f64,
    /// Velocity limit \[rad/s\].
    pub velocity: f64,
    /// Torque limit τ_max \[N·m\].
    pub effort: f64,
}

/// A revolute joint of a chain.
#[derive(Debug, Clone, PartialEq)]
pub struct JointDescription {
    /// URDF joint name.
    pub name: String,
    /// Its frame at q = 0 in the previous joint's frame (the base for the first).
    pub origin: Frame,
    /// Unit rotation axis in its own frame; positive q turns right-handed about it.
    pub axis: Unit<Vector3<f64>>,
    /// Limits.
    pub limits: JointLimits,
}

/// Mass and centre of mass of a moving link (fixed children merged).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Mass \[kg\].
    pub mass: f64,
    /// Centre of mass in the frame of the joint that moves it \[m\].
    pub com: Vector3<f64>,
}

/// One finger's chain as described.
#[derive(Debug, Clone, PartialEq)]
pub struct FingerDescription {
    /// Finger name.
    pub name: String,
    /// Base link.
    pub base_link: String,
    /// Tip link.
    pub tip_link: String,
    /// Base frame in the hand frame.
    pub base: Frame,
    /// Revolute joints, base to tip.
    pub joints: Vec<JointDescription>,
    /// Tip frame in the last joint's frame.
    pub tip: Frame,
    /// Tip radius r \[m\].
    pub tip_radius: f64,
    /// Tip pole p (unit, tip coordinates).
    pub tip_pole: Unit<Vector3<f64>>,
    /// Patch half-angle α \[rad\].
    pub tip_patch: f64,
    /// Per joint i, the link it moves.
    pub bodies: Vec<Body>,
    /// Collision primitives as capsules (the tip sphere itself excluded).
    pub capsules: Vec<LinkCapsule>,
    /// Links whose mesh collision geometry was left out (no primitive).
    pub ignored_meshes: Vec<String>,
}

/// The object held (SPEC §14.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Object {
    /// Radius R \[m\].
    pub radius: f64,
    /// Mass \[kg\].
    pub mass: f64,
    /// Centre O in the hand frame \[m\].
    pub centre: Vector3<f64>,
}

/// Friction at a contact (SPEC §1.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Friction {
    /// Coulomb coefficient μ.
    pub mu: f64,
    /// Torsional coefficient μ_t \[m\].
    pub torsion: f64,
}

/// A whole hand: chains, object, friction.
#[derive(Debug, Clone, PartialEq)]
pub struct HandDescription {
    /// The URDF's robot name.
    pub robot: String,
    /// The hand frame link.
    pub frame: String,
    /// The URDF file named by the section, if any (for the caller).
    pub urdf_file: Option<String>,
    /// Margin kept inside joint position limits \[rad\].
    pub joint_limit_margin: f64,
    /// Gravity in the hand frame \[m/s²\].
    pub gravity: Vector3<f64>,
    /// The object.
    pub object: Object,
    /// Friction.
    pub friction: Friction,
    /// The fingers, in the section's order.
    pub fingers: Vec<FingerDescription>,
}

impl HandDescription {
    /// Reads a hand from its URDF text and its hand section (TOML text).
    pub fn parse(urdf: &str, section: &str) -> Result<HandDescription, DescriptionError> {
        let sec: HandSection =
            toml::from_str(section).map_err(|e| DescriptionError::Section(one_line(&e)))?;
        let robot =
            urdf_rs::read_from_string(urdf).map_err(|e| DescriptionError::Urdf(one_line(&e)))?;
        Self::from_parts(&robot, &sec)
    }

    /// Builds the description from a parsed URDF and hand section.
    pub fn from_parts(
        robot: &Robot,
        sec: &HandSection,
    ) -> Result<HandDescription, DescriptionError> {
        check_section(sec)?;
        let tree = Tree::new(robot);
        let frame = match &sec.frame {
            Some(f) => {
                tree.link(f, "frame")?;
                f.clone()
            }
            None => tree.root().to_string(),
        };
        let mut fingers = Vec::with_capacity(sec.finger.len());
        for (k, f) in sec.finger.iter().enumerate() {
            let d = finger(&tree, &frame, k, f)?;
            for j in &d.joints {
                if j.limits.upper - j.limits.lower <= 2.0 * sec.joint_limit_margin {
                    return Err(DescriptionError::BadValue {
                        key: "joint_limit_margin".into(),
                        value: sec.joint_limit_margin,
                        requirement: "must leave a range inside every joint's limits",
                    });
                }
            }
            fingers.push(d);
        }
        let o = &sec.object;
        Ok(HandDescription {
            robot: robot.name.clone(),
            frame,
            urdf_file: sec.urdf.clone(),
            joint_limit_margin: sec.joint_limit_margin,
            gravity: Vector3::from(sec.gravity),
            object: Object {
                radius: o.radius,
                mass: o.mass,
                centre: Vector3::from(o.centre),
            },
            friction: Friction {
                mu: sec.friction.mu,
                torsion: sec.friction.torsion,
            },
            fingers,
        })
    }
}

fn one_line(e: &dyn std::fmt::Display) -> String {
    e.to_string()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

fn check_section(sec: &HandSection) -> Result<(), DescriptionError> {
    let bad = |key: &str, value: f64, requirement| {
        Err(DescriptionError::BadValue {
            key: key.into(),
            value,
            requirement,
        })
    };
    let positive = "must be positive and finite";
    if !(sec.object.radius > 0.0 && sec.object.radius.is_finite()) {
        return bad("object.radius", sec.object.radius, positive);
    }
    if !(sec.object.mass > 0.0 && sec.object.mass.is_finite()) {
        return bad("object.mass", sec.object.mass, positive);
    }
    if let Some(&c) = sec.object.centre.iter().find(|c| !c.is_finite()) {
        return bad("object.centre", c, "must be finite");
    }
    if !(sec.friction.mu > 0.0 && sec.friction.mu.is_finite()) {
        return bad("friction.mu", sec.friction.mu, positive);
    }
    if !(sec.friction.torsion >= 0.0 && sec.friction.torsion.is_finite()) {
        return bad(
            "friction.torsion",
            sec.friction.torsion,
            "must be ≥ 0 and finite",
        );
    }
    if !(sec.joint_limit_margin >= 0.0 && sec.joint_limit_margin.is_finite()) {
        return bad(
            "joint_limit_margin",
            sec.joint_limit_margin,
            "must be ≥ 0 and finite",
        );
    }
    if let Some(&g) = sec.gravity.iter().find(|g| !g.is_finite()) {
        return bad("gravity", g, "must be finite");
    }
    if sec.finger.is_empty() {
        return Err(DescriptionError::Fingers("no [[finger]]"));
    }
    for (i, f) in sec.finger.iter().enumerate() {
        if sec.finger[..i].iter().any(|g| g.name == f.name) {
            return Err(DescriptionError::Fingers("two [[finger]] share a name"));
        }
        if let Some(r) = f.tip_radius
            && !(r > 0.0 && r.is_finite())
        {
            return bad(&format!("finger[{i}].tip_radius"), r, positive);
        }
        let p = Vector3::from(f.tip_pole);
        if !(p.norm() > 0.0 && p.norm().is_finite()) {
            return bad(
                &format!("finger[{i}].tip_pole"),
                p.norm(),
                "must be a non-zero vector",
            );
        }
        if !(f.tip_patch_deg > 0.0 && f.tip_patch_deg <= 180.0) {
            return bad(
                &format!("finger[{i}].tip_patch_deg"),
                f.tip_patch_deg,
                "must be in (0, 180]",
            );
        }
    }
    Ok(())
}
