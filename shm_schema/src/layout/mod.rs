//! The documented byte layout of every payload, for C and Python mirrors.
//!
//! [`layouts`] lists every field with offset, size, type and unit, taken
//! from the compiler (`offset_of!`, `size_of`); a test checks that the
//! fields tile each struct exactly (no gap, no overlap, nothing missing),
//! that `LAYOUT.md` equals [`layout_markdown`] and that the Python package's
//! mirror, `client/python/gaitd/layout.py`, equals [`python_layout`], so
//! neither can drift.

use crate::codes::CodeInfo;
use crate::*;
use core::mem::{align_of, size_of};
use iceoryx2::prelude::ZeroCopySend;

/// One field of a payload struct.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldInfo {
    /// Field name.
    pub name: &'static str,
    /// Byte offset from the start of the struct.
    pub offset: usize,
    /// Size in bytes.
    pub size: usize,
    /// Rust type (`u64`, `[f64; 4]`, `FingerStatus`).
    pub ty: String,
    /// Physical unit or code table ("" if none).
    pub unit: &'static str,
    /// Meaning, one line.
    pub doc: &'static str,
}

/// One payload struct.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TypeLayout {
    /// Rust name.
    pub name: &'static str,
    /// iceoryx2 type name (compared when a service is opened).
    pub type_name: &'static str,
    /// `size_of`.
    pub size: usize,
    /// `align_of`.
    pub align: usize,
    /// Fields in offset order.
    pub fields: Vec<FieldInfo>,
}

fn short_type_name<F>() -> String {
    // "[shm_schema::status::FingerStatus; 3]" → "[FingerStatus; 3]"
    let full = core::any::type_name::<F>();
    let mut out = String::new();
    let mut word = String::new();
    for ch in full.chars() {
        if ch.is_alphanumeric() || ch == '_' || ch == ':' {
            word.push(ch);
        } else {
            out.push_str(word.rsplit("::").next().unwrap_or(""));
            word.clear();
            out.push(ch);
        }
    }
    out.push_str(word.rsplit("::").next().unwrap_or(""));
    out
}

fn field<T, F>(
    name: &'static str,
    offset: usize,
    _witness: fn(&T) -> &F,
    unit: &'static str,
    doc: &'static str,
) -> FieldInfo {
    FieldInfo {
        name,
        offset,
        size: size_of::<F>(),
        ty: short_type_name::<F>(),
        unit,
        doc,
    }
}

/// `f!(Type, field, unit, doc)`: a [`FieldInfo`] with offset, size and type
/// from the compiler.
macro_rules! f {
    ($t:ty, $field:ident, $unit:expr, $doc:expr) => {
        field(
            stringify!($field),
            offset_of!($t, $field),
            |s: &$t| &s.$field,
            $unit,
            $doc,
        )
    };
}

fn layout<T: ZeroCopySend>(name: &'static str, fields: Vec<FieldInfo>) -> TypeLayout {
    TypeLayout {
        name,
        // SAFETY: the type names are compile-time constants from the derive.
        type_name: unsafe { <T as ZeroCopySend>::type_name() },
        size: size_of::<T>(),
        align: align_of::<T>(),
        fields,
    }
}

mod client_payloads;
mod markdown;
mod plant_payloads;
mod python;

pub use markdown::layout_markdown;
pub use python::python_layout;

/// Every payload type, nested types after the types that use them: the
/// client's (commands, answers, status, events), then the plant's.
pub fn layouts() -> Vec<TypeLayout> {
    let mut all = client_payloads::layouts();
    all.extend(plant_payloads::layouts());
    all
}

/// Every code table: (enum name, rows).
pub fn code_tables() -> Vec<(&'static str, &'static [CodeInfo])> {
    vec![
        ("CommandKind", CommandKind::TABLE),
        ("GoalFrame", GoalFrame::TABLE),
        ("AnswerCode", AnswerCode::TABLE),
        ("GoalState", GoalState::TABLE),
        ("ReasonCode", ReasonCode::TABLE),
        ("Phase", Phase::TABLE),
        ("FingerPhase", FingerPhase::TABLE),
        ("GraspState", GraspState::TABLE),
        ("FaultCode", FaultCode::TABLE),
        ("EventKind", EventKind::TABLE),
        ("DaemonState", DaemonState::TABLE),
        ("PlantFingerMode", PlantFingerMode::TABLE),
        ("PlantFault", PlantFault::TABLE),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_tile_every_struct_exactly() {
        for t in layouts() {
            let mut end = 0;
            for f in &t.fields {
                assert_eq!(
                    f.offset, end,
                    "{}.{}: gap or overlap before it",
                    t.name, f.name
                );
                assert_eq!(f.offset % t.align.min(f.size.max(1)).min(8), 0);
                end = f.offset + f.size;
            }
            assert_eq!(end, t.size, "{}: fields do not cover the struct", t.name);
            assert!(t.type_name.starts_with("gaitd::"), "{}", t.type_name);
            assert!(
                t.type_name.ends_with(&format!(".v{SCHEMA_VERSION}")),
                "{}",
                t.type_name
            );
        }
    }

    #[test]
    fn the_change_list_names_this_version_first() {
        let versions: Vec<u32> = SCHEMA_CHANGES.iter().map(|(v, _)| *v).collect();
        assert_eq!(versions.first(), Some(&SCHEMA_VERSION), "{versions:?}");
        assert!(
            versions.windows(2).all(|w| w[0] == w[1] + 1),
            "{versions:?}"
        );
        assert_eq!(versions.last(), Some(&2));
    }

    #[test]
    fn type_names_are_short() {
        assert_eq!(short_type_name::<[FingerStatus; 3]>(), "[FingerStatus; 3]");
        assert_eq!(short_type_name::<u64>(), "u64");
    }

    /// What an out-of-date LAYOUT.md leads to.
    #[derive(Debug, PartialEq)]
    enum Stale {
        /// `GAITD_BLESS` set outside CI: rewrite it.
        Rewrite,
        /// Fail with this message.
        Fail(&'static str),
    }

    /// `GAITD_BLESS` rewrites the document, except in CI (`CI` set, and not
    /// `false` or `0`): there a bless would turn any schema change into a
    /// pass, so it fails even when the document is current.
    fn on_stale(bless: bool, ci: Option<&str>, current: bool) -> Option<Stale> {
        let ci = ci.is_some_and(|v| !matches!(v, "" | "false" | "0"));
        match (bless, ci, current) {
            (true, true, _) => Some(Stale::Fail(
                "GAITD_BLESS is set in CI (CI=true): generated files are never rewritten in CI; \
                 bless locally (`GAITD_BLESS=1 cargo test -p shm_schema`) and commit the result",
            )),
            (_, _, true) => None,
            (true, false, false) => Some(Stale::Rewrite),
            (false, _, false) => Some(Stale::Fail(
                "is out of date: run `GAITD_BLESS=1 cargo test -p shm_schema` \
                 and commit the result",
            )),
        }
    }

    #[test]
    fn ci_never_blesses() {
        assert_eq!(on_stale(true, None, false), Some(Stale::Rewrite));
        assert_eq!(on_stale(true, Some("false"), false), Some(Stale::Rewrite));
        assert_eq!(on_stale(false, None, true), None);
        assert!(matches!(on_stale(false, None, false), Some(Stale::Fail(_))));
        for current in [false, true] {
            let Some(Stale::Fail(why)) = on_stale(true, Some("true"), current) else {
                panic!("blessed in CI");
            };
            assert!(why.contains("CI"), "{why}");
        }
    }

    /// Fails (or, blessed, rewrites the file) unless `path` holds `want`.
    fn generated_file_is_current(path: &str, want: &str) {
        let have = std::fs::read_to_string(path).unwrap_or_default();
        let ci = std::env::var("CI").ok();
        let bless = std::env::var_os("GAITD_BLESS").is_some();
        match on_stale(bless, ci.as_deref(), have == want) {
            None => {}
            Some(Stale::Rewrite) => std::fs::write(path, want).unwrap(),
            Some(Stale::Fail(why)) => panic!("{path}: {why}"),
        }
    }

    #[test]
    fn layout_document_is_current() {
        generated_file_is_current(
            concat!(env!("CARGO_MANIFEST_DIR"), "/LAYOUT.md"),
            &layout_markdown(),
        );
    }

    /// The Python package's mirror (`client/python/gaitd/layout.py`).
    #[test]
    fn python_layout_module_is_current() {
        generated_file_is_current(
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../client/python/gaitd/layout.py"
            ),
            &python_layout(),
        );
    }
}
