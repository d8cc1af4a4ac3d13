//! Helpers shared by the workspace's tests.
//!
//! - [`counting`]: the one counting global allocator of the allocation
//!   tests, counting per thread.
//! - [`repo::root`]: the repository's root, for the tests that read it.
//! - [`skip()`]: how a test says that it could not run a check here, so that
//!   CI lists it instead of letting it pass unseen.
//! - [`quat::angle`]: the angle between two orientations given as four
//!   numbers, as the end-to-end tests read them.
//! - [`scratch_dir`]: a fresh temporary directory of the test's own.
//! - `random` (feature `random`): seeded unit vectors and Haar-random
//!   rotations, and the angle between two directions.

pub mod counting;
pub mod quat;
#[cfg(feature = "random")]
pub mod random;
pub mod repo;
mod scratch;
mod skip;

pub use scratch::scratch_dir;
pub use skip::{SKIP_LOG_ENV, skip};
