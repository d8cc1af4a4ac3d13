//! Where the repository is, for the tests that read its files.

use std::path::PathBuf;

/// The repository's root, for `test_support`'s own tests (the maps and
/// the module graph): two levels above this crate's manifest.
pub fn root() -> PathBuf {
    // At run time first: with a target directory shared between checkouts
    // the compile-time value may be another checkout's.
    let crate_dir = std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")));
    crate_dir
        .join("../..")
        .canonicalize()
        .expect("the repository root (tests/support/../..)")
}
