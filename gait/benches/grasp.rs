//! Benchmarks of grasp analysis (SPEC §3): Fact 3, Fact 4, the planar
//! three-contact certificate, the conic margin
//! (cold = build + solve, re-solved = update + solve) and grasp force
//! optimisation. Run: `cargo bench -p gait --bench grasp`.

#[path = "support/timing.rs"]
mod timing;

use std::hint::black_box;
use std::time::Duration;

use criterion::Criterion;
use gait::HandConfig;
use gait::grasp::facts::{fact3_slack, fact4_slack};
use gait::grasp::planar::three_hard_certificate;
use gait::grasp::{
    ConicSolver, Contact, ContactForce, Friction, GraspForceSolver, Load, closure_margin,
};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use test_support::random::unit;

const INPUTS: usize = 1024;

struct Inputs {
    pairs: Vec<[Vector3<f64>; 2]>,
    triples: Vec<[Vector3<f64>; 3]>,
    /// Force-closure grasps near the paper's (for force optimisation).
    hands: Vec<[Vector3<f64>; 3]>,
    soft_pairs: Vec<[Vector3<f64>; 2]>,
}

fn inputs() -> Inputs {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let pairs = (0..INPUTS)
        .map(|_| [unit(&mut rng), unit(&mut rng)])
        .collect();
    let triples = (0..INPUTS)
        .map(|_| [unit(&mut rng), unit(&mut rng), unit(&mut rng)])
        .collect();
    let hands = (0..INPUTS)
        .map(|_| {
            [0.0f64, 120.0, 240.0].map(|d| {
                let a = d.to_radians() + rng.random_range(-0.3..0.3);
                Vector3::new(a.cos(), a.sin(), rng.random_range(-0.3..0.3)).normalize()
            })
        })
        .collect();
    let soft_pairs = (0..INPUTS)
        .map(|_| {
            let a = unit(&mut rng);
            let b = (-a + unit(&mut rng) * 0.3).normalize();
            [a, b]
        })
        .collect();
    Inputs {
        pairs,
        triples,
        hands,
        soft_pairs,
    }
}

fn main() {
    timing::machine();
    let cfg = HandConfig::default();
    let fr = Friction::from_config(&cfg);
    let load = Load::from_config(&cfg);
    let theta = cfg.model.friction_angle_deg.to_radians();
    let inp = inputs();
    let mut c = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .configure_from_args();

    let mut i = 0;
    c.bench_function("fact3_slack", |b| {
        b.iter(|| {
            i = (i + 1) % INPUTS;
            let [p, q] = &inp.pairs[i];
            fact3_slack(black_box(p), black_box(q), theta, 0.0)
        })
    });
    c.bench_function("fact4_slack", |b| {
        b.iter(|| {
            i = (i + 1) % INPUTS;
            let [p, q, r] = &inp.triples[i];
            fact4_slack(black_box(p), black_box(q), black_box(r), theta)
        })
    });
    c.bench_function("planar_certificate", |b| {
        b.iter(|| {
            i = (i + 1) % INPUTS;
            three_hard_certificate(black_box(&inp.triples[i]), theta)
        })
    });
    c.bench_function("conic_margin_cold_3hard", |b| {
        b.iter(|| {
            i = (i + 1) % INPUTS;
            closure_margin(&inp.triples[i].map(Contact::hard), &fr)
        })
    });
    let mut solver = ConicSolver::new(fr);
    c.bench_function("conic_margin_resolve_3hard", |b| {
        b.iter(|| {
            i = (i + 1) % INPUTS;
            solver.margin(&inp.triples[i].map(Contact::hard))
        })
    });
    let mut soft = ConicSolver::new(fr);
    c.bench_function("conic_margin_resolve_2soft", |b| {
        b.iter(|| {
            i = (i + 1) % INPUTS;
            soft.margin(&inp.pairs[i].map(Contact::soft))
        })
    });
    let mut forces = GraspForceSolver::new(fr, load);
    let mut out = [ContactForce::default(); 3];
    c.bench_function("grasp_forces_resolve_3hard", |b| {
        b.iter(|| {
            i = (i + 1) % INPUTS;
            forces.solve(&inp.hands[i].map(Contact::hard), &mut out)
        })
    });
    let mut forces2 = GraspForceSolver::new(fr, load);
    let mut out2 = [ContactForce::default(); 2];
    c.bench_function("grasp_forces_resolve_2soft", |b| {
        b.iter(|| {
            i = (i + 1) % INPUTS;
            forces2.solve(&inp.soft_pairs[i].map(Contact::soft), &mut out2)
        })
    });
    c.bench_function("grasp_forces_cold_3hard", |b| {
        b.iter(|| {
            i = (i + 1) % INPUTS;
            GraspForceSolver::new(fr, load).solve(&inp.hands[i].map(Contact::hard), &mut out)
        })
    });
    c.final_summary();

    println!();
    let n = INPUTS;
    timing::worst_case("fact3_slack", 100_000, |k| {
        let [p, q] = &inp.pairs[k % n];
        fact3_slack(p, q, theta, 0.0)
    });
    timing::worst_case("fact4_slack", 100_000, |k| {
        let [p, q, r] = &inp.triples[k % n];
        fact4_slack(p, q, r, theta)
    });
    timing::worst_case("planar_certificate", 100_000, |k| {
        three_hard_certificate(&inp.triples[k % n], theta)
    });
    timing::worst_case("conic_margin_cold_3hard", 2_000, |k| {
        closure_margin(&inp.triples[k % n].map(Contact::hard), &fr)
    });
    timing::worst_case("conic_margin_resolve_3hard", 20_000, |k| {
        solver.margin(&inp.triples[k % n].map(Contact::hard))
    });
    timing::worst_case("conic_margin_resolve_2soft", 20_000, |k| {
        soft.margin(&inp.pairs[k % n].map(Contact::soft))
    });
    timing::worst_case("grasp_forces_resolve_3hard", 5_000, |k| {
        forces.solve(&inp.hands[k % n].map(Contact::hard), &mut out)
    });
    timing::worst_case("grasp_forces_resolve_2soft", 5_000, |k| {
        forces2.solve(&inp.soft_pairs[k % n].map(Contact::soft), &mut out2)
    });
    timing::worst_case("grasp_forces_cold_3hard", 1_000, |k| {
        GraspForceSolver::new(fr, load).solve(&inp.hands[k % n].map(Contact::hard), &mut out)
    });
}
