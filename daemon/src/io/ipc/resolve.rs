//! Where the daemon's iceoryx2 resources live: its `[ipc]` section
//! resolved (explicit keys → environment → iceoryx2 config file →
//! defaults, as every client resolves them), with where each value came
//! from for `gaitd --check-config`.

use super::IpcError;
use crate::config::IpcSection;
use iceoryx2::config::Config;
use iceoryx2::prelude::*;
use shm_schema::ipc::{
    ENV_FILE_PREFIX, ENV_ICEORYX2_CONFIG, ENV_PREFIX, ENV_ROOT_PATH, IpcRequest, IpcSettings,
    IpcSettingsError,
};

/// Where a resolved IPC value came from (`gaitd --check-config` says it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// Its `[ipc]` key in the daemon's config file.
    ConfigKey,
    /// An environment variable.
    Env(&'static str),
    /// The iceoryx2 config file that was loaded.
    Iceoryx2Config,
    /// The built-in default.
    Default,
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Origin::ConfigKey => f.write_str("from the config file"),
            Origin::Env(var) => write!(f, "from ${var}"),
            Origin::Iceoryx2Config => f.write_str("from the iceoryx2 config file"),
            Origin::Default => f.write_str("default"),
        }
    }
}

/// Where each value of a [`ResolvedIpc`] came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IpcOrigins {
    /// Of the service prefix.
    pub service_prefix: Origin,
    /// Of the iceoryx2 config file's path (`Default`: none loaded).
    pub iceoryx2_config: Origin,
    /// Of the root path.
    pub root_path: Origin,
    /// Of the file prefix.
    pub file_prefix: Origin,
}

impl IpcOrigins {
    /// The origins under the resolution order of [`IpcRequest`]: the
    /// explicit key, then the environment (`env`, empty counts as unset),
    /// then the iceoryx2 config file if one was loaded, then the default.
    pub fn of(ipc: &IpcSection, env: impl Fn(&str) -> Option<String>, file_loaded: bool) -> Self {
        let pick = |key: &str, var: &'static str, from_file: bool| {
            if !key.is_empty() {
                Origin::ConfigKey
            } else if env(var).is_some_and(|v| !v.is_empty()) {
                Origin::Env(var)
            } else if from_file {
                Origin::Iceoryx2Config
            } else {
                Origin::Default
            }
        };
        Self {
            service_prefix: pick(&ipc.service_prefix, ENV_PREFIX, false),
            iceoryx2_config: pick(&ipc.iceoryx2_config, ENV_ICEORYX2_CONFIG, false),
            root_path: pick(&ipc.root_path, ENV_ROOT_PATH, file_loaded),
            file_prefix: pick(&ipc.file_prefix, ENV_FILE_PREFIX, file_loaded),
        }
    }
}

/// What a daemon's `[ipc]` section resolves to, with where each value
/// came from.
#[derive(Debug, Clone)]
pub struct ResolvedIpc {
    /// The iceoryx2 config to use (the file's, root path and file prefix
    /// applied).
    pub config: Config,
    /// The values all peers must agree on.
    pub settings: IpcSettings,
    /// The iceoryx2 config file loaded, if any.
    pub iceoryx2_config: Option<String>,
    /// Where each value came from.
    pub origins: IpcOrigins,
}

/// Loads the iceoryx2 config a daemon with `ipc` settings uses and the
/// resolved settings (explicit keys → environment → config file → defaults).
pub fn resolve(ipc: &IpcSection) -> Result<(Config, IpcSettings), IpcError> {
    resolve_explained(ipc).map(|r| (r.config, r.settings))
}

/// [`resolve`], keeping where each value came from.
pub fn resolve_explained(ipc: &IpcSection) -> Result<ResolvedIpc, IpcError> {
    let env = |k: &str| std::env::var(k).ok();
    let opt = |s: &String| (!s.is_empty()).then(|| s.clone());
    let req = IpcRequest {
        service_prefix: opt(&ipc.service_prefix),
        iceoryx2_config: opt(&ipc.iceoryx2_config),
        root_path: opt(&ipc.root_path),
        file_prefix: opt(&ipc.file_prefix),
    }
    .or_env(env);
    let file = match &req.iceoryx2_config {
        Some(path) => Some(load_iceoryx2_config(path)?),
        None => None,
    };
    let origins = IpcOrigins::of(ipc, env, file.is_some());
    // SAFETY: getuid has no preconditions.
    let uid = unsafe { libc::getuid() };
    let run_dir = std::path::Path::new("/run/gaitd").is_dir();
    let settings = req.resolve(file.as_ref(), uid, run_dir);
    let mut config = file.unwrap_or_default();
    settings.apply(&mut config).map_err(|error| {
        let (value, origin) = match error {
            IpcSettingsError::BadServicePrefix => {
                (&settings.service_prefix, origins.service_prefix)
            }
            IpcSettingsError::BadRootPath => (&settings.root_path, origins.root_path),
            IpcSettingsError::BadFilePrefix => (&settings.file_prefix, origins.file_prefix),
        };
        IpcError::BadSetting {
            error,
            value: value.clone(),
            origin,
        }
    })?;
    Ok(ResolvedIpc {
        config,
        settings,
        iceoryx2_config: req.iceoryx2_config,
        origins,
    })
}

fn load_iceoryx2_config(path: &str) -> Result<Config, IpcError> {
    let bad = |e: &dyn std::fmt::Debug| IpcError::ConfigFile {
        path: path.to_owned(),
        why: format!("{e:?}"),
    };
    let fp = FilePath::new(path.as_bytes()).map_err(|e| bad(&e))?;
    Config::from_file(&fp).map_err(|e| bad(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn origins_follow_the_resolution_order() {
        let env = |k: &str| match k {
            ENV_PREFIX => Some("from-env".to_owned()),
            ENV_ROOT_PATH => Some(String::new()),
            ENV_FILE_PREFIX => Some("f_".to_owned()),
            _ => None,
        };
        let ipc = IpcSection {
            file_prefix: "explicit_".into(),
            ..IpcSection::default()
        };
        let o = IpcOrigins::of(&ipc, env, true);
        assert_eq!(o.service_prefix, Origin::Env(ENV_PREFIX));
        assert_eq!(o.iceoryx2_config, Origin::Default);
        // An empty variable counts as unset: the loaded file decides.
        assert_eq!(o.root_path, Origin::Iceoryx2Config);
        assert_eq!(o.file_prefix, Origin::ConfigKey);
        assert_eq!(IpcOrigins::of(&ipc, env, false).root_path, Origin::Default);
        assert_eq!(Origin::Env(ENV_PREFIX).to_string(), "from $GAITD_PREFIX");
    }
}
