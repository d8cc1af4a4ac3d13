//! A goal through the bridge, a cancel, the late joiner's history, and
//! `gaitctl --remote` from the command line.

use crate::support::{self, Pki, T, TestBridge};
use gaitd_client::remote::protocol::client_id_for;
use gaitd_client::{EventKind, GoalSpec, GoalState, ReasonCode, Verdict};
use gaitd_tests::TestDaemon;
use std::io::{BufRead, BufReader};
use std::process::Stdio;
use std::time::{Duration, Instant};

const LONG: Duration = Duration::from_secs(90);

fn wait_state(c: &mut gaitd_client::Client, goal: u64, state: GoalState) {
    let t0 = Instant::now();
    loop {
        let s = c.wait_status(T).unwrap();
        if s.goal.goal_id == goal && s.goal.state == state.code() {
            return;
        }
        assert!(t0.elapsed() < Duration::from_secs(20), "never {state:?}");
    }
}

#[test]
fn a_remote_goal_succeeds_a_cancel_stops_one_and_a_late_joiner_gets_the_history() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("goals");
    let d = support::weightless_daemon("remote-goals");
    let _local = d.client();
    // A cache deep enough for both goals' transitions even when a loaded
    // machine makes the debug daemon report Overrun events meanwhile (the
    // late joiner asks for the last 256 events, as every client does).
    let b = TestBridge::start(&d, &pki, "event_cache = 2048");
    let mut op = b.client(&pki, "op");
    assert!(op.is_remote());
    assert_eq!(op.identity(), Some("op"));
    assert_eq!(op.client_id(), client_id_for("op"));
    assert_eq!(op.daemon_pid(), None);

    // A goal through the bridge, to its end.
    let first = op
        .reorient(
            &GoalSpec::turn([0.0, 0.0, 1.0], std::f64::consts::FRAC_PI_2).unwrap(),
            T,
        )
        .unwrap();
    assert_eq!(first.verdict, Verdict::Accepted);
    let o = op.wait_outcome(first.goal_id, LONG).unwrap();
    assert_eq!(
        (o.state, o.reason),
        (GoalState::Succeeded, ReasonCode::Reached),
        "--- bridge log ---\n{}",
        b.log()
    );

    // A long one, canceled while it runs.
    let second = op
        .reorient(&GoalSpec::turn([0.0, 0.0, 1.0], 3.0).unwrap(), T)
        .unwrap();
    assert_eq!(second.verdict, Verdict::Accepted);
    wait_state(&mut op, second.goal_id, GoalState::Executing);
    assert_eq!(op.cancel(None, T).unwrap(), Verdict::Accepted);
    let o = op.wait_outcome(second.goal_id, LONG).unwrap();
    assert_eq!(
        (o.state, o.reason),
        (GoalState::Canceled, ReasonCode::CanceledByClient)
    );
    assert_eq!(op.bad_samples(), 0);

    // A monitor that connects now gets the recent events from the
    // bridge's cache: both goals' transitions, sent before it existed. (A
    // late joiner once got only live events, the history dropped: zenoh-ext
    // did that when the client also asked for late-publisher detection,
    // which the clients no longer do; PROTOCOL.md, "Events".)
    let mut late = b.client(&pki, "dash");
    let me = client_id_for("op");
    let ended = |events: &[gaitd_client::Event], goal: u64, state: GoalState| {
        events.iter().any(|e| {
            e.kind() == Ok(EventKind::GoalTransition)
                && (e.client_id, e.goal_id) == (me, goal)
                && e.state == state.code()
        })
    };
    let both = |seen: &[gaitd_client::Event]| {
        ended(seen, first.goal_id, GoalState::Succeeded)
            && ended(seen, second.goal_id, GoalState::Canceled)
    };
    let mut seen = Vec::new();
    let t0 = Instant::now();
    while !both(&seen) {
        if t0.elapsed() >= Duration::from_secs(20) {
            // Tell a lost history query from a cache without the events:
            // a second late joiner asks the same cache again.
            let mut again = b.client(&pki, "dash");
            let mut seen_again = Vec::new();
            let t1 = Instant::now();
            while !both(&seen_again) && t1.elapsed() < Duration::from_secs(10) {
                if let Some(e) = again.next_event(Duration::from_millis(200)).unwrap() {
                    seen_again.push(e);
                }
            }
            panic!(
                "the late joiner never got the history: {}; a second one then got {} ({})\n{}",
                history_report(&seen, late.missed_events()),
                history_report(&seen_again, again.missed_events()),
                if both(&seen_again) {
                    "the cache had them: the first history query was lost"
                } else {
                    "the cache did not have them either"
                },
                b.log()
            );
        }
        if let Some(e) = late.next_event(Duration::from_millis(200)).unwrap() {
            seen.push(e);
        }
    }
    let seqs: Vec<u64> = seen.iter().map(|e| e.seq).collect();
    assert!(delivered_as_documented(&seqs), "{seqs:?}");
    assert_eq!(late.bad_samples(), 0);
}

/// Whether events came as PROTOCOL.md "Events" says a client delivers
/// them: each once, the live ones in order and the history (every event
/// older than the first delivered: it can arrive after the first live
/// event) in order too.
fn delivered_as_documented(seqs: &[u64]) -> bool {
    let Some(&first) = seqs.first() else {
        return true;
    };
    let ascending = |older: bool| {
        seqs.iter()
            .filter(|&&s| (s < first) == older)
            .is_sorted_by(|a, b| a < b)
    };
    ascending(true) && ascending(false)
}

#[test]
fn the_delivery_oracle_takes_a_late_history_and_nothing_else() {
    let late: Vec<u64> = std::iter::once(35).chain(1..35).collect();
    assert!(delivered_as_documented(&late));
    assert!(delivered_as_documented(&[3, 4, 1, 5, 2, 6]), "interleaved");
    assert!(delivered_as_documented(&(1..40).collect::<Vec<u64>>()));
    assert!(!delivered_as_documented(&[1, 2, 2]), "a repeat");
    assert!(!delivered_as_documented(&[3, 1, 1]), "a repeated history");
    assert!(!delivered_as_documented(&[1, 3, 2]), "live out of order");
    assert!(!delivered_as_documented(&[5, 2, 1]), "history out of order");
}

/// What a late joiner got, to tell a dropped history (only live events,
/// fewer than 256) from one the Overrun events filled (256 or more, the
/// transitions older than the last 256).
fn history_report(seen: &[gaitd_client::Event], missed: u64) -> String {
    let count = |k: EventKind| seen.iter().filter(|e| e.kind() == Ok(k)).count();
    format!(
        "{} events ({} Overrun, {} goal transitions), seq {:?}..{:?}, {missed} missed",
        seen.len(),
        count(EventKind::Overrun),
        count(EventKind::GoalTransition),
        seen.first().map(|e| e.seq),
        seen.last().map(|e| e.seq),
    )
}

#[test]
fn gaitctl_remote_status_reorient_hold_cancel_and_events() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("cli");
    let d = support::weightless_daemon("remote-cli");
    let _local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    let run = |name: &str, args: &[&str]| support::run(b.gaitctl(&pki, name).args(args));
    let (rc, out, err) = run("dash", &["status", "--json"]);
    assert_eq!(rc, Some(0), "{err}");
    let s: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(s["daemon_state"], "Running");

    // A follower started before the goal sees its transitions live (the
    // bridge's history alone may have been filled by the daemon's Overrun
    // events on a loaded machine by the time it joins).
    let mut follower = b
        .gaitctl(&pki, "dash")
        .args(["events", "--json", "--follow", "--duration", "120"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let lines = follower.stdout.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel::<String>();
    let reader = std::thread::spawn(move || {
        for l in BufReader::new(lines).lines().map_while(Result::ok) {
            if tx.send(l).is_err() {
                break;
            }
        }
    });
    // It says on stderr when it has printed the history and follows.
    let mut err_lines = BufReader::new(follower.stderr.take().unwrap()).lines();
    let said = err_lines.next().and_then(Result::ok).unwrap_or_default();
    assert_eq!(said, "(following events; Ctrl-C to stop)");

    // op turns about z by `deg`, with `more` flags.
    let turn_z = |deg: &str, more: &[&str]| {
        let base = [
            "reorient",
            "--axis",
            "0,0,1",
            "--angle-deg",
            deg,
            "--relative",
        ];
        run("op", &[&base[..], more].concat())
    };
    let (rc, out, err) = turn_z("30", &["--wait"]);
    assert_eq!(rc, Some(0), "{out}{err}");
    assert!(out.contains("Succeeded (Reached)"), "{out}");

    let (rc, out, err) = run("op", &["hold"]);
    assert_eq!((rc, out.trim()), (Some(0), "hold: accepted"), "{err}");
    let (rc, out, _) = run("op", &["cancel"]);
    assert_eq!(
        (rc, out.trim()),
        (Some(1), "cancel: rejected (NoActiveGoal)")
    );

    // A goal without --wait: gaitctl says that the bridge's client-lost
    // policy applies once it exits.
    let (rc, out, err) = turn_z("10", &[]);
    assert_eq!(rc, Some(0), "{out}{err}");
    assert!(out.contains("accepted"), "{out}");
    assert!(err.contains("on_client_lost"), "no hint on stderr: {err}");

    let op_id = format!("{:x}", client_id_for("op"));
    let t0 = Instant::now();
    let mut seen = Vec::new();
    let succeeded = loop {
        let Ok(l) = rx.recv_timeout(Duration::from_secs(1)) else {
            if t0.elapsed() > LONG {
                break false;
            }
            continue;
        };
        let Ok(e) = serde_json::from_str::<serde_json::Value>(&l) else {
            continue;
        };
        if e["kind"] == "GoalTransition" {
            if e["state"] == "Succeeded" && e["client_id"] == op_id {
                break true;
            }
            seen.push(l);
        }
    };
    let _ = follower.kill();
    let _ = follower.wait();
    drop(rx);
    let _ = reader.join();
    assert!(
        succeeded,
        "no Succeeded transition of op's goal; saw {seen:?}"
    );
}

#[test]
fn gaitctl_remote_bench_measures_the_bridge_beside_bare_zenoh() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("bench");
    let d = TestDaemon::start("remote-bench");
    let _local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    let out = b
        .gaitctl(&pki, "op")
        .args([
            "bench",
            "--json",
            "--remote-statuses",
            "20",
            "--remote-goals",
            "3",
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_str(text.trim()).unwrap();
    assert_eq!(v["remote"]["status_latency_us"]["n"], 20, "{v}");
    assert_eq!(v["remote"]["goal_to_answer_us"]["n"], 3, "{v}");
    // The bridge's certificate lies beside ca.pem: the reference runs on
    // the bridge's link (QUIC) with mutual TLS too.
    assert_eq!(v["bare_zenoh"]["transport"], "quic (mutual TLS)", "{v}");
    assert_eq!(v["bare_zenoh"]["pub_sub_one_way_us"]["n"], 20, "{v}");
    assert_eq!(v["bare_zenoh"]["query_round_trip_us"]["n"], 100, "{v}");
    for s in [
        &v["remote"]["status_latency_us"],
        &v["remote"]["goal_to_answer_us"],
        &v["bare_zenoh"]["pub_sub_one_way_us"],
        &v["bare_zenoh"]["query_round_trip_us"],
    ] {
        let (p50, max) = (s["p50"].as_f64().unwrap(), s["max"].as_f64().unwrap());
        assert!(p50 > 0.0 && p50 <= max, "{v}");
    }
}
