//! The report of `gaitctl bench`: every figure as one JSON object (the
//! machine-readable result) and as a table for people.

use super::latency::{FirstMotion, GoalAnswers, StatusWindow};
use super::reference::Bare;
use super::summary;
use crate::common::us;
use serde_json::{Value, json};

/// Everything measured, raw.
#[derive(Debug)]
pub struct Measured {
    /// CPUs online, kernel, pinning.
    pub machine: Value,
    /// The daemon's process id and (RSS, peak RSS) \[kB\], if found.
    pub daemon: (Option<i32>, Option<(u64, u64)>),
    /// Goal → answer.
    pub goals: GoalAnswers,
    /// Goal → first motion.
    pub motion: FirstMotion,
    /// Tick compute time while moving \[µs\].
    pub moving_us: Vec<f64>,
    /// The status window.
    pub window: StatusWindow,
    /// Tick compute time in the status window, summarised.
    pub window_compute: Value,
    /// Missed periods, compute and jitter idle vs under load, if measured.
    pub load: Option<Value>,
    /// The bare iceoryx2 reference.
    pub bare: Bare,
    /// The fixed-work reference loop.
    pub reference_loop: Value,
}

/// `status p50 / reference p50`, if both are known.
fn ratio(status: &Value, reference: &Value) -> Option<f64> {
    match (status["p50"].as_f64(), reference["p50"].as_f64()) {
        (Some(s), Some(p)) if p > 0.0 => Some(s / p),
        _ => None,
    }
}

/// The report as JSON (summarising sorts the samples).
pub fn json(m: &mut Measured) -> Value {
    let (start, end) = (&m.window.start, &m.window.end);
    let t = &end.timing;
    let (pid, rss) = m.daemon;
    let status_s = summary(&mut m.window.publish_us);
    let pp_s = summary(&mut m.bare.one_way);
    let periodic_s = summary(&mut m.bare.periodic);
    json!({
        "machine": m.machine,
        "daemon": {
            "instance": format!("{:016x}", end.instance),
            "period_us": us(t.period_ns),
            "pid": pid,
            "rss_kb": rss.map(|r| r.0),
            "rss_peak_kb": rss.map(|r| r.1),
        },
        "goal_to_answer_us": summary(&mut m.goals.latency_us),
        "goal_verdicts": m.goals.verdicts,
        "goal_to_first_motion_ticks": summary(&mut m.motion.ticks),
        "goal_to_first_motion_wall_ms": summary(&mut m.motion.wall_ms),
        "status_vs_iceoryx2_pingpong_p50_ratio": ratio(&status_s, &pp_s),
        "status_vs_iceoryx2_periodic_p50_ratio": ratio(&status_s, &periodic_s),
        "status_publish_to_receive_us": status_s,
        "status_tick_to_receive_us": summary(&mut m.window.tick_us),
        "status_publish_to_receive_blocking_us": summary(&mut m.window.blocking_us),
        "iceoryx2_one_way_us": pp_s,
        "iceoryx2_half_round_trip_us": summary(&mut m.bare.half_rtt),
        "iceoryx2_periodic_one_way_us": periodic_s,
        "tick_compute_ns": {
            "p50": t.compute_p50_ns, "p99": t.compute_p99_ns, "max": t.compute_max_ns,
            "since": "daemon start",
        },
        "tick_compute_us_status_window": m.window_compute,
        "tick_compute_us_moving": summary(&mut m.moving_us),
        "reference_loop": m.reference_loop,
        "load": m.load,
        "missed_periods_in_window": t.overruns - start.timing.overruns,
        "jitter_histogram_window": super::tick::jitter_histogram(start, end),
        "jitter_p99_us_since_start": us(t.jitter_p99_ns),
    })
}

/// One latency row: p50, p99, max, mean, n (or n/a).
fn row(name: &str, v: &Value) {
    if v.is_null() {
        println!("{name:<36} {:>10}", "n/a");
        return;
    }
    let f = |k: &str| v[k].as_f64().map_or("-".into(), |x| format!("{x:.2}"));
    println!(
        "{name:<36} {:>10} {:>10} {:>10} {:>10} {:>8}",
        f("p50"),
        f("p99"),
        f("max"),
        f("mean"),
        v["n"]
    );
}

/// The report as a table.
pub fn print_table(r: &Value) {
    println!(
        "gaitctl bench  ({} cpus, kernel {}, loop {} us)",
        r["machine"]["cpus"],
        r["machine"]["kernel"].as_str().unwrap_or("?"),
        r["daemon"]["period_us"]
    );
    println!(
        "{:<36} {:>10} {:>10} {:>10} {:>10} {:>8}",
        "latency [us]", "p50", "p99", "max", "mean", "n"
    );
    for (name, key) in [
        ("goal -> answer", "goal_to_answer_us"),
        (
            "status publish -> client receive",
            "status_publish_to_receive_us",
        ),
        ("status tick -> client receive", "status_tick_to_receive_us"),
        (
            "status publish -> receive, blocking",
            "status_publish_to_receive_blocking_us",
        ),
        ("bare iceoryx2 one-way (same run)", "iceoryx2_one_way_us"),
        (
            "bare iceoryx2 round trip / 2",
            "iceoryx2_half_round_trip_us",
        ),
        (
            "bare iceoryx2 periodic one-way",
            "iceoryx2_periodic_one_way_us",
        ),
    ] {
        row(name, &r[key]);
    }
    println!("goal verdicts: {}", r["goal_verdicts"]);
    row(
        "goal -> first motion [ticks]",
        &r["goal_to_first_motion_ticks"],
    );
    let x = |k: &str| r[k].as_f64().map_or("-".into(), |x| format!("{x:.2}x"));
    println!(
        "status / bare iceoryx2 (p50): {} vs ping-pong, {} vs periodic publisher (target <= 2x)",
        x("status_vs_iceoryx2_pingpong_p50_ratio"),
        x("status_vs_iceoryx2_periodic_p50_ratio")
    );
    print_tick(r);
    if !r["load"].is_null() {
        super::many_clients::print(&r["load"]);
    }
    print_jitter(r);
    println!(
        "daemon RSS: {} kB (peak {} kB)",
        r["daemon"]["rss_kb"], r["daemon"]["rss_peak_kb"]
    );
}

/// Tick compute time: since start, in the window, moving, the reference.
fn print_tick(r: &Value) {
    let c = &r["tick_compute_ns"];
    println!(
        "tick compute [us] p50 {:.2} p99 {:.2} max {:.2} (since daemon start; target p99 <= 20)",
        c["p50"].as_f64().unwrap_or(0.0) / 1e3,
        c["p99"].as_f64().unwrap_or(0.0) / 1e3,
        c["max"].as_f64().unwrap_or(0.0) / 1e3
    );
    row(
        "tick compute, status window [us]",
        &r["tick_compute_us_status_window"],
    );
    row("tick compute, moving [us]", &r["tick_compute_us_moving"]);
    row(
        "fixed-work reference loop [us]",
        &r["reference_loop"]["compute_us"],
    );
    let (m, f) = (
        &r["tick_compute_us_moving"],
        &r["reference_loop"]["compute_us"],
    );
    if let (Some(mp), Some(fp), Some(mm), Some(fm)) = (
        m["p99"].as_f64(),
        f["p99"].as_f64(),
        m["max"].as_f64(),
        f["max"].as_f64(),
    ) {
        println!(
            "moving / reference: p99 {:.2}x (target <= 2x), max {:.2}x (target <= 1x)",
            mp / fp.max(1e-9),
            mm / fm.max(1e-9)
        );
    }
    println!(
        "missed periods in the bench window: {}",
        r["missed_periods_in_window"]
    );
}

/// The non-empty buckets of the window's wake-up jitter histogram.
fn print_jitter(r: &Value) {
    println!("wake-up jitter in the bench window:");
    for b in r["jitter_histogram_window"]
        .as_array()
        .into_iter()
        .flatten()
    {
        let n = b["count"].as_u64().unwrap_or(0);
        if n > 0 {
            let label = b["below_us"]
                .as_u64()
                .map_or("    >= 16384 us".into(), |u| format!("  < {u:>6} us"));
            println!("{label} {n:>9}");
        }
    }
}
