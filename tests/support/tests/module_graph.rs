//! Each crate's top-level modules depend on one another one way.
//!
//! A module that uses another which uses it back cannot be understood, or
//! moved, alone. For every library and binary crate of the workspace this
//! test reads the sources (no build), takes each file's top-level module
//! (`src/planner/search/mod.rs` → `planner`), and records an edge to every
//! other top-level module its code names — `crate::x`, `crate::{x, …}`, or
//! `super::…::x` climbing to the crate root — leaving out comments and the
//! `#[cfg(test)] mod` at a file's end. Then the crates in [`ACYCLIC`] have
//! no cycle at all, and every member of the workspace with more than one
//! module is in [`ACYCLIC`] (a new crate cannot start with a cycle
//! unnoticed).
//!
//! The crate graph itself needs no test: Cargo refuses cyclic
//! dependencies between packages.
//!
//! `cargo test -p test_support --test module_graph` runs in a second.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::Path;

use test_support::repo::{members, root};

/// Crates (source directories) whose module graph must be acyclic.
const ACYCLIC: [&str; 11] = [
    "gait/src",
    "shm_schema/src",
    "bridge/src",
    "tests/support/src",
    "kinematics/src",
    "daemon/src",
    "binaries/gaitctl/src",
    "binaries/trace_mcap/src",
    "binaries/gaitd_view/src",
    "client/src",
    "otg/src",
];

/// Every `.rs` file under `dir`, as its module path (`["planner",
/// "search"]` for `planner/search/mod.rs`), with its text. The crate root
/// files and the binaries' folder are left out.
fn modules(dir: &Path) -> Vec<(Vec<String>, String)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let mut entries: Vec<_> = fs::read_dir(&d)
            .unwrap_or_else(|e| panic!("{}: {e}", d.display()))
            .map(|e| e.expect("a directory entry").path())
            .collect();
        entries.sort();
        for p in entries {
            let rel = p.strip_prefix(dir).expect("under dir");
            if p.is_dir() {
                if rel != Path::new("bin") {
                    stack.push(p);
                }
                continue;
            }
            if p.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let mut path: Vec<String> = rel
                .with_extension("")
                .iter()
                .map(|c| c.to_string_lossy().into_owned())
                .collect();
            if path.last().is_some_and(|l| l == "mod") {
                path.pop();
            }
            if path == ["lib"] || path == ["main"] || path.is_empty() {
                continue;
            }
            let text = fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            out.push((path, text));
        }
    }
    out
}

/// The code of a file: comments dropped, and the test module at its end.
fn code(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        let t = line.trim_start();
        if t.starts_with("#[cfg(test)]")
            && lines
                .peek()
                .is_some_and(|n| n.trim_start().starts_with("mod "))
        {
            break;
        }
        if t.starts_with("//") {
            continue;
        }
        let line = line.split(" //").next().unwrap_or(line);
        out.push_str(line);
        out.push('\n');
    }
    out
}

fn ident_at(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The crate-root children a file's code names.
fn named_tops(path: &[String], code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    // crate::x and crate::{x, y::z, …}
    for (i, _) in code.match_indices("crate::") {
        if i > 0 {
            let before = code[..i].chars().next_back().unwrap_or(' ');
            if before.is_ascii_alphanumeric() || matches!(before, '_' | ':' | '$') {
                continue; // e.g. `$crate::` or `some_crate::`
            }
        }
        let rest = &code[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0usize;
            let mut at_start = true;
            for (k, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        at_start = true;
                        continue;
                    }
                    _ => {}
                }
                if at_start && depth == 0 && (c.is_ascii_alphanumeric() || c == '_') {
                    out.insert(ident_at(&group[k..]).to_string());
                    at_start = false;
                } else if !c.is_whitespace() {
                    at_start = false;
                }
            }
        } else {
            out.insert(ident_at(rest).to_string());
        }
    }
    // super::super::x reaching the crate root
    for (i, _) in code.match_indices("super::") {
        if code[..i].ends_with("super::") {
            continue; // counted from the first `super::` of the chain
        }
        let mut rest = &code[i..];
        let mut ups = 0;
        while let Some(r) = rest.strip_prefix("super::") {
            ups += 1;
            rest = r;
        }
        if ups == path.len() {
            out.insert(ident_at(rest).to_string());
        }
    }
    out
}

/// Top-level module → the top-level modules it uses.
fn graph(dir: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let files = modules(dir);
    let tops: BTreeSet<String> = files.iter().map(|(p, _)| p[0].clone()).collect();
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (path, text) in &files {
        let from = &path[0];
        let entry = g.entry(from.clone()).or_default();
        for to in named_tops(path, &code(text)) {
            if &to != from && tops.contains(&to) {
                entry.insert(to);
            }
        }
    }
    g
}

/// The modules that lie on a cycle (strongly connected components of
/// more than one module).
fn on_cycles(g: &BTreeMap<String, BTreeSet<String>>) -> BTreeSet<String> {
    let reach = |from: &str| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.to_string()];
        while let Some(m) = stack.pop() {
            for n in g.get(&m).into_iter().flatten() {
                if seen.insert(n.clone()) {
                    stack.push(n.clone());
                }
            }
        }
        seen
    };
    g.keys()
        .filter(|m| reach(m).contains(*m))
        .cloned()
        .collect()
}

fn describe(g: &BTreeMap<String, BTreeSet<String>>, cyclic: &BTreeSet<String>) -> String {
    cyclic
        .iter()
        .map(|m| {
            let to: Vec<_> = g[m].iter().filter(|n| cyclic.contains(*n)).collect();
            format!("  {m} → {to:?}")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn module_graphs_are_acyclic() {
    let root = root();
    for dir in ACYCLIC {
        let g = graph(&root.join(dir));
        assert!(g.len() > 1, "{dir}: no modules found");
        let cyclic = on_cycles(&g);
        assert!(
            cyclic.is_empty(),
            "{dir}: modules that use each other:\n{}",
            describe(&g, &cyclic)
        );
    }
}

#[test]
fn every_crate_with_modules_is_checked() {
    let root = root();
    let members = members(&root);
    assert!(members.len() > 5, "members not read: {members:?}");
    for m in members {
        let dir = format!("{m}/src");
        if !root.join(&dir).is_dir() || graph(&root.join(&dir)).len() <= 1 {
            continue; // no two modules, no cycle
        }
        assert!(
            ACYCLIC.contains(&dir.as_str()),
            "{dir}: not in ACYCLIC, so its module graph is not checked"
        );
    }
}

#[test]
fn the_reader_sees_edges_of_every_form() {
    let path = vec!["executor".to_string(), "grip".to_string()];
    let code = code(
        "use crate::planner::Plan;\nuse crate::{grasp::hold, state::HandState};\n\
         use super::super::sim;\n// crate::trace\nlet x = $crate::macros;\n",
    );
    let tops = named_tops(&path, &code);
    let want: BTreeSet<String> = ["planner", "grasp", "state", "sim"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(tops, want);
    let mut g = BTreeMap::new();
    g.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    g.insert("b".to_string(), BTreeSet::from(["c".to_string()]));
    g.insert("c".to_string(), BTreeSet::from(["a".to_string()]));
    g.insert("d".to_string(), BTreeSet::from(["a".to_string()]));
    let want: BTreeSet<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
    assert_eq!(on_cycles(&g), want);
}
