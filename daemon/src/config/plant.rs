//! `[plant]`: which hand the daemon controls (SPEC §6.2, shm_schema's
//! `PLANT-GUIDE.md`).

use super::{KeyError, int_range as range};
use serde::{Deserialize, Serialize};

/// Where the hand is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PlantKind {
    /// The embedded kinematic hand, in process: executes every setpoint
    /// exactly.
    #[default]
    Embedded,
    /// A hand or simulator in another process, over the plant services.
    Shm,
}

/// How the loop is paced with an external plant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PlantTiming {
    /// Both run on their own clocks; each tick takes the newest
    /// measurement.
    #[default]
    Realtime,
    /// The plant's measurement k at plant time t_k triggers tick k with
    /// now = t_k; the plant steps only after the command answering k.
    Lockstep,
}

/// `[plant]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlantSection {
    /// `"embedded"` (default) or `"shm"`.
    pub kind: PlantKind,
    /// `"realtime"` (default) or `"lockstep"` (kind = "shm" only).
    pub timing: PlantTiming,
    /// Realtime: a measurement that arrived longer ago than this counts as
    /// missing \[ms\].
    pub stale_after_ms: u32,
    /// Consecutive ticks without a fresh measurement tolerated, holding the
    /// last one, before the fault `PlantLost` (see [`DEFAULT_MAX_MISSED`]);
    /// also the most commands a measurement may lag behind. At most 200.
    pub max_missed: u32,
    /// How long the plant may take to send its first valid measurement
    /// before the log warns that none came (the daemon keeps waiting, in
    /// safe hold with `PlantWaiting`; nothing moves) \[ms\].
    pub connect_timeout_ms: u32,
    /// Lockstep: wall-clock time the loop waits for the next measurement
    /// before the fault `PlantLost` (it then keeps waiting for the plant to
    /// come back, never hangs) \[ms\].
    pub lockstep_timeout_ms: u32,
    /// Ticks in a row that each missed the timing contract before the
    /// fault `PlantTiming`; 0: never. Unset: the larger of
    /// [`DEFAULT_MAX_MISSES_IN_ROW`]
    /// and twice `max_missed` (a tolerance raised for blind ticks is not
    /// undercut by this one), see [`PlantSection::misses_in_row_limit`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_misses_in_row: Option<u32>,
}

/// Default of `plant.max_missed`: 10 ticks (10 ms at 1 kHz). libfranka
/// stops its robot after 20 lost packets; gaitd keeps commanding a moving
/// grasp while it holds the last measurement, and at the default fingertip
/// speed (0.5 m/s) 10 blind ticks are already 5 mm of motion unseen — ten
/// times `feedback.finger_tolerance` — so it gives up earlier. One or two
/// late packets (scheduling on a loaded host) never fault.
pub const DEFAULT_MAX_MISSED: u32 = 10;

/// Default of `plant.max_misses_in_row` (with the default `plant.max_missed`;
/// unset, it is the larger of this and twice `max_missed`): 20 ticks.
/// libfranka stops its robot after 20 consecutive lost packets; here a run
/// needs twice `plant.max_missed` (10) ticks that each missed something —
/// blind ticks alone are already a lost plant at 10 — so it catches a plant
/// or a loop that keeps getting its commands late or repeated while
/// measurements still arrive: 20 ms at 1 kHz, 10 mm of fingertip motion at
/// 0.5 m/s.
pub const DEFAULT_MAX_MISSES_IN_ROW: u32 = 20;

impl Default for PlantSection {
    fn default() -> Self {
        Self {
            kind: PlantKind::Embedded,
            timing: PlantTiming::Realtime,
            stale_after_ms: 20,
            max_missed: DEFAULT_MAX_MISSED,
            connect_timeout_ms: 5000,
            lockstep_timeout_ms: 1000,
            max_misses_in_row: None,
        }
    }
}

impl PlantSection {
    /// Validates every key, naming it.
    pub fn validate(&self) -> Result<(), KeyError> {
        if self.kind == PlantKind::Embedded && self.timing == PlantTiming::Lockstep {
            return Err(KeyError::Invalid {
                key: "plant.timing",
                why: "lockstep needs an external plant (plant.kind = \"shm\"); the embedded hand runs on the daemon's clock",
            });
        }
        range(
            "plant.stale_after_ms",
            self.stale_after_ms,
            1,
            10_000,
            "in [1, 10000] ms",
        )?;
        range(
            "plant.max_missed",
            self.max_missed,
            0,
            200,
            "in [0, 200] ticks",
        )?;
        range(
            "plant.connect_timeout_ms",
            self.connect_timeout_ms,
            1,
            3_600_000,
            "in [1, 3600000] ms",
        )?;
        range(
            "plant.lockstep_timeout_ms",
            self.lockstep_timeout_ms,
            1,
            600_000,
            "in [1, 600000] ms",
        )?;
        range(
            "plant.max_misses_in_row",
            self.misses_in_row_limit(),
            0,
            100_000,
            "in [0, 100000] ticks (0: never)",
        )
    }

    /// The run of timing-contract misses that faults (`PlantTiming`): the
    /// key, or the larger of 20 and twice `max_missed`.
    pub fn misses_in_row_limit(&self) -> u32 {
        self.max_misses_in_row
            .unwrap_or(DEFAULT_MAX_MISSES_IN_ROW.max(self.max_missed.saturating_mul(2)))
    }

    /// Whether the hand is outside the daemon.
    pub fn external(&self) -> bool {
        self.kind == PlantKind::Shm
    }

    /// Whether the loop is paced by the plant.
    pub fn lockstep(&self) -> bool {
        self.external() && self.timing == PlantTiming::Lockstep
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::DaemonConfig;

    fn load(text: &str) -> Result<DaemonConfig, String> {
        DaemonConfig::from_toml(text, "x.toml").map_err(|e| e.to_string())
    }

    #[test]
    fn defaults_and_choices() {
        let c = load("").unwrap();
        assert_eq!(c.plant, PlantSection::default());
        assert!(!c.plant.external());
        let c = load("[plant]\nkind = \"shm\"\ntiming = \"lockstep\"\n").unwrap();
        assert!(c.plant.lockstep());
    }

    #[test]
    fn every_bad_key_is_named() {
        for (text, key) in [
            ("[plant]\nkind = \"usb\"", "kind"),
            ("[plant]\ntiming = \"fast\"", "timing"),
            ("[plant]\ntiming = \"lockstep\"", "plant.timing"),
            (
                "[plant]\nkind = \"shm\"\nstale_after_ms = 0",
                "plant.stale_after_ms",
            ),
            ("[plant]\nmax_missed = 201", "plant.max_missed"),
            (
                "[plant]\nconnect_timeout_ms = 0",
                "plant.connect_timeout_ms",
            ),
            (
                "[plant]\nlockstep_timeout_ms = 0",
                "plant.lockstep_timeout_ms",
            ),
            ("[plant]\nrate = 3", "rate"),
            (
                "[plant]\nmax_misses_in_row = 100001",
                "plant.max_misses_in_row",
            ),
        ] {
            let e = load(text).unwrap_err();
            assert!(e.contains(key), "{text}: {e}");
        }
    }
}
