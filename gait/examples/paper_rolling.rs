//! The paper's rolling scenario, printed step by step (SPEC §2.4, paper
//! §3.2 and §4, Fig. 2–4):
//!
//! 1. the paper's start: three fingers 120° apart on the equator, fingertip
//!    poles touching — force-closure with three fingers, no two-finger pair;
//! 2. the roll to a two-finger force-closure pair (Fig. 4 frame 2): f1 and
//!    f2 roll apart along the equator, each by half the missing angle, to
//!    143° (Fact 3 boundary 140° + 2° margin, plus 1°) while f3 holds;
//! 3. f3 relocated by Fig. 2 paths and their repetition (Fig. 3) to a
//!    contact beyond one path's reach, while the pair f1–f2 holds.
//!
//! Every path is replayed at 1 kHz through the vector-form integrator
//! (SPEC §2.3) to show that the closed-form path is the rolling motion.
//!
//! Run: `cargo run --release -p gait --example paper_rolling`

use gait::contact::{BodyRates, ContactGeometry, ContactState, VectorIntegrator};
use gait::rolling::{RollGoal, RollLimits, RollingPath, fig2_reach, plan_roll};
use gait::{HandConfig, HandState};
use nalgebra::{UnitQuaternion, Vector3};

/// Latitude and longitude of a hand-frame direction \[deg\].
fn latlon(n: &Vector3<f64>) -> (f64, f64) {
    let lon = n.y.atan2(n.x).to_degrees();
    (
        n.z.asin().to_degrees(),
        if lon < -0.05 { lon + 360.0 } else { lon },
    )
}

fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Fact 3 (SPEC §3.1): two soft contacts are force-closure iff their angle
/// is at least π − 2θ; with the configured margin. (The grasp module lands
/// separately; this short local check is enough for the example.)
fn fact3(a: &Vector3<f64>, b: &Vector3<f64>, cfg: &HandConfig) -> bool {
    let m = &cfg.model;
    angle(a, b).to_degrees() >= 180.0 - 2.0 * m.friction_angle_deg + m.fc_margin_deg
}

/// Fact 4 (sufficient): an acute contact triangle whose plane passes
/// closer to O than R sin θ.
fn fact4(c: &[Vector3<f64>; 3], cfg: &HandConfig) -> bool {
    let acute = (0..3).all(|i| (c[(i + 1) % 3] - c[i]).dot(&(c[(i + 2) % 3] - c[i])) > 0.0);
    let normal = (c[1] - c[0]).cross(&(c[2] - c[0])).normalize();
    let dist = normal.dot(&c[0]).abs() * cfg.model.object_radius;
    acute && dist < cfg.model.object_radius * cfg.model.friction_angle_deg.to_radians().sin()
}

/// Three contacts are force-closure (SPEC §1.3 I1) by Fact 4, or because
/// two of them are (Fact 3).
fn grasp_fc(c: &[Vector3<f64>; 3], cfg: &HandConfig) -> bool {
    fact4(c, cfg) || (0..3).any(|i| fact3(&c[i], &c[(i + 1) % 3], cfg))
}

/// Degrees, with round-off around zero printed as 0.
fn deg(rad: f64) -> f64 {
    let d = rad.to_degrees();
    if d.abs() < 0.05 { 0.0 } else { d }
}

/// One printed row: object contact, fingertip contact, arc, roll, margin.
fn row(label: &str, path: &RollingPath, s: f64) {
    let e = path.eval(s);
    let (lat, lon) = latlon(&e.contact);
    let m = e.fingertip_contact;
    let pole = m.z.clamp(-1.0, 1.0).acos();
    // The azimuth of the fingertip contact is undefined at the pole.
    let az = if deg(pole) == 0.0 {
        "      —".to_string()
    } else {
        format!("{:6.1}°", deg(m.y.atan2(m.x)))
    };
    println!(
        "  {label:<9} ({:5.1}°,{lon:6.1}°)  {:5.1}° {az}  {:6.1} mm  {:6.1}°  {:5.1}°",
        deg(lat.to_radians()),
        deg(pole),
        e.arc * 1e3,
        deg(e.roll),
        deg(core::f64::consts::FRAC_PI_2 - pole),
    );
}

fn header() {
    println!("  step      object (lat, lon)  fingertip (pole, az)  arc         roll    hemisphere");
}

/// Replays `path` at 1 kHz (rolling rate ṡ = `rate` rad/s, constant per
/// segment) through the vector-form integrator; returns the largest
/// deviation from the closed form and both integrated arc lengths.
fn replay(path: &RollingPath, object: UnitQuaternion<f64>, rate: f64) -> (f64, f64, f64) {
    let g = *path.geometry();
    let mut vi = VectorIntegrator::new(g, ContactState::from_relative(path.start(), object));
    let mut worst: f64 = 0.0;
    for (i, seg) in path.segments().iter().enumerate() {
        let (s0, s1) = path.segment_range(i).expect("segment exists");
        let ticks = ((s1 - s0) / (rate * 1e-3)).ceil().max(1.0) as usize;
        let rates = BodyRates {
            object: Vector3::zeros(),
            fingertip: object * seg.axis * rate,
            slip: Vector3::zeros(),
        };
        for k in 1..=ticks {
            vi.advance_constant(&rates, (s1 - s0) / (rate * ticks as f64));
            let e = path.eval(s0 + (s1 - s0) * k as f64 / ticks as f64);
            worst = worst.max((object * e.contact - vi.state.normal).norm());
            worst = worst.max((e.roll - vi.state.roll).abs());
        }
    }
    (worst, vi.arc_object, vi.arc_fingertip)
}

fn main() {
    let cfg = HandConfig::default();
    cfg.validate().expect("default config is valid");
    let g = ContactGeometry::from_config(&cfg);
    let m = &cfg.model;
    let rate = cfg.limits.rolling.velocity;
    let mut hand = HandState::paper_start(&cfg);
    let contact = |h: &HandState, k: usize| ContactState::from_finger(&h.fingers[k], h.object, &g);
    let normals = |h: &HandState| [0, 1, 2].map(|k| h.fingers[k].contact_normal());
    println!(
        "gait paper_rolling: R = {} m, r = {} m, θ = {}°, γ = {}°, roll margin {}°, FC margin {}°",
        m.object_radius,
        m.fingertip_radius,
        m.friction_angle_deg,
        m.roll_limit_deg,
        m.roll_margin_deg,
        m.fc_margin_deg
    );
    let need = 180.0 - 2.0 * m.friction_angle_deg + m.fc_margin_deg;

    println!("\n1. Paper start (Fig. 4 frame 1): fingertip poles touch the equator 120° apart");
    for k in 0..3 {
        let c = contact(&hand, k).expect("paper start grasps");
        let (lat, lon) = latlon(&c.normal);
        println!(
            "  f{}: object ({lat:.1}°, {lon:.1}°), fingertip contact {:.1}° from its pole, roll {:.1}°",
            k + 1,
            angle(&c.fingertip_contact(), &Vector3::z()).to_degrees(),
            c.roll.to_degrees()
        );
    }
    let n = normals(&hand);
    println!(
        "  pairs {:.1}°, {:.1}°, {:.1}° < {need:.0}° (Fact 3 + margin): no two-finger FC pair; \
         Fact 4 three-finger FC: {}",
        angle(&n[0], &n[1]).to_degrees(),
        angle(&n[1], &n[2]).to_degrees(),
        angle(&n[2], &n[0]).to_degrees(),
        fact4(&n, &cfg)
    );

    let target_gap = need + 1.0;
    let half = (target_gap - angle(&n[0], &n[1]).to_degrees()) / 2.0;
    println!(
        "\n2. Roll f1, f2 apart along the equator by {half:.1}° each to {target_gap:.0}° \
         (Fig. 4 frame 2; the others hold)"
    );
    header();
    let mut fc_always = true;
    for (k, sign) in [(0usize, -1.0f64), (1, 1.0)] {
        let c = contact(&hand, k).expect("grasping");
        let rel = c.relative();
        let target = UnitQuaternion::from_scaled_axis(Vector3::z() * (sign * half.to_radians()))
            * rel.contact;
        let goal = RollGoal {
            target,
            final_roll: None,
        };
        let path = plan_roll(&g, &rel, &goal, &RollLimits::from_config(&cfg, false))
            .expect("direct roll is feasible");
        for j in 0..=3 {
            let s = path.length() * j as f64 / 3.0;
            row(&format!("f{} {}/3", k + 1, j), &path, s);
            let mut h = hand;
            h.fingers[k] = path.eval(s).finger_state(&hand.object, &g);
            fc_always &= grasp_fc(&normals(&h), &cfg);
        }
        let (dev, ao, af) = replay(&path, hand.object, rate);
        println!(
            "  1 kHz vector-form replay: deviation {dev:.1e}, arcs object {:.2} mm = fingertip {:.2} mm",
            ao * 1e3,
            af * 1e3
        );
        hand.fingers[k] = path.eval(path.length()).finger_state(&hand.object, &g);
    }
    let n = normals(&hand);
    println!(
        "  f1–f2 now {:.1}° ≥ {need:.0}°: Fact 3 FC pair {}; grasp FC at every sample {}",
        angle(&n[0], &n[1]).to_degrees(),
        fact3(&n[0], &n[1], &cfg),
        fc_always
    );

    let c3 = contact(&hand, 2).expect("f3 grasps");
    let rel = c3.relative();
    let lim = RollLimits::from_config(&cfg, false);
    let leg = 90.0 * m.fingertip_radius / m.object_radius;
    let one = fig2_reach(&g, lim.usable()).to_degrees();
    let lift = 40f64.to_radians();
    let d3 = Vector3::new(240f64.to_radians().cos(), 240f64.to_radians().sin(), 0.0);
    let target = UnitQuaternion::from_scaled_axis(d3.cross(&Vector3::z()).normalize() * lift) * d3;
    println!(
        "\n3. Relocate f3 40° up its longitude: a roll from the pole reaches {leg:.0}°, \
         one Fig. 2 path (Δτ ≤ {:.0}°) {one:.1}° more",
        lim.usable().to_degrees()
    );
    let goal = RollGoal {
        target: hand.object.inverse() * target,
        final_roll: None,
    };
    let path = plan_roll(&g, &rel, &goal, &lim).expect("f3 relocation is feasible");
    println!(
        "  plan: {} segments = {} Fig. 2 paths (turning against τ: free unwinding, no spin) + closing roll",
        path.len(),
        (path.len() - 1) / 3
    );
    header();
    row("start", &path, 0.0);
    for i in 0..path.len() {
        let (_, s1) = path.segment_range(i).expect("segment exists");
        let name = ["A→B", "B→C", "C→D"][i % 3];
        let label = if i + 1 == path.len() { "close" } else { name };
        row(
            &format!(
                "{}{label}",
                if i + 1 < path.len() {
                    (i / 3 + 1).to_string()
                } else {
                    String::new()
                }
            ),
            &path,
            s1,
        );
    }
    let (dev, ao, af) = replay(&path, hand.object, rate);
    let pm = path.margins();
    let ws = path
        .max_angle_from(&(hand.object.inverse() * d3))
        .to_degrees();
    println!(
        "  1 kHz replay: deviation {dev:.1e}; arcs object {:.1} mm, fingertip {:.1} mm",
        ao * 1e3,
        af * 1e3
    );
    println!(
        "  along the path: hemisphere margin ≥ {:.1}°, |τ| ≤ {:.1}° (limit {:.0}°), \
         ≤ {ws:.1}° from d3 (W3: {:.0}°)",
        deg(pm.min_hemisphere),
        pm.max_abs_roll.to_degrees(),
        m.roll_limit_deg,
        m.workspace_half_angle_deg
    );
    let end = path.end();
    hand.fingers[2] = path.eval(path.length()).finger_state(&hand.object, &g);
    println!(
        "\nSummary: f1–f2 force-closure pair at {:.1}° (Fact 3), held throughout: {}; f3 moved {:.1}° \
         (one roll + one Fig. 2 path reach {:.1}°)\n  by {} Fig. 2 paths, ending {:.0e} from its target \
         with roll {:.1}° and its contact {:.1}° inside the fingertip hemisphere",
        angle(&n[0], &n[1]).to_degrees(),
        fact3(&n[0], &n[1], &cfg),
        angle(&rel.contact, &end.contact).to_degrees(),
        leg + one,
        (path.len() - 1) / 3,
        (hand.fingers[2].contact_normal() - target).norm(),
        deg(end.roll),
        deg(end.hemisphere_margin())
    );
}
