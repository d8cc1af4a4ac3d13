//! What a plant reads of the daemon's configuration file: the model and
//! load (the hand it simulates) or `[hand]`'s chain hand (its description
//! and start grasp), the control rate, `[plant] timing` and `[ipc]` (how
//! to reach the daemon). The other sections are the daemon's.

use crate::common::ConnArgs;
use gait::planner::chains::ChainHand;
use gait::{HandConfig, HandState};
use gaitd_client::ConnectOptions;
use gaitd_client::plant::Pacing;
use std::path::Path;

/// A chain hand as the daemon's `[hand]` describes it: the hand, and
/// the grasp it starts in.
#[derive(Debug, Clone)]
pub struct ChainSetup {
    /// The hand (its description, with `[hand]`'s margins).
    pub hand: ChainHand,
    /// The start grasp (`hand.start_normals`).
    pub start: HandState,
}

/// The `[hand]` keys a plant reads (the daemon checks them all).
#[derive(Debug, Default, serde::Deserialize)]
#[serde(default)]
struct HandKeys {
    kind: String,
    description: String,
    patch_margin_deg: Option<f64>,
    link_clearance: Option<f64>,
    finger_gap: Option<f64>,
    start_normals: Vec<[f64; 3]>,
}

/// The plant's view of a daemon config file.
#[derive(Debug, Clone)]
pub struct PlantView {
    /// Model, load, limits, planner and feedback sections.
    pub hand: HandConfig,
    /// `[control] tick_hz`.
    pub tick_hz: f64,
    /// `[plant] timing`.
    pub timing: Pacing,
    /// `[ipc]` keys given in the file.
    pub prefix: Option<String>,
    /// `[ipc] root_path`.
    pub root_path: Option<String>,
    /// `[ipc] file_prefix`.
    pub file_prefix: Option<String>,
    /// `[ipc] iceoryx2_config`.
    pub iceoryx2_config: Option<String>,
    /// `[hand] kind = "chains"`: the chain hand.
    pub chains: Option<ChainSetup>,
}

fn string(t: &toml::Table, section: &str, key: &str) -> Option<String> {
    t.get(section)?
        .get(key)?
        .as_str()
        .filter(|s| !s.is_empty())
        .map(str::to_owned)
}

impl PlantView {
    /// Reads `path`.
    pub fn load(path: &str) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read {path}: {e}"))?;
        let t: toml::Table = text.parse().map_err(|e| format!("{path}: {e}"))?;
        let mut hand = toml::Table::new();
        for s in ["model", "load", "limits", "planner", "feedback"] {
            if let Some(v) = t.get(s) {
                hand.insert(s.into(), v.clone());
            }
        }
        let hand: HandConfig = toml::Value::Table(hand)
            .try_into()
            .map_err(|e| format!("{path}: {e}"))?;
        hand.validate().map_err(|e| format!("{path}: {e}"))?;
        let tick_hz = t
            .get("control")
            .and_then(|c| c.get("tick_hz"))
            .map_or(Some(1000.0), toml::Value::as_float)
            .ok_or_else(|| format!("{path}: control.tick_hz must be a number"))?;
        if !(100.0..=10_000.0).contains(&tick_hz) {
            return Err(format!(
                "{path}: control.tick_hz = {tick_hz} is out of [100, 10000] Hz"
            ));
        }
        let timing = match string(&t, "plant", "timing").as_deref() {
            None | Some("realtime") => Pacing::Realtime,
            Some("lockstep") => Pacing::Lockstep,
            Some(other) => {
                return Err(format!(
                    "{path}: plant.timing = \"{other}\" (expected \"realtime\" or \"lockstep\")"
                ));
            }
        };
        let chains = match t.get("hand") {
            Some(h) => chain_setup(path, h, &hand)?,
            None => None,
        };
        Ok(Self {
            hand,
            chains,
            tick_hz,
            timing,
            prefix: string(&t, "ipc", "service_prefix"),
            root_path: string(&t, "ipc", "root_path"),
            file_prefix: string(&t, "ipc", "file_prefix"),
            iceoryx2_config: string(&t, "ipc", "iceoryx2_config"),
        })
    }

    /// The control period \[ns\].
    pub fn period_ns(&self) -> u64 {
        (1e9 / self.tick_hz).round() as u64
    }

    /// How to reach the daemon: the command line first, then the file (the
    /// environment and defaults apply as for every client).
    pub fn connect_options(&self, conn: &ConnArgs) -> ConnectOptions {
        let mut o = ConnectOptions::new()
            .timeout(conn.timeout().max(std::time::Duration::from_secs(5)))
            .node_name("gaitd-plant");
        o.ipc.service_prefix = conn.prefix.clone().or_else(|| self.prefix.clone());
        o.ipc.root_path = conn.ipc_root.clone().or_else(|| self.root_path.clone());
        o.ipc.file_prefix = conn
            .ipc_file_prefix
            .clone()
            .or_else(|| self.file_prefix.clone());
        o.ipc.iceoryx2_config = conn
            .ipc_config
            .clone()
            .or_else(|| self.iceoryx2_config.clone());
        o
    }
}

/// The chain hand `[hand]` (`section`, of the file at `path`) describes,
/// if it is one.
fn chain_setup(
    path: &str,
    section: &toml::Value,
    config: &HandConfig,
) -> Result<Option<ChainSetup>, String> {
    let keys: HandKeys = section
        .clone()
        .try_into()
        .map_err(|e| format!("{path}: [hand]: {e}"))?;
    if keys.kind != "chains" {
        return Ok(None);
    }
    if keys.start_normals.len() != 3 {
        return Err(format!(
            "{path}: hand.start_normals: one contact normal per finger, three"
        ));
    }
    let dir = Path::new(path).parent().unwrap_or(Path::new("."));
    let description = kinematics::HandDescription::load(&dir.join(&keys.description), |p| {
        std::fs::read_to_string(p)
    })
    .map_err(|e| format!("{path}: hand.description: {e}"))?;
    let limits = kinematics::GraspLimits {
        margins: kinematics::Margins {
            patch: keys.patch_margin_deg.unwrap_or(5.0).to_radians(),
            clearance: keys.link_clearance.unwrap_or(0.005),
        },
        finger_gap: keys.finger_gap.unwrap_or(0.005),
    };
    let hand = ChainHand::new(&description, limits)
        .map_err(|e| format!("{path}: hand.description: {e}"))?;
    let start = hand.grasp(config, &keys.start_normals);
    Ok(Some(ChainSetup { hand, start }))
}
