//! Scratch directories: tests run in parallel, in one process and in
//! several, so none may share a fixed path.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};

/// A fresh, empty directory `gaitd-<tag>-<pid>-<n>` in the system's
/// temporary directory, `n` counting the calls in this process: unique
/// per process and call. The caller removes it when done (or leaves it
/// for a failure's diagnosis).
///
/// Panics if it cannot be made.
pub fn scratch_dir(tag: &str) -> PathBuf {
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("gaitd-{tag}-{}-{n}", std::process::id()));
    // An earlier process with this pid may have been killed before it
    // removed its directory.
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir)
        .unwrap_or_else(|e| panic!("scratch directory {}: {e}", dir.display()));
    dir
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_call_has_a_directory_of_its_own_and_empty() {
        let a = scratch_dir("scratch-test");
        let b = scratch_dir("scratch-test");
        assert_ne!(a, b);
        for d in [&a, &b] {
            assert!(d.is_dir(), "{}", d.display());
            assert_eq!(std::fs::read_dir(d).unwrap().count(), 0);
            let name = d.file_name().unwrap().to_string_lossy().into_owned();
            assert!(name.starts_with("gaitd-scratch-test-"), "{name}");
            std::fs::remove_dir_all(d).unwrap();
        }
    }
}
