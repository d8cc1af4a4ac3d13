//! Daemon configuration file (SPEC.md §7.1): TOML with the model sections of
//! [`gait::HandConfig`] (`[model]`, `[load]`, `[limits]`, `[planner]`,
//! `[feedback]`) and the daemon's own `[control]`, `[daemon]`, `[ipc]`,
//! `[rt]` and `[plant]` (in [`plant`]: which hand the daemon controls).
//! Every key is validated at start; errors name the key. Plain settings:
//! every part of the daemon reads them, and this module uses none of
//! those parts.

pub mod hand;
pub mod plant;

use gait::config::{FeedbackConfig, LimitsConfig, LoadConfig, ModelConfig, PlannerConfig};
use gait::{ConfigError, HandConfig};
pub use plant::{PlantKind, PlantSection, PlantTiming};
use serde::{Deserialize, Serialize};

/// Default path of the service's configuration file.
pub const DEFAULT_CONFIG_PATH: &str = "/etc/gaitd/gaitd.toml";

/// `[control]`: the control loop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlConfig {
    /// Control loop rate \[Hz\] (SPEC §6.1: 100 Hz – 10 kHz, default 1 kHz).
    pub tick_hz: f64,
}

impl Default for ControlConfig {
    fn default() -> Self {
        Self { tick_hz: 1000.0 }
    }
}

/// `[daemon]`: what the loop does besides control.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DaemonSection {
    /// Publish the status every this many ticks (1 = every tick).
    pub status_every: u32,
    /// Wake waiting clients (status notification) every this many published
    /// statuses; answers and events always notify at once. A notification is
    /// one syscall per listening client, made by the writer thread (not the
    /// loop); raise this to save that CPU when clients need fewer wake-ups.
    pub status_notify_every: u32,
    /// Commands taken from the queue per tick at most (the rest wait a tick).
    pub max_commands_per_tick: u32,
    /// Recent (client, goal id) pairs remembered to refuse duplicate ids.
    pub goal_id_memory: u32,
    /// On SIGTERM/SIGINT, how long the controller may take to come to rest
    /// before the final status is published anyway \[ms\].
    pub shutdown_timeout_ms: u32,
    /// Housekeeping period: dead-node cleanup, client count, STATUS= \[ms\].
    pub housekeeping_period_ms: u32,
    /// How the writer thread learns that a tick's output is queued.
    pub writer_wake: WriterWake,
    /// Directory where every goal's execution is recorded as a
    /// `gait-trajectory/1` trace (SPEC §8, §10); empty = no traces. Must be
    /// an existing directory the daemon can write to.
    pub trace_dir: String,
    /// Most goal traces kept in `trace_dir` (oldest removed first after
    /// each new one; 0 = keep every trace).
    pub trace_keep: u32,
}

/// How the writer thread (which publishes what the loop produced) is woken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WriterWake {
    /// The writer sleeps on its own absolute timer until the loop's next
    /// deadline, then waits (spinning briefly) for that tick to finish: the
    /// loop makes no system call for it. Waking a sleeping thread is a
    /// futex syscall plus an inter-processor interrupt, which on a VM cost
    /// the loop more than the control step itself (measured with `perf`).
    #[default]
    Timer,
    /// The loop unparks the writer after every tick (one futex wake on the
    /// loop thread). Needed when the loop runs on a mock clock (tests).
    Unpark,
}

impl Default for DaemonSection {
    fn default() -> Self {
        Self {
            status_every: 1,
            status_notify_every: 1,
            max_commands_per_tick: 8,
            goal_id_memory: 1024,
            shutdown_timeout_ms: 2000,
            housekeeping_period_ms: 1000,
            writer_wake: WriterWake::Timer,
            trace_dir: String::new(),
            trace_keep: 1000,
        }
    }
}

/// `[ipc]`: iceoryx2 services (SPEC §7.3). Empty strings mean: take the
/// environment variable (`GAITD_PREFIX`, `GAITD_IPC_CONFIG`,
/// `GAITD_IPC_ROOT`, `GAITD_IPC_FILE_PREFIX`), then the iceoryx2 config
/// file's value, then the built-in default; clients resolve the same way.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IpcSection {
    /// Service-name prefix (default `gaitd`).
    pub service_prefix: String,
    /// iceoryx2 config file to load (the service uses /etc/gaitd/iceoryx2.toml).
    pub iceoryx2_config: String,
    /// iceoryx2 root path override.
    pub root_path: String,
    /// iceoryx2 file prefix override (names in /dev/shm).
    pub file_prefix: String,
    /// Most clients at once (publishers of commands, status/event readers, listeners).
    pub max_clients: u32,
    /// Commands buffered per client before its sends are refused.
    pub command_queue: u32,
    /// Answers buffered per client (oldest dropped when full).
    pub answer_buffer: u32,
    /// Events kept as history for late subscribers.
    pub event_history: u32,
    /// Events buffered per client (oldest dropped when full).
    pub event_buffer: u32,
}

impl Default for IpcSection {
    fn default() -> Self {
        Self {
            service_prefix: String::new(),
            iceoryx2_config: String::new(),
            root_path: String::new(),
            file_prefix: String::new(),
            max_clients: 16,
            command_queue: 8,
            answer_buffer: 16,
            event_history: 64,
            event_buffer: 256,
        }
    }
}

/// `[rt]`: real-time setup, applied when permitted (SPEC §7.1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RtSection {
    /// Lock all memory (mlockall) so the loop never page-faults.
    pub lock_memory: bool,
    /// SCHED_FIFO priority of the loop thread, 1–99; 0 = normal scheduling.
    pub fifo_priority: u32,
    /// SCHED_FIFO priority of the writer thread (it publishes status,
    /// answers and events, and wakes the planner), below `fifo_priority`;
    /// 0 = normal scheduling; unset: `fifo_priority` − 10 (0 if that is
    /// not positive). Applied only once the loop runs SCHED_FIFO. See
    /// [`RtSection::writer_fifo_priority`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub writer_priority: Option<u32>,
    /// CPUs the loop thread may run on (empty: no pinning).
    pub loop_cpus: Vec<u32>,
    /// CPUs of the other threads (empty: no pinning).
    pub background_cpus: Vec<u32>,
    /// Busy-wait this long before each tick instead of sleeping \[µs\]
    /// (0: sleep all the way). Costs that much CPU per period.
    pub spin_us: u32,
}

impl Default for RtSection {
    fn default() -> Self {
        Self {
            lock_memory: true,
            fifo_priority: 80,
            writer_priority: None,
            loop_cpus: Vec::new(),
            background_cpus: Vec::new(),
            spin_us: 0,
        }
    }
}

/// The whole daemon configuration file.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
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
    /// `[daemon]`: status rate, command intake, shutdown, housekeeping.
    pub daemon: DaemonSection,
    /// `[ipc]`: iceoryx2 services.
    pub ipc: IpcSection,
    /// `[rt]`: real-time setup.
    pub rt: RtSection,
    /// `[plant]`: which hand (embedded, or another process over shared memory).
    pub plant: PlantSection,
    /// `[hand]`: the hand model (free fingertips, or finger chains).
    pub hand: hand::HandSection,
    /// The folder relative paths in the file are read from (the file's
    /// own; the working directory for text not read from a file).
    #[serde(skip)]
    pub dir: std::path::PathBuf,
}

/// A key whose value is refused. Every variant names the key as written in
/// the TOML file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KeyError {
    /// A key of the model sections (`[model]`, `[load]`, `[limits]`) or a rate.
    #[error(transparent)]
    Model(#[from] ConfigError),
    /// An integer out of its range.
    #[error("config key `{key}` = {value} is out of range: {expected}")]
    OutOfRange {
        /// Key, as written in the TOML file.
        key: &'static str,
        /// The value found.
        value: i64,
        /// The allowed range, in words.
        expected: &'static str,
    },
    /// A value that is not usable for another reason.
    #[error("config key `{key}`: {why}")]
    Invalid {
        /// Key, as written in the TOML file.
        key: &'static str,
        /// What is wrong.
        why: &'static str,
    },
}

/// `value` in [`lo`, `hi`], else the key's out-of-range error.
pub(crate) fn int_range(
    key: &'static str,
    value: u32,
    lo: u32,
    hi: u32,
    expected: &'static str,
) -> Result<(), KeyError> {
    if (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(KeyError::OutOfRange {
            key,
            value: value.into(),
            expected,
        })
    }
}

fn cpu_list(key: &'static str, cpus: &[u32]) -> Result<(), KeyError> {
    for (i, &c) in cpus.iter().enumerate() {
        if c >= 1024 {
            return Err(KeyError::OutOfRange {
                key,
                value: c.into(),
                expected: "CPU numbers in [0, 1023]",
            });
        }
        if cpus[..i].contains(&c) {
            return Err(KeyError::Invalid {
                key,
                why: "a CPU is listed twice",
            });
        }
    }
    Ok(())
}

impl DaemonSection {
    fn validate(&self) -> Result<(), KeyError> {
        int_range(
            "daemon.status_every",
            self.status_every,
            1,
            1000,
            "in [1, 1000] ticks",
        )?;
        int_range(
            "daemon.status_notify_every",
            self.status_notify_every,
            1,
            10_000,
            "in [1, 10000] statuses",
        )?;
        int_range(
            "daemon.max_commands_per_tick",
            self.max_commands_per_tick,
            1,
            64,
            "in [1, 64]",
        )?;
        int_range(
            "daemon.goal_id_memory",
            self.goal_id_memory,
            16,
            65_536,
            "in [16, 65536]",
        )?;
        int_range(
            "daemon.shutdown_timeout_ms",
            self.shutdown_timeout_ms,
            0,
            60_000,
            "in [0, 60000] ms",
        )?;
        int_range(
            "daemon.housekeeping_period_ms",
            self.housekeeping_period_ms,
            100,
            60_000,
            "in [100, 60000] ms",
        )?;
        int_range(
            "daemon.trace_keep",
            self.trace_keep,
            0,
            1_000_000,
            "in [0, 1000000] traces (0 = keep all)",
        )?;
        trace_dir("daemon.trace_dir", &self.trace_dir)
    }
}

/// An empty value (tracing off) or an existing directory this process may
/// create files in. Checked at start (and by `--check-config`) so a typo
/// fails loudly instead of silently losing every trace.
fn trace_dir(key: &'static str, dir: &str) -> Result<(), KeyError> {
    if dir.is_empty() {
        return Ok(());
    }
    if dir.contains('\0') {
        return Err(KeyError::Invalid {
            key,
            why: "contains a NUL byte",
        });
    }
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(KeyError::Invalid {
                key,
                why: "is not a directory",
            });
        }
        Err(_) => {
            return Err(KeyError::Invalid {
                key,
                why: "does not exist (create it, e.g. StateDirectory=gaitd in the unit)",
            });
        }
    }
    let c = std::ffi::CString::new(dir).map_err(|_| KeyError::Invalid {
        key,
        why: "contains a NUL byte",
    })?;
    // SAFETY: `c` is a valid NUL-terminated path; access(2) only reads it.
    // W_OK|X_OK: creating files in a directory needs both.
    if unsafe { libc::access(c.as_ptr(), libc::W_OK | libc::X_OK) } != 0 {
        return Err(KeyError::Invalid {
            key,
            why: "is not writable by this user",
        });
    }
    Ok(())
}

impl IpcSection {
    fn validate(&self) -> Result<(), KeyError> {
        let p = &self.service_prefix;
        if !p.is_empty()
            && !p
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b"._/-".contains(&b))
        {
            return Err(KeyError::Invalid {
                key: "ipc.service_prefix",
                why: "use only [A-Za-z0-9._/-]",
            });
        }
        if !self.root_path.is_empty() && !self.root_path.starts_with('/') {
            return Err(KeyError::Invalid {
                key: "ipc.root_path",
                why: "must be an absolute path",
            });
        }
        if self.file_prefix.contains('/') {
            return Err(KeyError::Invalid {
                key: "ipc.file_prefix",
                why: "must be a plain file name (no '/')",
            });
        }
        int_range("ipc.max_clients", self.max_clients, 1, 256, "in [1, 256]")?;
        int_range(
            "ipc.command_queue",
            self.command_queue,
            1,
            256,
            "in [1, 256]",
        )?;
        int_range(
            "ipc.answer_buffer",
            self.answer_buffer,
            1,
            1024,
            "in [1, 1024]",
        )?;
        int_range(
            "ipc.event_history",
            self.event_history,
            0,
            4096,
            "in [0, 4096]",
        )?;
        int_range(
            "ipc.event_buffer",
            self.event_buffer,
            1,
            4096,
            "in [1, 4096]",
        )?;
        if self.event_buffer < self.event_history {
            return Err(KeyError::Invalid {
                key: "ipc.event_buffer",
                why: "must be at least ipc.event_history",
            });
        }
        Ok(())
    }
}

impl RtSection {
    /// The writer thread's SCHED_FIFO priority, 0 for normal scheduling:
    /// below the loop's, so on a shared CPU the loop preempts it, and above
    /// every normal thread, so busy clients cannot hold back what the loop
    /// produced (status, answers, events, the planner's wake-up).
    pub fn writer_fifo_priority(&self) -> u32 {
        match (self.fifo_priority, self.writer_priority) {
            (0, _) => 0,
            (_, Some(p)) => p,
            (loop_priority, None) => loop_priority.saturating_sub(10),
        }
    }

    fn validate(&self) -> Result<(), KeyError> {
        int_range(
            "rt.fifo_priority",
            self.fifo_priority,
            0,
            99,
            "0 (normal scheduling) or 1-99",
        )?;
        let writer = self.writer_priority.unwrap_or(0);
        int_range(
            "rt.writer_priority",
            writer,
            0,
            99,
            "0 (normal scheduling) or 1-99",
        )?;
        if self.fifo_priority > 0 && writer >= self.fifo_priority {
            // On a shared CPU the loop must preempt the writer, never wait.
            return Err(KeyError::Invalid {
                key: "rt.writer_priority",
                why: "must be below rt.fifo_priority (or 0)",
            });
        }
        cpu_list("rt.loop_cpus", &self.loop_cpus)?;
        cpu_list("rt.background_cpus", &self.background_cpus)?;
        int_range(
            "rt.spin_us",
            self.spin_us,
            0,
            1000,
            "0-1000 µs (at most a period: the loop then never sleeps)",
        )
    }
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
        source: KeyError,
    },
}

impl DaemonConfig {
    /// The loop's busy-wait before each deadline (`[rt] spin_us`) \[ns\].
    pub fn spin_ns(&self) -> u64 {
        u64::from(self.rt.spin_us) * 1000
    }

    /// How long before the loop's deadline the writer thread wakes \[ns\]:
    /// with the loop (its `spin_ns`) when they may share a CPU, so the
    /// writer's timer never interrupts the loop's spin or tick; at the
    /// deadline when both are pinned to disjoint CPUs, so the writer does
    /// not spin through the loop's busy-wait on its own CPU.
    pub fn writer_lead_ns(&self) -> u64 {
        let (l, b) = (&self.rt.loop_cpus, &self.rt.background_cpus);
        let disjoint = !l.is_empty() && !b.is_empty() && !l.iter().any(|c| b.contains(c));
        if disjoint { 0 } else { self.spin_ns() }
    }

    /// The loop period \[ns\] (rounded to the nearest nanosecond).
    pub fn period_ns(&self) -> u64 {
        (1e9 / self.control.tick_hz).round() as u64
    }

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
    pub fn validate(&self) -> Result<(), KeyError> {
        self.hand().validate()?;
        let hz = self.control.tick_hz;
        if !hz.is_finite() {
            return Err(ConfigError::NotFinite {
                key: "control.tick_hz",
                value: hz,
            }
            .into());
        }
        if !(100.0..=10_000.0).contains(&hz) {
            return Err(ConfigError::OutOfRange {
                key: "control.tick_hz",
                value: hz,
                expected: "in [100, 10000] Hz",
            }
            .into());
        }
        self.daemon.validate()?;
        // Clients treat a daemon whose status is older than 1 s as gone.
        if f64::from(self.daemon.status_every) / hz > 0.5 {
            return Err(KeyError::Invalid {
                key: "daemon.status_every",
                why: "status must be published at least every 0.5 s (status_every / control.tick_hz)",
            });
        }
        self.ipc.validate()?;
        self.rt.validate()?;
        self.plant.validate()?;
        self.hand.validate()?;
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
        let mut cfg = Self::from_toml(&text, path)?;
        if let Some(dir) = std::path::Path::new(path).parent() {
            cfg.dir = dir.to_path_buf();
        }
        Ok(cfg)
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
    fn the_writer_wakes_with_the_loop_unless_their_cpus_are_disjoint() {
        let lead = |rt: &str| {
            DaemonConfig::from_toml(&format!("[rt]\nspin_us = 100\n{rt}"), "x")
                .unwrap()
                .writer_lead_ns()
        };
        assert_eq!(lead(""), 100_000);
        assert_eq!(lead("loop_cpus = [1]\n"), 100_000);
        assert_eq!(lead("loop_cpus = [1]\nbackground_cpus = [0, 1]\n"), 100_000);
        assert_eq!(lead("loop_cpus = [1]\nbackground_cpus = [0]\n"), 0);
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

    #[test]
    fn new_sections_name_their_keys() {
        let bad = [
            ("[daemon]\nstatus_every = 0\n", "daemon.status_every"),
            (
                "[daemon]\nmax_commands_per_tick = 65\n",
                "daemon.max_commands_per_tick",
            ),
            (
                "[daemon]\nhousekeeping_period_ms = 5\n",
                "daemon.housekeeping_period_ms",
            ),
            ("[ipc]\nservice_prefix = \"a b\"\n", "ipc.service_prefix"),
            ("[ipc]\nroot_path = \"relative\"\n", "ipc.root_path"),
            ("[ipc]\nfile_prefix = \"a/b\"\n", "ipc.file_prefix"),
            ("[ipc]\nmax_clients = 0\n", "ipc.max_clients"),
            ("[ipc]\nevent_history = 300\n", "ipc.event_buffer"),
            ("[rt]\nfifo_priority = 100\n", "rt.fifo_priority"),
            ("[rt]\nwriter_priority = 100\n", "rt.writer_priority"),
            (
                "[rt]\nfifo_priority = 50\nwriter_priority = 50\n",
                "rt.writer_priority",
            ),
            ("[rt]\nloop_cpus = [1, 1]\n", "rt.loop_cpus"),
            ("[rt]\nbackground_cpus = [5000]\n", "rt.background_cpus"),
            ("[rt]\nspin_us = 1001\n", "rt.spin_us"),
            ("[feedback]\nmax_replans = 101\n", "feedback.max_replans"),
            ("[feedback]\nlimit_guard = 1.5\n", "feedback.limit_guard"),
            ("[rt]\npriority = 3\n", "priority"),
        ];
        for (text, key) in bad {
            let e = DaemonConfig::from_toml(text, "x.toml").unwrap_err();
            assert!(e.to_string().contains(key), "{text}: {e}");
        }
        let ok = "[daemon]\nstatus_every = 2\n[ipc]\nservice_prefix = \"t/1\"\n[rt]\nloop_cpus = [1]\nfifo_priority = 0\n";
        let c = DaemonConfig::from_toml(ok, "x.toml").unwrap();
        assert_eq!(c.daemon.status_every, 2);
        assert_eq!(c.rt.loop_cpus, vec![1]);
        assert_eq!(c.period_ns(), 1_000_000);
        // Without a SCHED_FIFO loop the writer runs normal scheduling.
        assert_eq!(c.rt.writer_fifo_priority(), 0);
        let writer = |text| {
            DaemonConfig::from_toml(text, "x")
                .unwrap()
                .rt
                .writer_fifo_priority()
        };
        assert_eq!(writer(""), 70);
        assert_eq!(writer("[rt]\nfifo_priority = 50\n"), 40);
        assert_eq!(writer("[rt]\nfifo_priority = 5\n"), 0);
        assert_eq!(writer("[rt]\nfifo_priority = 50\nwriter_priority = 0\n"), 0);
        assert_eq!(writer("[rt]\nfifo_priority = 0\nwriter_priority = 60\n"), 0);
    }

    #[test]
    fn trace_dir_must_be_a_writable_directory() {
        let c = DaemonConfig::from_toml("", "x.toml").unwrap();
        assert_eq!(c.daemon.trace_dir, "", "tracing is off by default");
        let dir = test_support::scratch_dir("cfg-trace");
        let file = dir.join("a-file");
        std::fs::write(&file, "").unwrap();
        let ok = format!("[daemon]\ntrace_dir = \"{}\"\n", dir.display());
        let c = DaemonConfig::from_toml(&ok, "x.toml").unwrap();
        assert_eq!(c.daemon.trace_dir, dir.display().to_string());
        for (path, why) in [
            (dir.join("missing"), "does not exist"),
            (file.clone(), "is not a directory"),
        ] {
            let text = format!("[daemon]\ntrace_dir = \"{}\"\n", path.display());
            let e = DaemonConfig::from_toml(&text, "x.toml").unwrap_err();
            let e = e.to_string();
            assert!(e.contains("daemon.trace_dir") && e.contains(why), "{e}");
        }
        // A read-only directory (root may write anyway: only check if not).
        let ro = dir.join("ro");
        std::fs::create_dir_all(&ro).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
        // SAFETY: plain syscall.
        if unsafe { libc::geteuid() } != 0 {
            let text = format!("[daemon]\ntrace_dir = \"{}\"\n", ro.display());
            let e = DaemonConfig::from_toml(&text, "x.toml").unwrap_err();
            assert!(e.to_string().contains("not writable"), "{e}");
        }
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
