//! Real-time setup of the daemon's threads (SPEC §7.1, RT-TUNING.md): the
//! loop runs SCHED_FIFO at `rt.fifo_priority`, the writer (status, answers,
//! events, the planner's wake-up) SCHED_FIFO just below it, every other
//! thread normal scheduling. Where the kernel refuses SCHED_FIFO (no
//! CAP_SYS_NICE or RLIMIT_RTPRIO), each of the two warns and every thread
//! runs normal scheduling; the daemon works either way.

use gaitd_client::Client;
use gaitd_tests::TestDaemon;
use std::time::Duration;

/// One thread's name, scheduling policy and real-time priority, from
/// /proc/<pid>/task/<tid>/stat (proc(5): fields 40 rt_priority, 41 policy).
fn threads(pid: i32) -> Vec<(String, u32, u32)> {
    let mut out = Vec::new();
    for t in std::fs::read_dir(format!("/proc/{pid}/task")).unwrap() {
        let dir = t.unwrap().path();
        let comm = std::fs::read_to_string(dir.join("comm")).unwrap();
        let stat = std::fs::read_to_string(dir.join("stat")).unwrap();
        // The name (field 2) may hold spaces: count fields after its ')'.
        let after = &stat[stat.rfind(')').unwrap() + 1..];
        let f: Vec<&str> = after.split_whitespace().collect();
        let field = |n: usize| f[n - 3].parse::<u32>().unwrap();
        out.push((comm.trim().to_string(), field(41), field(40)));
    }
    out
}

const SCHED_OTHER: u32 = 0;
const SCHED_FIFO: u32 = 1;

#[test]
fn loop_and_writer_run_sched_fifo_the_rest_normal() {
    // The writer's priority is left unset: the loop's minus 10.
    let mut d = TestDaemon::with_rt("rt", "lock_memory = false\nfifo_priority = 35", "");
    d.spawn();
    d.wait_ready(Duration::from_secs(20));
    // The daemon works: a status arrives through the writer.
    let mut c = Client::connect(d.options()).expect("connects");
    c.wait_status(Duration::from_secs(5)).expect("a status");

    let ts = threads(d.pid());
    let log = d.log();
    let policy = |name: &str| {
        let t = ts.iter().find(|t| t.0 == name);
        let t = t.unwrap_or_else(|| panic!("no thread {name}: {ts:?}"));
        (t.1, t.2)
    };
    if log.contains("SCHED_FIFO not permitted") {
        // Refused: both threads say so, and nothing runs real-time.
        assert!(
            log.contains("SCHED_FIFO not permitted for the writer thread"),
            "{log}"
        );
        assert!(ts.iter().all(|t| t.1 == SCHED_OTHER), "{ts:?}");
        eprintln!("SCHED_FIFO not permitted here: checked the fallback only");
    } else {
        assert_eq!(policy("gaitd"), (SCHED_FIFO, 35), "the loop: {ts:?}");
        assert_eq!(policy("gaitd-writer"), (SCHED_FIFO, 25), "{ts:?}");
        assert!(log.contains("writer thread runs SCHED_FIFO"), "{log}");
        for t in ts
            .iter()
            .filter(|t| t.0 != "gaitd" && t.0 != "gaitd-writer")
        {
            assert_eq!((t.1, t.2), (SCHED_OTHER, 0), "{t:?} of {ts:?}");
        }
    }
    assert!(
        ts.iter().any(|t| t.0.starts_with("gaitd-plan")),
        "the planner thread exists: {ts:?}"
    );
}
