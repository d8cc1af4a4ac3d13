//! Real-time setup of the daemon's threads (SPEC §7.1, RT-TUNING.md): the
//! loop runs SCHED_FIFO at `rt.fifo_priority`, the writer (status, answers,
//! events, the planner's wake-up) SCHED_FIFO just below it, every other
//! thread normal scheduling. Where the kernel refuses the loop SCHED_FIFO
//! (no CAP_SYS_NICE or RLIMIT_RTPRIO), the daemon warns and every thread
//! runs normal scheduling (the writer is raised only after the loop was);
//! the daemon works either way.

use gaitd_client::Client;
use gaitd_tests::TestDaemon;
use std::time::Duration;

/// A thread of the daemon, as /proc/<pid>/task/<tid>/stat describes it
/// (proc(5): fields 40 rt_priority, 41 policy).
#[derive(Debug)]
struct Thread {
    tid: i32,
    name: String,
    policy: u32,
    priority: u32,
}

fn threads(pid: i32) -> Vec<Thread> {
    let mut out = Vec::new();
    for t in std::fs::read_dir(format!("/proc/{pid}/task")).unwrap() {
        let dir = t.unwrap().path();
        let comm = std::fs::read_to_string(dir.join("comm")).unwrap();
        let stat = std::fs::read_to_string(dir.join("stat")).unwrap();
        // The name (field 2) may hold spaces: count fields after its ')'.
        let after = &stat[stat.rfind(')').unwrap() + 1..];
        let f: Vec<&str> = after.split_whitespace().collect();
        let field = |n: usize| f[n - 3].parse::<u32>().unwrap();
        let tid = dir.file_name().unwrap().to_str().unwrap().parse().unwrap();
        out.push(Thread {
            tid,
            name: comm.trim().to_string(),
            policy: field(41),
            priority: field(40),
        });
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

    let pid = d.pid();
    let ts = threads(pid);
    let log = d.log();
    // The loop is the main thread; the writer is named.
    let find = |is: &dyn Fn(&Thread) -> bool, what: &str| {
        let t = ts.iter().find(|t| is(t));
        let t = t.unwrap_or_else(|| panic!("no {what} thread: {ts:?}"));
        (t.policy, t.priority)
    };
    let is_loop = |t: &Thread| t.tid == pid;
    let is_writer = |t: &Thread| t.name == "gaitd-writer";
    if log.contains("SCHED_FIFO not permitted") {
        // Refused: nothing runs real-time, the writer included.
        assert!(
            log.contains("loop and writer run with normal scheduling"),
            "{log}"
        );
        assert!(ts.iter().all(|t| t.policy == SCHED_OTHER), "{ts:?}");
        test_support::skip(
            "e2e_rt: loop and writer at their SCHED_FIFO priorities",
            &format!(
                "SCHED_FIFO refused ({}): checked the fallback only",
                rt_limits()
            ),
        );
    } else {
        assert_eq!(find(&is_loop, "loop"), (SCHED_FIFO, 35), "{ts:?}");
        assert_eq!(find(&is_writer, "writer"), (SCHED_FIFO, 25), "{ts:?}");
        assert!(log.contains("writer thread runs SCHED_FIFO"), "{log}");
        for t in ts.iter().filter(|t| !is_loop(t) && !is_writer(t)) {
            assert_eq!((t.policy, t.priority), (SCHED_OTHER, 0), "{t:?} of {ts:?}");
        }
    }
    assert!(
        ts.iter().any(|t| t.name == "gaitd-planner"),
        "the planner thread exists: {ts:?}"
    );
}

#[test]
fn writer_priority_zero_keeps_the_writer_normal() {
    let mut d = TestDaemon::with_rt(
        "rt0",
        "lock_memory = false\nfifo_priority = 35\nwriter_priority = 0",
        "",
    );
    d.spawn();
    d.wait_ready(Duration::from_secs(20));
    let ts = threads(d.pid());
    let writer = ts.iter().find(|t| t.name == "gaitd-writer");
    let writer = writer.expect("a writer thread");
    assert_eq!((writer.policy, writer.priority), (SCHED_OTHER, 0), "{ts:?}");
    let log = d.log();
    assert!(!log.contains("writer thread runs SCHED_FIFO"));
    if log.contains("SCHED_FIFO not permitted") {
        // Nothing was raised, so a normal writer proves nothing here.
        test_support::skip(
            "e2e_rt: writer_priority = 0 beside a SCHED_FIFO loop",
            &format!("SCHED_FIFO refused ({})", rt_limits()),
        );
    } else {
        assert_eq!(
            threads(d.pid())
                .iter()
                .find(|t| t.tid == d.pid())
                .map(|t| t.policy),
            Some(SCHED_FIFO),
            "the loop is real-time, the writer not"
        );
    }
}

/// Why the kernel may refuse SCHED_FIFO: the RLIMIT_RTPRIO of this process
/// and whether it has CAP_SYS_NICE (the daemon inherits both).
fn rt_limits() -> String {
    let mut r = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes into the struct it is given.
    let limit = if unsafe { libc::getrlimit(libc::RLIMIT_RTPRIO, &mut r) } == 0 {
        r.rlim_cur.to_string()
    } else {
        "unknown".into()
    };
    // capabilities(7): CAP_SYS_NICE is bit 23 of the effective set.
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let nice = status
        .lines()
        .find_map(|l| l.strip_prefix("CapEff:"))
        .and_then(|h| u64::from_str_radix(h.trim(), 16).ok())
        .map_or(
            "unknown",
            |caps| {
                if caps & (1 << 23) != 0 { "yes" } else { "no" }
            },
        );
    format!("RLIMIT_RTPRIO {limit}, CAP_SYS_NICE {nice}")
}
