//! A grasp of TriFingerPro fingers carried by the ball's turn (SPEC §14.2):
//! the joints follow the rolling law, the range ends exactly where a limit
//! of §14.1 binds, and a pair turns about the one axis that leaves both
//! contacts without spin.
//!
//! Every check here is the test's own: the no-slip condition solved for q̇
//! directly (J_v q̇ + r [n]ₓ J_ω q̇ = R ω × n, one 3×3 solve, not the
//! library's J_v⁻¹ route), integrated by the midpoint rule in small steps;
//! the limits read from the chain's numbers and the patch's definition;
//! spin recovered from forward kinematics alone (finite differences of the
//! tip's rotation, the ball's ω from both contacts' no-slip motion).

mod common;

use kinematics::carry::{
    Bound, Carrier, CarrierError, GraspLimits, MAX_SUBSTEPS, Scan, carry, carry_pair, carry_range,
    carry_range_with, no_spin_axis,
};
use kinematics::{
    Chain, ClosedFormIk, Margins, Object, Workspace, finger_gap, sphere_grid,
    workspace::object_clearance,
};
use nalgebra::{Matrix3, Rotation3, Vector3};
use rand::Rng;

use common::LIMITS;

fn setup() -> ([Chain<3>; 3], Object) {
    (common::chains(), common::hand().object)
}

/// The test's own carry: midpoint rule, `steps` steps.
fn reference_carry(
    chains: &[&Chain<3>],
    q: &mut [Vector3<f64>],
    o: &Object,
    axis: &Vector3<f64>,
    angle: f64,
    steps: usize,
) {
    let h = angle / steps as f64;
    for _ in 0..steps {
        for (c, q) in chains.iter().zip(q.iter_mut()) {
            let mid = *q + common::q_dot(c, q, o, axis) * (h / 2.0);
            *q += common::q_dot(c, &mid, o, axis) * h;
        }
    }
}

#[test]
fn the_joints_follow_the_rolling_law() {
    let (chains, o) = setup();
    let fingers = [&chains[0], &chains[1], &chains[2]];
    let start = common::top_grasp(&chains, &o);
    let axis = Vector3::new(0.3, -0.2, 1.0).normalize();
    let angle = 60f64.to_radians();
    let mut q = start;
    carry(&fingers, &mut q, &o, &axis, angle, 1f64.to_radians()).unwrap();
    let mut want = start;
    reference_carry(&fingers, &mut want, &o, &axis, angle, 20_000);
    let mut worst: f64 = 0.0;
    let mut drift: f64 = 0.0;
    for k in 0..3 {
        worst = worst.max((q[k] - want[k]).amax());
        let d = (chains[k].forward(&q[k]).tip_centre() - o.centre).norm();
        drift = drift.max((d - (o.radius + chains[k].tip_radius)).abs());
    }
    eprintln!("60° carry: joints off the reference by {worst:e} rad, tip off R + r by {drift:e} m");
    assert!(worst < 1e-7, "joints off the reference by {worst:e} rad");
    assert!(drift < 1e-9, "tip centre off R + r by {drift:e} m");
    for k in 0..3 {
        let moved = (chains[k].forward(&q[k]).tip_centre()
            - chains[k].forward(&start[k]).tip_centre())
        .norm();
        assert!(moved > 0.005, "finger {k}'s tip moved only {moved} m");
    }
}

/// The tightest of the test's own margins at `q`, and which kind binds
/// (0 joint, 1 patch, 2 clearance, 3 finger gap).
fn own_margin(
    chains: &[&Chain<3>],
    q: &[Vector3<f64>],
    o: &Object,
    lim: &GraspLimits,
) -> (f64, usize) {
    let mut worst = (f64::INFINITY, usize::MAX);
    let mut see = |m: f64, kind: usize| {
        if m < worst.0 {
            worst = (m, kind);
        }
    };
    for (c, q) in chains.iter().zip(q) {
        for i in 0..3 {
            see(q[i] - c.limits[i].lower - c.margin, 0);
            see(c.limits[i].upper - q[i] - c.margin, 0);
        }
        let s = c.forward(q);
        let n = common::normal(c, q, o);
        // The contact on the tip, u = Rᵀ(−n), against the pole.
        let u = -(s.tip.rotation.transpose() * n);
        let from_pole = u.angle(c.patch.pole.as_ref());
        see(c.patch.alpha - from_pole - lim.margins.patch, 1);
        see(object_clearance(c, &s, o) - lim.margins.clearance, 2);
    }
    for a in 0..chains.len() {
        for b in a + 1..chains.len() {
            let (sa, sb) = (chains[a].forward(&q[a]), chains[b].forward(&q[b]));
            see(
                finger_gap((chains[a], &sa), (chains[b], &sb)) - lim.finger_gap,
                3,
            );
        }
    }
    worst
}

fn kind(b: Bound) -> Option<usize> {
    match b {
        Bound::JointLimit { .. } => Some(0),
        Bound::TipPatch { .. } => Some(1),
        Bound::ObjectClearance { .. } => Some(2),
        Bound::FingerGap { .. } => Some(3),
        _ => None,
    }
}

/// The limits one at a time, so that each binds some carry (with the
/// planner's margins the links' clearance binds first nearly always).
const ONE_AT_A_TIME: [(&str, GraspLimits); 3] = [
    (
        "tip patch only",
        GraspLimits {
            margins: Margins {
                patch: LIMITS.margins.patch,
                clearance: f64::NEG_INFINITY,
            },
            finger_gap: f64::NEG_INFINITY,
        },
    ),
    (
        "finger gap only",
        GraspLimits {
            margins: Margins {
                patch: f64::NEG_INFINITY,
                clearance: f64::NEG_INFINITY,
            },
            finger_gap: LIMITS.finger_gap,
        },
    ),
    (
        "joint limits only",
        GraspLimits {
            margins: Margins {
                patch: f64::NEG_INFINITY,
                clearance: f64::NEG_INFINITY,
            },
            finger_gap: f64::NEG_INFINITY,
        },
    ),
];

#[test]
fn the_range_ends_where_a_limit_binds() {
    let (chains, o) = setup();
    let fingers = [&chains[0], &chains[1], &chains[2]];
    let iks = chains.each_ref().map(|c| ClosedFormIk::new(c).unwrap());
    let grid = sphere_grid(1500);
    let g = common::hand().gravity;
    let ws: Vec<_> = (0..3)
        .map(|k| Workspace::new(&chains[k], &iks[k], &o, &g, &grid, &LIMITS.margins))
        .collect();
    let mut rng = common::rng(11);
    let mut by_kind = [0usize; 4];
    let step = 2f64.to_radians();
    for (name, lim) in [("planner's margins", LIMITS)]
        .into_iter()
        .chain(ONE_AT_A_TIME)
    {
        let (mut cases, mut reached) = (0, 0);
        let mut ranges = Vec::new();
        let pick =
            |k: usize| -> Vec<Vector3<f64>> { ws[k].reached.iter().map(|(_, r)| r.q).collect() };
        let pool = [pick(0), pick(1), pick(2)];
        while cases < 20 {
            let q: [Vector3<f64>; 3] =
                std::array::from_fn(|k| pool[k][rng.random_range(0..pool[k].len())]);
            if own_margin(&fingers, &q, &o, &lim).0 < 0.0 {
                continue; // fingers in each other's way: not a grasp to start from
            }
            cases += 1;
            // Rolling keeps a TriFingerPro grasp 0.29 rad or more from its
            // joint limits over whole turns: for the joint-limit cases the
            // test narrows each joint to 0.2 rad either side of its start
            // (beyond the chain's margin).
            let mut narrow = chains;
            if name == "joint limits only" {
                for (c, q) in narrow.iter_mut().zip(&q) {
                    for (l, q) in c.limits.iter_mut().zip(q.iter()) {
                        (l.lower, l.upper) = (q - 0.2 - c.margin, q + 0.2 + c.margin);
                    }
                }
            }
            let fingers = [&narrow[0], &narrow[1], &narrow[2]];
            let axis = common::unit(&mut rng);
            let r = carry_range(&fingers, &q, &o, &axis, std::f64::consts::TAU, &lim, step);
            ranges.push(r.angle.to_degrees());
            // Every sample before the range keeps every margin…
            let mut at = q;
            let n = (r.angle / 0.5f64.to_radians()).ceil().max(1.0) as usize;
            for i in 0..n {
                carry(&fingers, &mut at, &o, &axis, r.angle / n as f64, step).unwrap();
                let (m, which) = own_margin(&fingers, &at, &o, &lim);
                assert!(
                    m > -1e-6,
                    "{name}, case {cases}: sample {i} of the range {:.4} rad breaks kind {which} by {m:e} ({:?})",
                    r.angle,
                    r.bound
                );
            }
            // …and just past it the limit named binds.
            match kind(r.bound) {
                Some(k) => {
                    by_kind[k] += 1;
                    carry(&fingers, &mut at, &o, &axis, 2e-3, step).unwrap();
                    let (m, which) = own_margin(&fingers, &at, &o, &lim);
                    assert!(
                        m < 0.0 && which == k,
                        "{name}, case {cases}: 2 mrad past the range ({:?}) the tightest margin is kind {which}, {m:e}",
                        r.bound
                    );
                }
                None => {
                    assert_eq!(r.bound, Bound::Reached, "{name}, case {cases}");
                    reached += 1;
                }
            }
        }
        ranges.sort_by(f64::total_cmp);
        eprintln!(
            "{name}: {cases} carries, range median {:.1}°, max {:.1}°, a full turn reached {reached}",
            ranges[ranges.len() / 2],
            ranges[ranges.len() - 1]
        );
    }
    eprintln!(
        "bound by joint limit {}, tip patch {}, clearance {}, finger gap {}",
        by_kind[0], by_kind[1], by_kind[2], by_kind[3]
    );
    assert!(
        by_kind.iter().all(|&n| n > 0),
        "every kind of limit bound some carry: {by_kind:?}"
    );
}

/// The ball's ω over a small step from two fingers' motion alone (least
/// squares of ω × (R n) = ċ − r ω_f × n), each finger's ω_f from its tip
/// rotations, and the largest spin (ω − ω_f)·n at the two contacts.
fn spin_over(chains: &[&Chain<3>; 2], q0: &[Vector3<f64>], q1: &[Vector3<f64>], o: &Object) -> f64 {
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    let mut rest = [(Vector3::zeros(), Vector3::zeros()); 2];
    for k in 0..2 {
        let (s0, s1) = (chains[k].forward(&q0[k]), chains[k].forward(&q1[k]));
        let n = (common::normal(chains[k], &q0[k], o) + common::normal(chains[k], &q1[k], o))
            .normalize();
        let wf = Rotation3::from_matrix_unchecked(s1.tip.rotation * s0.tip.rotation.transpose())
            .scaled_axis();
        let v = s1.tip_centre() - s0.tip_centre() - wf.cross(&n) * chains[k].tip_radius;
        let x = (n * o.radius).cross_matrix();
        a += x.transpose() * x;
        b -= x.transpose() * v;
        rest[k] = (n, wf);
    }
    // Two contacts leave ω along their common normal plane determined: the
    // normal equations are regular for contacts not antipodal.
    let w = a.lu().solve(&b).expect("two contacts fix ω");
    rest.iter()
        .map(|(n, wf)| ((w - wf).dot(n) / w.norm()).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_pair_turns_without_spin() {
    let (chains, o) = setup();
    let start = common::top_grasp(&chains, &o);
    let mut worst: f64 = 0.0;
    let mut fixed: f64 = 0.0;
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let pair = [&chains[a], &chains[b]];
        let q0 = [start[a], start[b]];
        let hint = Vector3::z();
        let axis = no_spin_axis(pair, &q0, &o, &hint).unwrap();
        // In small steps: each step's spin per radian turned.
        let mut q = q0;
        let mut along = axis;
        for _ in 0..20 {
            let before = q;
            along = carry_pair(
                pair,
                &mut q,
                &o,
                &along,
                0.5f64.to_radians(),
                0.1f64.to_radians(),
            )
            .unwrap();
            worst = worst.max(spin_over(&pair, &before, &q, &o));
        }
        // The same pair turned about a fixed other axis spins: the check
        // can see spin.
        let mut q = q0;
        let other = (axis + Vector3::x() * 0.5).normalize();
        carry(
            &pair,
            &mut q,
            &o,
            &other,
            0.5f64.to_radians(),
            0.1f64.to_radians(),
        )
        .unwrap();
        fixed = fixed.max(spin_over(&pair, &q0, &q, &o));
    }
    eprintln!(
        "pair turns: spin per radian {worst:e} along the no-spin axis, {fixed:e} about a fixed other axis"
    );
    assert!(
        worst < 1e-5,
        "a pair spins {worst:e} rad per rad along its no-spin axis"
    );
    assert!(
        fixed > 1e-2,
        "about another axis the check sees no spin ({fixed:e}): it cannot fail"
    );
}

/// A loop's view: the carry advanced to each tick's angle of a smooth
/// rest-to-rest turn (40° in 1 s at 1 kHz) ends where one carry does, its
/// joint rates match the joints' own differences, it goes back exactly,
/// and a jump it would need too many sub-steps for is refused untouched.
#[test]
fn a_carry_advanced_tick_by_tick_is_the_carry() {
    let (chains, o) = setup();
    let fingers = [&chains[0], &chains[1], &chains[2]];
    let start = common::top_grasp(&chains, &o);
    let axis = Vector3::new(0.2, 0.5, 1.0).normalize();
    let step = 1f64.to_radians();
    let total = 40f64.to_radians();
    let ticks = 1000;
    let mut c = Carrier::new(&fingers, &start, &o, &axis, step);
    let theta = |t: f64| total * 0.5 * (1.0 - (std::f64::consts::PI * t).cos());
    let mut worst_rate: f64 = 0.0;
    for i in 1..=ticks {
        let t = i as f64 / ticks as f64;
        let before: Vec<Vector3<f64>> = c.joints().to_vec();
        let mid_rate = (theta(t) - theta(t - 1.0 / ticks as f64)) * ticks as f64;
        let q = c.advance_to(theta(t)).unwrap().to_vec();
        // Central difference against the rates at the tick's midpoint,
        // estimated as the mean of both ends' rates.
        let mut probe = c;
        let end = probe.rates(mid_rate).unwrap();
        probe.advance_to(theta(t - 1.0 / ticks as f64)).unwrap();
        let begin = probe.rates(mid_rate).unwrap();
        for k in 0..3 {
            let diff = (q[k] - before[k]) * ticks as f64;
            let mean = (end[k] + begin[k]) * 0.5;
            worst_rate = worst_rate.max((diff - mean).amax());
        }
    }
    let mut want = start;
    carry(&fingers, &mut want, &o, &axis, total, step).unwrap();
    let off = (0..3)
        .map(|k| (c.joints()[k] - want[k]).amax())
        .fold(0.0, f64::max);
    eprintln!(
        "40° in 1000 ticks: joints off one carry by {off:e} rad, rates off the joints' differences by {worst_rate:e} rad/s"
    );
    assert!(off < 1e-9, "tick by tick ends {off:e} rad from one carry");
    assert!(worst_rate < 1e-6, "rates off by {worst_rate:e} rad/s");
    // Back to the start.
    c.advance_to(0.0).unwrap();
    let back = (0..3)
        .map(|k| (c.joints()[k] - start[k]).amax())
        .fold(0.0, f64::max);
    assert!(back < 1e-9, "back to 0 ends {back:e} rad from the start");
    // A jump beyond the bounded work is refused, nothing moved.
    let held = c;
    let far = step * (MAX_SUBSTEPS as f64 + 0.5);
    assert_eq!(c.advance_to(far).unwrap_err(), CarrierError::TooFar);
    assert_eq!(c.joints(), held.joints());
    assert_eq!(c.angle(), held.angle());
}

/// A coarser bisection of the same scan stops at one of the angles the
/// finer one passes through: never beyond it (a range is always an angle
/// found good), within `step / 2^bisections` of it, and — with fewer
/// halvings — short of it in general. Single fingers from the workspace
/// about random axes, as the chain planner's placement tables scan them.
#[test]
fn a_coarser_scan_stops_short_of_the_fine_one_within_its_resolution() {
    let (chains, o) = setup();
    let iks = chains.each_ref().map(|c| ClosedFormIk::new(c).unwrap());
    let grid = sphere_grid(600);
    let g = common::hand().gravity;
    let mut rng = common::rng(17);
    let step = 8f64.to_radians();
    let (mut cases, mut shorter) = (0, 0);
    for k in 0..3 {
        let ws = Workspace::new(&chains[k], &iks[k], &o, &g, &grid, &LIMITS.margins);
        for (_, r) in ws.reached.iter().take(40) {
            let axis = common::unit(&mut rng);
            let args = (
                &[&chains[k]][..],
                &[r.q][..],
                &o,
                &axis,
                std::f64::consts::FRAC_PI_2,
            );
            let fine = carry_range(args.0, args.1, args.2, args.3, args.4, &LIMITS, step);
            let coarse = carry_range_with(
                args.0,
                args.1,
                args.2,
                args.3,
                args.4,
                &LIMITS,
                Scan {
                    step,
                    bisections: 6,
                },
            );
            cases += 1;
            assert!(
                coarse.angle <= fine.angle && fine.angle - coarse.angle <= step / 64.0 + 1e-12,
                "finger {k}: coarse {:.5} rad against fine {:.5} rad",
                coarse.angle,
                fine.angle
            );
            shorter += usize::from(coarse.angle < fine.angle);
        }
    }
    println!("{cases} ranges: the coarse scan stopped short in {shorter}");
    assert!(shorter > cases / 4, "the halvings asked for change nothing");
}
