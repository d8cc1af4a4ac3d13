//! Helpers shared by the workspace's tests.
//!
//! - [`counting`]: the one counting global allocator of the allocation
//!   tests, counting per thread.
//! - [`repo::root`]: the repository's root, for the tests that read it.
//! - [`skip()`]: how a test says that it could not run a check here, so that
//!   CI lists it instead of letting it pass unseen.

pub mod counting;
pub mod repo;
mod skip;

pub use skip::{SKIP_LOG_ENV, skip};
