//! From the URDF tree to one finger's chain (used by [`super`]).
//!
//! Walks from the tip link up to the base link (the joints between them,
//! fixed ones folded into the next revolute joint's origin), from the base
//! up to the hand frame (fixed joints only), and gathers everything rigidly
//! attached to each chain link: masses, centres of mass, collision
//! primitives as capsules.

use std::collections::HashMap;

use nalgebra::{Unit, Vector3};
use urdf_rs::{Geometry, JointType, Robot};

use crate::capsule::{Capsule, LinkCapsule};
use crate::error::DescriptionError;
use crate::frame::Frame;
use crate::section::FingerSection;

use super::{Body, FingerDescription, JointDescription, JointLimits};

/// The URDF's tree by name.
pub(crate) struct Tree<'a> {
    robot: &'a Robot,
    links: HashMap<&'a str, usize>,
    /// Child link → the joint whose child it is.
    parent: HashMap<&'a str, usize>,
}

impl<'a> Tree<'a> {
    pub(crate) fn new(robot: &'a Robot) -> Self {
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

    pub(crate) fn root(&self) -> &'a str {
        self.robot
            .links
            .iter()
            .map(|l| l.name.as_str())
            .find(|l| !self.parent.contains_key(l))
            .unwrap_or("")
    }

    pub(crate) fn link(&self, name: &str, key: &str) -> Result<usize, DescriptionError> {
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

pub(crate) fn finger(
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
