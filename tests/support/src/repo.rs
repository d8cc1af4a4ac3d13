//! Where the repository is, for the tests that read its files, and the
//! Python its oracle tests run.

use std::path::{Path, PathBuf};

/// The environment variable naming the oracles' Python (default: the
/// repository's `.venv-oracles`).
pub const ORACLE_PYTHON_ENV: &str = "GAITD_ORACLE_PYTHON";

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

/// The workspace's members (their directories), as listed in the root
/// `Cargo.toml` under `root`.
pub fn members(root: &Path) -> Vec<String> {
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).expect("the root Cargo.toml");
    let line = manifest
        .lines()
        .find(|l| l.trim_start().starts_with("members"))
        .expect("a `members = [...]` line");
    let list = &line[line.find('[').expect("[") + 1..line.rfind(']').expect("]")];
    list.split(',')
        .map(|m| m.trim().trim_matches('"').to_string())
        .filter(|m| !m.is_empty())
        .collect()
}

/// The Python of the test oracles (ruckig, MuJoCo, the client package)
/// for the checkout at `repo`: [`ORACLE_PYTHON_ENV`], else
/// `repo/.venv-oracles/bin/python`, which `bash .ci/install` makes. The
/// caller names its checkout (its own manifest's parent): this crate's
/// may be another's.
///
/// Panics, saying how to get it, if it is not there.
pub fn oracle_python(repo: &Path) -> PathBuf {
    let p = std::env::var_os(ORACLE_PYTHON_ENV)
        .map(PathBuf::from)
        .unwrap_or_else(|| repo.join(".venv-oracles/bin/python"));
    assert!(
        p.exists(),
        "Python for the oracle tests not found at {}: run `bash .ci/install` \
         (creates .venv-oracles with ruckig, mujoco, numpy and iceoryx2==0.10.0) \
         or set {ORACLE_PYTHON_ENV}",
        p.display()
    );
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_oracle_python_is_the_checkouts_venv() {
        if std::env::var_os(ORACLE_PYTHON_ENV).is_some() {
            // The caller chose one: nothing of the default to check here.
            return;
        }
        let repo = crate::scratch_dir("oracle-python");
        let missing = std::panic::catch_unwind(|| oracle_python(&repo)).expect_err("no venv yet");
        let msg = missing.downcast_ref::<String>().expect("a message");
        assert!(
            msg.contains(".venv-oracles/bin/python") && msg.contains(".ci/install"),
            "{msg}"
        );
        let bin = repo.join(".venv-oracles/bin");
        std::fs::create_dir_all(&bin).unwrap();
        std::fs::write(bin.join("python"), "").unwrap();
        assert_eq!(oracle_python(&repo), bin.join("python"));
        std::fs::remove_dir_all(&repo).unwrap();
    }
}
