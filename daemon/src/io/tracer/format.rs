//! What a trace file is called and what its header says beyond the
//! `gait-trajectory/1` keys that `gait::trace::header` writes.
//!
//! Names: `gaitd-<instance>-client-<client>-goal-<goal>.jsonl` once
//! finished; while the goal runs its lines go to a hidden
//! `.<name>.part`.

use super::{PlanNote, TraceSettings};
use gait::executor::GoalTarget;
use shm_schema::{GoalState, ReasonCode};
use std::fmt::Write as _;
use std::path::PathBuf;

/// The final path of goal `goal_id` of client `client_id`'s trace.
pub fn trace_path(settings: &TraceSettings, client_id: u64, goal_id: u64) -> PathBuf {
    settings.dir.join(format!(
        "gaitd-{:016x}-client-{client_id:016x}-goal-{goal_id}.jsonl",
        settings.instance
    ))
}

/// The hidden file the lines go to while the goal runs.
pub fn part_path(settings: &TraceSettings, client_id: u64, goal_id: u64) -> PathBuf {
    settings.dir.join(format!(
        ".gaitd-{:016x}-client-{client_id:016x}-goal-{goal_id}.jsonl.part",
        settings.instance
    ))
}

/// Whether `name` is a finished trace's file name
/// (`gaitd-<instance>-client-<client>-goal-<goal>.jsonl`).
pub fn is_trace_name(name: &str) -> bool {
    name.starts_with("gaitd-") && name.ends_with(".jsonl") && name.contains("-goal-")
}

/// What the trace is of and how it ended.
#[derive(Debug, Clone)]
pub struct HeaderFacts {
    /// The planner's note on the goal's (last) plan, if any.
    pub plan: Option<PlanNote>,
    /// Sending client.
    pub client_id: u64,
    /// The client's goal id.
    pub goal_id: u64,
    /// The goal's target, if known.
    pub target: Option<GoalTarget>,
    /// Terminal state and reason (None: unknown).
    pub outcome: Option<(GoalState, ReasonCode)>,
    /// Ticks written.
    pub ticks: u64,
    /// Ticks lost.
    pub dropped: u64,
    /// A chain hand's description (its hand section file), for views that
    /// draw its links.
    pub hand_description: Option<String>,
}

/// The header's extra keys (JSON members, no braces): source, instance,
/// goal, target, outcome, tick counts and `"incomplete"`; on a chain hand
/// `"hand":"chains"` and `"hand_description"`, its hand section file.
pub fn header_extra(instance: u64, h: &HeaderFacts) -> String {
    let mut x = String::new();
    let _ = write!(
        x,
        "\"source\":\"gaitd\",\"instance\":\"{instance:016x}\",\"client_id\":{},\"goal_id\":{}",
        h.client_id, h.goal_id
    );
    match h.target {
        Some(GoalTarget::Orientation(q)) => {
            let q = q.quaternion();
            let _ = write!(x, ",\"target_q\":[{},{},{},{}]", q.w, q.i, q.j, q.k);
        }
        Some(GoalTarget::Rotation { axis, angle }) => {
            let _ = write!(
                x,
                ",\"target_axis\":[{},{},{}],\"target_angle\":{angle}",
                axis.x, axis.y, axis.z
            );
        }
        None => {}
    }
    let (state, reason) = h
        .outcome
        .map_or(("unknown", "unknown"), |(s, r)| (s.name(), r.name()));
    let _ = write!(
        x,
        ",\"outcome\":\"{state}\",\"reason\":\"{reason}\",\"ticks\":{},\"dropped_ticks\":{},\"incomplete\":{}",
        h.ticks,
        h.dropped,
        h.dropped > 0 || h.outcome.is_none()
    );
    if let Some(d) = &h.hand_description {
        let _ = write!(
            x,
            ",\"hand\":\"chains\",\"hand_description\":\"{}\"",
            json_escape(d)
        );
    }
    if let Some(p) = &h.plan {
        let e = &p.effort;
        let _ = write!(
            x,
            ",\"plan_route\":\"{}\",\"plan_effort\":{{\"expansions\":{},\"generated\":{},\"evaluated\":{},\"built\":{},\"refused\":{},\"passes\":{}}},\"planning_ms\":{}",
            json_escape(&p.route),
            e.expansions,
            e.generated,
            e.evaluated,
            e.built,
            e.refused,
            e.passes,
            p.planning_ms
        );
    }
    x
}

/// `s` as the inside of a JSON string.
fn json_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out
}
