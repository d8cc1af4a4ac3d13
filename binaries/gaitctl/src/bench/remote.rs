//! `gaitctl bench --remote`: what a remote client waits for through
//! gaitd-bridge, beside bare Zenoh in the same run.
//!
//! - status latency: the daemon's `publish_time_ns` to reception here,
//!   through the bridge (iceoryx2 → bridge → Zenoh); valid when both run
//!   on this host (loopback), as both use `CLOCK_MONOTONIC`;
//! - goal → answer: a small relative goal through the bridge's queryable
//!   to the daemon and back (each then canceled; paced under the bridge's
//!   default rate limit of 20 commands/s);
//! - the reference: two Zenoh sessions of this process over loopback, one
//!   listening, one connected, on the bridge's transport (TLS with the
//!   same CA when `bridge.pem`/`bridge.key` lie beside `ca.pem`, plain TCP
//!   otherwise): a publisher → subscriber one-way latency of 1144-byte
//!   samples and a get → queryable round trip of 144 bytes.

use super::summary;
use gaitd_client::{Client, GoalFrame, GoalSpec, TlsFiles, Verdict, monotonic_ns};
use serde_json::{Value, json};
use std::path::Path;
use std::sync::mpsc;
use std::time::{Duration, Instant};
use zenoh::Wait;

/// Pause between goal → answer samples (goal and cancel: 2 commands).
const PACE: Duration = Duration::from_millis(110);

fn zerr(e: impl std::fmt::Display) -> gaitd_client::Error {
    gaitd_client::Error::Remote(gaitd_client::RemoteError::Zenoh(
        gaitd_client::remote::zenoh_text(e),
    ))
}

/// Status latencies through the bridge \[µs\].
fn status_latency(c: &mut Client, n: usize, timeout: Duration) -> gaitd_client::Result<Vec<f64>> {
    let mut v = Vec::with_capacity(n);
    c.wait_status(timeout)?;
    while v.len() < n {
        let s = c.wait_status(timeout)?;
        let now = monotonic_ns();
        v.push(now.saturating_sub(s.publish_time_ns) as f64 / 1e3);
    }
    Ok(v)
}

/// Goal → answer through the bridge \[µs\].
fn goal_to_answer(c: &mut Client, n: usize, timeout: Duration) -> gaitd_client::Result<Vec<f64>> {
    let mut v = Vec::with_capacity(n);
    for i in 0..n {
        std::thread::sleep(PACE);
        let goal = GoalSpec::axis_angle(
            [0.0, 0.0, 1.0],
            0.01 * (i % 7) as f64 + 0.01,
            GoalFrame::Relative,
        )?;
        let t0 = Instant::now();
        let t = c.reorient(&goal, timeout)?;
        v.push(t0.elapsed().as_secs_f64() * 1e6);
        if t.verdict == Verdict::Accepted {
            let _ = c.cancel(Some(t.goal_id), timeout);
        }
    }
    Ok(v)
}

/// A free loopback port for `proto` (QUIC runs on UDP).
fn free_port(proto: &str) -> gaitd_client::Result<u16> {
    let addr = if proto == "quic" {
        std::net::UdpSocket::bind("127.0.0.1:0").and_then(|s| s.local_addr())
    } else {
        std::net::TcpListener::bind("127.0.0.1:0").and_then(|l| l.local_addr())
    };
    addr.map(|a| a.port())
        .map_err(|e| gaitd_client::Error::Settings(format!("no free port: {e}")))
}

/// One session of the reference: listening or connected, over `proto`
/// (`quic` or `tls` with `tls`'s files, else `tcp`).
fn session(
    port: u16,
    listen: bool,
    proto: &str,
    tls: Option<(&TlsFiles, &Path)>,
) -> gaitd_client::Result<zenoh::Session> {
    let ep = format!("{proto}/127.0.0.1:{port}");
    let mut link = json!({ "protocols": [proto] });
    if let Some((files, dir)) = tls {
        let (cert, key) = if listen {
            (dir.join("bridge.pem"), dir.join("bridge.key"))
        } else {
            (files.cert.clone(), files.key.clone())
        };
        let side = if listen { "listen" } else { "connect" };
        link["tls"] = json!({
            "root_ca_certificate": files.ca,
            format!("{side}_certificate"): cert,
            format!("{side}_private_key"): key,
            "enable_mtls": true,
        });
    }
    let (listen_eps, connect_eps) = if listen {
        (vec![ep], vec![])
    } else {
        (vec![], vec![ep])
    };
    let cfg = json!({
        "mode": "peer",
        "listen": { "endpoints": listen_eps },
        "connect": { "endpoints": connect_eps },
        "scouting": { "multicast": { "enabled": false }, "gossip": { "enabled": false } },
        "transport": { "link": link, "shared_memory": { "enabled": false } },
    });
    let cfg = zenoh::Config::from_json5(&cfg.to_string()).map_err(zerr)?;
    zenoh::open(cfg).wait().map_err(zerr)
}

/// Bare Zenoh on loopback over the bridge's link `proto` (`quic`, `tls`):
/// (transport, pub → sub one-way \[µs\], get → reply \[µs\]).
fn bare(
    n: usize,
    queries: usize,
    tls: Option<&TlsFiles>,
    proto: &str,
) -> gaitd_client::Result<(String, Vec<f64>, Vec<f64>)> {
    // TLS like the bridge when its certificate is at hand.
    let dir = tls.and_then(|t| t.ca.parent().map(Path::to_path_buf));
    let tls = match (tls, &dir) {
        (Some(t), Some(d)) if d.join("bridge.pem").exists() && d.join("bridge.key").exists() => {
            Some((t, d.as_path()))
        }
        _ => None,
    };
    let proto = if tls.is_some() { proto } else { "tcp" };
    let transport = if tls.is_some() {
        format!("{proto} (mutual TLS)")
    } else {
        proto.to_owned()
    };
    let port = free_port(proto)?;
    let a = session(port, true, proto, tls)?;
    let b = session(port, false, proto, tls)?;
    let key = format!("gaitctl-bench/{}/{port}", std::process::id());

    let (tx, rx) = mpsc::channel::<f64>();
    let _sub = b
        .declare_subscriber(format!("{key}/status"))
        .callback(move |s| {
            let now = monotonic_ns();
            let bytes = s.payload().to_bytes();
            if let Some(t) = bytes.get(..8) {
                let sent = u64::from_le_bytes(t.try_into().unwrap_or_default());
                let _ = tx.send(now.saturating_sub(sent) as f64 / 1e3);
            }
        })
        .wait()
        .map_err(zerr)?;
    let publisher = a
        .declare_publisher(format!("{key}/status"))
        .wait()
        .map_err(zerr)?;
    let qk = format!("{key}/cmd");
    let _q = a
        .declare_queryable(&qk)
        .callback(move |q| {
            let _ = q.reply(q.key_expr().clone(), vec![0u8; 80]).wait();
        })
        .wait()
        .map_err(zerr)?;
    // Wait until the sessions see each other.
    let t0 = Instant::now();
    while rx.try_recv().is_err() {
        let mut buf = vec![0u8; 1144];
        buf[..8].copy_from_slice(&monotonic_ns().to_le_bytes());
        publisher.put(buf).wait().map_err(zerr)?;
        if t0.elapsed() > Duration::from_secs(10) {
            return Err(gaitd_client::Error::Settings(
                "the bare Zenoh sessions never met".into(),
            ));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(50));
    while rx.try_recv().is_ok() {}
    let mut one_way = Vec::with_capacity(n);
    for _ in 0..n {
        // At the bridge's status rate (100 Hz would be slow: 1 kHz, as the daemon's).
        std::thread::sleep(Duration::from_millis(1));
        let mut buf = vec![0u8; 1144];
        buf[..8].copy_from_slice(&monotonic_ns().to_le_bytes());
        publisher.put(buf).wait().map_err(zerr)?;
        if let Ok(v) = rx.recv_timeout(Duration::from_secs(2)) {
            one_way.push(v);
        }
    }
    let mut rtt = Vec::with_capacity(queries);
    for _ in 0..queries {
        let t0 = Instant::now();
        let replies = b
            .get(&qk)
            .payload(vec![0u8; 144])
            .timeout(Duration::from_secs(2))
            .wait()
            .map_err(zerr)?;
        if replies.recv().is_ok() {
            rtt.push(t0.elapsed().as_secs_f64() * 1e6);
        }
    }
    Ok((transport, one_way, rtt))
}

/// Runs the remote benchmark and returns its JSON; the bare reference
/// runs over `proto`, the bridge's link.
pub fn run(
    c: &mut Client,
    proto: &str,
    tls: Option<&TlsFiles>,
    statuses: usize,
    goals: usize,
    timeout: Duration,
) -> gaitd_client::Result<Value> {
    let mut status = status_latency(c, statuses, timeout)?;
    let mut goal = goal_to_answer(c, goals, timeout)?;
    let (transport, mut one_way, mut rtt) = bare(statuses.max(goals), goals.max(100), tls, proto)?;
    Ok(json!({
        "remote": {
            "key_prefix": c.settings().service_prefix,
            "identity": c.identity(),
            "status_latency_us": summary(&mut status),
            "goal_to_answer_us": summary(&mut goal),
            "bad_samples": c.bad_samples(),
        },
        "bare_zenoh": {
            "transport": transport,
            "pub_sub_one_way_us": summary(&mut one_way),
            "query_round_trip_us": summary(&mut rtt),
        },
    }))
}

/// The table for people.
pub fn print_table(v: &Value) {
    let row = |name: &str, s: &Value| {
        let f = |k: &str| s[k].as_f64().map_or("-".into(), |x| format!("{x:.0}"));
        println!(
            "  {name:<40} n={:<6} p50 {:>7} µs  p99 {:>7} µs  max {:>7} µs",
            s["n"],
            f("p50"),
            f("p99"),
            f("max")
        );
    };
    println!(
        "through gaitd-bridge (identity {}):",
        v["remote"]["identity"]
    );
    row(
        "status publish → receive",
        &v["remote"]["status_latency_us"],
    );
    row("goal → answer", &v["remote"]["goal_to_answer_us"]);
    println!(
        "bare Zenoh on loopback, same run ({}):",
        v["bare_zenoh"]["transport"].as_str().unwrap_or("?")
    );
    row(
        "publisher → subscriber (1144 B)",
        &v["bare_zenoh"]["pub_sub_one_way_us"],
    );
    row(
        "get → reply (144 B)",
        &v["bare_zenoh"]["query_round_trip_us"],
    );
}
