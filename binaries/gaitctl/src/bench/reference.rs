//! The bare iceoryx2 reference of `gaitctl bench`: one-way latency between
//! this process and a child (`gaitctl __pong`), both busy-polling, with a
//! payload of the status's size — as a ping-pong (back to back) and as a
//! periodic publisher at the daemon's rate. The periodic one is the
//! like-for-like reference for the status latency: a publisher that sleeps
//! between sends is slower to deliver than one in a hot loop (caches, CPU
//! wake-up).

use super::pin;
use crate::common::us;
use gaitd_client::{Status, monotonic_ns};
use iceoryx2::prelude::*;
use std::process::{Child, Command as Process, ExitCode, Stdio};
use std::time::{Duration, Instant};

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

/// Ping-pong payload, the size of a [`Status`] so both measure the same copy.
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitctl::BenchPing.v3")]
pub struct BenchPing {
    seq: u64,
    t_send: u64,
    t_echo: u64,
    pad: [u64; 172],
}

const _: () = assert!(size_of::<BenchPing>() == size_of::<Status>());

impl BenchPing {
    const ZERO: Self = Self {
        seq: 0,
        t_send: 0,
        t_echo: 0,
        pad: [0; 172],
    };
}

/// Samples warming the caches before any is counted.
const WARM_UP: u64 = 100;

/// The bare iceoryx2 latencies of one run \[µs\].
#[derive(Debug, Default)]
pub struct Bare {
    /// Ping-pong, ping sent → echo stamped.
    pub one_way: Vec<f64>,
    /// Ping-pong, round trip / 2.
    pub half_rtt: Vec<f64>,
    /// Periodic publisher → this process.
    pub periodic: Vec<f64>,
}

/// Measures `pings` ping-pongs, then `samples` periodic samples every
/// `period_us`, in the daemon's iceoryx2 namespace (`root`, `file_prefix`).
pub fn measure(
    pings: usize,
    samples: usize,
    period_us: u64,
    (root, file_prefix): (&str, &str),
    peer_cpu: Option<u32>,
) -> gaitd_client::Result<Bare> {
    let (one_way, half_rtt) = ping_pong(pings, root, file_prefix, peer_cpu)?;
    let periodic = periodic(samples, period_us, root, file_prefix, peer_cpu)?;
    Ok(Bare {
        one_way,
        half_rtt,
        periodic,
    })
}

/// Arguments that pin a child `__pong` process.
fn cpu_args(cpu: Option<u32>) -> Vec<String> {
    cpu.map(|c| vec!["--cpu".to_string(), c.to_string()])
        .unwrap_or_default()
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

fn node(root: &str, file_prefix: &str) -> gaitd_client::Result<Node<ipc::Service>> {
    let config = ice_config(root, file_prefix)?;
    NodeBuilder::new()
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(ice("node"))
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

/// Starts `gaitctl __pong` on `service` with `extra` arguments.
fn spawn_peer(
    service: &str,
    (root, file_prefix): (&str, &str),
    extra: &[String],
    peer_cpu: Option<u32>,
    (stdout, what): (Stdio, &'static str),
) -> gaitd_client::Result<Child> {
    let exe = std::env::current_exe().map_err(|e| gaitd_client::Error::Ipc {
        what: "current exe",
        why: e.to_string(),
    })?;
    Process::new(exe)
        .args(["__pong", "--service", service, "--root", root])
        .args(["--file-prefix", file_prefix])
        .args(extra)
        .args(cpu_args(peer_cpu))
        .stdout(stdout)
        .spawn()
        .map_err(|e| gaitd_client::Error::Ipc {
            what,
            why: e.to_string(),
        })
}

/// The echo side: receives pings, stamps and returns them.
pub fn pong(a: &PongArgs) -> gaitd_client::Result<ExitCode> {
    pin(a.cpu)?;
    let node = node(&a.root, &a.file_prefix)?;
    if let Some(period_us) = a.periodic_us {
        return publish_periodically(&node, a, period_us);
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

/// The periodic side: `a.count` samples on absolute deadlines, like the
/// daemon's loop.
fn publish_periodically(
    node: &Node<ipc::Service>,
    a: &PongArgs,
    period_us: u64,
) -> gaitd_client::Result<ExitCode> {
    let svc = pair(node, &format!("{}/periodic", a.service))?;
    let tx = svc.publisher_builder().create().map_err(ice("publisher"))?;
    println!("ready");
    // Give the subscriber's connection a moment.
    std::thread::sleep(Duration::from_millis(50));
    let start = Instant::now();
    let period = Duration::from_micros(period_us);
    let mut p = BenchPing::ZERO;
    for k in 1..=a.count {
        let deadline = start + period * k as u32;
        std::thread::sleep(deadline.saturating_duration_since(Instant::now()));
        p.seq = k;
        p.t_send = monotonic_ns();
        tx.send_copy(p).map_err(ice("send"))?;
    }
    Ok(ExitCode::SUCCESS)
}

/// One-way and half round-trip latencies \[µs\] of `n` ping-pongs.
fn ping_pong(
    n: usize,
    root: &str,
    file_prefix: &str,
    peer_cpu: Option<u32>,
) -> gaitd_client::Result<(Vec<f64>, Vec<f64>)> {
    let service = format!("gaitctl-bench-{}", std::process::id());
    let node = node(root, file_prefix)?;
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
    let ns = (root, file_prefix);
    let mut child = spawn_peer(&service, ns, &[], peer_cpu, (Stdio::piped(), "spawn pong"))?;
    // The child says "ready" once its ports exist.
    let mut line = String::new();
    std::io::BufRead::read_line(
        &mut std::io::BufReader::new(child.stdout.take().expect("piped")),
        &mut line,
    )
    .ok();
    let (mut one_way, mut half_rtt) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mut payload = BenchPing::ZERO;
    let last = n as u64 + WARM_UP - 1;
    for i in 0..=last {
        payload.seq = if i == last { u64::MAX } else { i };
        payload.t_send = monotonic_ns();
        tx.send_copy(payload).map_err(ice("send"))?;
        let Some((p, t_back)) = wait_echo(&rx)? else {
            let _ = child.kill();
            return Err(gaitd_client::Error::Timeout {
                what: "the pong process",
                waited: Duration::from_secs(2),
            });
        };
        if i >= WARM_UP && p.seq != u64::MAX {
            one_way.push(us(p.t_echo - p.t_send));
            half_rtt.push(us(t_back - p.t_send) / 2.0);
        }
    }
    let _ = child.wait();
    Ok((one_way, half_rtt))
}

/// The echo of the last ping and when it arrived, busy-polling for at
/// most 2 s.
fn wait_echo(
    rx: &iceoryx2::port::subscriber::Subscriber<ipc::Service, BenchPing, ()>,
) -> gaitd_client::Result<Option<(BenchPing, u64)>> {
    let start = Instant::now();
    loop {
        if let Some(s) = rx.receive().map_err(ice("receive"))? {
            return Ok(Some((*s.payload(), monotonic_ns())));
        }
        if start.elapsed() > Duration::from_secs(2) {
            return Ok(None);
        }
        std::hint::spin_loop();
    }
}

/// Latencies \[µs\] of `n` samples from a child publishing every `period_us`.
fn periodic(
    n: usize,
    period_us: u64,
    root: &str,
    file_prefix: &str,
    peer_cpu: Option<u32>,
) -> gaitd_client::Result<Vec<f64>> {
    let service = format!("gaitctl-bench-{}", std::process::id());
    let node = node(root, file_prefix)?;
    let svc = pair(&node, &format!("{service}/periodic"))?;
    let rx = svc
        .subscriber_builder()
        .create()
        .map_err(ice("subscriber"))?;
    let extra = [
        "--periodic-us".to_string(),
        period_us.to_string(),
        "--count".to_string(),
        (n as u64 + WARM_UP).to_string(),
    ];
    let ns = (root, file_prefix);
    let mut child = spawn_peer(
        &service,
        ns,
        &extra,
        peer_cpu,
        (Stdio::null(), "spawn periodic publisher"),
    )?;
    let mut lat = Vec::with_capacity(n);
    let mut last = Instant::now();
    loop {
        if let Some(s) = rx.receive().map_err(ice("receive"))? {
            let now = monotonic_ns();
            let p = *s.payload();
            if p.seq > WARM_UP {
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
