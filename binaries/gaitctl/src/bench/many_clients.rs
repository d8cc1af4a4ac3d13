//! `gaitctl bench --load-seconds S`: does load from clients cost the loop
//! its deadlines (SPEC §12 "many status readers and goal writers at once
//! without missed ticks caused by them")?
//!
//! Two windows of S seconds on the running daemon, one idle and one with
//! background clients — readers blocking on every status, writers sending
//! goals, cancels, holds and malformed commands back to back, each its own
//! client and thread — and for each window: missed periods and the wake-up
//! jitter histogram (from the status counters), and the per-tick compute
//! time of the ticks this process saw (`compute_last_ns` of each status).

use crate::common::ConnArgs;
use gaitd_client::{Client, Command, GoalFrame, GoalSpec, Status};
use serde_json::json;
use shm_schema::status::{JITTER_BUCKETS, jitter_bucket_upper_ns};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Background clients.
struct Load {
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<(u64, u64)>>,
}

/// Reads every status until stopped; returns (statuses, errors).
fn read(mut c: Client, stop: &AtomicBool) -> (u64, u64) {
    let (mut n, mut errors) = (0, 0);
    while !stop.load(Ordering::Relaxed) {
        match c.wait_status(Duration::from_secs(1)) {
            Ok(_) => n += 1,
            Err(_) => errors += 1,
        }
    }
    (n, errors)
}

/// Sends commands back to back until stopped; returns (answered, errors).
fn write(mut c: Client, stop: &AtomicBool) -> (u64, u64) {
    let t = Duration::from_secs(2);
    let (mut n, mut errors) = (0u64, 0u64);
    while !stop.load(Ordering::Relaxed) {
        let r = match n % 4 {
            0 => GoalSpec::axis_angle([0.0, 0.0, 1.0], 0.05, GoalFrame::Relative)
                .and_then(|g| c.reorient(&g, t).map(|_| ())),
            1 => c.cancel(None, t).map(|_| ()),
            2 => c.hold(t).map(|_| ()),
            _ => {
                let me = c.client_id();
                let bad = Command::goal(me, 1, GoalFrame::Absolute, [f64::NAN, 0.0, 0.0, 0.0]);
                c.send_command(bad)
                    .and_then(|req| c.wait_answer(req, t).map(|_| ()))
            }
        };
        match r {
            Ok(()) => n += 1,
            Err(_) => errors += 1,
        }
    }
    (n, errors)
}

impl Load {
    fn start(conn: &ConnArgs, readers: usize, writers: usize) -> gaitd_client::Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let mut threads = Vec::new();
        for i in 0..readers + writers {
            // Connect here so a failure is reported, then move the client's
            // options (a Client itself stays on its thread).
            drop(conn.connect("gaitctl")?);
            let (conn, stop) = (conn.clone(), stop.clone());
            threads.push(std::thread::spawn(move || match conn.connect("gaitctl") {
                Ok(c) if i < readers => read(c, &stop),
                Ok(c) => write(c, &stop),
                Err(_) => (0, 1),
            }));
        }
        Ok(Self { stop, threads })
    }

    /// Stops the clients; returns (readers' statuses + writers' answers, errors).
    fn stop(self) -> (u64, u64) {
        self.stop.store(true, Ordering::Relaxed);
        self.threads
            .into_iter()
            .map(|t| t.join().unwrap_or((0, 1)))
            .fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
    }
}

/// One window: statuses seen, compute times \[µs\] of those ticks.
fn window(c: &mut Client, seconds: f64) -> gaitd_client::Result<(Status, Status, Vec<f64>)> {
    let first = c.wait_status(Duration::from_secs(2))?;
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    let mut compute = Vec::new();
    let mut last = first;
    while Instant::now() < end {
        let s = c.wait_status(Duration::from_secs(2))?;
        compute.push(s.timing.compute_last_ns as f64 / 1e3);
        last = s;
    }
    Ok((first, last, compute))
}

fn window_json(
    (first, last, mut compute): (Status, Status, Vec<f64>),
    extra: serde_json::Value,
) -> serde_json::Value {
    let hist: Vec<_> = (0..JITTER_BUCKETS)
        .map(|i| {
            json!({
                "below_us": (i + 1 < JITTER_BUCKETS).then(|| jitter_bucket_upper_ns(i) / 1000),
                "count": last.timing.jitter_hist[i] - first.timing.jitter_hist[i],
            })
        })
        .collect();
    json!({
        "ticks": last.tick - first.tick,
        "missed_periods": last.timing.overruns - first.timing.overruns,
        "tick_compute_us_of_seen_ticks": super::summary(&mut compute),
        "jitter_histogram": hist,
        "clients": last.clients,
        "load": extra,
    })
}

/// Runs the idle and the loaded window; returns their report.
pub fn run(
    conn: &ConnArgs,
    c: &mut Client,
    seconds: f64,
    readers: usize,
    writers: usize,
) -> gaitd_client::Result<serde_json::Value> {
    let idle = window(c, seconds)?;
    let load = Load::start(conn, readers, writers)?;
    // Let the clients connect and settle before the window starts.
    std::thread::sleep(Duration::from_millis(500));
    let loaded = window(c, seconds);
    let (done, errors) = load.stop();
    Ok(json!({
        "seconds": seconds,
        "idle": window_json(idle, json!(null)),
        "loaded": window_json(loaded?, json!({
            "readers": readers, "writers": writers,
            "statuses_and_answers": done, "client_errors": errors,
        })),
    }))
}

/// Prints the report of [`run`].
pub fn print(r: &serde_json::Value) {
    println!(
        "load: {} s idle, then {} s with {} status readers + {} goal writers",
        r["seconds"], r["seconds"], r["loaded"]["load"]["readers"], r["loaded"]["load"]["writers"]
    );
    for name in ["idle", "loaded"] {
        let w = &r[name];
        let c = &w["tick_compute_us_of_seen_ticks"];
        let f = |k: &str| c[k].as_f64().map_or("-".into(), |x| format!("{x:.2}"));
        println!(
            "  {name:<7} ticks {:>7}  missed {:>5}  compute [us] p50 {} p99 {} max {} ({} ticks seen)  clients {}",
            w["ticks"],
            w["missed_periods"],
            f("p50"),
            f("p99"),
            f("max"),
            c["n"],
            w["clients"]
        );
        let hist: Vec<String> = w["jitter_histogram"]
            .as_array()
            .into_iter()
            .flatten()
            .filter(|b| b["count"].as_u64().unwrap_or(0) > 0)
            .map(|b| match b["below_us"].as_u64() {
                Some(u) => format!("<{u}us:{}", b["count"]),
                None => format!(">=16384us:{}", b["count"]),
            })
            .collect();
        println!("          jitter {}", hist.join(" "));
    }
    println!(
        "  load clients: {} statuses/answers, {} errors",
        r["loaded"]["load"]["statuses_and_answers"], r["loaded"]["load"]["client_errors"]
    );
}
