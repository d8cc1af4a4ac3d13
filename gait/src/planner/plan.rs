//! A plan: a sequence of primitive motions (SPEC §4.2), each with its exact
//! start state, evaluable at any value of its path parameters.
//!
//! Each step moves along a fixed geometric path; the executor times the path
//! parameters with the trajectory generator (rest to rest, SPEC §5) and asks
//! the step for the hand state and its rates at those parameters. Because
//! every step stores its own start state, evaluating a step never accumulates
//! error from earlier steps.

use nalgebra::{UnitQuaternion, Vector3};

use super::carry_path::CarryPath;
use super::geometry::{rotation, swing};
use crate::contact::ContactGeometry;
use crate::hand_state::{FingerMode, HandState};
use crate::rolling::{RollSegment, Waypoint};

/// Most path parameters a step has (a rotation plus a concurrent free-finger
/// transfer, or up to three rolling fingers).
pub const MAX_DOFS: usize = 3;

/// Which kind of motion a path parameter is limited as (SPEC §5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepLimit {
    /// Object rotation angle \[rad\].
    Object,
    /// Fingertip path length in free space \[m\].
    Fingertip,
    /// Fingertip rotation relative to the object while rolling \[rad\].
    Rolling,
}

/// A change of a free fingertip's orientation: the minimal swing of its pole
/// axis (τ unchanged) plus a twist about the pole (τ changes by the twist),
/// both proportional to the path fraction λ ∈ [0, 1]:
/// Q(λ) = Rot(s, λ σ) · Q₀ · Rot_z(λ Δτ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reorientation {
    /// Unit swing axis s (hand frame; any unit vector when σ = 0).
    pub swing_axis: Vector3<f64>,
    /// Swing angle σ.
    pub swing_angle: f64,
    /// Twist Δτ about the pole axis (the roll change).
    pub twist: f64,
}

impl Reorientation {
    /// No change.
    pub const NONE: Self = Self {
        swing_axis: Vector3::new(0.0, 0.0, 1.0),
        swing_angle: 0.0,
        twist: 0.0,
    };

    /// The change that turns a fingertip with orientation `q0` so that its
    /// pole axis becomes `pole` and its roll changes by `twist`.
    pub fn towards(q0: &UnitQuaternion<f64>, pole: &Vector3<f64>, twist: f64) -> Self {
        let a0 = q0 * Vector3::z();
        let s = swing(&a0, pole);
        match s.axis_angle() {
            Some((axis, angle)) => Self {
                swing_axis: axis.into_inner(),
                swing_angle: angle,
                twist,
            },
            None => Self {
                twist,
                ..Self::NONE
            },
        }
    }

    /// Orientation at fraction `lambda` from `q0`.
    pub fn at(&self, q0: &UnitQuaternion<f64>, lambda: f64) -> UnitQuaternion<f64> {
        rotation(&self.swing_axis, lambda * self.swing_angle)
            * q0
            * rotation(&Vector3::z(), lambda * self.twist)
    }

    /// Angular velocity (hand frame) per unit of λ at fraction `lambda`.
    pub fn rate(&self, q0: &UnitQuaternion<f64>, lambda: f64) -> Vector3<f64> {
        let q = self.at(q0, lambda);
        self.swing_axis * self.swing_angle + (q * Vector3::z()) * self.twist
    }
}

/// A geometric path of a fingertip centre in free space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FreePath {
    /// Straight along the unit direction `dir` from radius `from` to `to`
    /// (lift: up from contact; place: down to contact).
    Radial {
        /// Unit direction from O.
        dir: Vector3<f64>,
        /// Start radius.
        from: f64,
        /// End radius.
        to: f64,
    },
    /// Great-circle arc at constant `radius` from direction `from` to `to`.
    Arc {
        /// Unit start direction.
        from: Vector3<f64>,
        /// Unit rotation axis of the arc.
        axis: Vector3<f64>,
        /// Arc angle seen from O.
        angle: f64,
        /// Radius of the arc.
        radius: f64,
    },
}

impl FreePath {
    /// Great-circle arc between two unit directions at `radius`.
    pub fn arc(from: &Vector3<f64>, to: &Vector3<f64>, radius: f64) -> Self {
        let q = swing(from, to);
        let (axis, angle) = q
            .axis_angle()
            .map_or((Vector3::z(), 0.0), |(a, t)| (a.into_inner(), t));
        Self::Arc {
            from: *from,
            axis,
            angle,
            radius,
        }
    }

    /// Path length \[m\].
    pub fn length(&self) -> f64 {
        match *self {
            Self::Radial { from, to, .. } => (to - from).abs(),
            Self::Arc { angle, radius, .. } => angle * radius,
        }
    }

    /// Position and unit tangent (d position / d length) at arc length `s`.
    pub fn at(&self, s: f64) -> (Vector3<f64>, Vector3<f64>) {
        match *self {
            Self::Radial { dir, from, to } => {
                let sign = if to >= from { 1.0 } else { -1.0 };
                (dir * (from + sign * s), dir * sign)
            }
            Self::Arc {
                from,
                axis,
                angle,
                radius,
            } => {
                if angle <= 0.0 {
                    return (from * radius, Vector3::zeros());
                }
                let u = rotation(&axis, s / radius) * from;
                (u * radius, axis.cross(&u))
            }
        }
    }
}

/// A fingertip moving in free space: path plus reorientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreeMove {
    /// Which finger.
    pub finger: usize,
    /// Path of its centre.
    pub path: FreePath,
    /// Orientation change along the path.
    pub turn: Reorientation,
    /// Whether the finger touches the object at the end of the move.
    pub contact_at_end: bool,
}

/// One finger rolling on the still object along a great circle: the contact
/// normal turns about the unit axis `w` (⊥ n) by `angle`; the fingertip turns
/// about `w` by (R + r)/r times as much (SPEC §2.3 with ω_o = 0, no spin).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GreatCircleRoll {
    /// Which finger.
    pub finger: usize,
    /// Unit axis w of the contact's great circle.
    pub axis: Vector3<f64>,
    /// Angle the contact moves on the object \[rad\] (signed about `axis`).
    pub angle: f64,
}

/// The motion of one step.
// A chain carry's fitted path makes its variant large; a box would cost
// steps their `Copy` and the executor an indirection, and a plan is one
// allocation either way (made off the loop).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// The object turns about `axis` by `angle` (≥ 0) with every grasping
    /// fingertip carried rigidly; optionally the free finger travels
    /// concurrently (time-synchronised).
    Rotate {
        /// Unit rotation axis (hand frame).
        axis: Vector3<f64>,
        /// Rotation angle \[rad\].
        angle: f64,
        /// Concurrent free-finger move.
        free: Option<FreeMove>,
    },
    /// The object turns about `axis` by `angle` (≥ 0) and the grasping
    /// chain fingers roll on it as the rolling law makes them (SPEC
    /// §14.2): their contacts follow `path`. A chain finger's tip
    /// orientation is its joints' (the chain hand's inverse kinematics
    /// gives them from the tip centre), so a carried finger's
    /// `orientation` and `roll` stay as they start.
    Carry {
        /// Unit rotation axis (hand frame).
        axis: Vector3<f64>,
        /// Rotation angle \[rad\].
        angle: f64,
        /// The carried contacts, fitted.
        path: CarryPath,
    },
    /// Up to three fingers roll on the still object, time-synchronised.
    Roll {
        /// The rolling fingers (`None` for the others).
        rolls: [Option<GreatCircleRoll>; 3],
        /// (R + r)/r: fingertip rotation per unit of contact travel.
        ratio: f64,
    },
    /// One finger moves in free space (transfer, lift or place).
    Free(FreeMove),
    /// One finger follows one segment of a rolling path (SPEC §2.4) on the
    /// still object; the parameter is the fingertip rotation relative to
    /// the object.
    RollSegment {
        /// Which finger.
        finger: usize,
        /// The segment (object frame).
        segment: RollSegment,
        /// The path state where the segment starts.
        from: Waypoint,
        /// Radii.
        geom: ContactGeometry,
    },
}

/// What a step does, for people and for gait counting. The codes are
/// stable (they cross process boundaries).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum StepKind {
    /// Rolling on the object (object still).
    Roll = 0,
    /// Object rotation by a grasping pair (or triple).
    Rotate = 1,
    /// A free finger travelling above the object.
    Transfer = 2,
    /// A free finger descending to make contact (one gait).
    Place = 3,
    /// A grasping finger leaving the object (one gait).
    Lift = 4,
}

/// The grip passing between fingers at the end of a step, with the
/// object and the fingers still (`load.handover_time`; SPEC §1.3 I1',
/// [`crate::grasp::grip`]): the grip of the finger just placed ramps
/// in, that of the finger that lifts next ramps out, and no contact force
/// jumps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Handover {
    /// The finger whose grip ramps in (the one this step placed).
    pub take: Option<usize>,
    /// The finger whose grip ramps out (the one the next step lifts).
    pub release: Option<usize>,
    /// The finger that spins on the object next: afterwards it pushes
    /// along its normal only (a spin under load, SPEC §1.3 I1').
    pub spin: Option<usize>,
    /// How long the ramp takes \[s\].
    pub duration: f64,
}

impl Handover {
    /// Bit mask of `take`.
    pub fn take_mask(&self) -> u8 {
        self.take.map_or(0, |k| 1 << k)
    }

    /// Bit mask of `release`.
    pub fn release_mask(&self) -> u8 {
        self.release.map_or(0, |k| 1 << k)
    }

    /// The carrying set after the handover, from the set `from` before
    /// (bits as `grasp::grip`: carrying fingers, spin marks).
    pub fn target(&self, from: u8) -> u8 {
        let carry =
            (from | self.take_mask()) & !self.release_mask() & crate::grasp::grip::CARRY_BITS;
        carry | self.spin.map_or(0, crate::grasp::grip::spin_bit)
    }
}

/// The handover at the end of the last of `steps`, made (passing nothing
/// yet, `time` long, its time added to the step's) if it has none; `None`
/// without handovers (`time` ≤ 0) or without steps.
pub(crate) fn end_handover(steps: &mut [Step], time: f64) -> Option<&mut Handover> {
    if time <= 0.0 {
        return None;
    }
    let last = steps.last_mut()?;
    if last.handover.is_none() {
        last.duration += time;
    }
    Some(last.handover.get_or_insert(Handover {
        take: None,
        release: None,
        spin: None,
        duration: time,
    }))
}

/// Where the last of `steps` placed `finger` (its handover takes it and
/// releases none) and the finger lifts next: the handover removed, since
/// a finger placed and lifted at once never carries and no grip passes
/// either way. Whether it was.
pub(crate) fn cancel_take(steps: &mut [Step], finger: usize) -> bool {
    if let Some(last) = steps.last_mut()
        && let Some(h) = last.handover
        && h.take == Some(finger)
        && h.release.is_none()
    {
        last.duration -= h.duration;
        last.handover = None;
        return true;
    }
    false
}

/// One primitive with its exact start state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// What it is.
    pub kind: StepKind,
    /// Hand state when it starts.
    pub start: HandState,
    /// The motion.
    pub motion: Motion,
    /// Planned duration at the configured limits, rest to rest, including
    /// the handover \[s\].
    pub duration: f64,
    /// A handover after the motion, at rest (its time is in `duration`).
    pub handover: Option<Handover>,
}

/// Path parameters of a step: their count, lengths and limit kinds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepDofs {
    /// Number of parameters used (1..=MAX_DOFS).
    pub count: usize,
    /// Final value of each parameter (start is 0).
    pub length: [f64; MAX_DOFS],
    /// Which limits apply.
    pub kind: [StepLimit; MAX_DOFS],
}

/// A hand state with its rates, as the controller commands it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setpoint {
    /// Poses.
    pub state: HandState,
    /// Object angular velocity (hand frame).
    pub object_rate: Vector3<f64>,
    /// Fingertip centre velocities.
    pub finger_velocity: [Vector3<f64>; 3],
    /// Fingertip angular velocities (hand frame).
    pub finger_rate: [Vector3<f64>; 3],
    /// Epoch of the controller's object estimate: it changes when the
    /// controller re-bases `state` on a measurement (SPEC §6.3, a replan
    /// after contact drift). A change of `state.object` across epochs is a
    /// correction of belief, not a commanded motion: a plant that moves the
    /// object by the commanded change (the kinematic hand) ignores it.
    pub estimate_epoch: u32,
}

impl Step {
    /// The finger the step is about: the one that moves in free space or
    /// rolls (the first, when several roll); `None` for a rotation.
    pub fn finger(&self) -> Option<usize> {
        match &self.motion {
            Motion::Free(m) => Some(m.finger),
            Motion::RollSegment { finger, .. } => Some(*finger),
            Motion::Roll { rolls, .. } => rolls[0].map(|r| r.finger),
            Motion::Rotate { .. } | Motion::Carry { .. } => None,
        }
    }

    /// Rest-to-rest duration at `limits`, all parameters synchronised (the
    /// slowest parameter sets it).
    pub fn planned_duration(&self, limits: &crate::config::LimitsConfig) -> f64 {
        let d = self.dofs();
        (0..d.count)
            .map(|i| {
                let lim = super::timing::step_limit(limits, d.kind[i]);
                super::timing::rest_to_rest(d.length[i], lim)
            })
            .fold(0.0, f64::max)
    }

    /// The step's path parameters.
    pub fn dofs(&self) -> StepDofs {
        let mut d = StepDofs {
            count: 1,
            length: [0.0; MAX_DOFS],
            kind: [StepLimit::Object; MAX_DOFS],
        };
        match &self.motion {
            Motion::Rotate { angle, free, .. } => {
                d.length[0] = *angle;
                if let Some(f) = free {
                    d.count = 2;
                    d.length[1] = f.path.length();
                    d.kind[1] = StepLimit::Fingertip;
                }
            }
            Motion::Carry { angle, .. } => d.length[0] = *angle,
            Motion::Roll { rolls, ratio } => {
                for (i, r) in rolls.iter().enumerate() {
                    d.kind[i] = StepLimit::Rolling;
                    d.length[i] = r.map_or(0.0, |r| r.angle.abs() * ratio);
                }
                d.count = MAX_DOFS;
            }
            Motion::Free(f) => {
                d.length[0] = f.path.length();
                d.kind[0] = StepLimit::Fingertip;
            }
            Motion::RollSegment { segment, .. } => {
                d.length[0] = segment.length;
                d.kind[0] = StepLimit::Rolling;
            }
        }
        d
    }

    /// Hand state and rates at path parameters `s` with rates `ds`.
    pub fn eval(&self, s: &[f64; MAX_DOFS], ds: &[f64; MAX_DOFS]) -> Setpoint {
        let mut sp = Setpoint {
            state: self.start,
            object_rate: Vector3::zeros(),
            finger_velocity: [Vector3::zeros(); 3],
            finger_rate: [Vector3::zeros(); 3],
            estimate_epoch: 0,
        };
        match &self.motion {
            Motion::Rotate { axis, free, .. } => {
                let q = rotation(axis, s[0]);
                let w = axis * ds[0];
                sp.state.object = q * self.start.object;
                sp.object_rate = w;
                for (k, f) in sp.state.fingers.iter_mut().enumerate() {
                    if f.mode == FingerMode::Grasping {
                        let pole = f.pole_axis();
                        f.center = q * f.center;
                        f.orientation = q * f.orientation;
                        f.roll += s[0] * axis.dot(&pole);
                        sp.finger_velocity[k] = w.cross(&f.center);
                        sp.finger_rate[k] = w;
                    }
                }
                if let Some(m) = free {
                    apply_free(m, s[1], ds[1], &mut sp);
                }
            }
            Motion::Carry { axis, path, .. } => {
                sp.state.object = rotation(axis, s[0]) * self.start.object;
                sp.object_rate = axis * ds[0];
                for (k, f) in sp.state.fingers.iter_mut().enumerate() {
                    if f.mode == FingerMode::Grasping && path.carries(k) {
                        let c = path.at(k, s[0]);
                        f.center = c.centre;
                        sp.finger_velocity[k] = c.centre_slope * ds[0];
                    }
                }
            }
            Motion::Roll { rolls, ratio } => {
                let ratio = *ratio;
                for (i, r) in rolls.iter().enumerate() {
                    let Some(r) = r else { continue };
                    let sign = r.angle.signum();
                    let contact_angle = sign * s[i] / ratio;
                    let q_n = rotation(&r.axis, contact_angle);
                    let q_f = rotation(&r.axis, contact_angle * ratio);
                    let f = &mut sp.state.fingers[r.finger];
                    let pole0 = f.pole_axis();
                    f.center = q_n * f.center;
                    f.orientation = q_f * f.orientation;
                    f.roll += contact_angle * ratio * r.axis.dot(&pole0);
                    let w_f = r.axis * (sign * ds[i]);
                    sp.finger_rate[r.finger] = w_f;
                    sp.finger_velocity[r.finger] =
                        (r.axis * (sign * ds[i] / ratio)).cross(&f.center);
                }
            }
            Motion::Free(m) => apply_free(m, s[0], ds[0], &mut sp),
            Motion::RollSegment {
                finger,
                segment,
                from,
                geom,
            } => {
                let q_o = self.start.object;
                let sample = segment.eval(geom, from, s[0].clamp(0.0, segment.length));
                sp.state.fingers[*finger] = sample.finger_state(&q_o, geom);
                sp.finger_rate[*finger] = q_o * sample.omega * ds[0];
                sp.finger_velocity[*finger] =
                    q_o * sample.d_contact * (geom.center_distance() * ds[0]);
            }
        }
        sp
    }
}

fn apply_free(m: &FreeMove, s: f64, ds: f64, sp: &mut Setpoint) {
    let len = m.path.length();
    let lambda = if len > 0.0 {
        (s / len).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let dlambda = if len > 0.0 { ds / len } else { 0.0 };
    let f = &mut sp.state.fingers[m.finger];
    let q0 = f.orientation;
    let (p, tangent) = m.path.at(s.clamp(0.0, len));
    f.center = p;
    f.orientation = m.turn.at(&q0, lambda);
    f.roll += lambda * m.turn.twist;
    // (The last bits of a generator sample must not decide contact.)
    f.mode = if m.contact_at_end && lambda >= 1.0 - 1e-12 {
        FingerMode::Grasping
    } else {
        FingerMode::Free
    };
    sp.finger_velocity[m.finger] = tangent * ds;
    sp.finger_rate[m.finger] = m.turn.rate(&q0, lambda) * dlambda;
}
