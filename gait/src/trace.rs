//! The `gait-trajectory/1` trace format (SPEC §10): JSON lines, SI units,
//! hand frame. A header line, then one line per control tick:
//!
//! ```text
//! {"format":"gait-trajectory/1","object_radius":0.5,"fingertip_radius":0.1,"mu":0.364,"dt":0.001,...}
//! {"t":T,"object_q":[w,x,y,z],"phase":"...","fingers":[F0,F1,F2],...}
//! Fi = {"p":[x,y,z],"q":[w,x,y,z],"contact":true|false,"grip_force":N,"roll":rad}
//! ```
//! On a chain hand (SPEC §14) each finger also has `"joints":[q1,q2,q3]`,
//! the commanded joint positions \[rad\], and the line `joint_margin`, the
//! tightest joint's distance inside its limits less their margin \[rad\].
//! Tick lines also carry `fc`, `fc_margin`, `load_margin` (`load.max_grip`
//! minus the largest normal force the load needs, SPEC §1.3 I1'; `null`
//! when no grip holds it), `remaining_angle`, `gaits` and
//! `estimate_epoch`, which changes where the controller re-based its object
//! estimate on a measurement (SPEC §6.3): `object_q` jumps there, without
//! object motion, so a replay starts over from that line.
//! Keys may be added, never renamed. This module only formats text (no
//! I/O); writers live in the binaries. Numbers are written in Rust's
//! shortest round-trip form, so a reader gets the exact `f64` back.

use core::fmt::Write;

use nalgebra::{UnitQuaternion, Vector3};

use crate::HandConfig;
use crate::executor::{Mode, TickReport};
use crate::hand_state::FingerMode;
use crate::planner::StepKind;

/// The format name in the header.
pub const FORMAT: &str = "gait-trajectory/1";

fn num(out: &mut String, x: f64) {
    // JSON has no NaN/Inf; the controller never produces them, but a trace
    // must stay parseable whatever happens.
    if x.is_finite() {
        let _ = write!(out, "{x}");
    } else {
        out.push_str("null");
    }
}

fn vec3(out: &mut String, v: &Vector3<f64>) {
    out.push('[');
    for (i, x) in v.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        num(out, *x);
    }
    out.push(']');
}

fn quat(out: &mut String, q: &UnitQuaternion<f64>) {
    let q = q.quaternion();
    out.push('[');
    for (i, x) in [q.w, q.i, q.j, q.k].iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        num(out, *x);
    }
    out.push(']');
}

/// Writes the header line (with newline): the four required numbers, the
/// format, and an echo of the model configuration, plus `extra` key/value
/// text (already JSON, without braces; may be empty).
pub fn header(out: &mut String, config: &HandConfig, dt: f64, extra: &str) {
    let m = &config.model;
    let _ = write!(
        out,
        "{{\"format\":\"{FORMAT}\",\"object_radius\":{},\"fingertip_radius\":{},\"mu\":{},\"dt\":{}",
        m.object_radius,
        m.fingertip_radius,
        config.mu(),
        dt
    );
    let _ = write!(
        out,
        ",\"workspace_half_angle_deg\":{},\"roll_limit_deg\":{},\"friction_angle_deg\":{},\"finger_azimuth_deg\":[{},{},{}],\"object_mass\":{}",
        m.workspace_half_angle_deg,
        m.roll_limit_deg,
        m.friction_angle_deg,
        m.finger_azimuth_deg[0],
        m.finger_azimuth_deg[1],
        m.finger_azimuth_deg[2],
        config.load.object_mass
    );
    // The physical model a replay must use (SPEC §1.2, §3.3): torsion
    // coefficient μ_t [m], gravity [m/s²], force limit and disturbance [N].
    let l = &config.load;
    let _ = write!(
        out,
        ",\"mu_torsion\":{},\"gravity\":[{},{},{}],\"max_grip\":{},\"disturbance_force\":{}",
        config.mu_torsion(),
        l.gravity[0],
        l.gravity[1],
        l.gravity[2],
        l.max_grip,
        l.disturbance_force
    );
    if !extra.is_empty() {
        out.push(',');
        out.push_str(extra);
    }
    out.push_str("}\n");
}

/// Name of what the hand is doing, for the `phase` key.
pub fn phase_name(phase: Mode, step: Option<StepKind>) -> &'static str {
    match (phase, step) {
        (Mode::Moving, Some(StepKind::Roll)) => "roll",
        (Mode::Moving, Some(StepKind::Rotate)) => "rotate",
        (Mode::Moving, Some(StepKind::Transfer)) => "transfer",
        (Mode::Moving, Some(StepKind::Place)) => "place",
        (Mode::Moving, Some(StepKind::Lift)) => "lift",
        (Mode::Moving, None) => "moving",
        (Mode::Stopping, _) => "stopping",
        (Mode::Planning, _) => "planning",
        (Mode::Holding, _) => "hold",
        (Mode::SafeHold, _) => "safe_hold",
    }
}

/// One fingertip in a [`Sample`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerSample {
    /// Fingertip centre `p` \[m\].
    pub p: Vector3<f64>,
    /// Fingertip orientation `q` (world-from-fingertip).
    pub q: UnitQuaternion<f64>,
    /// Touching the object (|p| = R + r).
    pub contact: bool,
    /// Intended normal force \[N\] (0 when not in contact).
    pub grip_force: f64,
    /// Roll angle \[rad\].
    pub roll: f64,
    /// A chain hand's commanded joints \[rad\].
    pub joints: Option<Vector3<f64>>,
}

/// Everything one tick's line holds, as a small fixed-size `Copy` value.
///
/// Why it exists: a real-time loop copies this (no allocation, no
/// formatting) and another thread formats it later with [`sample_line`];
/// [`line()`] goes through the same path, so offline planning and the daemon
/// write byte-identical lines for the same tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Planned object orientation (world-from-body).
    pub object_q: UnitQuaternion<f64>,
    /// The `phase` key ([`phase_name`]).
    pub phase: &'static str,
    /// Per finger.
    pub fingers: [FingerSample; crate::FINGERS],
    /// Force closure of the commanded grasp.
    pub fc: bool,
    /// Force-closure margin \[rad\].
    pub fc_margin: f64,
    /// Load margin `load.max_grip` − F* \[N\] (SPEC §1.3 I1').
    pub load_margin: f64,
    /// Angle still to rotate \[rad\].
    pub remaining_angle: f64,
    /// Gaits done.
    pub gaits: u32,
    /// [`Setpoint::estimate_epoch`](crate::planner::Setpoint): it changes
    /// where the controller re-based its object estimate on a measurement
    /// (after a slip, SPEC §6.3), so `object_q` jumps there without motion.
    pub estimate_epoch: u32,
    /// A chain hand's tightest joint margin \[rad\] (`None`: free
    /// fingertips).
    pub joint_margin: Option<f64>,
}

impl Sample {
    /// The sample of one executor tick.
    pub fn from_report(r: &TickReport) -> Self {
        let s = &r.setpoint.state;
        let fingers = core::array::from_fn(|k| {
            let f = &s.fingers[k];
            let contact = f.mode == FingerMode::Grasping;
            FingerSample {
                p: f.center,
                q: f.orientation,
                contact,
                grip_force: if contact { r.grip[k] } else { 0.0 },
                roll: f.roll,
                joints: r.joints[k],
            }
        });
        let chains = r.link_slack.iter().any(Option::is_some);
        let joint_margin = chains.then(|| {
            r.workspace_slack
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min)
        });
        Self {
            object_q: s.object,
            phase: phase_name(r.phase, r.step_kind),
            fingers,
            fc: r.force_closure.0,
            fc_margin: r.force_closure.1,
            load_margin: r.load_margin,
            remaining_angle: r.remaining_angle,
            gaits: r.gaits.0,
            estimate_epoch: r.setpoint.estimate_epoch,
            joint_margin,
        }
    }
}

/// Appends one tick's line (with newline) at time `t`.
pub fn line(out: &mut String, t: f64, r: &TickReport) {
    sample_line(out, t, &Sample::from_report(r));
}

/// Appends the line (with newline) of sample `s` at time `t`.
pub fn sample_line(out: &mut String, t: f64, s: &Sample) {
    out.push_str("{\"t\":");
    num(out, t);
    out.push_str(",\"object_q\":");
    quat(out, &s.object_q);
    let _ = write!(out, ",\"phase\":\"{}\",\"fingers\":[", s.phase);
    for (k, f) in s.fingers.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        out.push_str("{\"p\":");
        vec3(out, &f.p);
        out.push_str(",\"q\":");
        quat(out, &f.q);
        let _ = write!(out, ",\"contact\":{},\"grip_force\":", f.contact);
        num(out, f.grip_force);
        out.push_str(",\"roll\":");
        num(out, f.roll);
        if let Some(q) = &f.joints {
            out.push_str(",\"joints\":");
            vec3(out, q);
        }
        out.push('}');
    }
    out.push_str("],\"fc\":");
    out.push_str(if s.fc { "true" } else { "false" });
    out.push_str(",\"fc_margin\":");
    num(out, s.fc_margin);
    out.push_str(",\"load_margin\":");
    num(out, s.load_margin);
    out.push_str(",\"remaining_angle\":");
    num(out, s.remaining_angle);
    let _ = write!(
        out,
        ",\"gaits\":{},\"estimate_epoch\":{}",
        s.gaits, s.estimate_epoch
    );
    if let Some(m) = s.joint_margin {
        out.push_str(",\"joint_margin\":");
        num(out, m);
    }
    out.push_str("}\n");
}
