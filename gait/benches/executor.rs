//! Executor tick time (SPEC §11: p99 ≤ 20 µs, max ≤ 100 µs) and plan
//! execution statistics over random goals on the kinematic hand.
//!
//! `cargo bench -p gait --bench executor [-- GOALS]` runs GOALS Haar-random
//! goals one after the other from the paper's start, timing every
//! `Executor::tick` (feedback, trajectory, setpoint, invariant check,
//! report) with the kinematic plant; planning runs outside the timed
//! region, as on the daemon's planner thread, and the plan is delivered
//! inside it, at the start of the next tick, as the daemon's loop does.
//!
//! The ticks are also split by what they do (the plan's adoption, a step
//! ending and the next beginning, a step's middle by kind, a handover, at
//! rest), with each kind's share of the ticks above the overall p99: where
//! the tail comes from. (Back to back, the adoption tick follows the
//! planning on the same thread and finds the caches cold.)
//!
//! `-- GOALS --paced` ticks every millisecond, as the daemon does (each
//! tick finds its caches cooled by the sleep), and half a period after each
//! tick times a fixed amount of work of about a paced tick's median: that
//! reference sees the same machine at the same moments, so its spread is
//! the platform's and whatever spread the ticks have beyond it is theirs.

#[path = "../tests/planning/mod.rs"]
mod planning;

use std::time::Instant;

use gait::executor::{Executor, ExecutorCommand, ExecutorEvent, GoalTarget, Mode, TickReport};
use gait::planner::Planner;
use gait::sim::{KinematicHand, Plant};
use gait::{HandConfig, HandState};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn pct(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() as f64 * p).ceil() as usize).clamp(1, sorted.len()) - 1]
}

/// Worst-case grip computation: three contacts (the paper's start, held).
fn grip_three_contacts() {
    let cfg = HandConfig::default();
    let model = gait::grasp::grip::GripModel::new(&cfg);
    let s = HandState::paper_start(&cfg);
    let mut t = Vec::with_capacity(20_000);
    for _ in 0..20_000 {
        let t0 = Instant::now();
        std::hint::black_box(model.grip(std::hint::black_box(&s), &nalgebra::Vector3::zeros()));
        t.push(t0.elapsed().as_secs_f64() * 1e6);
    }
    t.sort_by(f64::total_cmp);
    println!(
        "grip forces, three contacts (paper start): p50 {:.2} µs p99 {:.2} µs max {:.2} µs",
        pct(&t, 0.5),
        pct(&t, 0.99),
        t[t.len() - 1]
    );
}

/// One unit of the reference work: arithmetic plus a walk over `buf`'s
/// cache lines (as `gaitctl bench`'s reference loop).
fn unit(buf: &mut [u64], x: f64) -> f64 {
    let mut y = x;
    for i in 0..64 {
        y = y.mul_add(1.000_000_1, 1e-9 * f64::from(i));
    }
    for line in buf.chunks_mut(8) {
        line[0] = line[0].wrapping_add(y.to_bits());
    }
    y
}

/// Units of [`unit`] that take about `us` µs back to back (warm).
fn units_for(buf: &mut [u64], us: f64) -> u32 {
    let t0 = Instant::now();
    let mut x = 1.0;
    for _ in 0..1000 {
        x = unit(std::hint::black_box(buf), std::hint::black_box(x));
    }
    std::hint::black_box(x);
    let per_unit = t0.elapsed().as_secs_f64() * 1e6 / 1000.0;
    ((us / per_unit.max(1e-6)).round() as u32).max(1)
}

/// What a tick did, for the split (module docs).
fn tick_class(rep: &TickReport, began: bool, ended: bool, planning: bool) -> &'static str {
    let still = rep.setpoint.object_rate == nalgebra::Vector3::zeros()
        && rep
            .setpoint
            .finger_velocity
            .iter()
            .all(|v| *v == nalgebra::Vector3::zeros());
    match (began, ended) {
        (true, true) => "step end + next step start",
        (true, false) => "first step start (plan adopted)",
        (false, true) => "last step end",
        _ if planning => "planning (waiting)",
        _ => match (rep.phase, rep.step_kind) {
            (Mode::Moving, Some(k)) if still => match k {
                gait::planner::StepKind::Place | gait::planner::StepKind::Lift => {
                    "handover (still)"
                }
                _ => "moving, still",
            },
            (Mode::Moving, Some(k)) => match k {
                gait::planner::StepKind::Roll => "mid-step Roll",
                gait::planner::StepKind::Rotate => "mid-step Rotate",
                gait::planner::StepKind::Transfer => "mid-step Transfer",
                gait::planner::StepKind::Place => "mid-step Place",
                gait::planner::StepKind::Lift => "mid-step Lift",
            },
            (Mode::Holding, _) => "holding",
            _ => "other",
        },
    }
}

/// Per kind of tick: n, p50, p99, max, and its share of the ticks above the
/// overall p99.
fn print_split(ticks: &[(&'static str, f64)], p99: f64) {
    let mut kinds: Vec<&'static str> = ticks.iter().map(|t| t.0).collect();
    kinds.sort_unstable();
    kinds.dedup();
    let tail = ticks.iter().filter(|t| t.1 > p99).count().max(1);
    println!(
        "{:<34} {:>8} {:>9} {:>9} {:>9} {:>14}",
        "tick kind", "n", "p50 µs", "p99 µs", "max µs", "> p99 (share)"
    );
    for k in kinds {
        let mut v: Vec<f64> = ticks.iter().filter(|t| t.0 == k).map(|t| t.1).collect();
        v.sort_by(f64::total_cmp);
        let above = v.iter().filter(|&&t| t > p99).count();
        println!(
            "{k:<34} {:>8} {:>9.2} {:>9.2} {:>9.2} {:>6} ({:>4.1}%)",
            v.len(),
            pct(&v, 0.5),
            pct(&v, 0.99),
            v[v.len() - 1],
            above,
            100.0 * above as f64 / tail as f64
        );
    }
}

fn main() {
    grip_three_contacts();
    let goals: u64 = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(200);
    let paced = std::env::args().any(|a| a == "--paced");
    let cfg = HandConfig::default();
    let start = HandState::paper_start(&cfg);
    let planner = Planner::new(&cfg).unwrap();
    let mut exec = Executor::new(&cfg, 1e-3, start).unwrap();
    let mut plant = KinematicHand::new(start, 1e-3);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut tick_us = Vec::with_capacity(goals as usize * 8000);
    let mut exec_s = Vec::new();
    let mut gaits = Vec::new();
    let mut classed = Vec::with_capacity(goals as usize * 8000);
    let mut next = Instant::now();
    // The paced reference (module docs): 32 KiB walked, as `gaitctl
    // bench`'s reference loop, for about a paced tick's median (5 µs on
    // the development VM).
    let mut buf = vec![0u64; 512 * 8];
    let units = units_for(&mut buf, 5.0);
    let mut reference_us = Vec::new();
    let mut x = 1.0;
    for id in 1..=goals {
        exec.command(ExecutorCommand::Goal {
            id,
            target: GoalTarget::Orientation(planning::haar(&mut rng)),
            limits: None,
        });
        let mut ticks = 0u64;
        let mut planned = None;
        loop {
            if paced {
                next += std::time::Duration::from_millis(1);
                std::thread::sleep(next.saturating_duration_since(Instant::now()));
            }
            let m = plant.read();
            let planning = exec.phase() == Mode::Planning;
            let t0 = Instant::now();
            // Delivered in the timed region, as the daemon's loop does.
            let old = planned
                .take()
                .and_then(|(goal, plan)| exec.deliver_plan(goal, plan));
            let rep = *exec.tick(m.as_ref());
            let us = t0.elapsed().as_secs_f64() * 1e6;
            drop(old);
            tick_us.push(us);
            plant.write(&rep.setpoint);
            let (mut began, mut ended) = (false, false);
            while let Some(e) = exec.pop_event() {
                began |= matches!(e, ExecutorEvent::Step { .. });
                ended |= matches!(e, ExecutorEvent::StepDone { .. });
            }
            classed.push((tick_class(&rep, began, ended, planning), us));
            if paced {
                std::thread::sleep(
                    (next + std::time::Duration::from_micros(500))
                        .saturating_duration_since(Instant::now()),
                );
                let t0 = Instant::now();
                for _ in 0..units {
                    x = unit(std::hint::black_box(&mut buf), std::hint::black_box(x));
                }
                reference_us.push(t0.elapsed().as_secs_f64() * 1e6);
            }
            if let Some(req) = exec.take_plan_request() {
                planned = Some((req.goal, req.plan(&planner).map(Box::new)));
            }
            ticks += 1;
            if rep.phase == Mode::Holding && ticks > 2 {
                gaits.push(f64::from(rep.gaits.0));
                break;
            }
        }
        exec_s.push(ticks as f64 * 1e-3);
    }
    for v in [&mut tick_us, &mut exec_s, &mut gaits] {
        v.sort_by(f64::total_cmp);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    println!(
        "executor tick: n={} p50 {:.2} µs p99 {:.2} µs p99.9 {:.2} µs max {:.2} µs",
        tick_us.len(),
        pct(&tick_us, 0.5),
        pct(&tick_us, 0.99),
        pct(&tick_us, 0.999),
        tick_us[tick_us.len() - 1]
    );
    print_split(&classed, pct(&tick_us, 0.99));
    std::hint::black_box(x);
    if !reference_us.is_empty() {
        reference_us.sort_by(f64::total_cmp);
        println!(
            "paced reference (fixed work, same periods): n={} p50 {:.2} µs p99 {:.2} µs p99.9 {:.2} µs max {:.2} µs",
            reference_us.len(),
            pct(&reference_us, 0.5),
            pct(&reference_us, 0.99),
            pct(&reference_us, 0.999),
            reference_us[reference_us.len() - 1]
        );
    }
    println!(
        "execution per goal ({goals} goals from the paper start, then chained): mean {:.2} s p95 {:.2} s max {:.2} s; gaits mean {:.2} max {}",
        mean(&exec_s),
        pct(&exec_s, 0.95),
        exec_s[exec_s.len() - 1],
        mean(&gaits),
        gaits[gaits.len() - 1]
    );
}
