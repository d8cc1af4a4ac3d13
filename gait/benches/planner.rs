//! Planning time and plan quality over Haar-random goals (SPEC §11).
//!
//! `cargo bench -p gait --bench planner [-- N]` prints, for goals from the
//! paper's start and from random valid two-finger states, with gravity on
//! (the default load: 0.1 kg, 0.5 N disturbance, `load.max_grip` 20 N) and
//! off (the same with g = 0): planning time p50 / p99 / max, gaits per
//! goal, execution time per goal, and the largest normal force a goal's
//! plan needs (F* over the load scenarios at every sample, median / max
//! over goals; SPEC §1.3 I1'). `GAIT_MASS=0.5` sets another object mass.
//! Planning time is wall time and, beside it, the thread's own CPU time
//! (`CLOCK_THREAD_CPUTIME_ID`), which on a shared machine excludes the
//! time other processes held the core.

#[path = "../tests/planning/mod.rs"]
mod planning;

use std::time::Instant;

use gait::planner::Planner;
use gait::{HandConfig, HandState};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn pct(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    sorted[((sorted.len() as f64 * p).ceil() as usize).clamp(1, sorted.len()) - 1]
}

/// CPU time this thread has run [ms] (CLOCK_THREAD_CPUTIME_ID).
fn thread_cpu_ms() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: a valid clock id and a valid out-pointer.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return f64::NAN;
    }
    ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 * 1e-6
}

fn config(gravity: bool) -> HandConfig {
    let mut cfg = HandConfig::default();
    if !gravity {
        cfg.load.gravity = [0.0; 3];
    }
    if let Ok(m) = std::env::var("GAIT_MASS") {
        cfg.load.object_mass = m.parse().unwrap();
    }
    if let Ok(b) = std::env::var("GAIT_MAX_GRIP") {
        cfg.load.max_grip = b.parse().unwrap();
    }
    if let Ok(b) = std::env::var("GAIT_PAIR_MARGIN") {
        cfg.planner.pair_margin_deg = b.parse().unwrap();
    }
    if let Ok(b) = std::env::var("GAIT_DETOUR_AXES") {
        cfg.planner.detour_axes = b.parse().unwrap();
    }
    if let Ok(b) = std::env::var("GAIT_WAYPOINTS") {
        cfg.planner.waypoint_axes = b.parse().unwrap();
    }
    if let Ok(b) = std::env::var("GAIT_DETOUR_ABOVE") {
        cfg.planner.detour_above_s = b.parse().unwrap();
    }
    if let Ok(b) = std::env::var("GAIT_WEIGHT") {
        cfg.planner.heuristic_weight = b.parse().unwrap();
    }
    if let Ok(b) = std::env::var("GAIT_BUDGET") {
        cfg.planner.max_expansions = b.parse().unwrap();
    }
    cfg
}

fn run(label: &str, n: usize, random_start: bool, gravity: bool) {
    let cfg = config(gravity);
    let planner = Planner::new(&cfg).unwrap();
    let grip = gait::executor::grip::GripModel::new(&cfg);
    let paper = HandState::paper_start(&cfg);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (mut times, mut cpu, mut dur, mut gaits) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut peaks = Vec::new();
    let mut fails = 0;
    let mut slow = Vec::new();
    for _ in 0..n {
        let start = if random_start {
            planning::random_two_finger_state(&mut rng, &cfg)
        } else {
            paper
        };
        let goal = planning::haar(&mut rng);
        let c0 = thread_cpu_ms();
        let t0 = Instant::now();
        let r = planner.plan(&start, &goal);
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        cpu.push(thread_cpu_ms() - c0);
        times.push(ms);
        if let Ok(p) = &r {
            slow.push((
                ms,
                p.summary.escaped,
                p.summary.expansions,
                p.summary.goal_angle.to_degrees(),
                p.summary.duration,
            ));
        }
        match r {
            Ok(p) => {
                dur.push(p.summary.duration);
                gaits.push(f64::from(p.summary.gaits));
                let f = gait::planner::load::plan_forces(
                    &grip,
                    cfg.limits.object.acceleration,
                    &p.start,
                    &p.steps,
                );
                peaks.push(f.max_peak);
            }
            Err(_) => fails += 1,
        }
    }
    if std::env::var("GAIT_LONG").is_ok() {
        let mut long = slow.clone();
        long.sort_by(|a, b| b.4.total_cmp(&a.4));
        for s in long.iter().take(20) {
            println!(
                "  long: {:.2} s escaped {} expansions {} angle {:.0} (planned in {:.2} ms)",
                s.4, s.1, s.2, s.3, s.0
            );
        }
    }
    if std::env::var("GAIT_SLOW").is_ok() {
        slow.sort_by(|a, b| b.0.total_cmp(&a.0));
        for s in slow.iter().take(40) {
            println!(
                "  slow: {:.2} ms escaped {} expansions {} angle {:.0}",
                s.0, s.1, s.2, s.3
            );
        }
    }
    for v in [&mut times, &mut cpu, &mut dur, &mut gaits, &mut peaks] {
        v.sort_by(f64::total_cmp);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let last = |v: &[f64]| v.last().copied().unwrap_or(f64::NAN);
    println!(
        "{label:<34} n={n} fails={fails} | plan ms p50 {:.3} p99 {:.3} max {:.3} (cpu {:.3} / {:.3} / {:.3}) | exec s median {:.2} mean {:.2} p95 {:.2} max {:.2} | gaits mean {:.2} p95 {} max {} | largest grip N median {:.1} max {:.1}",
        pct(&times, 0.5),
        pct(&times, 0.99),
        last(&times),
        pct(&cpu, 0.5),
        pct(&cpu, 0.99),
        last(&cpu),
        pct(&dur, 0.5),
        mean(&dur),
        pct(&dur, 0.95),
        last(&dur),
        mean(&gaits),
        pct(&gaits, 0.95),
        last(&gaits),
        pct(&peaks, 0.5),
        last(&peaks),
    );
}

fn main() {
    let n = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(2000);
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_owned())
        })
        .unwrap_or_default();
    println!(
        "planner benchmark on {cpu} ({} threads available), release build",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    let mass = config(true).load.object_mass;
    let limit = config(true).load.max_grip;
    println!("object {mass} kg, load.max_grip {limit} N");
    for gravity in [true, false] {
        let g = if gravity { "gravity on" } else { "gravity off" };
        run(&format!("from the paper start, {g}"), n, false, gravity);
        run(&format!("from random states, {g}"), n, true, gravity);
    }
}
