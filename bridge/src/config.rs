//! The bridge's configuration file (TOML), checked at start with a message
//! naming the key at fault (`deploy/gaitd-bridge.toml` documents every key).

use gaitd_client::remote::protocol as proto;
use serde::Deserialize;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Default listen endpoint: loopback only, mutual TLS.
pub const DEFAULT_LISTEN: &str = "quic/127.0.0.1:7460";

/// A configuration mistake, naming the key.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file cannot be read.
    #[error("cannot read {}: {why}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        why: String,
    },
    /// The TOML does not parse or has unknown keys.
    #[error("{}: {why}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message (names the key and line).
        why: String,
    },
    /// A value is out of range or inconsistent.
    #[error("{key}: {why}")]
    Invalid {
        /// The key, e.g. `bridge.status_rate_hz`.
        key: String,
        /// What is wrong.
        why: String,
    },
}

fn invalid(key: impl Into<String>, why: impl Into<String>) -> ConfigError {
    ConfigError::Invalid {
        key: key.into(),
        why: why.into(),
    }
}

/// Where gaitd is (as `gaitctl`'s flags; empty = environment, then the
/// iceoryx2 config file, then the defaults).
#[derive(Debug, Clone, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct GaitdSection {
    /// iceoryx2 config file, e.g. `/etc/gaitd/iceoryx2.toml`.
    pub iceoryx2_config: String,
    /// Service-name prefix.
    pub service_prefix: String,
    /// iceoryx2 root path.
    pub root_path: String,
    /// iceoryx2 file prefix.
    pub file_prefix: String,
}

/// The Zenoh side.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct ZenohSection {
    /// Endpoints to listen on (only `quic/` and `tls/`, both mutual TLS);
    /// loopback unless configured.
    pub listen: Vec<String>,
    /// Key prefix of every key.
    pub key_prefix: String,
    /// The private CA's certificate: clients must present a certificate it signed.
    pub ca: PathBuf,
    /// The bridge's certificate (signed by the CA; its names must match
    /// the host names clients connect to).
    pub cert: PathBuf,
    /// The bridge's private key.
    pub key: PathBuf,
    /// The bridge's Zenoh lease: its clients notice a bridge that died
    /// within it (they read it from the bridge at connection) \[ms\].
    pub lease_ms: u64,
}

impl Default for ZenohSection {
    fn default() -> Self {
        Self {
            listen: vec![DEFAULT_LISTEN.to_owned()],
            key_prefix: proto::DEFAULT_KEY_PREFIX.to_owned(),
            ca: "/etc/gaitd/pki/ca.pem".into(),
            cert: "/etc/gaitd/pki/bridge.pem".into(),
            key: "/etc/gaitd/pki/bridge.key".into(),
            lease_ms: 3000,
        }
    }
}

/// What the bridge does when a remote operator's last session vanishes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ClientLostPolicy {
    /// Send Hold on its behalf if its goal is running.
    Hold,
    /// Cancel its goal if it is running.
    Cancel,
    /// Nothing (the goal runs on).
    None,
}

/// Forwarding settings.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct BridgeSection {
    /// Status forwarded per second at most (latest value) \[Hz\].
    pub status_rate_hz: f64,
    /// Events kept for late joiners.
    pub event_cache: usize,
    /// Period of the event publisher's heartbeat (miss detection of the
    /// last events) \[ms\].
    pub heartbeat_ms: u64,
    /// How long a command waits for the daemon's answer \[ms\].
    pub command_timeout_ms: u64,
    /// When a remote operator's last session has been gone for
    /// `client_lost_grace_ms`.
    pub on_client_lost: ClientLostPolicy,
    /// How long an operator's last session may be gone before
    /// `on_client_lost` applies: a link that drops and reconnects within
    /// it (Zenoh does at once) does not stop the goal \[ms\].
    pub client_lost_grace_ms: u64,
    /// A client session that sent no beat (a put on its own
    /// `P/clients/<identity>/<session>`, PROTOCOL.md "Lost clients") for
    /// this long is gone, whatever its Zenoh lease \[ms\].
    pub client_beat_timeout_ms: u64,
    /// After the bridge (re)starts, how long operators have to connect
    /// again before one whose goal runs (the daemon's status says whose it
    /// is) counts as gone, the grace period then following \[ms\].
    pub reconnect_wait_ms: u64,
}

impl Default for BridgeSection {
    fn default() -> Self {
        Self {
            status_rate_hz: 100.0,
            event_cache: 64,
            heartbeat_ms: 500,
            command_timeout_ms: 1000,
            on_client_lost: ClientLostPolicy::Cancel,
            client_lost_grace_ms: 1000,
            client_beat_timeout_ms: 1500,
            reconnect_wait_ms: 2000,
        }
    }
}

/// Per-identity command rate limit (a token bucket).
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct RateLimitSection {
    /// Sustained commands per second per identity.
    pub commands_per_second: f64,
    /// Commands allowed at once above the sustained rate.
    pub burst: u32,
}

impl Default for RateLimitSection {
    fn default() -> Self {
        Self {
            commands_per_second: 20.0,
            burst: 10,
        }
    }
}

/// What an identity may do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Read status and events, send commands.
    Operator,
    /// Read status and events only.
    Monitor,
}

/// One client identity: a certificate common name and its role.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Identity {
    /// The certificate's common name.
    pub name: String,
    /// Operator or monitor.
    pub role: Role,
}

/// The whole file.
#[derive(Debug, Clone, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct Config {
    /// Where gaitd is.
    pub gaitd: GaitdSection,
    /// The Zenoh side.
    pub zenoh: ZenohSection,
    /// Forwarding.
    pub bridge: BridgeSection,
    /// Command rate limit.
    pub rate_limit: RateLimitSection,
    /// Who may connect; everyone else is denied.
    #[serde(rename = "identity")]
    pub identities: Vec<Identity>,
}

impl Config {
    /// Reads and checks a file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError::Read {
            path: path.to_owned(),
            why: e.to_string(),
        })?;
        Self::parse(&text, path)
    }

    /// Parses and checks TOML text (`path` for messages only).
    pub fn parse(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let c: Config = toml::from_str(text).map_err(|e| ConfigError::Parse {
            path: path.to_owned(),
            why: e.to_string(),
        })?;
        c.validate()?;
        Ok(c)
    }

    /// Checks every value (not the files: see [`Config::check_files`]).
    pub fn validate(&self) -> Result<(), ConfigError> {
        let z = &self.zenoh;
        if z.listen.is_empty() {
            return Err(invalid("zenoh.listen", "at least one endpoint"));
        }
        for ep in &z.listen {
            let ok = link_address(ep).is_some_and(|a| {
                a.rsplit_once(':')
                    .is_some_and(|(h, p)| !h.is_empty() && p.parse::<u16>().is_ok())
            });
            if !ok {
                return Err(invalid(
                    "zenoh.listen",
                    format!("`{ep}`: only quic/HOST:PORT or tls/HOST:PORT (mutual TLS) is offered"),
                ));
            }
        }
        if !proto::prefix_valid(&z.key_prefix) {
            return Err(invalid(
                "zenoh.key_prefix",
                "non-empty chunks of [A-Za-z0-9._-] separated by /",
            ));
        }
        let b = &self.bridge;
        if !(b.status_rate_hz > 0.0 && b.status_rate_hz <= 1000.0) {
            return Err(invalid("bridge.status_rate_hz", "must be in (0, 1000]"));
        }
        if !(1..=4096).contains(&b.event_cache) {
            return Err(invalid("bridge.event_cache", "must be in 1..=4096"));
        }
        if !(10..=60_000).contains(&b.heartbeat_ms) {
            return Err(invalid("bridge.heartbeat_ms", "must be in 10..=60000"));
        }
        if !(10..=60_000).contains(&b.command_timeout_ms) {
            return Err(invalid(
                "bridge.command_timeout_ms",
                "must be in 10..=60000",
            ));
        }
        if b.client_lost_grace_ms > 60_000 {
            return Err(invalid(
                "bridge.client_lost_grace_ms",
                "must be in 0..=60000",
            ));
        }
        if !(100..=600_000).contains(&b.client_beat_timeout_ms) {
            return Err(invalid(
                "bridge.client_beat_timeout_ms",
                "must be in 100..=600000",
            ));
        }
        if b.reconnect_wait_ms > 600_000 {
            return Err(invalid("bridge.reconnect_wait_ms", "must be in 0..=600000"));
        }
        if !(500..=600_000).contains(&self.zenoh.lease_ms) {
            return Err(invalid("zenoh.lease_ms", "must be in 500..=600000"));
        }
        let r = &self.rate_limit;
        if !(r.commands_per_second > 0.0 && r.commands_per_second.is_finite()) {
            return Err(invalid("rate_limit.commands_per_second", "must be > 0"));
        }
        if r.burst == 0 {
            return Err(invalid("rate_limit.burst", "must be at least 1"));
        }
        let mut seen = HashSet::new();
        for (i, id) in self.identities.iter().enumerate() {
            if !proto::identity_valid(&id.name) {
                return Err(invalid(
                    format!("identity[{i}].name"),
                    format!(
                        "`{}`: 1-64 characters of [A-Za-z0-9._-] (a certificate common name)",
                        id.name
                    ),
                ));
            }
            if !seen.insert(id.name.as_str()) {
                return Err(invalid(
                    format!("identity[{i}].name"),
                    format!("`{}` is listed twice", id.name),
                ));
            }
        }
        Ok(())
    }

    /// Checks that the three PEM files can be read.
    pub fn check_files(&self) -> Result<(), ConfigError> {
        for (key, path) in [
            ("zenoh.ca", &self.zenoh.ca),
            ("zenoh.cert", &self.zenoh.cert),
            ("zenoh.key", &self.zenoh.key),
        ] {
            let text = std::fs::read(path)
                .map_err(|e| invalid(key, format!("{}: {e}", path.display())))?;
            if !text.windows(11).any(|w| w == b"-----BEGIN ") {
                return Err(invalid(key, format!("{}: not a PEM file", path.display())));
            }
        }
        Ok(())
    }

    /// The role of an identity, if it is configured.
    pub fn role(&self, name: &str) -> Option<Role> {
        self.identities
            .iter()
            .find(|i| i.name == name)
            .map(|i| i.role)
    }

    /// The status period.
    pub fn status_period(&self) -> Duration {
        Duration::from_secs_f64(1.0 / self.bridge.status_rate_hz)
    }

    /// Whether any listen endpoint is reachable from other hosts.
    pub fn listens_beyond_loopback(&self) -> bool {
        self.zenoh.listen.iter().any(|ep| {
            let host = link_address(ep)
                .and_then(|a| a.rsplit_once(':'))
                .map_or("", |(h, _)| h);
            !(host == "localhost" || host.starts_with("127.") || host == "[::1]")
        })
    }
}

/// `HOST:PORT` of a `quic/` or `tls/` endpoint (the links the bridge offers).
pub fn link_address(ep: &str) -> Option<&str> {
    ep.strip_prefix("quic/").or_else(|| ep.strip_prefix("tls/"))
}

/// The Zenoh link protocols of `endpoints` (`quic`, `tls`), each once.
pub fn link_protocols(endpoints: &[String]) -> Vec<&'static str> {
    ["quic", "tls"]
        .into_iter()
        .filter(|p| endpoints.iter().any(|e| e.starts_with(&format!("{p}/"))))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Config, ConfigError> {
        Config::parse(text, Path::new("bridge.toml"))
    }

    #[test]
    fn defaults_are_loopback_and_deny_everyone() {
        let c = parse("").unwrap();
        assert_eq!(c.zenoh.listen, vec![DEFAULT_LISTEN]);
        assert!(!c.listens_beyond_loopback());
        assert!(c.identities.is_empty());
        assert_eq!(c.bridge.on_client_lost, ClientLostPolicy::Cancel);
        assert_eq!(c.status_period(), Duration::from_millis(10));
    }

    #[test]
    fn identities_and_roles() {
        let c = parse(
            "[[identity]]\nname = \"op\"\nrole = \"operator\"\n\
             [[identity]]\nname = \"dash\"\nrole = \"monitor\"\n",
        )
        .unwrap();
        assert_eq!(c.role("op"), Some(Role::Operator));
        assert_eq!(c.role("dash"), Some(Role::Monitor));
        assert_eq!(c.role("nobody"), None);
    }

    #[test]
    fn mistakes_name_their_key() {
        let cases = [
            ("[zenoh]\nlisten = [\"tcp/0.0.0.0:7460\"]", "zenoh.listen"),
            ("[zenoh]\nlisten = []", "zenoh.listen"),
            ("[zenoh]\nkey_prefix = \"a/*\"", "zenoh.key_prefix"),
            ("[bridge]\nstatus_rate_hz = 0", "bridge.status_rate_hz"),
            ("[bridge]\nevent_cache = 0", "bridge.event_cache"),
            (
                "[bridge]\nclient_lost_grace_ms = 60001",
                "bridge.client_lost_grace_ms",
            ),
            (
                "[bridge]\nclient_beat_timeout_ms = 50",
                "bridge.client_beat_timeout_ms",
            ),
            (
                "[bridge]\nreconnect_wait_ms = 600001",
                "bridge.reconnect_wait_ms",
            ),
            ("[zenoh]\nlease_ms = 100", "zenoh.lease_ms"),
            ("[rate_limit]\nburst = 0", "rate_limit.burst"),
            (
                "[[identity]]\nname = \"a/b\"\nrole = \"operator\"",
                "identity[0].name",
            ),
            (
                "[[identity]]\nname = \"a\"\nrole = \"operator\"\n[[identity]]\nname = \"a\"\nrole = \"monitor\"",
                "identity[1].name",
            ),
        ];
        for (text, key) in cases {
            let e = parse(text).unwrap_err().to_string();
            assert!(e.starts_with(key), "{text}: {e}");
        }
        let e = parse("[bridge]\nrate = 1").unwrap_err().to_string();
        assert!(e.contains("unknown field"), "{e}");
        let e = parse("[[identity]]\nname = \"a\"\nrole = \"admin\"")
            .unwrap_err()
            .to_string();
        assert!(e.contains("admin"), "{e}");
    }

    #[test]
    fn beyond_loopback_is_noticed() {
        let c = parse("[zenoh]\nlisten = [\"tls/0.0.0.0:7460\"]").unwrap();
        assert!(c.listens_beyond_loopback());
        let c =
            parse("[zenoh]\nlisten = [\"quic/127.0.0.1:7460\", \"quic/10.0.0.7:7460\"]").unwrap();
        assert!(c.listens_beyond_loopback());
    }

    #[test]
    fn links_offered_are_quic_and_tls() {
        let eps = |v: &[&str]| v.iter().map(|s| (*s).to_owned()).collect::<Vec<_>>();
        assert_eq!(link_protocols(&eps(&["quic/a:1"])), ["quic"]);
        assert_eq!(
            link_protocols(&eps(&["tls/a:1", "quic/b:2", "tls/c:3"])),
            ["quic", "tls"]
        );
        assert_eq!(link_address("quic/a:1"), Some("a:1"));
        assert_eq!(link_address("udp/a:1"), None);
        assert!(parse("[zenoh]\nlisten = [\"udp/127.0.0.1:7460\"]").is_err());
    }

    #[test]
    fn the_example_in_deploy_is_the_defaults_on_loopback() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../deploy/gaitd-bridge.toml");
        let c = Config::load(&path).unwrap();
        assert!(!c.listens_beyond_loopback(), "{:?}", c.zenoh.listen);
        let d = Config::default();
        assert_eq!(
            (&c.gaitd, &c.zenoh, &c.bridge, &c.rate_limit),
            (&d.gaitd, &d.zenoh, &d.bridge, &d.rate_limit),
            "deploy/gaitd-bridge.toml documents values other than the defaults"
        );
        assert_eq!(c.role("operator"), Some(Role::Operator));
        assert_eq!(c.role("dashboard"), Some(Role::Monitor));
    }
}
