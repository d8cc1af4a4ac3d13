//! The `gaitd` Python package's ctypes mirror of the schema
//! (`client/python/gaitd/layout.py`, generated from `shm_schema`'s layout
//! code, checked by `gaitd.schema`) matches the generated
//! `shm_schema/LAYOUT.md`: every payload's iceoryx2 type name, size,
//! alignment and every field's offset and size, every code table, the
//! bit constants and the service names. The same check catches deliberate
//! mutations of the mirror (swapped fields, a missing padding word, an old
//! type name, a renumbered code, a wrong bit), so it can fail.

mod python_support;

use gaitd_tests::repo_root;
use python_support::{json_output, script};

#[test]
fn the_python_mirror_matches_layout_md_and_a_broken_one_does_not() {
    let out = script("schema_check.py")
        .arg(repo_root().join("shm_schema/LAYOUT.md"))
        .output()
        .expect("run python");
    let v = json_output(&out, "schema_check.py");
    let problems = v["problems"].as_array().expect("problems");
    assert!(
        problems.is_empty(),
        "mirror differs from LAYOUT.md: {problems:#?}"
    );
    let mutations = v["mutations"].as_object().expect("mutations");
    assert_eq!(mutations.len(), 5);
    for (name, found) in mutations {
        let found = found.as_array().expect("problem list");
        println!("mutation {name}: {found:?}");
        assert!(
            !found.is_empty(),
            "the broken mirror '{name}' passed the check"
        );
    }
}
