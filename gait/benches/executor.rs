//! Executor tick time (SPEC §11: p99 ≤ 20 µs, max ≤ 100 µs) and plan
//! execution statistics over random goals on the kinematic hand.
//!
//! `cargo bench -p gait --bench executor [-- GOALS]` runs GOALS Haar-random
//! goals one after the other from the paper's start, timing every
//! `Executor::tick` (feedback, trajectory, setpoint, invariant check,
//! report) with the kinematic plant; planning runs outside the timed
//! region, as on the daemon's planner thread.

#[path = "../tests/planning/mod.rs"]
mod planning;

use std::time::Instant;

use gait::executor::{Executor, ExecutorCommand, GoalTarget, Mode};
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

fn main() {
    grip_three_contacts();
    let goals: u64 = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(200);
    let cfg = HandConfig::default();
    let start = HandState::paper_start(&cfg);
    let planner = Planner::new(&cfg).unwrap();
    let mut exec = Executor::new(&cfg, 1e-3, start).unwrap();
    let mut plant = KinematicHand::new(start, 1e-3);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut tick_us = Vec::with_capacity(goals as usize * 8000);
    let mut exec_s = Vec::new();
    let mut gaits = Vec::new();
    for id in 1..=goals {
        exec.command(ExecutorCommand::Goal {
            id,
            target: GoalTarget::Orientation(planning::haar(&mut rng)),
            limits: None,
        });
        let mut ticks = 0u64;
        loop {
            let m = plant.read();
            let t0 = Instant::now();
            let rep = *exec.tick(m.as_ref());
            tick_us.push(t0.elapsed().as_secs_f64() * 1e6);
            plant.write(&rep.setpoint);
            while exec.pop_event().is_some() {}
            if let Some(req) = exec.take_plan_request() {
                let plan = req.plan(&planner).map(Box::new);
                drop(exec.deliver_plan(req.goal, plan));
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
    println!(
        "execution per goal ({goals} goals from the paper start, then chained): mean {:.2} s p95 {:.2} s max {:.2} s; gaits mean {:.2} max {}",
        mean(&exec_s),
        pct(&exec_s, 0.95),
        exec_s[exec_s.len() - 1],
        mean(&gaits),
        gaits[gaits.len() - 1]
    );
}
