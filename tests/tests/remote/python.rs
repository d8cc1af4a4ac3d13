//! A remote Python client (`gaitd.remote.RemoteClient`, PyPI
//! `eclipse-zenoh`) through the bridge: it reads the status and sends a
//! goal that succeeds; its link cut with a command in flight (`cut.rs`'s
//! forwarder), it sends the command again and the daemon gets it once (a
//! monitor's command, which gets no reply at all, is not sent again).
//! Skipped, visibly, where the oracle Python lacks `zenoh`
//! (`pip install -e 'client/python[remote]'`).

use crate::cut::Cutter;
use crate::support::{Pki, T, TestBridge};
use gaitd_tests::{TestDaemon, client_python, oracle_python, output_within, repo_root};
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, channel};
use std::time::Duration;

/// Whether the oracle Python has `zenoh`; records the skip of `check` if not.
fn has_zenoh(check: &str) -> bool {
    match client_python().args(["-c", "import zenoh"]).output() {
        Ok(o) if o.status.success() => true,
        Ok(o) => {
            test_support::skip(
                check,
                &format!(
                    "eclipse-zenoh is not installed in {} ({}): pip install -e 'client/python[remote]'",
                    oracle_python().display(),
                    String::from_utf8_lossy(&o.stderr)
                        .lines()
                        .last()
                        .unwrap_or("")
                ),
            );
            false
        }
        Err(e) => {
            test_support::skip(check, &format!("no oracle Python: {e}"));
            false
        }
    }
}

#[test]
fn a_remote_python_client_sends_a_goal_and_reads_status() {
    let _one = crate::support::one_at_a_time();
    if !has_zenoh("remote Python client (gaitd.remote)") {
        return;
    }
    let pki = Pki::new("python");
    let d = crate::support::weightless_daemon("remote-python");
    let _local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    // The script's own waits add up to about 90 s; a hang fails here.
    let out = output_within(
        client_python()
            .arg(repo_root().join("tests/python/remote_goal.py"))
            .args([&b.endpoint, &pki.dir.display().to_string(), "op", &b.prefix])
            // Where no bridge listens: a free UDP port.
            .arg(format!(
                "quic/127.0.0.1:{}",
                crate::support::free_udp_port()
            )),
        Duration::from_secs(150),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "remote_goal.py failed:\n{stdout}\n{}\n--- bridge ---\n{}",
        String::from_utf8_lossy(&out.stderr),
        b.log()
    );
    let line = stdout
        .lines()
        .rev()
        .find(|l| l.starts_with('{'))
        .unwrap_or("");
    let v: serde_json::Value = serde_json::from_str(line).unwrap();
    println!("remote_goal.py: {v}");
    // What a user is told: no bridge (QUIC cannot tell that from a refused
    // certificate, so both are named), and a protocol the bridge refuses.
    let no_bridge = v["no_bridge_error"].as_str().unwrap_or_default();
    assert!(
        no_bridge.starts_with("no session with the bridge at quic/127.0.0.1:")
            && no_bridge.contains("is gaitd-bridge running there"),
        "{v}"
    );
    assert!(
        v["tcp_error"]
            .as_str()
            .unwrap_or_default()
            .contains("only accepts quic/HOST:PORT or tls/HOST:PORT"),
        "{v}"
    );
    assert_eq!(v["accepted"], true, "{v}");
    assert_eq!(v["outcome"], "Succeeded", "{v}");
    assert!(v["status_ticks_advance"].as_bool().unwrap(), "{v}");
    assert_eq!(
        v["client_id"],
        format!("{:x}", gaitd_client::remote::protocol::client_id_for("op"))
    );
}

/// A Python script talking line by line, killed when dropped.
struct Script {
    child: Child,
    lines: Receiver<String>,
    stderr: Option<std::thread::JoinHandle<String>>,
}

impl Script {
    fn start(c: &mut Command) -> Self {
        let mut child = c
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {c:?}: {e}"));
        let out = BufReader::new(child.stdout.take().unwrap());
        let mut err = child.stderr.take().unwrap();
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for l in out.lines().map_while(Result::ok) {
                if tx.send(l).is_err() {
                    break;
                }
            }
        });
        let stderr = Some(std::thread::spawn(move || {
            let mut s = String::new();
            let _ = err.read_to_string(&mut s);
            s
        }));
        Self {
            child,
            lines,
            stderr,
        }
    }

    /// The next line on stdout within `limit`, or what went wrong.
    fn line(&mut self, limit: Duration) -> Result<String, String> {
        self.lines.recv_timeout(limit).map_err(|e| {
            let _ = self.child.kill();
            let _ = self.child.wait();
            format!("no line from the script ({e})")
        })
    }

    fn say(&mut self, line: &str) {
        let stdin = self.child.stdin.as_mut().unwrap();
        stdin.write_all(format!("{line}\n").as_bytes()).unwrap();
        stdin.flush().unwrap();
    }

    /// Waits for the exit (killed after `limit`): its status and stderr.
    fn finish(mut self, limit: Duration) -> (Option<std::process::ExitStatus>, String) {
        let t0 = std::time::Instant::now();
        let status = loop {
            if let Some(s) = self.child.try_wait().unwrap() {
                break Some(s);
            }
            if t0.elapsed() > limit {
                let _ = self.child.kill();
                let _ = self.child.wait();
                break None;
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        let stderr = self.stderr.take().and_then(|t| t.join().ok());
        (status, stderr.unwrap_or_default())
    }
}

impl Drop for Script {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn a_remote_python_clients_command_whose_link_drops_reaches_the_daemon_once() {
    let _one = crate::support::one_at_a_time();
    if !has_zenoh("remote Python client, link cut (gaitd.remote)") {
        return;
    }
    let pki = Pki::new("python-cut");
    let d = TestDaemon::start("remote-python-cut");
    let mut local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    let cutter = Cutter::start(b.tls_endpoint.trim_start_matches("tls/").to_owned());
    let endpoint = format!("tls/127.0.0.1:{}", cutter.port);
    let mut script = Script::start(
        client_python()
            .arg(repo_root().join("tests/tests/remote/remote_cut.py"))
            .args([&endpoint, &pki.dir.display().to_string(), "op", &b.prefix]),
    );
    let said = script.line(Duration::from_secs(60));
    if said.as_deref() != Ok("connected") {
        let (_, stderr) = script.finish(Duration::from_secs(1));
        panic!(
            "remote_cut.py: {said:?}\n{stderr}\n--- bridge ---\n{}",
            b.log()
        );
    }
    // The daemon's own count of the commands it received.
    let commands = |local: &mut gaitd_client::Client| local.wait_status(T).unwrap().commands;
    let before = commands(&mut local);
    cutter.arm();
    script.say("go");
    let line = script.line(Duration::from_secs(60));
    let (status, stderr) = script.finish(Duration::from_secs(20));
    let line = line.unwrap_or_else(|e| panic!("{e}\n{stderr}"));
    assert!(
        status.is_some_and(|s| s.success()),
        "remote_cut.py: {status:?}\n{stderr}"
    );
    let v: serde_json::Value = serde_json::from_str(&line).unwrap();
    println!("remote_cut.py: {v}");
    assert_eq!(
        cutter.cuts.load(Ordering::Acquire),
        1,
        "the link was not cut"
    );
    assert_eq!(v["accepted"], true, "{v}\n{stderr}");
    // A monitor's command, dropped by access control, is not mistaken for
    // one whose link dropped: unanswered after a moment, not sent again.
    assert_eq!(v["monitor"], "NoAnswer", "{v}");
    assert!(v["monitor_s"].as_f64().unwrap() < 2.0, "{v}");
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        commands(&mut local),
        before + 1,
        "the daemon got the command twice (or never): {v}"
    );
    assert!(b.log().contains("request sent again"), "{}", b.log());
}
