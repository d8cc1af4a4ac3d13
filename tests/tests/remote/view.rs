//! `gaitd-view --remote`: the view of a daemon on another host, through its
//! gaitd-bridge as a monitor, recorded (`--save`) while a goal turns the
//! object; the recording, read back with Rerun's own decoder, has the
//! frames asked for and shows the object turning.

use crate::support::{Pki, T, TestBridge, run};
use gaitd_client::{GoalSpec, Verdict};
use gaitd_tests::{TestDaemon, workspace_bin};
use std::process::Command;
use std::time::{Duration, Instant};

#[path = "../rerun_support/mod.rs"]
mod rerun_support;

/// Frames the view records (at 10 per second: 2 s of the turn).
const FRAMES: usize = 20;

/// A daemon with its bridge, turning the object a full turn (about 8 s,
/// longer than a view needs to connect and record), past its plan: the
/// object has begun to turn.
struct Turning {
    _one: std::sync::MutexGuard<'static, ()>,
    pki: Pki,
    d: TestDaemon,
    b: TestBridge,
    local: gaitd_client::Client,
}

impl Turning {
    fn start(tag: &str) -> Self {
        let one = crate::support::one_at_a_time();
        let pki = Pki::new(tag);
        let d = TestDaemon::start(&format!("remote-{tag}"));
        let b = TestBridge::start(&d, &pki, "");
        let mut local = d.client();
        let t = local
            .reorient(&GoalSpec::turn([0.0, 0.0, 1.0], 6.2).unwrap(), T)
            .unwrap();
        assert_eq!(t.verdict, Verdict::Accepted);
        let t0 = Instant::now();
        while local.wait_status(T).unwrap().goal.remaining_angle > 6.0 {
            assert!(
                t0.elapsed() < Duration::from_secs(30),
                "the goal does not move"
            );
        }
        Self {
            _one: one,
            pki,
            d,
            b,
            local,
        }
    }
}

#[test]
fn gaitd_view_records_a_remote_daemon_through_its_bridge() {
    // The local client stays connected: its goal turns on.
    let Turning {
        _one,
        pki,
        d,
        b,
        local: _local,
    } = Turning::start("view");
    let rrd = d.dir.join("remote-view.rrd");
    let (rc, out, err) = run(Command::new(workspace_bin("gaitd-view"))
        .args(["--remote", &b.endpoint, "--pki"])
        .arg(&pki.dir)
        .args([
            "--identity",
            "dash",
            "--prefix",
            &b.prefix,
            "--timeout",
            "10",
        ])
        .args(["--rate", "10", "--report-every", "0"])
        .args(["--frames", &FRAMES.to_string(), "--save"])
        .arg(&rrd));
    assert_eq!(rc, Some(0), "{out}{err}\n--- bridge log ---\n{}", b.log());
    let rec = rerun_support::read(&rrd);
    assert_eq!(rec.object.len(), FRAMES, "{out}");
    let mut object = rec.object.clone();
    object.sort_by_key(|(time, _)| *time);
    let (q0, q1) = (object[0].1, object[FRAMES - 1].1);
    let dot: f32 = (0..4).map(|i| q0[i] * q1[i]).sum();
    let turned = 2.0 * f64::from(dot.abs().min(1.0)).acos();
    println!("{out}remote view: {FRAMES} frames, the object turned {turned:.3} rad");
    assert!(
        turned > 0.1,
        "the object did not turn in the recording: {turned} rad"
    );
    for e in [
        "world/object/ball",
        "world/tips/commanded",
        "plots/tick/compute_us",
    ] {
        assert!(rec.entities.contains(e), "no {e} in {:?}", rec.entities);
    }
    // The plan's path comes through the bridge too (its cache holds the
    // latest, so a view that joins mid-plan has it): the path ahead is
    // drawn while the goal executes.
    let ahead = rec.rows.get("world/ahead/tips").copied().unwrap_or(0);
    println!("remote view: {ahead} frames with the path ahead");
    assert!(
        ahead >= FRAMES / 2,
        "{ahead} of {FRAMES} frames drew the path ahead\n--- bridge log ---\n{}",
        b.log()
    );
}

/// A subscriber that joins mid-plan without asking for history (a plain
/// Zenoh subscriber on `P/plan`, PROTOCOL.md) still gets the plan's path:
/// the bridge sends the latest again every second while nothing newer
/// comes.
#[test]
fn a_subscriber_without_history_gets_the_latest_path_within_a_second() {
    use gaitd_client::remote::protocol as proto;
    use gaitd_client::remote::tls;
    use gaitd_client::shm_schema::PlanPath;
    use std::sync::{Arc, Mutex};
    use zenoh::Wait;
    let Turning {
        _one,
        pki,
        d: _d,
        b,
        mut local,
    } = Turning::start("plan-repeat");
    let goal = local.wait_status(T).unwrap().goal.goal_id;
    let ep = tls::parse_endpoint(&b.endpoint).unwrap();
    let opts = gaitd_client::RemoteOptions::new(&b.endpoint, pki.files("dash"));
    let session = zenoh::open(tls::client_config(&ep, &opts, T).unwrap())
        .wait()
        .unwrap();
    let got: Arc<Mutex<Vec<PlanPath>>> = Arc::default();
    let sink = got.clone();
    let _sub = session
        .declare_subscriber(proto::plan_key(&b.prefix))
        .callback(move |s| {
            let bytes = s.payload().to_bytes();
            if let Ok(b) = <&[u8; PlanPath::SIZE]>::try_from(bytes.as_ref()) {
                sink.lock().unwrap().push(PlanPath::from_bytes(b));
            }
        })
        .wait()
        .unwrap();
    let joined = Instant::now();
    std::thread::sleep(Duration::from_millis(2500));
    let got = got.lock().unwrap().clone();
    println!(
        "a plain subscriber got {} path samples in {:?}",
        got.len(),
        joined.elapsed()
    );
    assert!(
        got.len() >= 2,
        "{} path samples in 2.5 s (the latest is repeated every second)\n--- bridge log ---\n{}",
        got.len(),
        b.log()
    );
    for p in &got {
        assert!(p.checked().is_ok(), "a path that fails its check");
        assert_eq!(p.goal_id, goal, "the path of another goal");
    }
}
