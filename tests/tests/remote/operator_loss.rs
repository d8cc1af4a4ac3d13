//! An operator whose goal runs, gone — through real bridge processes on
//! loopback (PROTOCOL.md, "Lost clients"):
//!
//! - the bridge killed (SIGKILL) while the operator's goal runs, the
//!   operator gone meanwhile, the bridge restarted 1 s later: the restarted
//!   bridge reads from the daemon whose goal runs and, the operator not
//!   coming back, applies `on_client_lost` (cancel);
//! - an operator with a 10 s Zenoh lease (Zenoh's default, what a client
//!   built from the protocol gets unless it sets one) killed with SIGKILL:
//!   the bridge notices within its own bound (the client's beats stop), not
//!   after the client's lease.

use crate::support::{Pki, T, TestBridge, one_at_a_time, weightless_daemon};
use gaitd_client::remote::protocol::client_id_for;
use gaitd_client::{Client, GoalSpec, GoalState, ReasonCode, Verdict};
use gaitd_tests::{oracle_python, repo_root};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Waits until op's goal executes; returns its id.
fn executing(local: &mut Client) -> u64 {
    let op = client_id_for("op");
    let t0 = Instant::now();
    loop {
        let s = local.wait_status(T).unwrap();
        if s.goal.client_id == op && s.goal.state == GoalState::Executing.code() {
            return s.goal.goal_id;
        }
        assert!(t0.elapsed() < Duration::from_secs(60), "never executed");
    }
}

/// How `goal` ended, as the daemon's status says, and when.
fn ended(local: &mut Client, goal: u64) -> (GoalState, ReasonCode, Instant) {
    let t0 = Instant::now();
    loop {
        let s = local.wait_status(T).unwrap();
        let state = s.goal_state().unwrap();
        if s.goal.goal_id == goal && state.is_terminal() {
            return (state, s.goal_reason().unwrap(), Instant::now());
        }
        assert!(t0.elapsed() < Duration::from_secs(60), "never ended");
    }
}

#[test]
fn a_restarted_bridge_cancels_the_running_goal_of_an_operator_that_is_gone() {
    let _one = one_at_a_time();
    let pki = Pki::new("restart-lost");
    let d = weightless_daemon("remote-restart-lost");
    let mut local = d.client();
    let mut b = TestBridge::start(&d, &pki, "");
    let mut op = b.client(&pki, "op");
    // Three full turns: still running long after the restart.
    let turn = GoalSpec::turn([0.0, 0.0, 1.0], 3.0 * std::f64::consts::TAU).unwrap();
    assert_eq!(op.reorient(&turn, T).unwrap().verdict, Verdict::Accepted);
    let goal = executing(&mut local);
    b.kill();
    // The operator goes while the bridge is down: nothing tells anyone.
    drop(op);
    std::thread::sleep(Duration::from_secs(1));
    let restarted = Instant::now();
    b.spawn();
    let (state, reason, at) = ended(&mut local, goal);
    let after = at - restarted;
    println!("the goal ended {after:?} after the bridge restarted: {state:?} ({reason:?})");
    assert_eq!(
        (state, reason),
        (GoalState::Canceled, ReasonCode::CanceledByClient)
    );
    // reconnect_wait_ms 2000 + client_lost_grace_ms 1000, then the stop.
    assert!(after < Duration::from_secs(10), "{after:?}");
    let log = b.log();
    assert!(log.contains("client-lost policy applied"), "{log}");
}

/// A Python operator with a 10 s lease: sends a long goal, says so, waits.
const LONG_LEASE_OPERATOR: &str = r#"
import sys, time
from gaitd.remote import RemoteClient
endpoint, pki, prefix = sys.argv[1:4]
c = RemoteClient.connect(endpoint, f"{pki}/ca.pem", f"{pki}/op.pem", f"{pki}/op.key",
                         prefix=prefix, timeout=10.0, lease=10.0)
r = c.turn((0.0, 0.0, 1.0), 3 * 6.283185307179586)
print("sent", r.code, flush=True)
time.sleep(600)
"#;

#[test]
fn a_killed_operator_with_a_long_lease_is_noticed_within_the_bridges_bound() {
    let _one = one_at_a_time();
    let has_zenoh = Command::new(oracle_python())
        .args(["-c", "import zenoh"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_zenoh {
        test_support::skip(
            "operator lost within the bridge's bound (Python remote client)",
            "eclipse-zenoh is not installed in the oracle Python: pip install -e 'client/python[remote]'",
        );
        return;
    }
    let pki = Pki::new("long-lease");
    let d = weightless_daemon("remote-long-lease");
    let mut local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    let mut child = Command::new(oracle_python())
        .env("PYTHONPATH", repo_root().join("client/python"))
        .args(["-c", LONG_LEASE_OPERATOR, &b.endpoint])
        .arg(&pki.dir)
        .arg(&b.prefix)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    assert!(line.starts_with("sent Accepted"), "{line:?}");
    let goal = executing(&mut local);
    let killed = Instant::now();
    child.kill().unwrap();
    let _ = child.wait();
    let (state, reason, at) = ended(&mut local, goal);
    let after = at - killed;
    println!("canceled {after:?} after the operator (lease 10 s) was killed: {state:?}");
    assert_eq!(
        (state, reason),
        (GoalState::Canceled, ReasonCode::CanceledByClient)
    );
    // client_beat_timeout_ms 1500 + client_lost_grace_ms 1000 + the stop:
    // well under the client's 10 s lease.
    assert!(after < Duration::from_secs(6), "{after:?}\n{}", b.log());
}
