//! Benchmarks of the per-tick invariant check (SPEC §1.3): the closed-form
//! paths, and three-finger states that are not force-closure (no Fact 3
//! pair, no Fact 4, no planar certificate) with and without the conic
//! fallback, plus the I5 slip check.
//! Run: `cargo bench -p gait --bench hand`.

#[path = "support/timing.rs"]
mod timing;

use std::time::Duration;

use criterion::Criterion;
use gait::hand::{FcMethod, InvariantChecker};
use gait::{FingerMode, HandConfig, HandState};
use nalgebra::{Rotation3, Unit, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const INPUTS: usize = 1024;

fn perturbed(rng: &mut ChaCha8Rng, cfg: &HandConfig, spread: f64) -> HandState {
    let mut s = HandState::paper_start(cfg);
    for f in &mut s.fingers {
        let axis = Unit::new_normalize(Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ));
        let r = Rotation3::from_axis_angle(&axis, rng.random_range(0.0..spread));
        f.center = r * f.center;
        f.orientation = UnitQuaternion::from_rotation_matrix(&r) * f.orientation;
        f.roll = rng.random_range(-0.5..0.5);
    }
    s
}

/// States by the method that decides I1.
fn states(cfg: &HandConfig, want: impl Fn(FcMethod) -> bool, free: bool) -> Vec<HandState> {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut probe = InvariantChecker::new(cfg).unwrap();
    let mut out = Vec::with_capacity(INPUTS);
    for _ in 0..1_000_000 {
        if out.len() == INPUTS {
            break;
        }
        let mut s = perturbed(&mut rng, cfg, 1.0);
        if free {
            s.fingers[2].mode = FingerMode::Free;
            s.fingers[2].center *= 1.03;
        }
        if want(probe.force_closure(&s).method) {
            out.push(s);
        }
    }
    assert_eq!(out.len(), INPUTS, "too few states of the requested kind");
    out
}

fn main() {
    timing::machine();
    let cfg = HandConfig::default();
    let fact3 = states(&cfg, |m| matches!(m, FcMethod::Fact3 { .. }), false);
    let fact4 = states(&cfg, |m| m == FcMethod::Fact4, false);
    let conic = states(&cfg, |m| m == FcMethod::Conic, false);
    let two = states(&cfg, |_| true, true);
    let mut checker = InvariantChecker::new(&cfg).unwrap();
    let mut fast = InvariantChecker::new(&cfg).unwrap();
    fast.set_conic_fallback(false);
    let mut c = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .configure_from_args();
    let mut i = 0;
    for (name, set) in [
        ("check_two_fingers", &two),
        ("check_three_fingers_pair_decides", &fact3),
        ("check_three_fingers_fact4_decides", &fact4),
        ("check_three_fingers_not_fc_conic", &conic),
    ] {
        c.bench_function(name, |b| {
            b.iter(|| {
                i = (i + 1) % INPUTS;
                checker.check(&set[i])
            })
        });
    }
    c.bench_function("check_three_fingers_not_fc_no_fallback", |b| {
        b.iter(|| {
            i = (i + 1) % INPUTS;
            fast.check(&conic[i])
        })
    });
    c.bench_function("check_slip_three_fingers", |b| {
        b.iter(|| {
            i = (i + 1) % (INPUTS - 1);
            checker.check_slip(&fact4[i], &fact4[i + 1])
        })
    });
    c.final_summary();

    println!();
    for (name, set, runs) in [
        ("check_two_fingers", &two, 100_000),
        ("check_three_fingers_pair_decides", &fact3, 100_000),
        ("check_three_fingers_fact4_decides", &fact4, 100_000),
        ("check_three_fingers_not_fc_conic (solves)", &conic, 20_000),
    ] {
        timing::worst_case(name, runs, |k| checker.check(&set[k % INPUTS]));
    }
    timing::worst_case("check_three_fingers_not_fc_no_fallback", 100_000, |k| {
        fast.check(&conic[k % INPUTS])
    });
    timing::worst_case("check_slip_three_fingers", 100_000, |k| {
        let k = k % (INPUTS - 1);
        checker.check_slip(&fact4[k], &fact4[k + 1])
    });
    println!(
        "conic solves run by the checker: {}",
        checker.conic_solves()
    );
}
