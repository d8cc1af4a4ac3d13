//! Shared by the integration tests: the shipped TriFingerPro description
//! and seeded random configurations.
#![allow(dead_code)]

use kinematics::{Chain, HandDescription};
use nalgebra::{SVector, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

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

/// A seeded generator.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// A configuration uniform in the limits with margin.
pub fn random_q<const N: usize>(chain: &Chain<N>, rng: &mut ChaCha8Rng) -> SVector<f64, N> {
    let (lo, hi) = (chain.lower(), chain.upper());
    SVector::from_fn(|i, _| rng.random_range(lo[i]..=hi[i]))
}

/// A unit vector uniform on the sphere.
pub fn random_unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
}
