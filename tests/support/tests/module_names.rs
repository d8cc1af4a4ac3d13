//! One name per concept: no two modules of one crate share a file name.
//!
//! Two `report.rs` in one crate make a reader (and a search by file name)
//! guess which report is meant; names that say what each file holds
//! (`gait`'s `tick_report.rs` and `invariant_report.rs`) do not. For
//! every member of the workspace this test lists the `.rs` files under its
//! `src/` — leaving out `mod.rs`, `lib.rs` and `main.rs`, whose names are
//! the language's, and `src/bin/`, where each file is a crate of its own —
//! and fails on any file name found twice, naming both paths.
//!
//! `cargo test -p test_support --test module_names` runs in a second.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

use test_support::repo::{members, root};

/// The module files under `src` (relative to it), sorted.
fn module_files(src: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let p = e.expect("a directory entry").path();
            let rel = p.strip_prefix(src).expect("under src").to_path_buf();
            if p.is_dir() {
                if rel != Path::new("bin") {
                    stack.push(p);
                }
            } else if p.extension().is_some_and(|x| x == "rs")
                && !matches!(
                    p.file_name().and_then(|n| n.to_str()),
                    Some("mod.rs" | "lib.rs" | "main.rs")
                )
            {
                out.push(rel);
            }
        }
    }
    out.sort();
    out
}

/// The file names found more than once, each with every path holding it.
fn shared_names(files: &[PathBuf]) -> BTreeMap<String, Vec<&PathBuf>> {
    let mut by_name: BTreeMap<String, Vec<&PathBuf>> = BTreeMap::new();
    for f in files {
        let name = f
            .file_name()
            .expect("a file")
            .to_string_lossy()
            .into_owned();
        by_name.entry(name).or_default().push(f);
    }
    by_name.retain(|_, paths| paths.len() > 1);
    by_name
}

#[test]
fn no_two_modules_of_a_crate_share_a_file_name() {
    let root = root();
    let members = members(&root);
    assert!(members.len() > 5, "members not read: {members:?}");
    let mut found = Vec::new();
    let mut crates = 0;
    for m in members {
        let src = root.join(&m).join("src");
        if !src.is_dir() {
            continue;
        }
        crates += 1;
        for (name, paths) in shared_names(&module_files(&src)) {
            let paths: Vec<_> = paths
                .iter()
                .map(|p| format!("{m}/src/{}", p.display()))
                .collect();
            found.push(format!("  {name}: {}", paths.join(", ")));
        }
    }
    assert!(crates > 5, "only {crates} crates with a src/ found");
    assert!(
        found.is_empty(),
        "module files that share a name in one crate (rename them to say what each holds):\n{}",
        found.join("\n")
    );
}

#[test]
fn a_shared_name_is_found_at_any_depth() {
    let files: Vec<PathBuf> = [
        "executor/report.rs",
        "hand/report.rs",
        "hand/check.rs",
        "report/x.rs",
    ]
    .iter()
    .map(PathBuf::from)
    .collect();
    let shared = shared_names(&files);
    assert_eq!(shared.keys().collect::<Vec<_>>(), ["report.rs"]);
    assert_eq!(shared["report.rs"].len(), 2);
}
