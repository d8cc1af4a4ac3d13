//! The load margin reaches the client (SPEC §1.3 I1', issue "Holding
//! against gravity"): the daemon's real loop (`Runtime`, the gait
//! controller, iceoryx2 ports, the writer thread) on the mock clock; every
//! status the client receives carries `load_grip` (F*, the largest normal
//! force the commanded grasp needs) and `load_margin` = `load.max_grip` −
//! `load_grip`.
//!
//! Checked against the test's own exact problem, not the controller's
//! closed form: an SOCP (Clarabel, `gait::grasp::forces::LoadSolver`, the
//! reference solver that never runs on the loop) over the grasping
//! fingers' commanded contacts as soft contacts, the weight m·g plus a
//! disturbance force of `load.disturbance_force` along 14 directions of
//! the test's choosing (±axes, the 8 cube diagonals) and a disturbance
//! torque of `load.disturbance_torque` about ±axes. Those loads lie inside
//! every load the controller promises to hold, and the fingers that carry
//! it are among the grasping ones, so at rest (no I·α) its F* can be no
//! less than the SOCP's optimum over all grasping fingers. (No upper
//! bound: while a finger's share ramps in or out the carrying pair may
//! need far more than all three fingers would; the ratio is printed.)

#[path = "support/ipc_rig.rs"]
mod ipc_rig;

use gait::grasp::contact::{Contact, Friction};
use gait::grasp::forces::LoadSolver;
use ipc_rig::{Namespace, gait_loop};
use nalgebra::Vector3;
use shm_schema::{Command, FingerPhase, GoalFrame, Status};

/// The test's load scenarios (force \[N\], torque \[N·m\]) for `hand`.
fn scenarios(hand: &gait::HandConfig) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let l = &hand.load;
    let weight = Vector3::from(l.gravity) * l.object_mass;
    let mut dirs: Vec<Vector3<f64>> = Vec::new();
    for k in 0..3 {
        for s in [-1.0, 1.0] {
            let mut v = Vector3::zeros();
            v[k] = s;
            dirs.push(v);
        }
    }
    for i in 0..8 {
        let b = |bit: i32| if i & bit == 0 { -1.0 } else { 1.0 };
        dirs.push(Vector3::new(b(1), b(2), b(4)).normalize());
    }
    let mut out: Vec<_> = dirs
        .iter()
        .map(|d| (weight + d * l.disturbance_force, Vector3::zeros()))
        .collect();
    out.extend(dirs[..6].iter().map(|d| (weight, d * l.disturbance_torque)));
    out
}

/// The SOCP optimum for the status's grasping fingers.
fn reference(s: &Status, hand: &gait::HandConfig, solver: &LoadSolver) -> Option<f64> {
    let contacts: Vec<Contact> = s
        .fingers
        .iter()
        .filter(|f| f.phase() == Ok(FingerPhase::Grasping))
        .map(|f| Contact::soft(Vector3::from(f.contact_hand).normalize()))
        .collect();
    if contacts.len() < 2 {
        return None;
    }
    solver
        .solve(&contacts, &scenarios(hand), hand.load.min_grip)
        .ok()
        .map(|x| x.peak_normal)
}

/// Checks one status; the ratio of its F* to the optimum when the SOCP
/// applies (two or more grasping fingers).
fn check(s: &Status, hand: &gait::HandConfig, solver: &LoadSolver, still: bool) -> Option<f64> {
    let margin = hand.load.max_grip - s.load_grip;
    assert!(
        (s.load_margin - margin).abs() <= 1e-9 * (1.0 + margin.abs()),
        "tick {}: load margin {} N, max_grip − load_grip = {margin} N",
        s.tick,
        s.load_margin
    );
    let opt = reference(s, hand, solver)?;
    // The lower bound only without acceleration: the controller holds the
    // commanded I·α too, which may help (the test's loads have α = 0).
    assert!(
        !still || s.load_grip >= opt * (1.0 - 1e-6),
        "tick {}: reported F* {} N below the SOCP optimum {opt} N",
        s.tick,
        s.load_grip
    );
    Some(s.load_grip / opt)
}

#[test]
fn every_status_reports_the_load_the_grasp_must_hold() {
    let ns = Namespace::new("ld");
    let hand = ns.cfg.hand();
    let m = &hand.model;
    let mu = m.friction_angle_deg.to_radians().tan();
    let solver = LoadSolver::new(Friction {
        mu,
        mu_torsion: m.torsion_ratio * m.fingertip_radius * mu,
        object_radius: m.object_radius,
    });
    assert!(
        hand.load.object_mass > 0.0 && Vector3::from(hand.load.gravity).norm() > 0.0,
        "the default config has gravity on"
    );
    let mut g = gait_loop(&ns, 46, |_| {});
    let (mut checked, mut worst_ratio, mut least_margin) = (0u32, 0.0f64, f64::INFINITY);
    let mut prev_omega = [0.0; 3];
    let mut still_checked = 0u32;
    let mut tally = |s: &Status| {
        least_margin = least_margin.min(s.load_margin);
        // Still: commanded ω zero now and at the status before (no α).
        let still = s.commanded_object_omega == [0.0; 3] && prev_omega == [0.0; 3];
        prev_omega = s.commanded_object_omega;
        if let Some(r) = check(s, &hand, &solver, still) {
            still_checked += u32::from(still);
            worst_ratio = worst_ratio.max(r);
            checked += 1;
        }
    };
    // At rest in the start grasp.
    for _ in 0..20 {
        for s in g.tick().0 {
            tally(&s);
        }
    }
    // Along a goal, every 25th status.
    g.client.send(Command::goal(
        5,
        1,
        GoalFrame::Relative,
        [0.9238795325112867, 0.0, 0.3826834323650898, 0.0],
    ));
    let mut n = 0u64;
    // 8000 ticks of motion; mock time runs on while the planner thread
    // works in wall time (as the daemon's ticks do).
    let mut ticks = 0;
    while ticks < 8000 {
        for s in g.tick().0 {
            n += 1;
            tally(&s);
        }
        if !g.yield_to_planner() {
            ticks += 1;
        }
    }
    assert!(checked > 20, "only {checked} of {n} statuses checked");
    assert!(
        still_checked > 20,
        "only {still_checked} still statuses checked"
    );
    eprintln!(
        "{n} statuses along the goal; checked {checked} ({still_checked} still): reported F* / SOCP optimum ≤ {worst_ratio:.3}, least load margin {least_margin:.2} N"
    );
    g.finish();
}
