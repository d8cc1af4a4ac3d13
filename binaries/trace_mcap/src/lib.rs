//! `gait-trajectory/1` traces as MCAP recordings, the container Foxglove,
//! the ROS 2 bag tools and Rerun open, and back (docs/design/10-traces.md,
//! "MCAP").
//!
//! Channels (all `message_encoding = "json"`, schemas `jsonschema`):
//!
//! | topic | schema | what |
//! | --- | --- | --- |
//! | [`HEADER_TOPIC`] | `gaitd.TraceHeader` | the header line, once |
//! | [`SAMPLE_TOPIC`] | `gaitd.TraceSample` | each tick's line, verbatim |
//! | [`TF_TOPIC`] | `foxglove.FrameTransforms` | object and fingertip frames in `hand` |
//! | [`SCENE_TOPIC`] | `foxglove.SceneUpdate` | the sphere and the fingertips |
//!
//! A message's log time is its sample's `t` in nanoseconds (the header's:
//! the first sample's). The trace's own lines are copied byte for byte, so
//! [`read()`] gives back exactly the lines [`write()`] was given, numbers and
//! all. [`file::read`] reads a trace back whichever of the two it is in.
//! This crate is the only one that builds `mcap`: gaitctl and gaitd-view
//! use it, the daemon and the client library do not.

pub mod file;
mod scene;
pub mod schema;

use std::collections::BTreeMap;
use std::io::{BufRead, Seek, Write};

use serde_json::Value;

/// Topic of the trace's header line (one message).
pub const HEADER_TOPIC: &str = "/gaitd/header";
/// Topic of the trace's tick lines (one message per tick).
pub const SAMPLE_TOPIC: &str = "/gaitd/sample";
/// Topic of the frames for 3D views (`foxglove.FrameTransforms`).
pub const TF_TOPIC: &str = "/gaitd/tf";
/// Topic of the shapes for 3D views (`foxglove.SceneUpdate`).
pub const SCENE_TOPIC: &str = "/gaitd/scene";

/// Period of the frame messages \[s\]: a 3D view needs no more than 100 Hz,
/// and at the control rate they would outweigh the samples.
pub const TF_PERIOD: f64 = 0.01;

/// Why a trace could not be converted or read back.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Reading the trace or writing the recording failed.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The trace has no header line.
    #[error("empty trace")]
    Empty,
    /// The first line is not a `gait-trajectory/1` header.
    #[error(
        "line 1: not a {} header (no matching \"format\")",
        gait::trace::FORMAT
    )]
    NotATrace,
    /// A line is not JSON.
    #[error("line {line}: {source}")]
    Json {
        /// Line number, from 1.
        line: usize,
        /// The parser's complaint.
        source: serde_json::Error,
    },
    /// A line lacks a key, or has one of the wrong type or size.
    #[error("line {line}: `{what}` is missing or malformed")]
    Field {
        /// Line number, from 1.
        line: usize,
        /// The key.
        what: &'static str,
    },
    /// The trace has a header but no samples.
    #[error("the trace has no samples")]
    NoSamples,
    /// The MCAP library refused the recording (truncated, corrupt, …).
    #[error("not a readable MCAP recording: {0}")]
    Mcap(#[from] mcap::McapError),
    /// A readable MCAP recording without a gait trace in it.
    #[error("no gait trace in this MCAP recording (no message on {HEADER_TOPIC})")]
    NoHeader,
    /// More than one header message.
    #[error("more than one message on {HEADER_TOPIC}")]
    TwoHeaders,
    /// A trace message that is not UTF-8 JSON text.
    #[error("a message on {topic} is not JSON text")]
    NotText {
        /// Its topic.
        topic: &'static str,
    },
}

/// What [`write()`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Written {
    /// Samples (tick lines).
    pub samples: u64,
    /// Messages on all channels.
    pub messages: u64,
    /// Log time of the first sample \[ns\].
    pub start_ns: u64,
    /// Log time of the last sample \[ns\].
    pub end_ns: u64,
}

/// The trace's lines, as read back from a recording.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Lines {
    /// The header line (without newline).
    pub header: String,
    /// The tick lines in order (without newlines).
    pub samples: Vec<String>,
}

/// Whether `prefix` (a file's first bytes) starts with the MCAP magic.
pub fn is_mcap(prefix: &[u8]) -> bool {
    prefix.starts_with(mcap::MAGIC)
}

/// Seconds → nanoseconds, if the time fits a log time.
fn ns(t: f64) -> Option<u64> {
    let x = (t * 1e9).round();
    (x.is_finite() && x >= 0.0 && x < u64::MAX as f64).then_some(x as u64)
}

fn parse(text: &str, line: usize) -> Result<Value, Error> {
    serde_json::from_str(text).map_err(|source| Error::Json { line, source })
}

fn channel<W: Write + Seek>(
    w: &mut mcap::Writer<W>,
    topic: &str,
    name: &str,
    schema: &str,
) -> Result<u16, Error> {
    let id = w.add_schema(name, "jsonschema", schema.as_bytes())?;
    Ok(w.add_channel(id, topic, "json", &BTreeMap::new())?)
}

/// Writes the trace read from `trace` (JSON lines) to `out` as MCAP.
///
/// The header is held back until the first sample gives its log time, so
/// the recording starts at the trace's first tick. On an error `out` holds
/// a partial recording: the caller removes it.
pub fn write<R: BufRead, W: Write + Seek>(trace: R, out: W) -> Result<Written, Error> {
    let mut lines = trace.lines();
    let header = lines.next().ok_or(Error::Empty)??;
    let h = parse(&header, 1)?;
    if h["format"].as_str() != Some(gait::trace::FORMAT) {
        return Err(Error::NotATrace);
    }
    let num = |what: &'static str| {
        h[what]
            .as_f64()
            .filter(|x| x.is_finite() && *x > 0.0)
            .ok_or(Error::Field { line: 1, what })
    };
    let (dt, big_r, r) = (num("dt")?, num("object_radius")?, num("fingertip_radius")?);
    let stride = ((TF_PERIOD / dt).round() as u64).max(1);

    let options =
        mcap::WriteOptions::new().library(concat!("gaitd trace_mcap/", env!("CARGO_PKG_VERSION")));
    let mut w = options.create(out)?;
    let header_ch = channel(&mut w, HEADER_TOPIC, "gaitd.TraceHeader", schema::HEADER)?;
    let sample_ch = channel(&mut w, SAMPLE_TOPIC, "gaitd.TraceSample", schema::SAMPLE)?;
    let tf_ch = channel(
        &mut w,
        TF_TOPIC,
        "foxglove.FrameTransforms",
        schema::FRAME_TRANSFORMS,
    )?;
    let scene_ch = channel(
        &mut w,
        SCENE_TOPIC,
        "foxglove.SceneUpdate",
        schema::SCENE_UPDATE,
    )?;
    let mut seq: BTreeMap<u16, u32> = BTreeMap::new();
    let mut put = |w: &mut mcap::Writer<W>, ch: u16, t: u64, data: &[u8]| {
        let s = seq.entry(ch).or_default();
        *s = s.wrapping_add(1);
        let h = mcap::records::MessageHeader {
            channel_id: ch,
            sequence: *s,
            log_time: t,
            publish_time: t,
        };
        w.write_to_known_channel(&h, data)
    };

    let mut written = Written {
        samples: 0,
        messages: 0,
        start_ns: 0,
        end_ns: 0,
    };
    // The last pose, written out at the end if the stride skipped it.
    let mut pending: Option<(u64, scene::Pose)> = None;
    let mut contacts: Option<[bool; 3]> = None;
    for (i, text) in lines.enumerate() {
        let line = i + 2;
        let text = text?;
        let text = text.trim();
        if text.is_empty() {
            continue;
        }
        let v = parse(text, line)?;
        let t = v["t"]
            .as_f64()
            .and_then(ns)
            .ok_or(Error::Field { line, what: "t" })?;
        let pose = scene::Pose::of(&v, line)?;
        if written.samples == 0 {
            written.start_ns = t;
            put(&mut w, header_ch, t, header.trim().as_bytes())?;
            written.messages += 1;
        }
        put(&mut w, sample_ch, t, text.as_bytes())?;
        let changed = contacts != Some(pose.contacts());
        if changed {
            contacts = Some(pose.contacts());
            let data = scene::scene_update(t, big_r, r, pose.contacts());
            put(&mut w, scene_ch, t, &data)?;
            written.messages += 1;
        }
        if changed || written.samples.is_multiple_of(stride) {
            put(&mut w, tf_ch, t, &scene::frame_transforms(t, &pose))?;
            written.messages += 1;
            pending = None;
        } else {
            pending = Some((t, pose));
        }
        written.samples += 1;
        written.messages += 1;
        written.end_ns = t;
    }
    if let Some((t, pose)) = pending {
        put(&mut w, tf_ch, t, &scene::frame_transforms(t, &pose))?;
        written.messages += 1;
    }
    if written.samples == 0 {
        return Err(Error::NoSamples);
    }
    w.finish()?;
    Ok(written)
}

/// Reads the trace's lines back from a whole MCAP recording in memory.
///
/// A truncated or corrupt recording is an error, never a shorter or
/// altered trace: the reader checks the records up to the end magic and
/// each chunk's CRC.
pub fn read(mcap: &[u8]) -> Result<Lines, Error> {
    let mut header = None;
    let mut samples = Vec::new();
    // Chunk CRCs checked: a changed digit must not pass for a trace.
    let options = mcap::read::Options::ValidateChunkCrcs.into();
    for m in mcap::MessageStream::new_with_options(mcap, options)? {
        let m = m?;
        let topic = match m.channel.topic.as_str() {
            HEADER_TOPIC => HEADER_TOPIC,
            SAMPLE_TOPIC => SAMPLE_TOPIC,
            _ => continue,
        };
        let text = String::from_utf8(m.data.into_owned()).map_err(|_| Error::NotText { topic })?;
        if topic == HEADER_TOPIC {
            if header.replace(text).is_some() {
                return Err(Error::TwoHeaders);
            }
        } else {
            samples.push(text);
        }
    }
    let header = header.ok_or(Error::NoHeader)?;
    Ok(Lines { header, samples })
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = r#"{"format":"gait-trajectory/1","object_radius":0.5,"fingertip_radius":0.1,"mu":0.4,"dt":0.001}"#;
    const TIP: &str = r#"{"p":[0.6,0,0],"q":[1,0,0,0],"contact":true}"#;

    fn convert(text: &str) -> Result<Written, Error> {
        write(text.as_bytes(), std::io::Cursor::new(Vec::new()))
    }

    fn sample(t: &str) -> String {
        format!(r#"{{"t":{t},"object_q":[1,0,0,0],"fingers":[{TIP},{TIP},{TIP}]}}"#)
    }

    #[test]
    fn bad_traces_are_typed_errors() {
        assert!(matches!(convert(""), Err(Error::Empty)));
        assert!(matches!(
            convert("{\"format\":\"x\"}\n"),
            Err(Error::NotATrace)
        ));
        assert!(matches!(convert("{\n"), Err(Error::Json { line: 1, .. })));
        assert!(matches!(
            convert(&format!("{HEADER}\n")),
            Err(Error::NoSamples)
        ));
        let neg = format!("{HEADER}\n{}\n{}\n", sample("0.001"), sample("-1"));
        assert!(matches!(
            convert(&neg),
            Err(Error::Field { line: 3, what: "t" })
        ));
        let no_fingers = format!("{HEADER}\n{{\"t\":0.001,\"object_q\":[1,0,0,0]}}\n");
        assert!(matches!(
            convert(&no_fingers),
            Err(Error::Field {
                line: 2,
                what: "fingers"
            })
        ));
        let good = format!("{HEADER}\n{}\n{}\n", sample("0.001"), sample("0.002"));
        let w = convert(&good).expect("a trace");
        assert_eq!((w.samples, w.start_ns, w.end_ns), (2, 1_000_000, 2_000_000));
    }

    #[test]
    fn what_is_not_an_mcap_recording_is_an_error() {
        assert!(!is_mcap(b"{\"format\""));
        assert!(matches!(read(b"{\"format\":1}"), Err(Error::Mcap(_))));
        assert!(matches!(read(&mcap::MAGIC[..6]), Err(Error::Mcap(_))));
    }
}
