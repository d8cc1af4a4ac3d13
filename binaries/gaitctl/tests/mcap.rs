//! Traces as MCAP recordings, through the `gaitctl` binary: `plan --mcap`
//! and `trace mcap` write the same recording; read back with the MCAP
//! library it holds the trace's lines and times exactly, every message
//! validates against its channel's schema; `plot` draws the same picture
//! from it as from the JSON lines; a damaged recording is one clear error.
//!
//! The trace is a real one: a 120° turn planned and executed offline
//! (finger substitutions, so fingers touch and leave the sphere), 0.3 s.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

use serde_json::Value;

fn gaitctl(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gaitctl"))
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("gaitctl runs")
}

fn ok(out: Output) -> Output {
    assert!(
        out.status.success(),
        "gaitctl failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A scratch directory with `t.jsonl` and `t.mcap` of one `gaitctl plan`.
fn fixture() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        // In the target directory, remade by each run: nothing left in /tmp.
        let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("gaitctl-mcap");
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let (jsonl, mcap) = (d.join("t.jsonl"), d.join("t.mcap"));
        ok(gaitctl(&[
            "plan",
            "--axis",
            "0,0,1",
            "--angle",
            "120",
            "--relative",
            "-o",
            jsonl.to_str().unwrap(),
            "--mcap",
            mcap.to_str().unwrap(),
        ]));
        d
    })
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The recording's messages: (topic, schema name, schema encoding, schema
/// text, message encoding, log time, data).
type Msg = (String, String, String, String, String, u64, Vec<u8>);

fn messages(mcap: &[u8]) -> Vec<Msg> {
    mcap::MessageStream::new(mcap)
        .expect("an MCAP recording")
        .map(|m| {
            let m = m.expect("a readable message");
            let s = m.channel.schema.as_ref().expect("a schema");
            (
                m.channel.topic.clone(),
                s.name.clone(),
                s.encoding.clone(),
                String::from_utf8(s.data.to_vec()).expect("schema text"),
                m.channel.message_encoding.clone(),
                m.log_time,
                m.data.to_vec(),
            )
        })
        .collect()
}

#[test]
fn the_recording_holds_the_trace_lines_and_their_times() {
    let d = fixture();
    let text = String::from_utf8(read(&d.join("t.jsonl"))).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let msgs = messages(&read(&d.join("t.mcap")));
    let on = |topic: &str| -> Vec<&Msg> { msgs.iter().filter(|m| m.0 == topic).collect() };
    let header = on("/gaitd/header");
    assert_eq!(header.len(), 1);
    assert_eq!(header[0].6, lines[0].as_bytes());
    let samples = on("/gaitd/sample");
    assert_eq!(samples.len(), lines.len() - 1, "one message per tick");
    for (m, line) in samples.iter().zip(&lines[1..]) {
        let (got, want): (Value, Value) = (
            serde_json::from_slice(&m.6).unwrap(),
            serde_json::from_str(line).unwrap(),
        );
        // The numbers themselves, not only the text: `f64` equality.
        assert_eq!(got, want);
        let t = want["t"].as_f64().unwrap();
        assert_eq!(m.5, (t * 1e9).round() as u64, "log time = t in ns");
    }
    assert_eq!(header[0].5, samples[0].5, "the header at the first tick");
    // `trace mcap` of the JSON lines writes the very same recording.
    let again = d.join("again.mcap");
    ok(gaitctl(&[
        "trace",
        "mcap",
        d.join("t.jsonl").to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
    ]));
    assert!(read(&again) == read(&d.join("t.mcap")));
}

#[test]
fn every_message_validates_against_its_channel_schema() {
    let msgs = messages(&read(&fixture().join("t.mcap")));
    let mut schemas: BTreeMap<String, Value> = BTreeMap::new();
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for (topic, name, schema_enc, schema, msg_enc, _, data) in &msgs {
        assert_eq!(
            (schema_enc.as_str(), msg_enc.as_str()),
            ("jsonschema", "json")
        );
        let s = schemas.entry(topic.clone()).or_insert_with(|| {
            serde_json::from_str(schema)
                .unwrap_or_else(|e| panic!("{topic}: schema {name} is not JSON: {e}"))
        });
        assert_eq!(s["title"].as_str(), Some(name.as_str()), "{topic}");
        let v: Value = serde_json::from_slice(data).expect("a JSON message");
        if let Err(e) = validate(s, s, &v, "") {
            panic!("{topic}: {e}\n{v}");
        }
        *counts.entry(topic.clone()).or_default() += 1;
    }
    let topics: BTreeSet<&str> = counts.keys().map(String::as_str).collect();
    let want = [
        "/gaitd/header",
        "/gaitd/sample",
        "/gaitd/scene",
        "/gaitd/tf",
    ];
    assert_eq!(topics, want.into_iter().collect());
    // The scene again wherever a finger touches or leaves the sphere.
    assert!(counts["/gaitd/scene"] >= 3, "{counts:?}");
}

/// A JSON Schema validator for the keywords these schemas use; any other
/// keyword fails, so a schema cannot say more than is checked here.
fn validate(root: &Value, s: &Value, v: &Value, at: &str) -> Result<(), String> {
    let obj = s.as_object().ok_or(format!("{at}: schema not an object"))?;
    for (k, want) in obj {
        match k.as_str() {
            "title" | "description" | "$defs" => {}
            "$ref" => {
                let name = want.as_str().and_then(|r| r.strip_prefix("#/$defs/"));
                let target = name.and_then(|n| root["$defs"].get(n));
                validate(root, target.ok_or(format!("{at}: bad $ref"))?, v, at)?;
            }
            "type" => {
                let types: Vec<&str> = match want {
                    Value::String(t) => vec![t.as_str()],
                    Value::Array(a) => a.iter().filter_map(Value::as_str).collect(),
                    _ => return Err(format!("{at}: bad type")),
                };
                let fits = |t: &str| match t {
                    "object" => v.is_object(),
                    "array" => v.is_array(),
                    "string" => v.is_string(),
                    "boolean" => v.is_boolean(),
                    "null" => v.is_null(),
                    "number" => v.is_number(),
                    "integer" => v.is_u64() || v.is_i64(),
                    _ => false,
                };
                if !types.iter().any(|t| fits(t)) {
                    return Err(format!("{at}: {v} is not {types:?}"));
                }
            }
            "const" if v != want => return Err(format!("{at}: {v} is not {want}")),
            "const" => {}
            "minimum" | "maximum" => {
                let (x, b) = (v.as_f64(), want.as_f64().ok_or("bad bound")?);
                let out = x.is_some_and(|x| if k == "minimum" { x < b } else { x > b });
                if out {
                    return Err(format!("{at}: {v} beyond {k} {b}"));
                }
            }
            "minItems" | "maxItems" => {
                let (n, b) = (v.as_array().map(Vec::len), want.as_u64().ok_or("bad")?);
                let out = n.is_some_and(|n| {
                    if k == "minItems" {
                        (n as u64) < b
                    } else {
                        n as u64 > b
                    }
                });
                if out {
                    return Err(format!("{at}: {} items against {k} {b}", n.unwrap_or(0)));
                }
            }
            "items" => {
                for (i, x) in v.as_array().into_iter().flatten().enumerate() {
                    validate(root, want, x, &format!("{at}/{i}"))?;
                }
            }
            "properties" => {
                let props = want.as_object().ok_or("bad properties")?;
                for (name, ps) in props {
                    if let Some(x) = v.get(name) {
                        validate(root, ps, x, &format!("{at}/{name}"))?;
                    }
                }
            }
            "required" => {
                for name in want
                    .as_array()
                    .into_iter()
                    .flatten()
                    .filter_map(Value::as_str)
                {
                    if v.is_object() && v.get(name).is_none() {
                        return Err(format!("{at}: `{name}` missing"));
                    }
                }
            }
            other => return Err(format!("{at}: keyword {other} not checked here")),
        }
    }
    Ok(())
}

#[test]
fn plot_draws_the_same_picture_from_the_recording() {
    let d = fixture();
    let (a, b) = (d.join("jsonl.svg"), d.join("mcap.svg"));
    ok(gaitctl(&[
        "plot",
        d.join("t.jsonl").to_str().unwrap(),
        "-o",
        a.to_str().unwrap(),
    ]));
    ok(gaitctl(&[
        "plot",
        d.join("t.mcap").to_str().unwrap(),
        "-o",
        b.to_str().unwrap(),
    ]));
    assert!(read(&a) == read(&b), "the two SVGs differ");
}

#[test]
fn a_damaged_recording_is_one_clear_error() {
    let d = fixture();
    let good = read(&d.join("t.mcap"));
    let mut flipped = good.clone();
    // A byte of the records (past the header and schemas).
    flipped[good.len() / 3] ^= 0x5a;
    // A digit of a sample: the JSON stays valid, only the CRC tells.
    let mut digit = good.clone();
    let at = |text: &[u8], from: usize| {
        let key = b"\"grip_force\":";
        from + text[from..]
            .windows(key.len())
            .position(|w| w == key)
            .unwrap()
            + key.len()
    };
    let i = at(&good, good.len() / 2);
    digit[i] = if digit[i] == b'7' { b'6' } else { b'7' };
    let cases = [
        ("half", good[..good.len() / 2].to_vec()),
        ("no end", good[..good.len() - 4].to_vec()),
        ("magic only", good[..8].to_vec()),
        ("a flipped byte", flipped),
        ("a changed digit", digit),
    ];
    for (what, bytes) in cases {
        let p = d.join(format!("bad-{}.mcap", what.replace(' ', "-")));
        std::fs::write(&p, bytes).unwrap();
        let out = gaitctl(&["plot", p.to_str().unwrap(), "-o", "/dev/null/x.svg"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{what}: {err}");
        assert_eq!(err.lines().count(), 1, "{what}: one line:\n{err}");
        assert!(err.starts_with("gaitctl: "), "{what}: {err}");
        assert!(
            err.contains("MCAP") && err.contains(p.to_str().unwrap()),
            "{what}: {err}"
        );
        assert!(!err.contains("panicked"), "{what}: {err}");
    }
}

#[test]
fn a_bad_trace_leaves_no_recording() {
    let d = fixture();
    let text = String::from_utf8(read(&d.join("t.jsonl"))).unwrap();
    let mut lines: Vec<&str> = text.lines().take(3).collect();
    lines.push("{\"t\": oops}");
    let (bad, out) = (d.join("bad.jsonl"), d.join("bad-out.mcap"));
    std::fs::write(&bad, lines.join("\n")).unwrap();
    let o = gaitctl(&[
        "trace",
        "mcap",
        bad.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "one line:\n{err}");
    assert!(err.contains("line 4"), "{err}");
    assert!(!out.exists(), "a partial recording was left");
}
