//! What the free fingertips offer as resting partners (the placements of
//! a free finger that make, with a grasping contact, a pair holding the
//! load at rest): every candidate the hand says it decided where the
//! contact really is makes a good pair there and holds the load there, by
//! the hand's own exact tests asked again here — the search takes those
//! without asking twice. Contacts are random, within 2° of the grasping
//! finger's own candidates (where the search's contacts are), so most fall
//! between the hand's table cells.

mod planning;

use gait::HandConfig;
use gait::planner::fingertips::Fingertips;
use gait::planner::hand_model::HandModel;
use planning::in_cap;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn partners_decided_at_the_contact_make_a_good_pair_that_holds_there() {
    let cfg = HandConfig::default();
    let hand = Fingertips::new(&cfg).for_pass(true, false);
    assert!(hand.load_active(), "the default configuration has a load");
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let (mut decided, mut rounded, mut rounded_held) = (0, 0, 0);
    for _ in 0..300 {
        let x = rng.random_range(0..3);
        let z = (x + rng.random_range(1..3)) % 3;
        let own = hand.candidates(x);
        let near = own[rng.random_range(0..own.len())];
        let cx = in_cap(&mut rng, &near, 2f64.to_radians());
        let cand = hand.candidates(z);
        hand.resting_partners(x, &cx, z, &mut |i, exact| {
            let c = &cand[i];
            let holds = hand.good_pair(c, &cx) && hand.pair_holds((x, &cx), (z, c), None);
            if exact {
                decided += 1;
                assert!(
                    holds,
                    "candidate {i} of finger {z} was offered as decided at {cx:?} \
                     (finger {x}) but does not make a good pair holding the load there"
                );
            } else {
                rounded += 1;
                rounded_held += usize::from(holds);
            }
            true
        });
    }
    println!(
        "{decided} partners decided at the contact; {rounded} from the table's sure cells, \
         {rounded_held} of them holding at the contact too"
    );
    assert!(
        decided > 0,
        "no partner was decided at the contact: nothing tested"
    );
}
