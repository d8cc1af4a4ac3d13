//! Planning time and plan quality over Haar-random goals (SPEC §11).
//!
//! `cargo bench -p gait --bench planner [-- N]` (N goals per start,
//! default 2000) prints, for each start — the paper's start; random valid
//! two-finger states; chained states (each goal from where the one before
//! ended); post-cancel states (where the executor leaves the hand when a
//! goal is canceled a random while after it was sent) — with gravity on
//! (the default load: 0.1 kg, 0.5 N disturbance, `load.max_grip` 20 N)
//! and off:
//!
//! - planning time: wall time and, beside it, the thread's own CPU time
//!   (`CLOCK_THREAD_CPUTIME_ID`, which on a shared machine leaves out the
//!   time other processes held the core), p50 / p99 / max;
//! - failures, by reason (the planner's budget is `planner.max_expansions`:
//!   no wall clock here, so the run is reproducible);
//! - time to goal median / p95 / max and, against a lower bound — the
//!   goal's angle turned at the object's limits in one move, no gaits —
//!   the median and p99 of their ratio;
//! - gaits mean / p95 / max;
//! - every 10th plan checked sample by sample by the test's own SOCP
//!   (`tests/planning/load.rs`, not the planner's model): samples not
//!   held, and the largest F* of the checked plans.
//!
//! `GAIT_STARTS=paper,random` runs only those starts; `GAIT_GRAVITY=on`
//! only one load; `GAIT_DUMP=1` also prints a line per goal (CPU time,
//! the search's effort, execution time, gaits, route or refusal), to find
//! what the slowest goals have in common.

#[path = "../tests/planning/mod.rs"]
mod planning;

use std::collections::BTreeMap;
use std::time::Instant;

use gait::executor::{ExecutorCommand, GoalTarget, Mode};
use gait::planner::{PlanError, Planner, timing::DurationModel};
use gait::{HandConfig, HandState};
use planning::load::LoadCheck;
use planning::run::Rig;
use rand::{Rng, SeedableRng};
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
    cfg
}

/// Where the goals start from.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum From {
    Paper,
    Random,
    Chained,
    Canceled,
}

impl From {
    fn name(self) -> &'static str {
        match self {
            From::Paper => "paper start",
            From::Random => "random states",
            From::Chained => "chained states",
            From::Canceled => "post-cancel states",
        }
    }
}

/// Where a goal canceled a random while (0.3–4 s) after it was sent
/// leaves the hand: the executor brakes, finishes a gait in flight, and
/// rests (the kinematic hand follows exactly).
fn after_a_cancel(cfg: &HandConfig, at: HandState, rng: &mut ChaCha8Rng) -> HandState {
    let mut rig = Rig::new(*cfg, at, 1e-3);
    rig.command(ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Orientation(planning::haar(rng)),
        limits: None,
    });
    for _ in 0..rng.random_range(300..4000) {
        rig.tick();
    }
    if rig.exec.phase() == Mode::Moving {
        rig.command(ExecutorCommand::Cancel);
    }
    rig.run_until_idle(400_000);
    *rig.plant.state()
}

#[derive(Default)]
struct Figures {
    wall: Vec<f64>,
    cpu: Vec<f64>,
    duration: Vec<f64>,
    ratio: Vec<f64>,
    gaits: Vec<f64>,
    refused: BTreeMap<String, usize>,
    checked: usize,
    not_held: usize,
    peak: f64,
}

fn run(from: From, n: usize, gravity: bool) {
    let cfg = config(gravity);
    let planner = Planner::new(&cfg).unwrap();
    let timing = DurationModel::new(&cfg);
    let check = LoadCheck::new(&cfg);
    let paper = HandState::paper_start(&cfg);
    // As the daemon does at start-up, off the loop: what every plan from
    // its start state begins with (start-up time, not planning time).
    let c0 = thread_cpu_ms();
    planner.prepare(&paper);
    eprintln!(
        "{:?}, gravity {gravity}: planner prepared for the paper start in {:.0} ms CPU",
        from,
        thread_cpu_ms() - c0
    );
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut f = Figures::default();
    let mut at = paper;
    let dump = std::env::var_os("GAIT_DUMP").is_some();
    for i in 0..n {
        let start = match from {
            From::Paper => paper,
            From::Random => planning::random_two_finger_state(&mut rng, &cfg),
            From::Chained => at,
            From::Canceled => {
                at = after_a_cancel(&cfg, at, &mut rng);
                at
            }
        };
        let goal = planning::haar(&mut rng);
        let c0 = thread_cpu_ms();
        let t0 = Instant::now();
        let r = planner.plan(&start, &goal);
        f.wall.push(t0.elapsed().as_secs_f64() * 1e3);
        f.cpu.push(thread_cpu_ms() - c0);
        if dump {
            let cpu = f.cpu.last().copied().unwrap_or(f64::NAN);
            match &r {
                Ok(p) => println!(
                    "goal {i}: {cpu:.1} ms, {:?}, {:.2} s, {} gaits, {}",
                    p.summary.effort, p.summary.duration, p.summary.gaits, p.route
                ),
                Err(e) => println!("goal {i}: {cpu:.1} ms, refused {e:?}"),
            }
        }
        match r {
            Ok(p) => {
                let bound = timing.rotate(p.summary.goal_angle);
                f.duration.push(p.summary.duration);
                if bound > 0.0 {
                    f.ratio.push(p.summary.duration / bound);
                }
                f.gaits.push(f64::from(p.summary.gaits));
                if gravity && i % 10 == 0 {
                    let (peak, bad) = planning::plan_load::plan_load(&check, &p);
                    f.checked += 1;
                    f.not_held += usize::from(bad.is_some());
                    f.peak = f.peak.max(peak);
                }
                if from == From::Chained {
                    at = p.end_state();
                }
            }
            Err(e) => {
                let name = match e {
                    PlanError::LoadInfeasible { .. } => "LoadInfeasible".to_owned(),
                    e => format!("{e:?}"),
                };
                *f.refused.entry(name).or_default() += 1;
            }
        }
    }
    for v in [
        &mut f.wall,
        &mut f.cpu,
        &mut f.duration,
        &mut f.ratio,
        &mut f.gaits,
    ] {
        v.sort_by(f64::total_cmp);
    }
    let last = |v: &[f64]| v.last().copied().unwrap_or(f64::NAN);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let g = if gravity { "on " } else { "off" };
    let fails: usize = f.refused.values().sum();
    println!(
        "| {:<18} | {g} | {n} | {fails} {:?} | {:.1} / {:.1} / {:.0} | {:.1} / {:.1} / {:.0} | {:.2} / {:.2} / {:.2} s | {:.2} / {:.2} | {:.2} / {} / {} | {} |",
        from.name(),
        f.refused,
        pct(&f.wall, 0.5),
        pct(&f.wall, 0.99),
        last(&f.wall),
        pct(&f.cpu, 0.5),
        pct(&f.cpu, 0.99),
        last(&f.cpu),
        pct(&f.duration, 0.5),
        pct(&f.duration, 0.95),
        last(&f.duration),
        pct(&f.ratio, 0.5),
        pct(&f.ratio, 0.99),
        mean(&f.gaits),
        pct(&f.gaits, 0.95),
        last(&f.gaits),
        if gravity {
            format!(
                "{} checked, {} not held, F* ≤ {:.2} N",
                f.checked, f.not_held, f.peak
            )
        } else {
            "—".to_owned()
        },
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
    let cfg = HandConfig::default();
    println!(
        "planner benchmark on {cpu} ({} threads available), release build; object {} kg, load.max_grip {} N, planner.max_expansions {}",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        cfg.load.object_mass,
        cfg.load.max_grip,
        cfg.planner.max_expansions,
    );
    println!(
        "| from | gravity | goals | refused | plan wall ms p50 / p99 / max | plan CPU ms p50 / p99 / max | time to goal median / p95 / max | time ÷ bound median / p99 | gaits mean / p95 / max | load, every 10th plan |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let starts =
        std::env::var("GAIT_STARTS").unwrap_or_else(|_| "paper,random,chained,canceled".into());
    let loads = match std::env::var("GAIT_GRAVITY").as_deref() {
        Ok("on") => vec![true],
        Ok("off") => vec![false],
        _ => vec![true, false],
    };
    for gravity in loads {
        for from in [From::Paper, From::Random, From::Chained, From::Canceled] {
            let key = match from {
                From::Paper => "paper",
                From::Random => "random",
                From::Chained => "chained",
                From::Canceled => "canceled",
            };
            if starts.split(',').any(|s| s == key) {
                run(from, n, gravity);
            }
        }
    }
}
