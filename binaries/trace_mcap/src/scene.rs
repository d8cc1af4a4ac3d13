//! The 3D channels: Foxglove's `FrameTransforms` and `SceneUpdate` messages
//! (JSON) of a trace sample.
//!
//! The frames move (`/gaitd/tf`) and the shapes are fixed to them
//! (`frame_locked`), so the scene is written only when it changes: at the
//! start and where a finger touches or leaves the sphere.

use serde_json::{Value, json};

use crate::Error;

/// One fingertip of a sample: centre [m], orientation [w, x, y, z], contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Tip {
    pub p: [f64; 3],
    pub q: [f64; 4],
    pub contact: bool,
}

/// What the 3D channels need of a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pose {
    pub object_q: [f64; 4],
    pub tips: [Tip; 3],
}

/// Finger colours, as in `gaitctl plot` (red, blue, green).
const COLORS: [[f64; 3]; 3] = [
    [0.839, 0.153, 0.157],
    [0.122, 0.467, 0.706],
    [0.173, 0.627, 0.173],
];

/// The fixed frame.
pub(crate) const HAND_FRAME: &str = "hand";
/// The object's frame.
pub(crate) const OBJECT_FRAME: &str = "object";
/// Fingertip frames, numbered from 1 as in `gaitctl plot`.
pub(crate) const TIP_FRAMES: [&str; 3] = ["fingertip1", "fingertip2", "fingertip3"];

fn numbers<const N: usize>(v: &Value, what: &'static str, line: usize) -> Result<[f64; N], Error> {
    let bad = || Error::Field { line, what };
    let a = v.as_array().filter(|a| a.len() == N).ok_or_else(bad)?;
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = x.as_f64().filter(|x| x.is_finite()).ok_or_else(bad)?;
    }
    Ok(out)
}

impl Pose {
    /// Reads the pose of a sample line (`line` is its number, for errors).
    pub(crate) fn of(sample: &Value, line: usize) -> Result<Self, Error> {
        let fingers = sample["fingers"]
            .as_array()
            .filter(|a| a.len() == 3)
            .ok_or(Error::Field {
                line,
                what: "fingers",
            })?;
        let tip = |f: &Value| -> Result<Tip, Error> {
            Ok(Tip {
                p: numbers::<3>(&f["p"], "p", line)?,
                q: numbers::<4>(&f["q"], "q", line)?,
                contact: f["contact"].as_bool().ok_or(Error::Field {
                    line,
                    what: "contact",
                })?,
            })
        };
        Ok(Self {
            object_q: numbers::<4>(&sample["object_q"], "object_q", line)?,
            tips: [tip(&fingers[0])?, tip(&fingers[1])?, tip(&fingers[2])?],
        })
    }

    /// The contact flags, to see when the scene changes.
    pub(crate) fn contacts(&self) -> [bool; 3] {
        self.tips.map(|t| t.contact)
    }
}

/// Foxglove's time: whole seconds and nanoseconds.
fn time(ns: u64) -> Value {
    json!({"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000})
}

/// Trace quaternion [w, x, y, z] → Foxglove's {x, y, z, w}.
fn quat(q: &[f64; 4]) -> Value {
    json!({"x": q[1], "y": q[2], "z": q[3], "w": q[0]})
}

fn vec3(v: &[f64; 3]) -> Value {
    json!({"x": v[0], "y": v[1], "z": v[2]})
}

fn transform(ns: u64, child: &str, p: &[f64; 3], q: &[f64; 4]) -> Value {
    json!({
        "timestamp": time(ns),
        "parent_frame_id": HAND_FRAME,
        "child_frame_id": child,
        "translation": vec3(p),
        "rotation": quat(q),
    })
}

/// The `foxglove.FrameTransforms` message of a pose at `ns`.
pub(crate) fn frame_transforms(ns: u64, pose: &Pose) -> Vec<u8> {
    let mut transforms = vec![transform(ns, OBJECT_FRAME, &[0.0; 3], &pose.object_q)];
    for (tip, frame) in pose.tips.iter().zip(TIP_FRAMES) {
        transforms.push(transform(ns, frame, &tip.p, &tip.q));
    }
    json!({ "transforms": transforms }).to_string().into_bytes()
}

/// An entity with only spheres and arrows (the other lists empty: Foxglove
/// requires them all).
fn entity(ns: u64, id: &str, frame: &str, spheres: Vec<Value>, arrows: Vec<Value>) -> Value {
    json!({
        "timestamp": time(ns),
        "frame_id": frame,
        "id": id,
        "lifetime": time(0),
        "frame_locked": true,
        "metadata": [],
        "arrows": arrows,
        "cubes": [],
        "spheres": spheres,
        "cylinders": [],
        "lines": [],
        "triangles": [],
        "texts": [],
        "models": [],
    })
}

fn sphere(diameter: f64, rgb: [f64; 3], a: f64) -> Value {
    json!({
        "pose": {"position": vec3(&[0.0; 3]), "orientation": quat(&[1.0, 0.0, 0.0, 0.0])},
        "size": vec3(&[diameter; 3]),
        "color": {"r": rgb[0], "g": rgb[1], "b": rgb[2], "a": a},
    })
}

/// The `foxglove.SceneUpdate` message at `ns`: the sphere (radius `big_r`)
/// with its x, y, z axes as red, green, blue arrows so that its rotation
/// shows, and the fingertips (radius `r`), opaque while touching.
pub(crate) fn scene_update(ns: u64, big_r: f64, r: f64, contacts: [bool; 3]) -> Vec<u8> {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    // Arrows point along +x at identity: +y is +x turned 90° about z, +z
    // is +x turned -90° about y.
    let axes = [
        ([1.0, 0.0, 0.0, 0.0], [0.9, 0.1, 0.1]),
        ([h, 0.0, 0.0, h], [0.1, 0.7, 0.1]),
        ([h, 0.0, -h, 0.0], [0.1, 0.1, 0.9]),
    ];
    let arrows = axes
        .iter()
        .map(|(q, c)| {
            json!({
                "pose": {"position": vec3(&[0.0; 3]), "orientation": quat(q)},
                "shaft_length": 1.15 * big_r,
                "shaft_diameter": 0.04 * big_r,
                "head_length": 0.15 * big_r,
                "head_diameter": 0.1 * big_r,
                "color": {"r": c[0], "g": c[1], "b": c[2], "a": 1.0},
            })
        })
        .collect();
    let mut entities = vec![entity(
        ns,
        "object",
        OBJECT_FRAME,
        vec![sphere(2.0 * big_r, [0.75, 0.75, 0.75], 0.6)],
        arrows,
    )];
    for (k, frame) in TIP_FRAMES.iter().enumerate() {
        let a = if contacts[k] { 1.0 } else { 0.35 };
        entities.push(entity(
            ns,
            frame,
            frame,
            vec![sphere(2.0 * r, COLORS[k], a)],
            Vec::new(),
        ));
    }
    json!({ "deletions": [], "entities": entities })
        .to_string()
        .into_bytes()
}
