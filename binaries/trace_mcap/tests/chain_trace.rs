//! A chain hand's trace through MCAP: the lines the daemon writes for a
//! hand of finger chains (each finger's `joints`, the sample's
//! `joint_margin`, the header's `hand` and `hand_description`) come back
//! from the recording as they went in, and the recording's JSON schemas
//! declare every key those lines have, so a tool that reads the schema
//! (Foxglove's raw-message panel, a ROS 2 bag reader) sees them.

use gait::HandConfig;
use gait::trace::{FingerSample, Sample, header, sample_line};
use nalgebra::{UnitQuaternion, Vector3};
use serde_json::Value;

/// The joints of finger `k` at sample `i` \[rad\].
fn joints(i: usize, k: usize) -> Vector3<f64> {
    Vector3::new(
        0.1 * k as f64,
        0.9 - 0.01 * i as f64,
        -1.7 + 0.02 * i as f64,
    )
}

/// A chain hand's trace: the header with the daemon's chain keys, then
/// `n` ticks whose fingers carry joints.
fn chain_trace(n: usize) -> String {
    let mut out = String::new();
    header(
        &mut out,
        &HandConfig::default(),
        0.001,
        "\"source\":\"gaitd\",\"hand\":\"chains\",\"hand_description\":\"/opt/hands/trifingerpro/hand.toml\"",
    );
    for i in 0..n {
        let fingers = std::array::from_fn(|k| FingerSample {
            p: Vector3::new(0.04, 0.01 * k as f64, 0.0),
            q: UnitQuaternion::identity(),
            contact: k != 1,
            grip_force: if k == 1 { 0.0 } else { 1.5 },
            roll: 0.0,
            joints: Some(joints(i, k)),
        });
        let s = Sample {
            object_q: UnitQuaternion::from_euler_angles(0.0, 0.0, 0.01 * i as f64),
            phase: "rotate",
            fingers,
            fc: true,
            fc_margin: 0.2,
            load_margin: 0.3,
            remaining_angle: 1.0,
            gaits: 0,
            estimate_epoch: 0,
            joint_margin: Some(0.25),
        };
        sample_line(&mut out, (i + 1) as f64 * 0.001, &s);
    }
    out
}

#[test]
fn a_chain_traces_joints_and_description_come_back_from_its_recording() {
    let dir = std::env::temp_dir().join(format!("trace-mcap-chain-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("chain.mcap");
    let file = std::fs::File::create(&path).unwrap();
    let w = trace_mcap::write(chain_trace(25).as_bytes(), file).expect("a recording");
    assert_eq!(w.samples, 25);
    let t = trace_mcap::file::read(&path).expect("read back");
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(
        t.hand_description.as_deref(),
        Some("/opt/hands/trifingerpro/hand.toml")
    );
    assert_eq!(t.samples.len(), 25);
    for (i, s) in t.samples.iter().enumerate() {
        for (k, f) in s.fingers.iter().enumerate() {
            let q = f
                .joints
                .unwrap_or_else(|| panic!("sample {i}: finger {k} has no joints"));
            assert_eq!(Vector3::from(q), joints(i, k), "sample {i}, finger {k}");
        }
    }
}

/// The names of the properties `schema` declares at `path` (object keys
/// to walk, `[]` for an array's items).
fn declared(schema: &Value, path: &[&str]) -> Vec<String> {
    let mut v = schema;
    for p in path {
        v = if *p == "[]" {
            &v["items"]
        } else {
            &v["properties"][p]
        };
    }
    v["properties"]
        .as_object()
        .unwrap_or_else(|| panic!("no properties at {path:?}"))
        .keys()
        .cloned()
        .collect()
}

#[test]
fn the_recordings_schemas_declare_every_key_of_a_chain_trace() {
    let sample_schema: Value = serde_json::from_str(trace_mcap::schema::SAMPLE).unwrap();
    let header_schema: Value = serde_json::from_str(trace_mcap::schema::HEADER).unwrap();
    let text = chain_trace(1);
    let mut lines = text.lines();
    let head: Value = serde_json::from_str(lines.next().unwrap()).unwrap();
    let sample: Value = serde_json::from_str(lines.next().unwrap()).unwrap();
    let of_sample = declared(&sample_schema, &[]);
    for key in sample.as_object().unwrap().keys() {
        assert!(
            of_sample.contains(key),
            "sample key {key} not in the schema"
        );
    }
    let of_finger = declared(&sample_schema, &["fingers", "[]"]);
    for f in sample["fingers"].as_array().unwrap() {
        for key in f.as_object().unwrap().keys() {
            assert!(
                of_finger.contains(key),
                "finger key {key} not in the schema"
            );
        }
    }
    // The header allows other keys (writers add their own); the model's
    // and the chain hand's are declared.
    let of_header = declared(&header_schema, &[]);
    for key in head.as_object().unwrap().keys() {
        if key != "source" {
            assert!(
                of_header.contains(key),
                "header key {key} not in the schema"
            );
        }
    }
}
