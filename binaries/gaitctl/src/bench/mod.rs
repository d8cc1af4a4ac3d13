//! `gaitctl bench`: latency benchmarks against a running daemon (SPEC §11).
//! Figures are printed as a table and as JSON; nothing is
//! asserted (these machines are shared and noisy).
//!
//! In the order they run, by what they measure:
//! - [`latency`]: goal → answer, goal → first motion, status publish →
//!   receive (busy-polling and blocking);
//! - [`tick`]: tick compute time while moving, the window's wake-up jitter,
//!   and a fixed-work reference loop at the same rate (`noise`): the
//!   platform's own tail;
//! - [`many_clients`] (with `--load-seconds`): missed periods idle vs under load;
//! - [`reference`](mod@reference): a bare iceoryx2 one-way latency in the same run, the
//!   reference of the status latency;
//! - [`report`]: the JSON result and the table, with the daemon's RSS;
//! - [`plant`] (with `--plant-steps`, instead of the above): the plant
//!   interface's lockstep latency, against a daemon gaitctl starts;
//! - [`remote`] (with `--remote`, instead of the above): status latency and
//!   goal → answer through gaitd-bridge, beside bare Zenoh.

mod latency;
mod many_clients;
mod noise;
mod plant;
mod reference;
#[cfg(feature = "remote")]
mod remote;
mod report;
mod soak;
mod tick;

pub use reference::{PongArgs, pong};

use crate::common::ConnArgs;
use serde_json::json;
use std::process::ExitCode;
use std::time::Duration;

/// Options.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Goals sent for goal → answer latency.
    #[arg(long, default_value_t = 200)]
    goals: usize,
    /// Goals executed for goal → first motion (each is planned, started,
    /// then canceled).
    #[arg(long, default_value_t = 10)]
    motions: usize,
    /// Statuses received for status latency.
    #[arg(long, default_value_t = 5000)]
    statuses: usize,
    /// Ping-pong round trips of the bare iceoryx2 reference.
    #[arg(long, default_value_t = 5000)]
    pings: usize,
    /// Print only the JSON.
    #[arg(long)]
    json: bool,
    /// Instead of the latency benchmarks: the plant interface. gaitctl
    /// starts a daemon with an external plant in lockstep and is that
    /// plant for this many steps (see `bench::plant`).
    #[arg(long, value_name = "STEPS")]
    plant_steps: Option<usize>,
    /// Instead of the latency benchmarks: a soak run of this many seconds
    /// (a stream of goals, daemon RSS sampled; see `soak`).
    #[arg(long, value_name = "SECONDS")]
    soak: Option<f64>,
    /// Soak: seconds between RSS samples.
    #[arg(long, default_value_t = 10.0)]
    sample_every: f64,
    /// Soak: seconds of warm-up before growth is counted (default: a tenth
    /// of the run, at most 120 s).
    #[arg(long)]
    warmup: Option<f64>,
    /// Also measure missed periods and tick compute time in two windows of
    /// this many seconds, idle and under client load (0: skip).
    #[arg(long, default_value_t = 0.0)]
    load_seconds: f64,
    /// Load: status readers (each its own client and thread).
    #[arg(long, default_value_t = 8)]
    load_readers: usize,
    /// Load: goal writers (each its own client and thread).
    #[arg(long, default_value_t = 4)]
    load_writers: usize,
    /// Pin this process's measuring thread to this CPU (the status reader
    /// and the bare iceoryx2 reference's receiving end).
    #[arg(long, value_name = "CPU")]
    cpu: Option<u32>,
    /// Pin the bare iceoryx2 reference's sending process to this CPU (put
    /// it where the daemon's writer thread runs: like-for-like).
    #[arg(long, value_name = "CPU")]
    peer_cpu: Option<u32>,
    /// Tick compute time while the hand moves: statuses read during a
    /// half turn about z (planned and executed; 0: skip).
    #[arg(long, default_value_t = 1)]
    moving_turns: usize,
    /// Periods of the fixed-work reference loop beside the tick compute
    /// time (0: skip; see `noise`). Default: as many as moving ticks were
    /// read (at least 5000), so that both maxima come from as many samples.
    #[arg(long)]
    noise_periods: Option<usize>,
    /// CPU of the reference loop (put it where the daemon's loop runs).
    #[arg(long, value_name = "CPU")]
    noise_cpu: Option<u32>,
    /// SCHED_FIFO priority of the reference loop if permitted (the
    /// daemon's `rt.fifo_priority`; 0: normal scheduling).
    #[arg(long, default_value_t = 80)]
    noise_priority: i32,
    /// With --remote: statuses received through the bridge (at its
    /// status rate, 100 Hz by default).
    #[arg(long, default_value_t = 1000)]
    remote_statuses: usize,
    /// With --remote: goals sent through the bridge (paced at 9 per second,
    /// under its default rate limit).
    #[arg(long, default_value_t = 100)]
    remote_goals: usize,
}

/// Pins the calling thread to `cpu` (placement decides latencies on a
/// machine with few CPUs: a reader and a sender sharing one measure the
/// scheduler).
pub fn pin(cpu: Option<u32>) -> gaitd_client::Result<()> {
    let Some(cpu) = cpu else { return Ok(()) };
    if cpu as usize >= libc::CPU_SETSIZE as usize {
        return Err(gaitd_client::Error::Settings(format!(
            "CPU {cpu} is out of range"
        )));
    }
    // SAFETY: cpu_set_t is plain data; CPU_SET writes within it (checked
    // against CPU_SETSIZE above).
    let rc = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu as usize, &mut set);
        libc::sched_setaffinity(0, size_of::<libc::cpu_set_t>(), &set)
    };
    if rc != 0 {
        return Err(gaitd_client::Error::Settings(format!(
            "cannot pin to CPU {cpu}: {}",
            std::io::Error::last_os_error()
        )));
    }
    Ok(())
}

/// The reference loop beside the tick compute time: the platform's own
/// tail at the same rate, doing the median work of the ticks it is
/// compared with (the moving ones, else the status window's), over as many
/// periods as there are moving ticks (at least 5000) unless `periods` is
/// given — a maximum of 5000 samples is no yardstick for one of 75 000.
/// Returns (periods, work \[µs\]).
fn reference_like(
    moving_us: &[f64],
    window: &serde_json::Value,
    periods: Option<usize>,
) -> (usize, Option<f64>) {
    let mut sorted = moving_us.to_vec();
    let work = summary(&mut sorted)["p50"]
        .as_f64()
        .or_else(|| window["p50"].as_f64());
    (periods.unwrap_or(moving_us.len().max(5000)), work)
}

/// n, p50, p99, max, mean of a sample.
pub fn summary(v: &mut [f64]) -> serde_json::Value {
    if v.is_empty() {
        return json!(null);
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| v[((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
    json!({
        "n": v.len(),
        "p50": q(0.5),
        "p99": q(0.99),
        "max": v[v.len() - 1],
        "mean": v.iter().sum::<f64>() / v.len() as f64,
    })
}

/// Runs the benchmarks (or the soak run), in the order of the module docs.
pub fn run(conn: &ConnArgs, a: &Args) -> gaitd_client::Result<ExitCode> {
    // SAFETY: sysconf has no preconditions. (Counted before pinning,
    // which narrows what the process may use.)
    let online_cpus = unsafe { libc::sysconf(libc::_SC_NPROCESSORS_ONLN) };
    pin(a.cpu)?;
    if let Some(steps) = a.plant_steps {
        plant::run(steps, a.pings, a.json)?;
        return Ok(ExitCode::SUCCESS);
    }
    let mut c = conn.connect("gaitctl")?;
    if let Some(seconds) = a.soak {
        let warmup = a.warmup.unwrap_or((seconds / 10.0).min(120.0));
        return soak::run(
            &mut c,
            seconds,
            Duration::from_secs_f64(a.sample_every.max(0.1)),
            Duration::from_secs_f64(warmup.max(0.0)),
            a.json,
        );
    }
    let timeout = conn.timeout();
    #[cfg(feature = "remote")]
    if c.is_remote() {
        let tls = conn.tls_files()?;
        let proto = conn
            .remote
            .as_deref()
            .and_then(|e| gaitd_client::remote::tls::parse_endpoint(e).ok())
            .map_or("quic", |e| e.protocol);
        let v = remote::run(
            &mut c,
            proto,
            Some(&tls),
            a.remote_statuses,
            a.remote_goals,
            timeout,
        )?;
        if !a.json {
            remote::print_table(&v);
        }
        println!("{v}");
        return Ok(ExitCode::SUCCESS);
    }
    let first = c.wait_status(timeout)?;
    let period_ns = first.timing.period_ns.max(1);
    let goals = latency::goal_to_answer(&mut c, a.goals, period_ns, timeout)?;
    let motion = latency::goal_to_first_motion(&mut c, a.motions, timeout)?;
    let moving_us = tick::compute_while_moving(&mut c, a.moving_turns, timeout)?;
    let mut window = latency::status_window(&mut c, a.statuses, first, timeout)?;
    let load = if a.load_seconds > 0.0 {
        let (readers, writers) = (a.load_readers, a.load_writers);
        Some(many_clients::run(
            conn,
            &mut c,
            a.load_seconds,
            readers,
            writers,
        )?)
    } else {
        None
    };
    let settings = c.settings().clone();
    let namespace = (settings.root_path.as_str(), settings.file_prefix.as_str());
    let period_us = (window.end.timing.period_ns / 1000).max(1);
    let bare = reference::measure(a.pings, a.statuses, period_us, namespace, a.peer_cpu)?;
    let window_compute = summary(&mut window.compute_us);
    let (periods, work_us) = reference_like(&moving_us, &window_compute, a.noise_periods);
    let reference = tick::Reference {
        periods,
        cpu: a.noise_cpu,
        priority: a.noise_priority,
    };
    let reference_loop = tick::reference_loop(reference, period_us, work_us);
    let pid = c.daemon_pid();
    let mut measured = report::Measured {
        machine: json!({
            "cpus": online_cpus,
            "kernel": std::fs::read_to_string("/proc/sys/kernel/osrelease").unwrap_or_default().trim(),
            "bench_cpu": a.cpu,
            "peer_cpu": a.peer_cpu,
        }),
        daemon: (pid, pid.and_then(soak::rss_kb)),
        goals,
        motion,
        moving_us,
        window,
        window_compute,
        load,
        bare,
        reference_loop,
    };
    let report = report::json(&mut measured);
    if !a.json {
        report::print_table(&report);
        println!();
    }
    println!("{report}");
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference does what the moving ticks do, as often.
    #[test]
    fn the_reference_loop_is_like_for_like_with_the_moving_ticks() {
        let moving: Vec<f64> = (0..20_000).map(|i| 3.0 + f64::from(i % 3)).collect();
        let window = json!({"p50": 1.5});
        assert_eq!(reference_like(&moving, &window, None), (20_000, Some(4.0)));
        assert_eq!(reference_like(&moving, &window, Some(7)), (7, Some(4.0)));
        // No moving ticks: the window's median, the least periods.
        assert_eq!(reference_like(&[], &window, None), (5000, Some(1.5)));
    }
}
