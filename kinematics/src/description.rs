//! A hand description: the URDF's chains plus the gaitd hand section (SPEC §14.4).
//!
//! [`HandDescription::parse`] takes the URDF text and the hand section's
//! text (the caller reads the files) and builds, per finger, the chain of
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
//! its fixed-size, per-tick form.

use std::collections::HashMap;

use nalgebra::{Unit, Vector3};
use urdf_rs::{Geometry, JointType, Robot};

use crate::capsule::{Capsule, LinkCapsule};
use crate::error::DescriptionError;
use crate::frame::Frame;
use crate::section::{FingerSection, HandSection};

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

/// The URDF's tree by name.
struct Tree<'a> {
    robot: &'a Robot,
    links: HashMap<&'a str, usize>,
    /// Child link → the joint whose child it is.
    parent: HashMap<&'a str, usize>,
}

impl<'a> Tree<'a> {
    fn new(robot: &'a Robot) -> Self {
        let links = robot
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| (l.name.as_str(), i))
            .collect();
        let parent = robot
            .joints
            .iter()
            .enumerate()
            .map(|(i, j)| (j.child.link.as_str(), i))
            .collect();
        Tree {
            robot,
            links,
            parent,
        }
    }

    fn root(&self) -> &'a str {
        self.robot
            .links
            .iter()
            .map(|l| l.name.as_str())
            .find(|l| !self.parent.contains_key(l))
            .unwrap_or("")
    }

    fn link(&self, name: &str, key: &str) -> Result<usize, DescriptionError> {
        self.links
            .get(name)
            .copied()
            .ok_or_else(|| DescriptionError::UnknownLink {
                key: key.into(),
                link: name.into(),
            })
    }

    /// Joints from `top` down to `bottom` (top first), or None if `bottom`
    /// is not below `top`.
    fn path(&self, top: &str, bottom: &str) -> Option<Vec<usize>> {
        let mut joints = Vec::new();
        let mut at = bottom;
        while at != top {
            let &j = self.parent.get(at)?;
            if joints.len() > self.robot.joints.len() {
                return None; // a cycle: not a tree
            }
            joints.push(j);
            at = self.robot.joints[j].parent.link.as_str();
        }
        joints.reverse();
        Some(joints)
    }
}

fn origin(j: &urdf_rs::Joint) -> Frame {
    Frame::from_xyz_rpy(j.origin.xyz.0, j.origin.rpy.0)
}

fn finger(
    tree: &Tree<'_>,
    frame: &str,
    k: usize,
    f: &FingerSection,
) -> Result<FingerDescription, DescriptionError> {
    tree.link(&f.base, &format!("finger[{k}].base"))?;
    tree.link(&f.tip, &format!("finger[{k}].tip"))?;
    let robot = tree.robot;
    let base_path = tree
        .path(frame, &f.base)
        .ok_or_else(|| DescriptionError::BaseNotFixed {
            finger: f.name.clone(),
            base: f.base.clone(),
            frame: frame.into(),
            joint: "(none: the base is not below the frame)".into(),
        })?;
    let mut base = Frame::IDENTITY;
    for &j in &base_path {
        let joint = &robot.joints[j];
        if joint.joint_type != JointType::Fixed {
            return Err(DescriptionError::BaseNotFixed {
                finger: f.name.clone(),
                base: f.base.clone(),
                frame: frame.into(),
                joint: joint.name.clone(),
            });
        }
        base = base.compose(&origin(joint));
    }
    let path = tree
        .path(&f.base, &f.tip)
        .ok_or_else(|| DescriptionError::TipNotBelowBase {
            finger: f.name.clone(),
            tip: f.tip.clone(),
            base: f.base.clone(),
        })?;
    // Links of the chain, each with its segment (0: fixed to the base, i:
    // moved by revolute joint i) and its frame in that segment's frame.
    let mut joints = Vec::new();
    let mut links: Vec<(&str, usize, Frame)> = vec![(f.base.as_str(), 0, Frame::IDENTITY)];
    let mut pending = Frame::IDENTITY;
    for &j in &path {
        let joint = &robot.joints[j];
        match joint.joint_type {
            JointType::Fixed => pending = pending.compose(&origin(joint)),
            JointType::Revolute => {
                joints.push(revolute(joint, pending.compose(&origin(joint)))?);
                pending = Frame::IDENTITY;
            }
            ref other => {
                return Err(DescriptionError::NonRevoluteJoint {
                    finger: f.name.clone(),
                    joint: joint.name.clone(),
                    kind: format!("{other:?}").to_lowercase(),
                });
            }
        }
        links.push((joint.child.link.as_str(), joints.len(), pending));
    }
    if joints.is_empty() {
        return Err(DescriptionError::NoJoints {
            finger: f.name.clone(),
            base: f.base.clone(),
            tip: f.tip.clone(),
        });
    }
    let tip = pending;
    let on_chain: Vec<&str> = links.iter().map(|l| l.0).collect();
    // Everything rigidly attached to a chain link (fixed joints, off the chain).
    let mut attached = Vec::new();
    for &(name, seg, fr) in &links {
        attached.push((name, seg, fr));
        let mut stack = vec![(name, fr)];
        while let Some((at, at_fr)) = stack.pop() {
            for j in robot.joints.iter().filter(|j| j.parent.link == at) {
                let child = j.child.link.as_str();
                if j.joint_type == JointType::Fixed && !on_chain.contains(&child) {
                    let c = at_fr.compose(&origin(j));
                    attached.push((child, seg, c));
                    stack.push((child, c));
                }
            }
        }
    }
    let n = joints.len();
    let mut mass = vec![0.0; n + 1];
    let mut moment = vec![Vector3::zeros(); n + 1];
    let mut capsules = Vec::new();
    let mut ignored_meshes = Vec::new();
    let mut urdf_tip_radius = None;
    for &(name, seg, fr) in &attached {
        let link = &robot.links[tree.links[name]];
        let m = link.inertial.mass.value;
        let com = fr.point(&Vector3::from(link.inertial.origin.xyz.0));
        mass[seg] += m;
        moment[seg] += com * m;
        for c in &link.collision {
            let g = fr.compose(&Frame::from_xyz_rpy(c.origin.xyz.0, c.origin.rpy.0));
            if name == f.tip
                && let Geometry::Sphere { radius } = c.geometry
                && c.origin.xyz.0 == [0.0; 3]
            {
                urdf_tip_radius = Some(radius);
                continue; // the tip sphere is the contact, not an obstacle
            }
            match capsule_of(&c.geometry, &g) {
                Some(capsule) => capsules.push(LinkCapsule {
                    segment: seg,
                    capsule,
                }),
                None => ignored_meshes.push(name.to_string()),
            }
        }
    }
    let bodies = (1..=n)
        .map(|s| Body {
            mass: mass[s],
            com: if mass[s] > 0.0 {
                moment[s] / mass[s]
            } else {
                Vector3::zeros()
            },
        })
        .collect();
    let tip_radius =
        f.tip_radius
            .or(urdf_tip_radius)
            .ok_or_else(|| DescriptionError::NoTipRadius {
                finger: f.name.clone(),
                tip: f.tip.clone(),
            })?;
    Ok(FingerDescription {
        name: f.name.clone(),
        base_link: f.base.clone(),
        tip_link: f.tip.clone(),
        base,
        joints,
        tip,
        tip_radius,
        tip_pole: Unit::new_normalize(Vector3::from(f.tip_pole)),
        tip_patch: f.tip_patch_deg.to_radians(),
        bodies,
        capsules,
        ignored_meshes,
    })
}

fn revolute(j: &urdf_rs::Joint, origin: Frame) -> Result<JointDescription, DescriptionError> {
    let bad = |problem| {
        Err(DescriptionError::BadLimit {
            joint: j.name.clone(),
            problem,
        })
    };
    let l = &j.limit;
    if !(l.lower.is_finite() && l.upper.is_finite()) {
        return bad("lower and upper limits must be finite");
    }
    if l.lower >= l.upper {
        return bad("no <limit>, or lower ≥ upper");
    }
    if !(l.velocity > 0.0 && l.velocity.is_finite()) {
        return bad("velocity limit must be positive");
    }
    if !(l.effort > 0.0 && l.effort.is_finite()) {
        return bad("effort limit must be positive");
    }
    let a = Vector3::from(j.axis.xyz.0);
    if !(a.norm() > 0.0 && a.iter().all(|x| x.is_finite())) {
        return Err(DescriptionError::BadAxis {
            joint: j.name.clone(),
        });
    }
    Ok(JointDescription {
        name: j.name.clone(),
        origin,
        axis: Unit::new_normalize(a),
        limits: JointLimits {
            lower: l.lower,
            upper: l.upper,
            velocity: l.velocity,
            effort: l.effort,
        },
    })
}

/// The capsule enclosing a collision primitive placed at `g`; None for a mesh.
fn capsule_of(geometry: &Geometry, g: &Frame) -> Option<Capsule> {
    let along = |axis: Vector3<f64>, half: f64, radius: f64| Capsule {
        a: g.point(&(axis * -half)),
        b: g.point(&(axis * half)),
        radius,
    };
    match *geometry {
        Geometry::Sphere { radius } => Some(along(Vector3::z(), 0.0, radius)),
        // A cylinder lies inside the capsule on its axis with its radius.
        Geometry::Cylinder { radius, length } | Geometry::Capsule { radius, length } => {
            Some(along(Vector3::z(), length / 2.0, radius))
        }
        Geometry::Box { ref size } => {
            let s = size.0;
            let i = (0..3).max_by(|&a, &b| s[a].total_cmp(&s[b])).unwrap_or(2);
            let (u, v) = ((i + 1) % 3, (i + 2) % 3);
            let radius = 0.5 * (s[u] * s[u] + s[v] * s[v]).sqrt();
            let mut axis = Vector3::zeros();
            axis[i] = 1.0;
            Some(along(axis, s[i] / 2.0, radius))
        }
        Geometry::Mesh { .. } => None,
    }
}
