//! Keeping the newest N traces: after each trace is written, the oldest
//! finished traces beyond `TraceSettings::keep` are removed (by
//! modification time, then name). Only files of the daemon's naming
//! pattern count; other files in the directory are never touched.

use super::format::is_trace_name;
use std::path::{Path, PathBuf};

/// Removes the oldest traces in `dir` beyond `keep` (0: keep all); returns
/// how many were removed.
pub fn prune(dir: &Path, keep: usize) -> u64 {
    if keep == 0 {
        return 0;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut traces: Vec<(std::time::SystemTime, PathBuf)> = entries
        .flatten()
        .filter(|e| is_trace_name(&e.file_name().to_string_lossy()))
        .filter_map(|e| {
            let m = e.metadata().ok()?;
            m.is_file()
                .then(|| (m.modified().unwrap_or(std::time::UNIX_EPOCH), e.path()))
        })
        .collect();
    if traces.len() <= keep {
        return 0;
    }
    traces.sort();
    let excess = traces.len() - keep;
    let mut removed = 0;
    for (_, path) in traces.into_iter().take(excess) {
        match std::fs::remove_file(&path) {
            Ok(()) => removed += 1,
            Err(e) => {
                tracing::warn!(path = %path.display(), error = %e, "trace: cannot remove an old trace")
            }
        }
    }
    removed
}
