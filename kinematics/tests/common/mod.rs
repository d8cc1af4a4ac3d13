//! Shared by the integration tests: the shipped TriFingerPro description
//! and seeded random configurations.
#![allow(dead_code)]

use kinematics::{Chain, ClosedFormIk, HandDescription, Object};
use nalgebra::{Matrix3, SVector, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

// Each test binary uses some of these only.
#[allow(unused_imports)]
pub use test_support::random::{rng, unit};

/// Margins a planner would keep (the tests' choice): 5° inside the tip
/// patch, 5 mm between links and ball, 5 mm between two fingers.
pub const LIMITS: kinematics::GraspLimits = kinematics::GraspLimits {
    margins: kinematics::Margins {
        patch: 5.0 * std::f64::consts::PI / 180.0,
        clearance: 0.005,
    },
    finger_gap: 0.005,
};

/// The shipped URDF.
pub const URDF: &str = include_str!("../../../deploy/hands/trifingerpro/trifingerpro.urdf");
/// The shipped hand section.
pub const SECTION: &str = include_str!("../../../deploy/hands/trifingerpro/hand.toml");

/// The shipped description.
pub fn hand() -> HandDescription {
    HandDescription::parse(URDF, SECTION).expect("the shipped TriFingerPro description parses")
}

/// The three fingers' chains.
pub fn chains() -> [Chain<3>; 3] {
    let h = hand();
    std::array::from_fn(|k| {
        Chain::<3>::from_description(&h.fingers[k], h.joint_limit_margin).expect("3 joints")
    })
}

/// A configuration uniform in the limits with margin.
pub fn random_q<const N: usize>(chain: &Chain<N>, rng: &mut ChaCha8Rng) -> SVector<f64, N> {
    let (lo, hi) = (chain.lower(), chain.upper());
    SVector::from_fn(|i, _| rng.random_range(lo[i]..=hi[i]))
}

/// The contact normal of `chain` at `q` on the ball `o`, from forward
/// kinematics.
pub fn normal(chain: &Chain<3>, q: &Vector3<f64>, o: &Object) -> Vector3<f64> {
    (chain.forward(q).tip_centre() - o.centre).normalize()
}

/// q̇ of one finger for the ball's ω: the no-slip condition
/// ċ − r ω_f × n = ω × (R n) with ċ = J_v q̇, ω_f = J_ω q̇, as one system.
pub fn q_dot(chain: &Chain<3>, q: &Vector3<f64>, o: &Object, w: &Vector3<f64>) -> Vector3<f64> {
    let s = chain.forward(q);
    let n = normal(chain, q, o);
    let nx = Matrix3::new(0.0, -n.z, n.y, n.z, 0.0, -n.x, -n.y, n.x, 0.0);
    let m = s.jacobian_v() + nx * s.jacobian_w() * chain.tip_radius;
    m.lu()
        .solve(&w.cross(&(n * o.radius)))
        .expect("regular grasp")
}

/// The three tips 30° from the ball's top at the fingers' azimuths.
pub fn top_grasp(chains: &[Chain<3>; 3], o: &Object) -> [Vector3<f64>; 3] {
    let beta = 30f64.to_radians();
    std::array::from_fn(|k| {
        let az = [75.0f64, -45.0, -165.0][k].to_radians();
        let n = Vector3::new(beta.sin() * az.cos(), beta.sin() * az.sin(), beta.cos());
        ClosedFormIk::new(&chains[k])
            .unwrap()
            .solve(
                &(o.centre + n * (o.radius + chains[k].tip_radius)),
                &chains[k].mid_range(),
            )
            .expect("inside the limits")
    })
}
