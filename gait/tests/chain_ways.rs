//! A chain finger's way out of a grasp and over to its next contact
//! (SPEC §14.3): a lift whose links sweep into another finger is refused
//! before the search builds on it, as the test's own finer sampling of the
//! lift finds; and a placement whose way at the hover height passes too
//! near another finger rises higher first, its way then passing the exact
//! check. TriFingerPro holding the tennis ball, random grasps of the
//! planner's own candidate contacts.

mod chain_hand;
#[path = "../../kinematics/tests/common/mod.rs"]
mod common;

use gait::planner::chains::certify::{CheckParams, check, check_way};
use gait::planner::chains::model::ChainModel;
use gait::planner::chains::steps::ChainBuilder;
use gait::planner::hand_model::HandModel;
use gait::planner::plan::Reorientation;
use gait::planner::{FreeMove, FreePath, Motion, StepKind};
use gait::{FingerMode, HandState};
use kinematics::workspace::object_clearance;
use nalgebra::Vector3;
use rand::Rng;

use chain_hand::{config, model};

/// Random three-finger grasps of the candidate contacts that are
/// force-closure with every pair apart, each then carried as far as the
/// fingers follow about a random axis.
fn grasps(m: &ChainModel, n: usize, seed: u64) -> Vec<HandState> {
    carried_grasps(m, n, seed, 0.999)
}

/// [`grasps`], each carried `share` of the way its fingers follow.
fn carried_grasps(m: &ChainModel, n: usize, seed: u64, share: f64) -> Vec<HandState> {
    let mut rng = common::rng(seed);
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let pick: [usize; 3] = std::array::from_fn(|k| rng.random_range(0..m.candidates(k).len()));
        let c: [Vector3<f64>; 3] = std::array::from_fn(|k| m.candidates(k)[pick[k]]);
        let apart = (0..3).all(|a| (a + 1..3).all(|b| m.apart((a, &c[a]), (b, &c[b]))));
        if !apart || !m.fc_triple(&c) {
            continue;
        }
        let mut s = HandState::paper_start(&config());
        for (k, f) in s.fingers.iter_mut().enumerate() {
            f.mode = FingerMode::Grasping;
            f.center = c[k] * radius(m, k);
        }
        // Carried about a random axis as far as it goes: where a carry
        // stops, two fingers often stand at the least gap.
        let axis = common::unit(&mut rng);
        let range = m.carry_range(&s, &[0, 1, 2], &axis, std::f64::consts::PI);
        m.carry(&mut s, &axis, share * range);
        out.push(s);
    }
    out
}

fn radius(m: &ChainModel, k: usize) -> f64 {
    m.hand().object().radius + m.hand().chain(k).tip_radius
}

/// The least margin, over 200 points of finger `k`'s lift out along its
/// normal to the hover height, of its joint limits \[rad\], its links'
/// clearance to the ball and its gap to the other two \[m\], each beyond
/// the hand's own (negative: broken), by the test's own sampling: the
/// inverse kinematics point by point on the branch the finger is on,
/// forward kinematics, capsule distances.
fn lift_margin(m: &ChainModel, s: &HandState, k: usize) -> f64 {
    lift_margins(m, s, k)
        .into_iter()
        .fold(f64::INFINITY, f64::min)
}

/// [`lift_margin`]'s margin at each of its 201 points (−∞ from where the
/// finger's branch does not reach).
fn lift_margins(m: &ChainModel, s: &HandState, k: usize) -> Vec<f64> {
    let h = m.hand();
    let lim = h.limits();
    let others: Vec<(usize, _)> = (0..3)
        .filter(|&j| j != k)
        .map(|j| {
            let q = h
                .joints(j, &s.fingers[j].center, None)
                .expect("a grasping finger");
            (j, h.chain(j).forward(&q))
        })
        .collect();
    let n = s.fingers[k].center.normalize();
    let (from, to) = (
        radius(m, k),
        radius(m, k) + config().planner.transfer_height,
    );
    let mut q = h.joints(k, &s.fingers[k].center, None).expect("reached");
    let mut out = vec![f64::NEG_INFINITY; 201];
    for (i, at) in out.iter_mut().enumerate() {
        let rho = from + (to - from) * i as f64 / 200.0;
        let Some(next) = h.nearest_branch(k, &(n * rho), &q) else {
            break;
        };
        q = next;
        let sk = h.chain(k).forward(&q);
        let mut least = h.chain(k).limit_margin(&q);
        let clearance = object_clearance(h.chain(k), &sk, h.object());
        least = least.min(clearance - lim.margins.clearance);
        for (j, sj) in &others {
            let gap = if k < *j {
                h.gap(k, *j).gap((h.chain(k), &sk), (h.chain(*j), sj))
            } else {
                h.gap(*j, k).gap((h.chain(*j), sj), (h.chain(k), &sk))
            };
            least = least.min(gap - lim.finger_gap);
        }
        *at = least;
    }
    out
}

/// Two grasps the planner met (tip centres in the ball's frame \[m\]) in
/// which the lift of one finger sweeps its links within the least gap of
/// another's, though every pair stands apart at rest.
const SWEPT: [(usize, [[f64; 3]; 3]); 2] = [
    (
        0,
        [
            [
                0.03493189843752063,
                -0.002146824995768515,
                0.025834155962168717,
            ],
            [
                0.0424127589889423,
                0.009297257565306805,
                -0.002639863011308169,
            ],
            [
                -0.04051965478424302,
                -0.014567109614161237,
                -0.006181172516688996,
            ],
        ],
    ),
    (
        2,
        [
            [
                -0.006605930023410957,
                0.015537608606813885,
                0.04008982922521616,
            ],
            [
                -0.00694154194275072,
                -0.039013713547704484,
                -0.017944223322334793,
            ],
            [
                -0.017756446653767688,
                0.03355486994931156,
                0.02123745053247951,
            ],
        ],
    ),
];

/// A lift that sweeps a finger into another (the test's own sampling
/// finds a gap below the least) is refused; among random grasps, every
/// lift that keeps clear of every limit by half a millimetre is allowed,
/// and none that breaks one by as much is.
#[test]
fn a_lift_that_sweeps_into_another_finger_is_refused() {
    let m = model();
    for (k, tips) in SWEPT {
        let mut s = HandState::paper_start(&config());
        for (f, c) in s.fingers.iter_mut().zip(tips) {
            f.mode = FingerMode::Grasping;
            f.center = Vector3::from(c);
        }
        let at_rest = (0..3).all(|a| {
            (a + 1..3).all(|b| {
                let (ca, cb) = (s.fingers[a].contact_normal(), s.fingers[b].contact_normal());
                m.apart((a, &ca), (b, &cb))
            })
        });
        assert!(
            at_rest,
            "finger {k}: the grasp's fingers are not apart at rest"
        );
        let margin = lift_margin(&m, &s, k);
        assert!(
            margin < 0.0,
            "finger {k}: the lift keeps {margin:.2e} clear"
        );
        assert!(
            !m.can_lift(&s, k),
            "finger {k}: lifted {margin:.2e} past a limit"
        );
    }
    let (mut refused, mut allowed) = (0, 0);
    for s in grasps(&m, 150, 11) {
        for k in 0..3 {
            let margin = lift_margin(&m, &s, k);
            let can = m.can_lift(&s, k);
            if margin < -5e-4 {
                assert!(!can, "finger {k} lifts {margin:.2e} past a limit: {s:?}");
            }
            if margin > 5e-4 {
                assert!(can, "finger {k} lifts clear by {margin:.2e}: {s:?}");
            }
            refused += usize::from(!can);
            allowed += usize::from(can);
        }
    }
    println!("random grasps: {refused} lifts refused, {allowed} allowed");
    assert!(allowed > 0);
}

/// Where a carry stops with two fingers exactly the least gap apart, a
/// lift can bring them closer before it takes them apart, between two of
/// the check's samples. The check finds every lift the test's 201-point
/// walk finds below a limit, though it samples the 15 mm lift only every
/// 5 mm (it refines where the margins at two samples do not prove the way
/// between them clear); and it refuses none the walk finds clear by
/// 0.1 mm.
#[test]
fn a_lift_that_first_closes_a_gap_is_refused_between_samples() {
    let m = model();
    let coarse = CheckParams {
        free_step: 0.005,
        ..*m.check_params()
    };
    let (mut inside, mut refused, mut allowed) = (0, 0, 0);
    for s in carried_grasps(&m, 1500, 21, 1.0) {
        // (A carry's end may be a rounding past a limit where it stops.)
        if check(m.hand(), &s, &[], m.check_params()).is_err() {
            continue;
        }
        for k in 0..3 {
            let walk = lift_margins(&m, &s, k);
            let least = walk.iter().copied().fold(f64::INFINITY, f64::min);
            let mut b = builder(&m, &s);
            let mut joints = b.joints();
            b.lift(k).expect("a lift is a step");
            let lift = b.steps.last().expect("the lift");
            let verdict = check_way(m.hand(), std::slice::from_ref(lift), &mut joints, &coarse);
            if least < -1e-7 {
                assert!(
                    verdict.is_err(),
                    "finger {k} lifts {least:.2e} past a limit: {s:?}"
                );
                refused += 1;
                // Broken only inside, clear at every one of the coarse
                // samples (0, 5, 10, 15 mm: points 0, 200/3, …, 200).
                let at_samples = [0, 67, 133, 200].iter().all(|&i| walk[i] >= 0.0);
                inside += usize::from(at_samples);
            }
            if least > 1e-4 {
                assert_eq!(
                    verdict,
                    Ok(()),
                    "finger {k} lifts clear by {least:.2e}: {s:?}"
                );
                allowed += 1;
            }
        }
    }
    println!("{refused} lifts refused ({inside} broken only between samples), {allowed} allowed");
    assert!(
        inside > 0 && allowed > 0,
        "{inside} broken between samples, {allowed} allowed"
    );
}

/// The planner's builder from `s`, no handovers.
fn builder<'a>(m: &'a ChainModel, s: &HandState) -> ChainBuilder<'a> {
    let c = m.config();
    ChainBuilder::new(
        m.hand(),
        c.limits,
        0.0,
        c.planner.transfer_height,
        *m.check_params(),
        *s,
    )
}

/// Finger `k` of `s` lifted, then placed at `contact` by the builder.
fn placed<'a>(
    m: &'a ChainModel,
    s: &HandState,
    k: usize,
    contact: &Vector3<f64>,
) -> Option<ChainBuilder<'a>> {
    let mut b = builder(m, s);
    b.lift(k).ok()?;
    b.place(k, contact).ok()?;
    Some(b)
}

/// A placement whose way at the hover height (an arc over the ball,
/// then down) comes too near another finger rises first; the way the
/// builder keeps passes the exact check, and is longer only where it
/// rose.
#[test]
fn a_placement_blocked_at_the_hover_height_rises_first() {
    let m = model();
    let mut rng = common::rng(12);
    let (mut rose, mut level) = (0, 0);
    for s in grasps(&m, 150, 13) {
        let k = rng.random_range(0..3);
        if !m.can_lift(&s, k) {
            continue;
        }
        let to = m.candidates(k)[rng.random_range(0..m.candidates(k).len())];
        let (g, h) = ((k + 1) % 3, (k + 2) % 3);
        let (cg, ch) = (s.fingers[g].contact_normal(), s.fingers[h].contact_normal());
        if !(m.apart((k, &to), (g, &cg)) && m.apart((k, &to), (h, &ch))) {
            continue;
        }
        let Some(b) = placed(&m, &s, k, &to) else {
            continue;
        };
        // The lift, then the way: a rise (radial, outwards) before the arc
        // where the builder rose.
        let way = &b.steps[1..];
        let rise = matches!(
            way[0].motion,
            Motion::Free(FreeMove { path: FreePath::Radial { from, to, .. }, .. }) if to > from
        );
        let mut joints = lifted_joints(&m, &s, k);
        let kept = check_way(m.hand(), way, &mut joints, m.check_params());
        // The same placement at the hover height, made here.
        let hover = hover_way(&m, &way[0].start, k, &to);
        let mut joints = lifted_joints(&m, &s, k);
        let at_hover = check_way(m.hand(), &hover, &mut joints, m.check_params());
        if rise {
            rose += 1;
            assert!(
                at_hover.is_err(),
                "rose though the way at the hover height is clear"
            );
            assert_eq!(kept, Ok(()), "the higher way is not clear either");
        } else {
            level += 1;
            assert_eq!(kept.is_ok(), at_hover.is_ok(), "{kept:?} / {at_hover:?}");
        }
    }
    println!("{rose} placements rose, {level} did not");
    assert!(rose > 0 && level > 0, "{rose} rose, {level} level");
}

/// Every finger's joints once finger `k` of `s` is lifted.
fn lifted_joints(m: &ChainModel, s: &HandState, k: usize) -> [Option<Vector3<f64>>; 3] {
    let mut b = builder(m, s);
    b.lift(k).expect("lifted");
    b.joints()
}

/// The way at the hover height from `at` (finger `k` lifted): an arc to
/// above `to`, then down onto it.
fn hover_way(
    m: &ChainModel,
    at: &HandState,
    k: usize,
    to: &Vector3<f64>,
) -> Vec<gait::planner::Step> {
    let c = at.fingers[k].center;
    let rho = c.norm();
    let arc = FreePath::arc(&(c / rho), to, rho);
    let down = FreePath::Radial {
        dir: *to,
        from: rho,
        to: radius(m, k),
    };
    let mut out = Vec::new();
    let mut state = *at;
    for (kind, path) in [(StepKind::Transfer, arc), (StepKind::Place, down)] {
        let mut step = gait::planner::Step {
            kind,
            start: state,
            motion: Motion::Free(FreeMove {
                finger: k,
                path,
                turn: Reorientation::NONE,
                contact_at_end: kind == StepKind::Place,
            }),
            duration: 0.0,
            handover: None,
        };
        step.duration = step.planned_duration(&m.config().limits);
        state = step.eval(&step.dofs().length, &[0.0; 3]).state;
        out.push(step);
    }
    out
}

/// The gap test's verdicts are remembered (the search asks the same
/// candidates again and again): asked twice, in both orders, a model
/// answers as another model asked once does, for pairs of the planner's
/// candidates.
#[test]
fn remembered_gap_verdicts_are_the_fresh_ones() {
    let (m, other) = (model(), model());
    let mut rng = common::rng(41);
    let mut seen = [0usize; 2];
    for _ in 0..400 {
        let a = rng.random_range(0..3);
        let b = (a + rng.random_range(1..3)) % 3;
        let na = m.candidates(a)[rng.random_range(0..m.candidates(a).len())];
        let nb = m.candidates(b)[rng.random_range(0..m.candidates(b).len())];
        let first = m.apart((a, &na), (b, &nb));
        // Asked once of the other model (a pair drawn twice is rare).
        let fresh = other.apart((a, &na), (b, &nb));
        assert_eq!(first, fresh);
        assert_eq!(m.apart((a, &na), (b, &nb)), fresh, "remembered");
        assert_eq!(m.apart((b, &nb), (a, &na)), fresh, "the other way round");
        seen[fresh as usize] += 1;
    }
    assert!(seen[0] >= 20 && seen[1] >= 20, "{seen:?}");
}
