//! End to end, separate processes: gaitd and the client library —
//! commands, their answers and the reasons of refusals.

use gaitd_client::{
    Command, DaemonState, FingerPhase, GoalFrame, GoalSpec, GoalState, LimitKind, LimitOrder,
    Phase, ReasonCode, Verdict,
};
use gaitd_tests::TestDaemon;
use std::time::Duration;

const T: Duration = Duration::from_secs(5);

#[test]
fn status_flows_every_tick_with_the_paper_start() {
    let d = TestDaemon::start("status");
    let mut c = d.client();
    let first = c.wait_status(T).unwrap();
    let mut last = first;
    for _ in 0..20 {
        let s = c.wait_status(T).unwrap();
        assert!(s.tick > last.tick, "ticks increase");
        assert_eq!(s.instance, first.instance);
        last = s;
    }
    let s = last;
    s.check().unwrap();
    assert_eq!(s.daemon_state(), Ok(DaemonState::Running));
    assert_eq!(s.phase(), Ok(Phase::Hold));
    assert_eq!(s.goal_state(), Ok(GoalState::None));
    assert_eq!(s.timing.period_ns, 1_000_000);
    assert!(
        s.time_ns <= s.publish_time_ns,
        "published after the tick started"
    );
    for f in &s.fingers {
        assert_eq!(f.phase(), Ok(FingerPhase::Grasping));
        let r = f.contact_hand.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((r - 0.5).abs() < 1e-12, "contact on the sphere of radius R");
    }
    assert_ne!(c.daemon_pid(), None, "daemon node visible");
}

#[test]
fn commands_are_answered() {
    let d = TestDaemon::start("commands");
    let mut c = d.client();
    assert_eq!(c.hold(T).unwrap(), Verdict::Accepted);
    assert_eq!(
        c.reset(T).unwrap(),
        Verdict::Rejected(ReasonCode::NotFaulted)
    );
    assert_eq!(
        c.cancel(None, T).unwrap(),
        Verdict::Rejected(ReasonCode::NoActiveGoal)
    );
    // A goal is accepted, planned, executed and reported Succeeded, with
    // the object at the goal orientation.
    let goal = GoalSpec::axis_angle([0.0, 0.0, 1.0], 1.0, GoalFrame::Relative).unwrap();
    let t = c.reorient(&goal, T).unwrap();
    assert_eq!(t.verdict, Verdict::Accepted);
    let o = c.wait_outcome(t.goal_id, Duration::from_secs(60)).unwrap();
    assert_eq!(
        (o.state, o.reason),
        (GoalState::Succeeded, ReasonCode::Reached)
    );
    let s = c.wait_status(T).unwrap();
    // 1 rad about z from the paper's start (identity): q = (cos ½, 0, 0, sin ½).
    let want = [0.5f64.cos(), 0.0, 0.0, 0.5f64.sin()];
    let dot: f64 = s
        .measured_object_q
        .iter()
        .zip(want)
        .map(|(a, b)| a * b)
        .sum();
    let err = 2.0 * dot.abs().min(1.0).acos();
    assert!(
        err < 1e-6,
        "object at the goal: {:?} ({err} rad off)",
        s.measured_object_q
    );
    assert_eq!((s.commands, s.rejected), (4, 2));
}

/// Every kind of bad input gets its reason; the daemon keeps running.
#[test]
fn bad_inputs_are_rejected_with_reasons() {
    let d = TestDaemon::start("bad");
    let mut c = d.client();
    let me = c.client_id();
    let q = [1.0, 0.0, 0.0, 0.0];
    let goal = |id: u64, q: [f64; 4]| Command::goal(me, id, GoalFrame::Absolute, q);
    // A valid goal first (the object is already there): its id is then a
    // duplicate below.
    assert_eq!(
        c.command(goal(17, q), T).unwrap().verdict(),
        Ok(Verdict::Accepted)
    );
    let cases: Vec<(Command, ReasonCode)> = vec![
        (
            goal(1, [f64::NAN, 0.0, 0.0, 0.0]),
            ReasonCode::NonFiniteQuaternion,
        ),
        (
            goal(2, [f64::INFINITY, 0.0, 0.0, 0.0]),
            ReasonCode::NonFiniteQuaternion,
        ),
        (
            goal(3, [0.0, f64::NEG_INFINITY, 0.0, 0.0]),
            ReasonCode::NonFiniteQuaternion,
        ),
        (goal(4, [0.0; 4]), ReasonCode::ZeroQuaternion),
        (
            goal(5, [1e300, 0.0, 0.0, 1e300]),
            ReasonCode::NonUnitQuaternion,
        ),
        (goal(6, [0.5, 0.5, 0.0, 0.0]), ReasonCode::NonUnitQuaternion),
        (
            Command {
                kind: 0,
                ..goal(7, q)
            },
            ReasonCode::UnknownCommandKind,
        ),
        (
            Command {
                kind: 99,
                ..goal(8, q)
            },
            ReasonCode::UnknownCommandKind,
        ),
        (
            Command {
                frame: 7,
                ..goal(9, q)
            },
            ReasonCode::UnknownGoalFrame,
        ),
        (goal(0, q), ReasonCode::ZeroGoalId),
        (
            Command {
                client_id: 0,
                ..goal(10, q)
            },
            ReasonCode::ZeroClientId,
        ),
        (
            Command {
                reserved: 5,
                ..goal(11, q)
            },
            ReasonCode::NonZeroReserved,
        ),
        (
            Command {
                limit_mask: 1 << 12,
                ..goal(12, q)
            },
            ReasonCode::BadLimitMask,
        ),
        (
            goal(13, q).with_limit(LimitKind::Object, LimitOrder::Velocity, -1.0),
            ReasonCode::NonPositiveLimit,
        ),
        (
            goal(14, q).with_limit(LimitKind::Rolling, LimitOrder::Jerk, 0.0),
            ReasonCode::NonPositiveLimit,
        ),
        (
            goal(15, q).with_limit(LimitKind::Fingertip, LimitOrder::Acceleration, f64::NAN),
            ReasonCode::NonFiniteLimit,
        ),
        (
            goal(16, q).with_limit(LimitKind::Object, LimitOrder::Jerk, 1e9),
            ReasonCode::LimitAboveConfigured,
        ),
        (goal(17, q), ReasonCode::DuplicateGoalId),
        (
            Command::goal(me, 18, GoalFrame::AxisAngle, [f64::NAN, 0.0, 0.0, 1.0]),
            ReasonCode::BadAxisAngle,
        ),
        (
            Command::goal(me, 19, GoalFrame::AxisAngle, [1.0, 0.0, 0.0, 0.0]),
            ReasonCode::BadAxisAngle,
        ),
        (
            Command {
                target: q,
                ..Command::hold(me)
            },
            ReasonCode::NonZeroReserved,
        ),
    ];
    for (i, (cmd, want)) in cases.iter().enumerate() {
        let a = c.command(*cmd, T).unwrap();
        assert_eq!(
            a.verdict(),
            Ok(Verdict::Rejected(*want)),
            "case {i}: {cmd:?}"
        );
        assert_eq!(a.goal_id, cmd.goal_id, "answer echoes the goal id");
    }
    let s = c.wait_status(T).unwrap();
    assert_eq!(s.rejected, cases.len() as u64);
    assert_eq!(s.daemon_state(), Ok(DaemonState::Running));

    // A flood of garbage: some sends may be refused (queue full), the
    // daemon never stops ticking.
    let before = c.wait_status(T).unwrap().tick;
    let mut busy = 0;
    for i in 0..2000u64 {
        let junk = Command {
            kind: (i % 7) as u32,
            frame: (i % 5) as u32,
            target: [f64::from_bits(i.wrapping_mul(0x9e37_79b9_7f4a_7c15)); 4],
            ..Command::ZERO
        };
        match c.send_command(junk) {
            Ok(_) => {}
            Err(gaitd_client::Error::Busy) => busy += 1,
            Err(e) => panic!("{e}"),
        }
    }
    std::thread::sleep(Duration::from_millis(200));
    let after = c.wait_status(T).unwrap();
    assert!(after.tick > before + 50, "the loop kept ticking");
    assert!(after.rejected >= s.rejected + 2000 - busy);
    assert_eq!(c.hold(T).unwrap(), Verdict::Accepted, "still answering");
}

#[test]
fn gaitctl_status_and_watch_show_the_daemon() {
    let d = TestDaemon::start("gaitctl");
    let out = d.gaitctl().args(["status", "--json"]).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["phase"], "Hold");
    assert_eq!(v["daemon_state"], "Running");
    assert_eq!(v["fingers"].as_array().unwrap().len(), 3);

    let out = d
        .gaitctl()
        .args(["watch", "--frames", "3", "--live", "always"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("\x1b[H"), "refreshes in place");
    assert!(text.contains("phase Hold"), "{text}");
    assert!(text.matches("tick compute").count() == 3, "three frames");
    assert!(text.contains("latest events"), "{text}");
    assert!(text.contains("DaemonStarted"), "the history: {text}");

    let out = d.gaitctl().arg("hold").output().unwrap();
    assert!(out.status.success());
    let out = d
        .gaitctl()
        .args([
            "reorient",
            "--axis",
            "0,0,1",
            "--angle-deg",
            "-30",
            "--relative",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("accepted"));
    let out = d.gaitctl().arg("events").output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("DaemonStarted") && text.contains("Hold"),
        "{text}"
    );
    let out = d.gaitctl().args(["events", "--json"]).output().unwrap();
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert!(lines.iter().any(|v| v["kind"] == "DaemonStarted"));
    let goal = lines
        .iter()
        .find(|v| v["kind"] == "GoalTransition")
        .expect("the goal's transitions");
    assert!(goal["state"].is_string() && goal["goal_id"].as_u64() > Some(0));
}

#[test]
fn no_daemon_is_a_clear_error() {
    let d = TestDaemon::new("nodaemon", "");
    let t0 = std::time::Instant::now();
    let err =
        gaitd_client::Client::connect(d.options().timeout(Duration::from_millis(300))).unwrap_err();
    assert!(
        t0.elapsed() < Duration::from_secs(5),
        "the timeout is honoured"
    );
    assert!(
        matches!(err, gaitd_client::Error::NoDaemon { .. }),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("no gaitd running") && msg.contains(&d.prefix),
        "{msg}"
    );
}

/// A client that finds every slot taken waits for one until its timeout
/// (as it waits for a daemon that is still creating its services), and
/// the reason it gives up names the limit.
#[test]
fn a_client_waits_for_a_free_slot_within_its_timeout() {
    let mut d = TestDaemon::new("slots", "");
    let cfg = std::fs::read_to_string(d.config_path()).expect("config");
    let cfg = cfg.replacen("[ipc]\n", "[ipc]\nmax_clients = 1\n", 1);
    std::fs::write(d.config_path(), cfg).expect("config");
    d.spawn();
    let first = d.client();
    let Err(err) = gaitd_client::Client::connect(d.options().timeout(Duration::from_millis(300)))
    else {
        panic!("a second client while the only slot is taken");
    };
    assert!(
        err.to_string().contains("max_clients"),
        "the reason names the limit: {err}"
    );
    let opts = d.options().timeout(Duration::from_secs(20));
    let second = std::thread::spawn(move || gaitd_client::Client::connect(opts).map(|_| ()));
    std::thread::sleep(Duration::from_millis(500));
    drop(first);
    second
        .join()
        .expect("no panic")
        .expect("the second client connects once the first has left");
}

/// `gaitctl bench` runs end to end (small counts; figures are not asserted).
#[test]
fn gaitctl_bench_reports_every_figure() {
    // Weightless, and few of each measurement: the figures' presence is
    // checked here, not their values (the half turn the tick compute time
    // is read over takes about 4 s instead of 11 s under the default load).
    let mut d = TestDaemon::new("bench", "[load]\ngravity = [0.0, 0.0, 0.0]\n");
    d.spawn();
    let out = d
        .gaitctl()
        .args([
            "bench",
            "--goals",
            "5",
            "--motions",
            "3",
            "--statuses",
            "50",
            "--pings",
            "50",
            "--noise-periods",
            "1000",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for k in [
        "goal_to_answer_us",
        "status_publish_to_receive_us",
        "iceoryx2_one_way_us",
        "iceoryx2_periodic_one_way_us",
    ] {
        assert!(v[k]["n"].as_u64().is_some_and(|n| n > 0), "{k}: {v}");
        assert!(v[k]["p50"].as_f64().unwrap() > 0.0, "{k}");
    }
    assert!(v["tick_compute_ns"]["max"].as_u64().unwrap() > 0);
    assert!(v["daemon"]["rss_kb"].as_u64().unwrap() > 0);
    assert_eq!(v["jitter_histogram_window"].as_array().unwrap().len(), 16);
}
