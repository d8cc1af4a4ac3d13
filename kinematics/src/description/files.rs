//! A description from its files: the hand section file and the URDF it
//! names (its `urdf` key, relative to the section's folder). The caller
//! does the reading (`read`): this crate does no I/O.

use std::path::{Path, PathBuf};

use super::HandDescription;
use crate::error::DescriptionError;
use crate::section::HandSection;

/// Why a description could not be had from its files; each names the
/// hand section file.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// A file could not be read.
    #[error("{path}: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The reader's error.
        source: std::io::Error,
    },
    /// The hand section names no URDF.
    #[error("{0}: the key `urdf` (the hand's URDF file) is missing")]
    NoUrdf(PathBuf),
    /// The description is not a valid hand.
    #[error("{path}: {source}")]
    Description {
        /// The hand section file.
        path: PathBuf,
        /// What is wrong.
        source: DescriptionError,
    },
}

impl HandDescription {
    /// The hand the section file `section_path` describes, with the URDF
    /// it names, each file read by `read`.
    pub fn load(
        section_path: &Path,
        read: impl Fn(&Path) -> std::io::Result<String>,
    ) -> Result<HandDescription, LoadError> {
        let read = |path: &Path| {
            read(path).map_err(|source| LoadError::Read {
                path: path.to_path_buf(),
                source,
            })
        };
        let invalid = |source| LoadError::Description {
            path: section_path.to_path_buf(),
            source,
        };
        let sec: HandSection = toml::from_str(&read(section_path)?)
            .map_err(|e| invalid(DescriptionError::Section(super::one_line(&e))))?;
        let urdf_name = sec
            .urdf
            .as_deref()
            .ok_or_else(|| LoadError::NoUrdf(section_path.to_path_buf()))?;
        let dir = section_path.parent().unwrap_or(Path::new("."));
        let robot = urdf_rs::read_from_string(&read(&dir.join(urdf_name))?)
            .map_err(|e| invalid(DescriptionError::Urdf(super::one_line(&e))))?;
        Self::from_parts(&robot, &sec).map_err(invalid)
    }
}
