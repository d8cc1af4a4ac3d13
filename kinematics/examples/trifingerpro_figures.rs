//! The figures of deploy/hands/trifingerpro/README.md: for balls at the ends
//! of the 30–50 mm / 50–100 g range and the default, where the ball sits,
//! the grasp's joints and margins, and the grip the torque box allows.
//!
//! `cargo run -p kinematics --example trifingerpro_figures`

use kinematics::{Chain, ClosedFormIk, HandDescription, gravity_torques, max_force_scale};
use nalgebra::Vector3;

const URDF: &str = include_str!("../../deploy/hands/trifingerpro/trifingerpro.urdf");
const SECTION: &str = include_str!("../../deploy/hands/trifingerpro/hand.toml");

struct Grasp {
    q: [Vector3<f64>; 3],
    limit: f64,
    patch_from_pole: f64,
    clearance: f64,
    spacing: f64,
}

fn grasp(chains: &[Chain<3>], centre: Vector3<f64>, big_r: f64) -> Option<Grasp> {
    let mut g = Grasp {
        q: [Vector3::zeros(); 3],
        limit: f64::INFINITY,
        patch_from_pole: 0.0,
        clearance: f64::INFINITY,
        spacing: f64::INFINITY,
    };
    let mut tips = [Vector3::zeros(); 3];
    for (k, c) in chains.iter().enumerate() {
        // finger_0's contact at azimuth 75° on the equator, the others turned with their fingers.
        let az = (75.0 - 120.0 * k as f64).to_radians();
        let n = Vector3::new(az.cos(), az.sin(), 0.0);
        let q = ClosedFormIk::new(c)
            .ok()?
            .solve(&(centre + n * (big_r + c.tip_radius)), &c.mid_range())
            .ok()?;
        let s = c.forward(&q);
        g.q[k] = q;
        g.limit = g.limit.min(c.limit_margin(&q));
        g.patch_from_pole = g
            .patch_from_pole
            .max(c.patch.angle_from_pole(&s.tip.rotation, &n));
        for cap in c.capsules(&s).as_slice() {
            g.clearance = g.clearance.min(cap.sphere_gap(&centre, big_r));
        }
        tips[k] = s.tip_centre();
    }
    for i in 0..3 {
        g.spacing = g.spacing.min((tips[i] - tips[(i + 1) % 3]).norm());
    }
    Some(g)
}

fn main() {
    let h = HandDescription::parse(URDF, SECTION).expect("description");
    let chains: Vec<Chain<3>> = h
        .fingers
        .iter()
        .map(|f| Chain::from_description(f, h.joint_limit_margin).unwrap())
        .collect();
    println!(
        "| R [mm] | centre height [mm] (feasible range) | joints (every finger) [rad] | tightest limit margin [rad] | contact from tip pole [deg] | link clearance [mm] | tip spacing [mm] |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut best_centres = Vec::new();
    for big_r in [0.030, 0.0335, 0.035, 0.050] {
        // Feasible heights (links clear, contact in the patch); of those
        // within 1 mrad of the largest joint-limit margin, the middle one.
        let feasible: Vec<(f64, f64)> = (30..=160)
            .filter_map(|mm| {
                let z = mm as f64 * 1e-3;
                let g = grasp(&chains, Vector3::new(0.0, 0.0, z), big_r)?;
                (g.clearance > 0.0 && g.patch_from_pole < std::f64::consts::FRAC_PI_2)
                    .then_some((z, g.limit))
            })
            .collect();
        let top = feasible
            .iter()
            .map(|f| f.1)
            .fold(f64::NEG_INFINITY, f64::max);
        let plateau: Vec<f64> = feasible
            .iter()
            .filter(|f| f.1 >= top - 1e-3)
            .map(|f| f.0)
            .collect();
        let z = plateau[plateau.len() / 2];
        let best = grasp(&chains, Vector3::new(0.0, 0.0, z), big_r).map(|g| (z, g));
        let (z, g) = best.expect("a feasible height");
        println!(
            "| {:.1} | {:.0} ({:.0}–{:.0}) | ({:.3}, {:.3}, {:.3}) | {:.3} | {:.1} | {:.1} | {:.1} |",
            big_r * 1e3,
            z * 1e3,
            feasible[0].0 * 1e3,
            feasible[feasible.len() - 1].0 * 1e3,
            g.q[0].x,
            g.q[0].y,
            g.q[0].z,
            g.limit,
            g.patch_from_pole.to_degrees(),
            g.clearance * 1e3,
            g.spacing * 1e3
        );
        best_centres.push((big_r, z));
    }
    let o = h.object;
    let g = grasp(&chains, o.centre, o.radius).expect("the configured grasp");
    println!(
        "| {:.1} (hand.toml) | {:.0} (hand.toml) | ({:.3}, {:.3}, {:.3}) | {:.3} | {:.1} | {:.1} | {:.1} |",
        o.radius * 1e3,
        o.centre.z * 1e3,
        g.q[0].x,
        g.q[0].y,
        g.q[0].z,
        g.limit,
        g.patch_from_pole.to_degrees(),
        g.clearance * 1e3,
        g.spacing * 1e3
    );
    best_centres.push((o.radius, o.centre.z));
    println!();
    println!(
        "Holding the ball's weight by friction (three equator contacts, μ = {}), at each R's centre height:",
        h.friction.mu
    );
    println!();
    println!(
        "| R [mm] | mass [g] | normal force needed per tip [N] | admissible / needed (torque box, link weight included) |"
    );
    println!("|---|---|---|---|");
    for &(big_r, z) in &best_centres {
        let centre = Vector3::new(0.0, 0.0, z);
        let g = grasp(&chains, centre, big_r).unwrap();
        for mass in [0.050, 0.058, 0.100] {
            // Each tip carries a third of the weight by friction: tangential
            // mg/3 up, normal mg/(3μ) inward (at the cone's edge).
            let w = mass * 9.81 / 3.0;
            let normal = w / h.friction.mu;
            let mut ratio = f64::INFINITY;
            for (k, c) in chains.iter().enumerate() {
                let s = c.forward(&g.q[k]);
                let n = (s.tip_centre() - centre).normalize();
                let f = -n * normal + Vector3::z() * w;
                let gt = gravity_torques(c, &s, &h.gravity);
                let k_max = max_force_scale(&s, &f.normalize(), &gt, &c.effort()).unwrap_or(0.0);
                ratio = ratio.min(k_max / f.norm());
            }
            println!(
                "| {:.1} | {:.0} | {:.3} | {:.1} |",
                big_r * 1e3,
                mass * 1e3,
                normal,
                ratio
            );
        }
    }
}
