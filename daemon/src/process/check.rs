//! What `gaitd --check-config` prints: the configuration in effect, as
//! TOML that gaitd would accept. Unlike the file, it has the values the
//! daemon will use — environment overrides (`GAITD_PREFIX`, …) applied,
//! the iceoryx2 root path and file prefix resolved, derived defaults such
//! as `rt.writer_priority` filled in — and a comment on each `[ipc]`
//! location key saying where its value came from.

use crate::config::DaemonConfig;
use crate::io::ipc::{Origin, ResolvedIpc};

/// The configuration in effect for `cfg` (loaded from `path`) with its
/// IPC resolved as `ipc`.
pub fn effective_config(
    cfg: &DaemonConfig,
    ipc: &ResolvedIpc,
    path: &str,
) -> Result<String, toml::ser::Error> {
    let mut shown = cfg.clone();
    shown.rt.writer_priority = Some(cfg.rt.writer_fifo_priority());
    shown.plant.max_misses_in_row = Some(cfg.plant.misses_in_row_limit());
    let s = &ipc.settings;
    shown.ipc.service_prefix.clone_from(&s.service_prefix);
    shown.ipc.iceoryx2_config = ipc.iceoryx2_config.clone().unwrap_or_default();
    shown.ipc.root_path.clone_from(&s.root_path);
    shown.ipc.file_prefix.clone_from(&s.file_prefix);
    let text = toml::to_string_pretty(&shown)?;
    let mut out = format!(
        "# gaitd configuration in effect ({path}): environment overrides applied,\n\
         # defaults filled in; comments say where the [ipc] locations come from.\n\n"
    );
    let mut section = String::new();
    for line in text.lines() {
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            section = name.to_owned();
        }
        out.push_str(line);
        if let Some(note) = note(&section, line, cfg, ipc) {
            out.push_str("  # ");
            out.push_str(&note);
        }
        out.push('\n');
    }
    Ok(out)
}

/// The comment for `line` of `section`, if it gets one.
fn note(section: &str, line: &str, cfg: &DaemonConfig, ipc: &ResolvedIpc) -> Option<String> {
    let key = line.split_once(" = ").map(|(k, _)| k)?;
    let o = &ipc.origins;
    let origin = match (section, key) {
        ("ipc", "service_prefix") => o.service_prefix,
        ("ipc", "root_path") => o.root_path,
        ("ipc", "file_prefix") => o.file_prefix,
        ("ipc", "iceoryx2_config") if ipc.iceoryx2_config.is_none() => {
            return Some("none: iceoryx2's built-in defaults".into());
        }
        ("ipc", "iceoryx2_config") => o.iceoryx2_config,
        ("rt", "writer_priority") if cfg.rt.writer_priority.is_none() => {
            return Some("unset: derived from fifo_priority".into());
        }
        ("plant", "max_misses_in_row") if cfg.plant.max_misses_in_row.is_none() => {
            return Some("unset: the larger of 20 and 2 × max_missed".into());
        }
        _ => return None,
    };
    Some(match (origin, key) {
        (Origin::Default, "root_path") => {
            "default (as root or when /run/gaitd exists: /run/gaitd/iceoryx2/, else /tmp/gaitd-<uid>/iceoryx2/)".into()
        }
        _ => origin.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::ipc::IpcOrigins;
    use shm_schema::ipc::IpcSettings;

    fn resolved(origins: IpcOrigins, iceoryx2_config: Option<&str>) -> ResolvedIpc {
        ResolvedIpc {
            config: iceoryx2::config::Config::default(),
            settings: IpcSettings {
                service_prefix: "xyz".into(),
                root_path: "/tmp/r/".into(),
                file_prefix: "f_".into(),
            },
            iceoryx2_config: iceoryx2_config.map(str::to_owned),
            origins,
        }
    }

    fn line<'a>(text: &'a str, section: &str, key: &str) -> &'a str {
        let body = text
            .split(&format!("[{section}]\n"))
            .nth(1)
            .expect("section printed");
        body.lines()
            .find(|l| l.starts_with(&format!("{key} = ")))
            .expect("key printed")
    }

    #[test]
    fn ipc_values_in_effect_with_their_origins() {
        let cfg = DaemonConfig::default();
        let origins = IpcOrigins {
            service_prefix: Origin::Env("GAITD_PREFIX"),
            iceoryx2_config: Origin::Env("GAITD_IPC_CONFIG"),
            root_path: Origin::Iceoryx2Config,
            file_prefix: Origin::ConfigKey,
        };
        let text =
            effective_config(&cfg, &resolved(origins, Some("/x/iox.toml")), "a.toml").unwrap();
        assert_eq!(
            line(&text, "ipc", "service_prefix"),
            "service_prefix = \"xyz\"  # from $GAITD_PREFIX"
        );
        assert_eq!(
            line(&text, "ipc", "iceoryx2_config"),
            "iceoryx2_config = \"/x/iox.toml\"  # from $GAITD_IPC_CONFIG"
        );
        assert_eq!(
            line(&text, "ipc", "root_path"),
            "root_path = \"/tmp/r/\"  # from the iceoryx2 config file"
        );
        assert_eq!(
            line(&text, "ipc", "file_prefix"),
            "file_prefix = \"f_\"  # from the config file"
        );
        assert_eq!(
            line(&text, "rt", "writer_priority"),
            "writer_priority = 70  # unset: derived from fifo_priority"
        );
        // Still a configuration gaitd accepts, meaning the same.
        let back = DaemonConfig::from_toml(&text, "x").unwrap();
        assert_eq!(back.ipc.service_prefix, "xyz");
        assert_eq!(back.rt.writer_fifo_priority(), 70);
    }

    #[test]
    fn no_iceoryx2_config_and_defaults_say_so() {
        let origins = IpcOrigins {
            service_prefix: Origin::Default,
            iceoryx2_config: Origin::Default,
            root_path: Origin::Default,
            file_prefix: Origin::Default,
        };
        let text =
            effective_config(&DaemonConfig::default(), &resolved(origins, None), "a").unwrap();
        assert!(
            line(&text, "ipc", "iceoryx2_config")
                .ends_with("\"\"  # none: iceoryx2's built-in defaults")
        );
        assert!(line(&text, "ipc", "root_path").contains("# default ("));
        assert!(line(&text, "ipc", "file_prefix").ends_with("# default"));
    }
}
