//! Daemon configuration file (SPEC.md §7.1): TOML with the model sections of
//! [`gait::HandConfig`] (`[model]`, `[load]`, `[limits]`) plus `[control]`.
//! Every key is validated at start; errors name the key.

use gait::config::{FeedbackConfig, LimitsConfig, LoadConfig, ModelConfig, PlannerConfig};
use gait::{ConfigError, HandConfig};
use serde::{Deserialize, Serialize};

/// Default path of the service's configuration file.
pub const DEFAULT_CONFIG_PATH: &str = "/etc/gaitd/gaitd.toml";

/// `[control]`: the control loop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlConfig {
    /// Control loop rate [Hz] (SPEC §6.1: 100 Hz – 10 kHz, default 1 kHz).
    pub tick_hz: f64,
}

impl Default for ControlConfig {
    fn default() -> Self {
        Self { tick_hz: 1000.0 }
    }
}

/// The whole daemon configuration file.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DaemonConfig {
    /// `[model]`: geometry, friction, workspace, margins.
    pub model: ModelConfig,
    /// `[load]`: object load.
    pub load: LoadConfig,
    /// `[limits]`: motion limits.
    pub limits: LimitsConfig,
    /// `[planner]`: planner tuning.
    pub planner: PlannerConfig,
    /// `[feedback]`: fault detection.
    pub feedback: FeedbackConfig,
    /// `[control]`: loop rate.
    pub control: ControlConfig,
}

/// Why a configuration file could not be used.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("cannot read config file {path}: {source}")]
    Io {
        /// Path as given.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// The file is not valid TOML for this schema (unknown key, wrong type).
    #[error("config file {path}: {message}")]
    Parse {
        /// Path as given.
        path: String,
        /// The parser's message (names the key and line).
        message: String,
    },
    /// A value is out of range.
    #[error("config file {path}: {source}")]
    Invalid {
        /// Path as given.
        path: String,
        /// Which key and why.
        source: ConfigError,
    },
}

impl DaemonConfig {
    /// The model part, as the maths crate wants it.
    pub fn hand(&self) -> HandConfig {
        HandConfig {
            model: self.model,
            load: self.load,
            limits: self.limits,
            planner: self.planner,
            feedback: self.feedback,
        }
    }

    /// Validates every key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.hand().validate()?;
        let hz = self.control.tick_hz;
        if !hz.is_finite() {
            return Err(ConfigError::NotFinite {
                key: "control.tick_hz",
                value: hz,
            });
        }
        if !(100.0..=10_000.0).contains(&hz) {
            return Err(ConfigError::OutOfRange {
                key: "control.tick_hz",
                value: hz,
                expected: "in [100, 10000] Hz",
            });
        }
        Ok(())
    }

    /// Parses and validates TOML text; `path` is only used in messages.
    pub fn from_toml(text: &str, path: &str) -> Result<Self, LoadError> {
        let cfg: DaemonConfig = toml::from_str(text).map_err(|e| LoadError::Parse {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        cfg.validate().map_err(|source| LoadError::Invalid {
            path: path.to_owned(),
            source,
        })?;
        Ok(cfg)
    }

    /// Reads, parses and validates a file.
    pub fn load(path: &str) -> Result<Self, LoadError> {
        let text = std::fs::read_to_string(path).map_err(|source| LoadError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::from_toml(&text, path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_file_is_the_default() {
        let c = DaemonConfig::from_toml("", "x.toml").unwrap();
        assert_eq!(c, DaemonConfig::default());
    }

    #[test]
    fn errors_name_the_key() {
        let e = DaemonConfig::from_toml("[control]\ntick_hz = 50\n", "x.toml").unwrap_err();
        assert!(e.to_string().contains("control.tick_hz"), "{e}");
        let e = DaemonConfig::from_toml("[control]\ntick_rate = 50\n", "x.toml").unwrap_err();
        assert!(e.to_string().contains("tick_rate"), "{e}");
        let e = DaemonConfig::from_toml(
            "[limits.object]\nvelocity = -1\nacceleration = 4\njerk = 40\n",
            "x.toml",
        )
        .unwrap_err();
        assert!(e.to_string().contains("limits.object.velocity"), "{e}");
    }
}
