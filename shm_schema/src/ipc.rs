//! Where the iceoryx2 resources live, shared by the daemon and every client
//! (SPEC §7.3, §9).
//!
//! All peers must agree on three things: the iceoryx2 root path (static
//! configs, node records), the iceoryx2 file prefix (names in /dev/shm) and
//! the service-name prefix. Both sides resolve each the same way:
//! explicit setting → environment variable → built-in default. Tests and
//! developers give every instance its own triple so that parallel daemons
//! never collide. This module is pure: callers read the environment and the
//! iceoryx2 config file and pass the values in.

use iceoryx2::config::Config;
use iceoryx2::prelude::{FileName, Path, SemanticString};

/// Path of the shipped iceoryx2 config file in a service installation.
pub const DEFAULT_ICEORYX2_CONFIG: &str = "/etc/gaitd/iceoryx2.toml";

/// Default iceoryx2 root path: under the unit's `RuntimeDirectory=gaitd`,
/// never a private /tmp (SPEC §9).
pub const SERVICE_ROOT_PATH: &str = "/run/gaitd/iceoryx2/";

/// Default iceoryx2 file prefix (shared-memory names in /dev/shm).
pub const DEFAULT_FILE_PREFIX: &str = "gaitd_";

/// Environment variable: service-name prefix.
pub const ENV_PREFIX: &str = "GAITD_PREFIX";
/// Environment variable: iceoryx2 root path.
pub const ENV_ROOT_PATH: &str = "GAITD_IPC_ROOT";
/// Environment variable: iceoryx2 file prefix.
pub const ENV_FILE_PREFIX: &str = "GAITD_IPC_FILE_PREFIX";
/// Environment variable: iceoryx2 config file to load.
pub const ENV_ICEORYX2_CONFIG: &str = "GAITD_IPC_CONFIG";

/// iceoryx2 node name of the daemon.
pub const DAEMON_NODE_NAME: &str = "gaitd";
/// iceoryx2 node name of the daemon's housekeeping thread.
pub const HOUSEKEEPING_NODE_NAME: &str = "gaitd-housekeeping";

/// The default root path for a process of user `uid`: the service's
/// runtime directory when it exists (or when running as root), otherwise a
/// per-user directory under /tmp so that a developer's daemon and clients
/// agree without any setting.
pub fn default_root_path(uid: u32, run_dir_exists: bool) -> String {
    if uid == 0 || run_dir_exists {
        SERVICE_ROOT_PATH.to_owned()
    } else {
        format!("/tmp/gaitd-{uid}/iceoryx2/")
    }
}

/// The three values all peers must agree on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IpcSettings {
    /// Service-name prefix (default [`DEFAULT_PREFIX`](crate::DEFAULT_PREFIX)).
    pub service_prefix: String,
    /// iceoryx2 root path (absolute, ends with `/`).
    pub root_path: String,
    /// iceoryx2 file prefix.
    pub file_prefix: String,
}

/// Why [`IpcSettings`] cannot be applied.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IpcSettingsError {
    /// The root path is not an absolute path iceoryx2 accepts.
    BadRootPath,
    /// The file prefix is not a file name iceoryx2 accepts.
    BadFilePrefix,
    /// The service prefix is empty or contains characters outside `[A-Za-z0-9._/-]`.
    BadServicePrefix,
}

impl core::fmt::Display for IpcSettingsError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            IpcSettingsError::BadRootPath => "iceoryx2 root path must be an absolute path",
            IpcSettingsError::BadFilePrefix => {
                "iceoryx2 file prefix must be a plain file name (no '/')"
            }
            IpcSettingsError::BadServicePrefix => {
                "service prefix must be non-empty and use only [A-Za-z0-9._/-]"
            }
        })
    }
}

impl core::error::Error for IpcSettingsError {}

impl IpcSettings {
    /// Checks the values without touching any config.
    pub fn validate(&self) -> Result<(), IpcSettingsError> {
        let p = &self.service_prefix;
        let ok = !p.is_empty()
            && p.len() <= 200
            && p.bytes()
                .all(|b| b.is_ascii_alphanumeric() || b"._/-".contains(&b));
        if !ok {
            return Err(IpcSettingsError::BadServicePrefix);
        }
        if !self.root_path.starts_with('/') || Path::new(self.root_path.as_bytes()).is_err() {
            return Err(IpcSettingsError::BadRootPath);
        }
        if self.file_prefix.contains('/') || FileName::new(self.file_prefix.as_bytes()).is_err() {
            return Err(IpcSettingsError::BadFilePrefix);
        }
        Ok(())
    }

    /// Writes root path and file prefix into an iceoryx2 config (the other
    /// keys of the config are kept).
    pub fn apply(&self, config: &mut Config) -> Result<(), IpcSettingsError> {
        self.validate()?;
        let mut root = self.root_path.clone();
        if !root.ends_with('/') {
            root.push('/');
        }
        let root = Path::new(root.as_bytes()).map_err(|_| IpcSettingsError::BadRootPath)?;
        config.global.set_root_path(&root);
        config.global.prefix = FileName::new(self.file_prefix.as_bytes())
            .map_err(|_| IpcSettingsError::BadFilePrefix)?;
        Ok(())
    }
}

/// What a process asks for; `None` = not set explicitly (config key or
/// command-line flag). See the module docs for the resolution order.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct IpcRequest {
    /// Service-name prefix.
    pub service_prefix: Option<String>,
    /// iceoryx2 config file to load.
    pub iceoryx2_config: Option<String>,
    /// iceoryx2 root path.
    pub root_path: Option<String>,
    /// iceoryx2 file prefix.
    pub file_prefix: Option<String>,
}

impl IpcRequest {
    /// Fills every unset value from the environment (`env(name)`; empty
    /// values count as unset).
    pub fn or_env(mut self, env: impl Fn(&str) -> Option<String>) -> Self {
        let get = |k: &str| env(k).filter(|v| !v.is_empty());
        self.service_prefix = self.service_prefix.or_else(|| get(ENV_PREFIX));
        self.iceoryx2_config = self.iceoryx2_config.or_else(|| get(ENV_ICEORYX2_CONFIG));
        self.root_path = self.root_path.or_else(|| get(ENV_ROOT_PATH));
        self.file_prefix = self.file_prefix.or_else(|| get(ENV_FILE_PREFIX));
        self
    }

    /// The final settings: explicit values, else those of the loaded
    /// iceoryx2 config `file`, else the defaults.
    pub fn resolve(&self, file: Option<&Config>, uid: u32, run_dir_exists: bool) -> IpcSettings {
        IpcSettings {
            service_prefix: self
                .service_prefix
                .clone()
                .unwrap_or_else(|| crate::DEFAULT_PREFIX.to_owned()),
            root_path: self.root_path.clone().unwrap_or_else(|| match file {
                Some(c) => c.global.root_path().to_string(),
                None => default_root_path(uid, run_dir_exists),
            }),
            file_prefix: self.file_prefix.clone().unwrap_or_else(|| match file {
                Some(c) => c.global.prefix.as_str().to_owned(),
                None => DEFAULT_FILE_PREFIX.to_owned(),
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(prefix: &str, root: &str, file: &str) -> IpcSettings {
        IpcSettings {
            service_prefix: prefix.into(),
            root_path: root.into(),
            file_prefix: file.into(),
        }
    }

    #[test]
    fn settings_are_checked_and_applied() {
        let mut c = Config::default();
        s("gaitd", "/tmp/x/iceoryx2", "gx_").apply(&mut c).unwrap();
        assert_eq!(c.global.root_path().to_string(), "/tmp/x/iceoryx2/");
        assert_eq!(c.global.prefix.as_str(), "gx_");
        assert_eq!(
            s("", "/tmp", "a").validate(),
            Err(IpcSettingsError::BadServicePrefix)
        );
        assert_eq!(
            s("a b", "/tmp", "a").validate(),
            Err(IpcSettingsError::BadServicePrefix)
        );
        assert_eq!(
            s("a", "tmp", "a").validate(),
            Err(IpcSettingsError::BadRootPath)
        );
        assert_eq!(
            s("a", "/tmp", "a/b").validate(),
            Err(IpcSettingsError::BadFilePrefix)
        );
    }

    #[test]
    fn explicit_beats_env_beats_file_beats_default() {
        let env = |k: &str| match k {
            ENV_PREFIX => Some("from-env".to_owned()),
            ENV_FILE_PREFIX => Some(String::new()),
            _ => None,
        };
        let r = IpcRequest {
            root_path: Some("/explicit/".into()),
            ..Default::default()
        }
        .or_env(env);
        let mut file = Config::default();
        file.global.prefix = FileName::new(b"file_").unwrap();
        let s = r.resolve(Some(&file), 1000, false);
        assert_eq!(s.service_prefix, "from-env");
        assert_eq!(s.root_path, "/explicit/");
        assert_eq!(s.file_prefix, "file_");
        let s = IpcRequest::default().resolve(None, 1000, false);
        assert_eq!(s.file_prefix, DEFAULT_FILE_PREFIX);
        assert_eq!(s.root_path, "/tmp/gaitd-1000/iceoryx2/");
        assert_eq!(s.service_prefix, crate::DEFAULT_PREFIX);
    }

    #[test]
    fn default_root_follows_the_runtime_directory() {
        assert_eq!(default_root_path(0, false), SERVICE_ROOT_PATH);
        assert_eq!(default_root_path(1000, true), SERVICE_ROOT_PATH);
        assert_eq!(default_root_path(1000, false), "/tmp/gaitd-1000/iceoryx2/");
    }
}
