//! `gaitctl bench`: latency benchmarks against a running daemon (SPEC §11,
//! issue item 6). Figures are printed as a table and as JSON; nothing is
//! asserted (these machines are shared and noisy).
//!
//! - goal → answer: a reorientation goal sent at a phase spread over the
//!   period, its answer received (the client blocks on the daemon's
//!   notification, as applications do);
//! - status latency: `publish_time_ns` (stamped by the daemon's writer just
//!   before publishing) to reception by this process busy-polling (and,
//!   separately, blocking on the notification like applications), beside a
//!   bare iceoryx2 one-way latency measured in the same run between this
//!   process and a child (`gaitctl __pong`), also busy-polling, with a
//!   payload of the status's size — both as ping-pong (back-to-back) and
//!   as a periodic publisher at the daemon's rate, which is the like-for-like
//!   reference (a publisher that sleeps between sends is slower to deliver
//!   than one in a hot loop: caches and CPU wake-up, measured here);
//! - tick compute time p50/p99/max and missed periods from the status,
//!   beside a fixed-work reference loop at the same rate (`noise`): the
//!   platform's own tail;
//!   the wake-up jitter histogram of the bench window; daemon RSS.

use crate::common::{ConnArgs, us};
use gaitd_client::{GoalFrame, GoalSpec, Status, Verdict, monotonic_ns};
use iceoryx2::prelude::*;
use serde_json::json;
use shm_schema::status::{JITTER_BUCKETS, jitter_bucket_upper_ns};
use std::collections::BTreeMap;
use std::process::{Command as Process, ExitCode, Stdio};
use std::time::{Duration, Instant};

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
    /// time (0: skip; see `noise`).
    #[arg(long, default_value_t = 5000)]
    noise_periods: usize,
    /// CPU of the reference loop (put it where the daemon's loop runs).
    #[arg(long, value_name = "CPU")]
    noise_cpu: Option<u32>,
    /// SCHED_FIFO priority of the reference loop if permitted (the
    /// daemon's `rt.fifo_priority`; 0: normal scheduling).
    #[arg(long, default_value_t = 80)]
    noise_priority: i32,
}

/// Options of the hidden echo process.
#[derive(clap::Args, Debug)]
pub struct PongArgs {
    /// Service name prefix of the ping-pong pair.
    #[arg(long)]
    service: String,
    /// iceoryx2 root path.
    #[arg(long)]
    root: String,
    /// iceoryx2 file prefix.
    #[arg(long)]
    file_prefix: String,
    /// Publish periodically every this many µs instead of echoing.
    #[arg(long)]
    periodic_us: Option<u64>,
    /// With --periodic-us: how many samples.
    #[arg(long, default_value_t = 0)]
    count: u64,
    /// Pin to this CPU.
    #[arg(long)]
    cpu: Option<u32>,
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

/// Arguments that pin a child `__pong` process.
fn cpu_args(cpu: Option<u32>) -> Vec<String> {
    cpu.map(|c| vec!["--cpu".to_string(), c.to_string()])
        .unwrap_or_default()
}

/// Ping-pong payload, the size of a [`Status`] so both measure the same copy.
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitctl::BenchPing.v1")]
pub struct BenchPing {
    seq: u64,
    t_send: u64,
    t_echo: u64,
    pad: [u64; 140],
}

const _: () = assert!(size_of::<BenchPing>() == size_of::<Status>());

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

fn ice_config(root: &str, file_prefix: &str) -> gaitd_client::Result<iceoryx2::config::Config> {
    let s = shm_schema::ipc::IpcSettings {
        service_prefix: "bench".into(),
        root_path: root.into(),
        file_prefix: file_prefix.into(),
    };
    let mut c = iceoryx2::config::Config::default();
    s.apply(&mut c)
        .map_err(|e| gaitd_client::Error::Settings(e.to_string()))?;
    Ok(c)
}

fn ice<E: std::fmt::Debug>(what: &'static str) -> impl Fn(E) -> gaitd_client::Error {
    move |e| gaitd_client::Error::Ipc {
        what,
        why: format!("{e:?}"),
    }
}

type Svc =
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, BenchPing, ()>;

fn pair(node: &Node<ipc::Service>, name: &str) -> gaitd_client::Result<Svc> {
    node.service_builder(&ServiceName::new(name).map_err(ice("service name"))?)
        .publish_subscribe::<BenchPing>()
        .max_publishers(1)
        .max_subscribers(1)
        .open_or_create()
        .map_err(ice("bench service"))
}

/// The echo side: receives pings, stamps and returns them.
pub fn pong(a: &PongArgs) -> gaitd_client::Result<ExitCode> {
    pin(a.cpu)?;
    let config = ice_config(&a.root, &a.file_prefix)?;
    let node = NodeBuilder::new()
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(ice("node"))?;
    if let Some(period_us) = a.periodic_us {
        let svc = pair(&node, &format!("{}/periodic", a.service))?;
        let tx = svc.publisher_builder().create().map_err(ice("publisher"))?;
        println!("ready");
        // Give the subscriber's connection a moment, then publish on
        // absolute deadlines like the daemon's loop.
        std::thread::sleep(Duration::from_millis(50));
        let start = Instant::now();
        let period = Duration::from_micros(period_us);
        let mut p = BenchPing {
            seq: 0,
            t_send: 0,
            t_echo: 0,
            pad: [0; 140],
        };
        for k in 1..=a.count {
            let deadline = start + period * k as u32;
            std::thread::sleep(deadline.saturating_duration_since(Instant::now()));
            p.seq = k;
            p.t_send = monotonic_ns();
            tx.send_copy(p).map_err(ice("send"))?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    let ping = pair(&node, &format!("{}/ping", a.service))?;
    let pong = pair(&node, &format!("{}/pong", a.service))?;
    let rx = ping
        .subscriber_builder()
        .create()
        .map_err(ice("subscriber"))?;
    let tx = pong
        .publisher_builder()
        .create()
        .map_err(ice("publisher"))?;
    println!("ready");
    let mut idle = Instant::now();
    while idle.elapsed() < Duration::from_secs(5) {
        if let Some(s) = rx.receive().map_err(ice("receive"))? {
            let mut p = *s.payload();
            p.t_echo = monotonic_ns();
            tx.send_copy(p).map_err(ice("send"))?;
            if p.seq == u64::MAX {
                break;
            }
            idle = Instant::now();
        } else {
            std::hint::spin_loop();
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// One-way and half round-trip latencies [µs] of `n` ping-pongs.
fn ping_pong(
    n: usize,
    root: &str,
    file_prefix: &str,
    peer_cpu: Option<u32>,
) -> gaitd_client::Result<(Vec<f64>, Vec<f64>)> {
    let service = format!("gaitctl-bench-{}", std::process::id());
    let config = ice_config(root, file_prefix)?;
    let node = NodeBuilder::new()
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(ice("node"))?;
    let ping = pair(&node, &format!("{service}/ping"))?;
    let pong = pair(&node, &format!("{service}/pong"))?;
    let tx = ping
        .publisher_builder()
        .create()
        .map_err(ice("publisher"))?;
    let rx = pong
        .subscriber_builder()
        .create()
        .map_err(ice("subscriber"))?;
    let exe = std::env::current_exe().map_err(|e| gaitd_client::Error::Ipc {
        what: "current exe",
        why: e.to_string(),
    })?;
    let mut child = Process::new(exe)
        .args([
            "__pong",
            "--service",
            &service,
            "--root",
            root,
            "--file-prefix",
            file_prefix,
        ])
        .args(cpu_args(peer_cpu))
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| gaitd_client::Error::Ipc {
            what: "spawn pong",
            why: e.to_string(),
        })?;
    let mut line = String::new();
    std::io::BufRead::read_line(
        &mut std::io::BufReader::new(child.stdout.take().expect("piped")),
        &mut line,
    )
    .ok();
    let (mut one_way, mut half_rtt) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mut payload = BenchPing {
        seq: 0,
        t_send: 0,
        t_echo: 0,
        pad: [0; 140],
    };
    for i in 0..n as u64 + 100 {
        payload.seq = if i == n as u64 + 99 { u64::MAX } else { i };
        payload.t_send = monotonic_ns();
        tx.send_copy(payload).map_err(ice("send"))?;
        let start = Instant::now();
        let back = loop {
            if let Some(s) = rx.receive().map_err(ice("receive"))? {
                break Some((*s.payload(), monotonic_ns()));
            }
            if start.elapsed() > Duration::from_secs(2) {
                break None;
            }
            std::hint::spin_loop();
        };
        let Some((p, t_back)) = back else {
            let _ = child.kill();
            return Err(gaitd_client::Error::Timeout {
                what: "the pong process",
                waited: Duration::from_secs(2),
            });
        };
        // The first 100 warm the caches and are not counted.
        if i >= 100 && p.seq != u64::MAX {
            one_way.push(us(p.t_echo - p.t_send));
            half_rtt.push(us(t_back - p.t_send) / 2.0);
        }
    }
    let _ = child.wait();
    Ok((one_way, half_rtt))
}

/// Latencies [µs] of `n` samples from a child publishing every `period_us`.
fn periodic(
    n: usize,
    period_us: u64,
    root: &str,
    file_prefix: &str,
    peer_cpu: Option<u32>,
) -> gaitd_client::Result<Vec<f64>> {
    let service = format!("gaitctl-bench-{}", std::process::id());
    let config = ice_config(root, file_prefix)?;
    let node = NodeBuilder::new()
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(ice("node"))?;
    let svc = pair(&node, &format!("{service}/periodic"))?;
    let rx = svc
        .subscriber_builder()
        .create()
        .map_err(ice("subscriber"))?;
    let exe = std::env::current_exe().map_err(|e| gaitd_client::Error::Ipc {
        what: "current exe",
        why: e.to_string(),
    })?;
    let mut child = Process::new(exe)
        .args([
            "__pong",
            "--service",
            &service,
            "--root",
            root,
            "--file-prefix",
            file_prefix,
        ])
        .args([
            "--periodic-us",
            &period_us.to_string(),
            "--count",
            &(n + 100).to_string(),
        ])
        .args(cpu_args(peer_cpu))
        .stdout(Stdio::null())
        .spawn()
        .map_err(|e| gaitd_client::Error::Ipc {
            what: "spawn periodic publisher",
            why: e.to_string(),
        })?;
    let mut lat = Vec::with_capacity(n);
    let mut last = Instant::now();
    loop {
        if let Some(s) = rx.receive().map_err(ice("receive"))? {
            let now = monotonic_ns();
            let p = *s.payload();
            // The first 100 warm up and are not counted.
            if p.seq > 100 {
                lat.push(us(now.saturating_sub(p.t_send)));
            }
            last = Instant::now();
            if lat.len() >= n {
                break;
            }
        } else if last.elapsed() > Duration::from_secs(2) {
            break;
        } else {
            std::hint::spin_loop();
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    Ok(lat)
}

/// Runs the benchmarks.
pub fn run(conn: &ConnArgs, a: &Args) -> gaitd_client::Result<ExitCode> {
    // SAFETY: sysconf has no preconditions. (Counted before pinning,
    // which narrows what the process may use.)
    let online_cpus = unsafe { libc::sysconf(libc::_SC_NPROCESSORS_ONLN) };
    pin(a.cpu)?;
    let mut c = conn.connect()?;
    if let Some(seconds) = a.soak {
        let warmup = a.warmup.unwrap_or((seconds / 10.0).min(120.0));
        return crate::soak::run(
            &mut c,
            seconds,
            Duration::from_secs_f64(a.sample_every.max(0.1)),
            Duration::from_secs_f64(warmup.max(0.0)),
            a.json,
        );
    }
    let first = c.wait_status(conn.timeout())?;

    // goal → answer. Commands are read at the start of a tick, so a goal
    // sent right after a status (as a loop sending back to back does)
    // always waits a whole period; each goal is sent at a spread-out phase
    // of the period instead, as independent applications would.
    let mut goal_answer = Vec::with_capacity(a.goals);
    let mut verdicts: BTreeMap<String, usize> = BTreeMap::new();
    let period_ns = first.timing.period_ns.max(1);
    for i in 0..a.goals {
        let goal = GoalSpec::axis_angle(
            [0.0, 0.0, 1.0],
            0.01 * (i % 7) as f64 + 0.01,
            GoalFrame::Relative,
        )?;
        c.wait_status(conn.timeout())?;
        // Golden-ratio sequence: phases evenly spread over [0, period).
        let phase = ((i as f64 * 0.618_033_988_75).fract() * period_ns as f64) as u64;
        let until = Instant::now() + Duration::from_nanos(phase);
        while Instant::now() < until {
            std::hint::spin_loop();
        }
        let t0 = Instant::now();
        let t = c.reorient(&goal, conn.timeout())?;
        goal_answer.push(t0.elapsed().as_secs_f64() * 1e6);
        let key = match t.verdict {
            Verdict::Accepted => "accepted".to_string(),
            Verdict::Rejected(r) => format!("rejected {r}"),
        };
        *verdicts.entry(key).or_default() += 1;
        if t.verdict == Verdict::Accepted {
            // Do not leave a goal running: the next one would preempt it anyway.
            let _ = c.cancel(Some(t.goal_id), conn.timeout());
        }
    }

    // goal → first motion: ticks from the tick that accepted the goal to
    // the first status showing the hand moving for it (planning included).
    let mut first_motion = Vec::with_capacity(a.motions);
    let mut planning_ms = Vec::with_capacity(a.motions);
    for i in 0..a.motions {
        let goal = GoalSpec::turn([0.0, 0.0, 1.0], 0.3 + 0.05 * i as f64)?;
        let t = c.reorient(&goal, conn.timeout())?;
        if t.verdict != Verdict::Accepted {
            continue;
        }
        let goal_id = t.goal_id;
        let deadline = Instant::now() + Duration::from_secs(10);
        let t_answer = Instant::now();
        while Instant::now() < deadline {
            if let Some(s) = c.latest_status()?
                && s.goal.goal_id == goal_id
                && s.phase != shm_schema::Phase::Hold.code()
            {
                first_motion.push(s.tick.saturating_sub(t.tick) as f64);
                planning_ms.push(t_answer.elapsed().as_secs_f64() * 1e3);
                break;
            }
            std::hint::spin_loop();
        }
        let _ = c.cancel(Some(goal_id), conn.timeout());
        // Back at rest before the next one.
        let deadline = Instant::now() + Duration::from_secs(10);
        while Instant::now() < deadline {
            if c.wait_status(conn.timeout())?.phase == shm_schema::Phase::Hold.code() {
                break;
            }
        }
    }

    // tick compute while moving: every status of a half turn about z
    // (rolling, rotations and gaits; the status window below is at rest).
    let mut moving_compute = Vec::new();
    for _ in 0..a.moving_turns {
        let t = c.reorient(
            &GoalSpec::turn([0.0, 0.0, 1.0], std::f64::consts::PI)?,
            conn.timeout(),
        )?;
        if t.verdict != Verdict::Accepted {
            continue;
        }
        let (mut last_tick, mut started) = (0, false);
        let deadline = Instant::now() + Duration::from_secs(60);
        while Instant::now() < deadline {
            let Some(s) = c.latest_status()? else {
                continue;
            };
            if s.tick == last_tick || s.goal.goal_id != t.goal_id {
                std::hint::spin_loop();
                continue;
            }
            last_tick = s.tick;
            let moving = s.phase != shm_schema::Phase::Hold.code();
            if moving {
                started = true;
                moving_compute.push(us(s.timing.compute_last_ns));
            } else if started {
                break;
            }
        }
    }

    // status publish → receive, busy-polling
    let (mut status_lat, mut tick_lat, mut compute_seen) = (
        Vec::with_capacity(a.statuses),
        Vec::with_capacity(a.statuses),
        Vec::with_capacity(a.statuses),
    );
    let mut last_tick = c.latest_status()?.map_or(0, |s| s.tick);
    let window_start = c.latest_status()?.unwrap_or(first);
    let deadline = Instant::now() + Duration::from_secs(60);
    while status_lat.len() < a.statuses && Instant::now() < deadline {
        if let Some(s) = c.latest_status()?
            && s.tick != last_tick
        {
            let now = monotonic_ns();
            last_tick = s.tick;
            status_lat.push(us(now.saturating_sub(s.publish_time_ns)));
            tick_lat.push(us(now.saturating_sub(s.time_ns)));
            compute_seen.push(us(s.timing.compute_last_ns));
        } else {
            std::hint::spin_loop();
        }
    }
    let last = c.latest_status()?.unwrap_or(first);
    // The same, blocking on the daemon's notification as applications do
    // (`wait_status`): adds the wake-up of a sleeping thread.
    let mut blocking_lat = Vec::with_capacity(a.statuses / 5);
    for _ in 0..a.statuses / 5 {
        let s = c.wait_status(conn.timeout())?;
        blocking_lat.push(us(monotonic_ns().saturating_sub(s.publish_time_ns)));
    }
    let load = if a.load_seconds > 0.0 {
        Some(crate::load::run(
            conn,
            &mut c,
            a.load_seconds,
            a.load_readers,
            a.load_writers,
        )?)
    } else {
        None
    };

    // bare iceoryx2, same run
    let settings = c.settings().clone();
    let (mut one_way, mut half_rtt) = ping_pong(
        a.pings,
        &settings.root_path,
        &settings.file_prefix,
        a.peer_cpu,
    )?;
    let period_us = (last.timing.period_ns / 1000).max(1);
    let mut periodic_lat = periodic(
        a.statuses,
        period_us,
        &settings.root_path,
        &settings.file_prefix,
        a.peer_cpu,
    )?;

    // The platform's own tail at the same rate and median work.
    let compute_s = summary(&mut compute_seen);
    let noise = if a.noise_periods > 0 {
        let work = compute_s["p50"].as_f64().unwrap_or(5.0);
        match crate::noise::reference_loop(
            a.noise_periods,
            Duration::from_micros(period_us),
            Duration::from_secs_f64(work * 1e-6),
            a.noise_cpu,
            a.noise_priority,
        ) {
            Ok((s, fifo)) => json!({"compute_us": s, "fifo": fifo, "work_us": work}),
            Err(e) => json!({"error": e}),
        }
    } else {
        json!(null)
    };

    let t = &last.timing;
    let hist: Vec<_> = (0..JITTER_BUCKETS)
        .map(|i| {
            let n = t.jitter_hist[i] - window_start.timing.jitter_hist[i];
            json!({"below_us": if i + 1 < JITTER_BUCKETS { Some(jitter_bucket_upper_ns(i) / 1000) } else { None }, "count": n})
        })
        .collect();
    let rss = c.daemon_pid().and_then(crate::soak::rss_kb);
    let status_s = summary(&mut status_lat);
    let pp_s = summary(&mut one_way);
    let periodic_s = summary(&mut periodic_lat);
    let ratio =
        |reference: &serde_json::Value| match (status_s["p50"].as_f64(), reference["p50"].as_f64())
        {
            (Some(s), Some(p)) if p > 0.0 => Some(s / p),
            _ => None,
        };
    let (ratio_pp, ratio_periodic) = (ratio(&pp_s), ratio(&periodic_s));
    let report = json!({
        "machine": {
            "cpus": online_cpus,
            "kernel": std::fs::read_to_string("/proc/sys/kernel/osrelease").unwrap_or_default().trim(),
            "bench_cpu": a.cpu,
            "peer_cpu": a.peer_cpu,
        },
        "daemon": {
            "instance": format!("{:016x}", last.instance),
            "period_us": us(t.period_ns),
            "pid": c.daemon_pid(),
            "rss_kb": rss.map(|r| r.0),
            "rss_peak_kb": rss.map(|r| r.1),
        },
        "goal_to_answer_us": summary(&mut goal_answer),
        "goal_verdicts": verdicts,
        "goal_to_first_motion_ticks": summary(&mut first_motion),
        "goal_to_first_motion_wall_ms": summary(&mut planning_ms),
        "status_publish_to_receive_us": status_s,
        "status_tick_to_receive_us": summary(&mut tick_lat),
        "status_publish_to_receive_blocking_us": summary(&mut blocking_lat),
        "iceoryx2_one_way_us": pp_s,        "iceoryx2_half_round_trip_us": summary(&mut half_rtt),
        "iceoryx2_periodic_one_way_us": periodic_s,
        "status_vs_iceoryx2_pingpong_p50_ratio": ratio_pp,
        "status_vs_iceoryx2_periodic_p50_ratio": ratio_periodic,
        "tick_compute_ns": {
            "p50": t.compute_p50_ns, "p99": t.compute_p99_ns, "max": t.compute_max_ns,
            "since": "daemon start",
        },
        "tick_compute_us_status_window": compute_s,
        "tick_compute_us_moving": summary(&mut moving_compute),
        "reference_loop": noise,
        "load": load,
        "missed_periods_in_window": t.overruns - window_start.timing.overruns,
        "jitter_histogram_window": hist,
        "jitter_p99_us_since_start": us(t.jitter_p99_ns),
    });
    if !a.json {
        print_table(&report);
        println!();
    }
    println!("{report}");
    Ok(ExitCode::SUCCESS)
}

fn print_table(r: &serde_json::Value) {
    let row = |name: &str, v: &serde_json::Value| {
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
    };
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
    row("goal -> answer", &r["goal_to_answer_us"]);
    row(
        "status publish -> client receive",
        &r["status_publish_to_receive_us"],
    );
    row(
        "status tick -> client receive",
        &r["status_tick_to_receive_us"],
    );
    row(
        "status publish -> receive, blocking",
        &r["status_publish_to_receive_blocking_us"],
    );
    row(
        "bare iceoryx2 one-way (same run)",
        &r["iceoryx2_one_way_us"],
    );
    row(
        "bare iceoryx2 round trip / 2",
        &r["iceoryx2_half_round_trip_us"],
    );
    row(
        "bare iceoryx2 periodic one-way",
        &r["iceoryx2_periodic_one_way_us"],
    );
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
    println!(
        "missed periods in the bench window: {}",
        r["missed_periods_in_window"]
    );
    if !r["load"].is_null() {
        crate::load::print(&r["load"]);
    }
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
    println!(
        "daemon RSS: {} kB (peak {} kB)",
        r["daemon"]["rss_kb"], r["daemon"]["rss_peak_kb"]
    );
}
