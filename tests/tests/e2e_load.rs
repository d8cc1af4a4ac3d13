//! Load (SPEC §12): many status readers and goal writers at once. Eight
//! readers (each its own client, blocking on the daemon's notifications as
//! applications do) and four writers (each its own client: goals, cancels,
//! holds and malformed commands back to back) on one daemon process.
//!
//! Functional outcomes only, no wall-clock assertions (shared, noisy
//! machines): every command is answered, readers see strictly increasing
//! ticks of one daemon instance with clean statuses, the daemon stays
//! alive, and its final status counts every command. Whether the load
//! causes missed periods is measured by `gaitctl bench --load-seconds`.

use gaitd_client::{Client, Command, GoalFrame, GoalSpec, Verdict};
use gaitd_tests::TestDaemon;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

const READERS: usize = 8;
const WRITERS: usize = 4;
/// Commands per writer.
const COMMANDS: u64 = 120;
const T: Duration = Duration::from_secs(30);

/// What a reader saw.
#[derive(Debug, Default)]
struct Seen {
    statuses: u64,
    first_tick: u64,
    last_tick: u64,
    instances: u64,
}

fn reader(c: &mut Client, stop: &AtomicBool) -> Seen {
    let mut seen = Seen::default();
    let mut instance = 0;
    while !stop.load(Ordering::Acquire) {
        let s = c.wait_status(T).expect("a status within the timeout");
        if s.instance != instance {
            instance = s.instance;
            seen.instances += 1;
        }
        assert!(
            s.tick > seen.last_tick,
            "tick went from {} to {}",
            seen.last_tick,
            s.tick
        );
        let n: f64 = s
            .commanded_object_q
            .iter()
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt();
        assert!((n - 1.0).abs() < 1e-9, "object quaternion norm {n}");
        assert_eq!(s.fault, 0, "no fault under load");
        if seen.statuses == 0 {
            seen.first_tick = s.tick;
        }
        seen.last_tick = s.tick;
        seen.statuses += 1;
    }
    seen
}

/// Sends `COMMANDS` commands, each waited for; returns (accepted, rejected).
fn writer(c: &mut Client, k: u64) -> (u64, u64) {
    let (mut accepted, mut rejected) = (0, 0);
    let mut count = |v: Verdict| match v {
        Verdict::Accepted => accepted += 1,
        Verdict::Rejected(_) => rejected += 1,
    };
    for i in 0..COMMANDS {
        let angle = 0.05 + 0.01 * ((i + k) % 5) as f64;
        match (i + k) % 5 {
            0 | 1 => {
                let g = GoalSpec::axis_angle([0.0, 0.0, 1.0], angle, GoalFrame::Relative).unwrap();
                count(c.reorient(&g, T).expect("goal answered").verdict);
            }
            2 => count(c.cancel(None, T).expect("cancel answered")),
            3 => count(c.hold(T).expect("hold answered")),
            _ => {
                let me = c.client_id();
                let bad = Command::goal(me, 1, GoalFrame::Absolute, [f64::NAN, 0.0, 0.0, 0.0]);
                let req = c.send_command(bad).expect("sent");
                let a = c.wait_answer(req, T).expect("garbage answered");
                let v = a.verdict().expect("answer decodes");
                assert!(matches!(v, Verdict::Rejected(_)), "{v:?}");
                count(v);
            }
        }
    }
    (accepted, rejected)
}

#[test]
fn eight_readers_and_four_writers_at_once() {
    let d = TestDaemon::start("load");
    let mut main = d.client();
    let before = main.wait_status(T).unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let readers: Vec<_> = (0..READERS)
        .map(|_| {
            let (opts, stop) = (d.options(), stop.clone());
            std::thread::spawn(move || {
                let mut c = Client::connect(opts).expect("reader connects");
                reader(&mut c, &stop)
            })
        })
        .collect();
    let writers: Vec<_> = (0..WRITERS as u64)
        .map(|k| {
            let opts = d.options();
            std::thread::spawn(move || {
                let mut c = Client::connect(opts).expect("writer connects");
                writer(&mut c, k)
            })
        })
        .collect();
    let (mut accepted, mut rejected) = (0, 0);
    for w in writers {
        let (a, r) = w.join().expect("writer ok");
        accepted += a;
        rejected += r;
    }
    stop.store(true, Ordering::Release);
    let seen: Vec<Seen> = readers
        .into_iter()
        .map(|r| r.join().expect("reader ok"))
        .collect();
    let total = WRITERS as u64 * COMMANDS;
    assert_eq!(accepted + rejected, total, "every command answered");
    assert!(
        accepted > 0 && rejected >= total / 5,
        "{accepted}/{rejected}"
    );
    for (i, s) in seen.iter().enumerate() {
        assert_eq!(s.instances, 1, "reader {i}: one daemon instance");
        assert!(
            s.statuses > 10 && s.last_tick > s.first_tick,
            "reader {i}: {s:?}"
        );
    }
    assert!(d.log().contains("gaitd: ready") && !d.log().contains("panicked"));
    let mut d = d;
    assert!(d.running(), "daemon alive:\n{}", d.log());
    // The final status counts every command (the writers' and none lost).
    let after = main.wait_status(T).unwrap();
    assert_eq!(after.instance, before.instance);
    assert!(after.commands - before.commands >= total, "{after:?}");
    assert!(after.rejected - before.rejected >= WRITERS as u64 * COMMANDS / 5);
    assert!(after.rejected <= after.commands);
    assert_eq!(after.fault, 0);
    println!(
        "{total} commands ({accepted} accepted, {rejected} rejected); statuses per reader: {:?}; \
         missed periods during the run: {}",
        seen.iter().map(|s| s.statuses).collect::<Vec<_>>(),
        after.timing.overruns - before.timing.overruns
    );
}
