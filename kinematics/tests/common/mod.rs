//! Shared by the integration tests: the shipped TriFingerPro description
//! and seeded random configurations.
#![allow(dead_code)]

use kinematics::{Chain, HandDescription};
use nalgebra::SVector;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

// Each test binary uses some of these only.
#[allow(unused_imports)]
pub use test_support::random::{rng, unit};

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
