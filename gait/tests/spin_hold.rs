//! The grip of a fingertip spinning in a three-finger grasp under load
//! (`gait::grasp::HoldModel::spinning`, SPEC §1.3 I1'), against the test's
//! own SOCP (`planning::load`: the spinner frictionless, the other two soft,
//! 26 disturbance directions, no friction margin):
//! - whenever the model says the grasp holds, the exact F* is no larger
//!   than the model's (it is an upper bound);
//! - the commanded normal forces (scenario 0, within 0.01 N), with the
//!   spinner pushing along its normal only, hold the weight.
//!
//! Random triples of contacts in the three workspace cones, clear of one
//! another, a random spinner.

mod planning;

use gait::HandConfig;
use gait::grasp::{Accel, HoldModel};
use gait::planner::candidates::Candidates;
use gait::planner::geometry::Geometry;
use nalgebra::Vector3;
use planning::load::{Kind, LoadCheck};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn the_spinning_grip_bounds_the_exact_load_and_holds_the_weight() {
    let cfg = HandConfig::default();
    let g = Geometry::new(&cfg);
    let cand = Candidates::new(&g, 6.0);
    let check = LoadCheck::new(&cfg);
    let hold = HoldModel::new(&cfg);
    let loads = hold.loads(Accel::None);
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    let (mut tried, mut model_ok, mut exact_ok, mut worst) = (0, 0, 0, f64::INFINITY);
    while tried < 600 {
        let n: [Vector3<f64>; 3] =
            std::array::from_fn(|k| cand.points[k][rng.random_range(0..cand.points[k].len())]);
        if (0..3).any(|a| (a + 1..3).any(|b| n[a].dot(&n[b]) > g.cos_sep_contact)) {
            continue;
        }
        tried += 1;
        let spinner = rng.random_range(0..3usize);
        let m = hold.spinning(&n, spinner, &loads);
        let (exact_holds, exact) = check.holds_with(&n, Kind::Soft, None, 1 << spinner);
        exact_ok += usize::from(exact_holds);
        if !m.feasible {
            continue;
        }
        model_ok += 1;
        assert!(
            exact <= m.max_peak * (1.0 + 1e-6) + 1e-6,
            "{n:?} spinner {spinner}: exact F* {exact} above the model's {}",
            m.max_peak
        );
        worst = worst.min(m.max_peak / exact);
        assert!(
            check.commanded_holds_weight_with(
                &n,
                &m.normal,
                Kind::Soft,
                &Vector3::zeros(),
                0.01,
                1 << spinner
            ),
            "{n:?} spinner {spinner}: the commanded normals {:?} do not hold the weight",
            m.normal
        );
        assert!(m.normal.iter().all(|&f| f <= cfg.load.max_grip));
    }
    println!(
        "{tried} triples: the model holds {model_ok}, the exact SOCP {exact_ok}; model F* / exact F* at least {worst:.3}"
    );
    assert!(model_ok > 0, "no triple held while spinning");
}
