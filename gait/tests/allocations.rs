//! Heap allocations on the paths a control tick may take, measured with a
//! counting global allocator: Clarabel re-solves (SPEC §3.2; the numbers
//! are stated in the `gait::grasp` docs, and this test fails if they grow)
//! and the invariant check (must be zero on its closed-form path).

mod common;

use gait::grasp::{ConicSolver, Contact, ContactForce, Friction, GraspForceSolver, Load};
use gait::hand::{FcMethod, InvariantChecker};
use gait::{FingerMode, HandConfig, HandState};
use nalgebra::{UnitQuaternion, Vector3};
use rand::Rng;

use test_support::counting;

#[global_allocator]
static GLOBAL: counting::Counting = counting::Counting;

fn count<T>(f: impl FnOnce() -> T) -> (T, usize, usize) {
    let (r, c) = counting::count(f);
    (r, c.allocs, c.bytes)
}

/// Otherwise every count below is zero and proves nothing.
#[test]
fn the_counter_is_installed() {
    assert!(counting::is_installed());
}

#[test]
fn conic_resolve_allocations() {
    let cfg = HandConfig::default();
    let mut rng = common::rng(7);
    let mut solver = ConicSolver::new(Friction::from_config(&cfg));
    solver
        .prepare(&[gait::grasp::ContactKind::Hard; 3])
        .unwrap();
    let mut per_call = Vec::with_capacity(1000);
    for _ in 0..1000 {
        let c = [
            common::unit(&mut rng),
            common::unit(&mut rng),
            common::unit(&mut rng),
        ]
        .map(Contact::hard);
        let (r, n, b) = count(|| solver.margin(&c));
        r.unwrap();
        per_call.push((n, b));
    }
    let max = per_call.iter().map(|p| p.0).max().unwrap();
    let min = per_call.iter().map(|p| p.0).min().unwrap();
    let bytes = per_call.iter().map(|p| p.1).max().unwrap();
    println!("conic re-solve: allocations per call min {min} max {max}, bytes max {bytes}");
    assert!(
        max <= 1 && bytes <= 512,
        "conic re-solve allocates more than documented"
    );
}

#[test]
fn force_resolve_allocations() {
    let cfg = HandConfig::default();
    let mut rng = common::rng(8);
    let mut solver = GraspForceSolver::new(Friction::from_config(&cfg), Load::from_config(&cfg));
    let mut out = [ContactForce::default(); 3];
    solver
        .prepare(&[gait::grasp::ContactKind::Hard; 3])
        .unwrap();
    let mut per_call = Vec::with_capacity(200);
    let mut solved = 0;
    for _ in 0..200 {
        let base = [0.0f64, 120.0, 240.0].map(|d| {
            let a = d.to_radians() + rng.random_range(-0.3..0.3);
            Vector3::new(a.cos(), a.sin(), rng.random_range(-0.3..0.3)).normalize()
        });
        let c = base.map(Contact::hard);
        let (r, n, b) = count(|| solver.solve(&c, &mut out));
        per_call.push((n, b));
        solved += usize::from(r.is_ok());
    }
    let max = per_call.iter().map(|p| p.0).max().unwrap();
    let min = per_call.iter().map(|p| p.0).min().unwrap();
    let bytes = per_call.iter().map(|p| p.1).max().unwrap();
    println!(
        "force re-solve ({solved} solved): allocations per call min {min} max {max}, bytes max {bytes}"
    );
    assert!(
        max <= 1 && bytes <= 512,
        "force re-solve allocates more than documented"
    );
}

/// Random three- and two-finger states with contacts in their cones.
fn random_state(rng: &mut rand_chacha::ChaCha8Rng, cfg: &HandConfig) -> HandState {
    let mut s = HandState::paper_start(cfg);
    let rc = cfg.model.object_radius + cfg.model.fingertip_radius;
    for f in &mut s.fingers {
        let off = rng.random_range(0.0..1.2);
        let n = common::at_angle(rng, &f.contact_normal(), off);
        f.center = n * rc;
        f.orientation = UnitQuaternion::from_scaled_axis(common::unit(rng) * 3.0);
        f.roll = rng.random_range(-1.0..1.0);
    }
    if rng.random_bool(0.3) {
        let k = rng.random_range(0..3);
        s.fingers[k].mode = FingerMode::Free;
        s.fingers[k].center *= 1.03;
    }
    s
}

#[test]
fn invariant_check_allocations() {
    let cfg = HandConfig::default();
    let mut rng = common::rng(9);
    let mut checker = InvariantChecker::new(&cfg).unwrap();
    let states: Vec<HandState> = (0..20_000).map(|_| random_state(&mut rng, &cfg)).collect();
    let (mut closed, mut closed_allocs, mut conic, mut conic_allocs) =
        (0usize, 0usize, 0usize, 0usize);
    let mut prev = states[0];
    for s in &states {
        let before = checker.conic_solves();
        let (r, n, _) = count(|| checker.check(s).unwrap());
        let (slip, n_slip, _) = count(|| checker.check_slip(&prev, s).unwrap());
        let _ = slip.ok();
        assert_eq!(n_slip, 0, "check_slip allocated");
        prev = *s;
        if checker.conic_solves() > before {
            assert_eq!(r.force_closure.method, FcMethod::Conic);
            conic += 1;
            conic_allocs += n;
        } else {
            closed += 1;
            closed_allocs += n;
        }
    }
    println!(
        "invariant check: {closed} closed-form checks, {closed_allocs} allocations; \
         {conic} with a conic solve, {conic_allocs} allocations"
    );
    assert_eq!(
        closed_allocs, 0,
        "the closed-form invariant check allocated"
    );
    assert!(
        conic > 0 && conic_allocs <= conic,
        "conic path allocates more than documented"
    );

    // Without the conic fallback nothing allocates, whatever the state.
    checker.set_conic_fallback(false);
    let (_, n, _) = count(|| {
        for s in &states {
            let _ = checker.check(s).unwrap();
        }
    });
    println!(
        "invariant check without conic fallback: {} checks, {n} allocations",
        states.len()
    );
    assert_eq!(n, 0);
}
