//! Reading `gait-trajectory/1` traces (SPEC §10) back, from JSON lines or
//! their MCAP recording (told apart by the first bytes): `gaitctl plot`,
//! `gaitctl plan --from TRACE` (start where a trace ended) and
//! `gaitd-view --replay` read them through [`read`].

use std::io::{BufRead, Read};
use std::path::Path;

use gait::{FingerMode, FingerState, HandState};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde_json::Value;

/// One finger of one sample.
#[derive(Debug, Clone, Copy)]
pub struct TraceFinger {
    /// Fingertip centre \[m\].
    pub p: Vector3<f64>,
    /// Fingertip orientation.
    pub q: UnitQuaternion<f64>,
    /// Touching the object.
    pub contact: bool,
    /// Normal force \[N\].
    pub grip: f64,
    /// Roll τ \[rad\].
    pub roll: f64,
    /// A chain hand's commanded joints \[rad\] (if recorded).
    pub joints: Option<[f64; 3]>,
}

/// One tick of a trace.
#[derive(Debug, Clone)]
pub struct TraceSample {
    /// Time \[s\].
    pub t: f64,
    /// Object orientation.
    pub object: UnitQuaternion<f64>,
    /// The fingers.
    pub fingers: [TraceFinger; 3],
    /// Force-closure slack (if recorded).
    pub fc_margin: Option<f64>,
    /// Load margin \[N\] (if recorded and a grip holds the load).
    pub load_margin: Option<f64>,
    /// Angle still to turn to the goal \[rad\] (if recorded).
    pub remaining_angle: Option<f64>,
    /// What the hand is doing (if recorded): `gait::trace::phase_name`.
    pub phase: Option<String>,
}

/// A whole trace.
#[derive(Debug, Clone)]
pub struct Trace {
    /// Object radius R \[m\].
    pub object_radius: f64,
    /// Fingertip radius r \[m\].
    pub fingertip_radius: f64,
    /// Workspace cone half angle β \[deg\] (default 60 if absent).
    pub workspace_half_angle_deg: f64,
    /// Finger base azimuths \[deg\] (default 0, 120, 240 if absent).
    pub finger_azimuth_deg: [f64; 3],
    /// Control period \[s\] (if recorded).
    pub dt: Option<f64>,
    /// A chain hand's description, its hand section file (if recorded).
    pub hand_description: Option<String>,
    /// The samples.
    pub samples: Vec<TraceSample>,
}

fn num(v: &Value, what: &str, line: usize) -> Result<f64, String> {
    v.as_f64()
        .ok_or_else(|| format!("line {line}: `{what}` is not a number"))
}

fn arr<const N: usize>(v: &Value, what: &str, line: usize) -> Result<[f64; N], String> {
    let a = v
        .as_array()
        .filter(|a| a.len() == N)
        .ok_or_else(|| format!("line {line}: `{what}` is not an array of {N} numbers"))?;
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = num(x, what, line)?;
    }
    Ok(out)
}

fn quat(v: &Value, what: &str, line: usize) -> Result<UnitQuaternion<f64>, String> {
    let [w, x, y, z] = arr::<4>(v, what, line)?;
    Ok(UnitQuaternion::new_normalize(Quaternion::new(w, x, y, z)))
}

/// Reads a trace file: JSON lines, or an MCAP recording of one (told by
/// its first bytes, `gaitctl trace mcap`).
pub fn read(path: &Path) -> Result<Trace, String> {
    let file =
        std::fs::File::open(path).map_err(|e| format!("cannot open {}: {e}", path.display()))?;
    let mut file = std::io::BufReader::new(file);
    let prefix = file
        .fill_buf()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    if crate::is_mcap(prefix) {
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let lines = crate::read(&bytes).map_err(|e| format!("{}: {e}", path.display()))?;
        let all = std::iter::once(lines.header)
            .chain(lines.samples)
            .map(Ok::<_, String>);
        return parse(path, all);
    }
    parse(path, file.lines().map(|l| l.map_err(|e| e.to_string())))
}

/// Parses a trace's lines, header first.
fn parse(
    path: &Path,
    lines: impl Iterator<Item = Result<String, String>>,
) -> Result<Trace, String> {
    let mut lines = lines.enumerate();
    let (_, first) = lines
        .next()
        .ok_or_else(|| format!("{}: empty trace", path.display()))?;
    let first = first?;
    let h: Value = serde_json::from_str(&first).map_err(|e| format!("line 1: {e}"))?;
    if h.get("format").and_then(Value::as_str) != Some(gait::trace::FORMAT) {
        return Err(format!(
            "{}: not a {} trace (header line has no matching \"format\")",
            path.display(),
            gait::trace::FORMAT
        ));
    }
    let mut trace = Trace {
        object_radius: num(&h["object_radius"], "object_radius", 1)?,
        fingertip_radius: num(&h["fingertip_radius"], "fingertip_radius", 1)?,
        workspace_half_angle_deg: h["workspace_half_angle_deg"].as_f64().unwrap_or(60.0),
        finger_azimuth_deg: arr::<3>(&h["finger_azimuth_deg"], "finger_azimuth_deg", 1)
            .unwrap_or([0.0, 120.0, 240.0]),
        dt: h["dt"].as_f64(),
        hand_description: h["hand_description"].as_str().map(str::to_owned),
        samples: Vec::new(),
    };
    for (i, l) in lines {
        let n = i + 1;
        let l = l?;
        if l.trim().is_empty() {
            continue;
        }
        let v: Value = serde_json::from_str(&l).map_err(|e| format!("line {n}: {e}"))?;
        let fingers = v["fingers"]
            .as_array()
            .filter(|a| a.len() == 3)
            .ok_or_else(|| format!("line {n}: `fingers` is not an array of 3"))?;
        let mut fs = [TraceFinger {
            p: Vector3::zeros(),
            q: UnitQuaternion::identity(),
            contact: false,
            grip: 0.0,
            roll: 0.0,
            joints: None,
        }; 3];
        for (f, fv) in fs.iter_mut().zip(fingers) {
            f.p = Vector3::from(arr::<3>(&fv["p"], "p", n)?);
            f.q = quat(&fv["q"], "q", n)?;
            f.contact = fv["contact"].as_bool().unwrap_or(false);
            f.grip = fv["grip_force"].as_f64().unwrap_or(0.0);
            f.roll = fv["roll"].as_f64().unwrap_or(0.0);
            f.joints = match &fv["joints"] {
                Value::Null => None,
                j => Some(arr::<3>(j, "joints", n)?),
            };
        }
        trace.samples.push(TraceSample {
            t: num(&v["t"], "t", n)?,
            object: quat(&v["object_q"], "object_q", n)?,
            fingers: fs,
            fc_margin: v["fc_margin"].as_f64(),
            load_margin: v["load_margin"].as_f64(),
            remaining_angle: v["remaining_angle"].as_f64(),
            phase: v["phase"].as_str().map(str::to_owned),
        });
    }
    if trace.samples.is_empty() {
        return Err(format!("{}: the trace has no samples", path.display()));
    }
    Ok(trace)
}

impl TraceSample {
    /// The hand state of this sample (for `plan --from TRACE`).
    pub fn hand_state(&self) -> HandState {
        HandState {
            object: self.object,
            fingers: self.fingers.map(|f| FingerState {
                mode: if f.contact {
                    FingerMode::Grasping
                } else {
                    FingerMode::Free
                },
                center: f.p,
                orientation: f.q,
                roll: f.roll,
            }),
        }
    }
}
