mod planning;
use gait::planner::Planner;
use gait::HandConfig;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

#[test]
#[ignore]
fn debug_failures() {
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    for i in 0..2000 {
        let start = planning::random_two_finger_state(&mut rng, &cfg);
        let goal = planning::haar(&mut rng);
        if planner.plan(&start, &goal).is_ok() { continue; }
        let (pair, free) = gait::planner::search::split(&start).unwrap();
        let t1 = planner.theory1(&start, pair, free);
        let (axis, total) = gait::planner::rotation_to(&start.object, &goal);
        let g = planner.geometry();
        let ranges: Vec<String> = pair.iter().map(|&k| {
            let f = &start.fingers[k];
            format!("f{k}: cone {:.1} roll {:.1} tau {:.1} ang_to_base {:.1}",
              gait::planner::geometry::cone_exit(g, k, &axis, &f.contact_normal()).to_degrees(),
              gait::planner::geometry::roll_exit(g, &axis, &f.pole_axis(), f.roll).to_degrees(),
              f.roll.to_degrees(),
              gait::planner::geometry::angle_between(&f.contact_normal(), &g.base[k]).to_degrees())
        }).collect();
        let sep = gait::planner::geometry::angle_between(&start.fingers[pair[0]].contact_normal(), &start.fingers[pair[1]].contact_normal()).to_degrees();
        println!("goal {i}: theory1 {t1} total {:.1} axis {:.2?} pair {pair:?} sep {sep:.1} {ranges:?}", total.to_degrees(), axis.as_slice());
    }
}

#[test]
#[ignore]
fn debug_budget() {
    for budget in [3000u32, 20000, 100000] {
        let mut cfg = HandConfig::default();
        cfg.planner.max_expansions = budget;
        let planner = Planner::new(&cfg).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let mut fails = 0;
        for _ in 0..2000 {
            let start = planning::random_two_finger_state(&mut rng, &cfg);
            let goal = planning::haar(&mut rng);
            if planner.plan(&start, &goal).is_err() { fails += 1; }
        }
        println!("budget {budget}: fails {fails}");
    }
}

#[test]
#[ignore]
fn debug_one() {
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let want: usize = std::env::var("GOAL").unwrap().parse().unwrap();
    for i in 0..=want {
        let start = planning::random_two_finger_state(&mut rng, &cfg);
        let goal = planning::haar(&mut rng);
        if i != want { continue; }
        unsafe { std::env::set_var("GAIT_DEBUG", "1") };
        let r = planner.plan(&start, &goal);
        println!("{:?}", r.map(|p| p.summary));
    }
}
