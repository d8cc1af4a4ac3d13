//! An independent model of what the daemon's command intake must answer,
//! written from SPEC §7.3/§12 and the field docs of `shm_schema::Command`
//! rather than from `Command::validate`: for a command it lists every
//! reason that applies. The intake may pick any of them (the order of the
//! checks is its business) but must reject when one applies for sure and
//! accept when none does. Floating-point boundaries (norm tolerance, zero
//! and axis thresholds) are computed differently here, so a band of a few
//! ulps around each threshold is "may" rather than "must".
//!
//! Shared by `tests/intake_fuzz.rs` (stable, CI) and the libFuzzer target
//! in `daemon/fuzz/` (nightly).

#![allow(dead_code)]

use gait::config::LimitsConfig;
use gaitd::config::DaemonConfig;
use gaitd::control::controller::{
    ClientTarget, ControlCommand, ControlOutput, Controller, TickContext,
};
use gaitd::control::tick_events::TickEvents;
use gaitd::realtime::intake::Intake;
use shm_schema::{Answer, Command, CommandKind, GoalFrame, ReasonCode, Verdict};
use std::collections::VecDeque;

// The model's own numbers, from `shm_schema/LAYOUT.md` ("Command
// validation"), never imported from the code under test: a change there
// must show up here as a failure.
/// Accepted deviation of a goal quaternion's norm from 1.
pub const NORM_TOLERANCE: f64 = 1e-3;
/// Largest |angle| of an axis-angle goal: 64π (32 turns) \[rad\].
pub const MAX_ANGLE: f64 = 64.0 * std::f64::consts::PI;
/// Limit overrides: bits 0–8 of `limit_mask`.
pub const OVERRIDES: u32 = 9;
/// Smallest override, as a fraction of the configured limit.
pub const MIN_OVERRIDE_FRACTION: f64 = 0.01;

/// A set of reason codes (bit = code; codes are < 64).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Reasons(pub u64);

impl Reasons {
    /// Adds `r`.
    pub fn add(&mut self, r: ReasonCode) {
        self.0 |= 1 << r.code();
    }
    /// Adds `r` when `cond`.
    pub fn add_if(&mut self, cond: bool, r: ReasonCode) {
        if cond {
            self.add(r);
        }
    }
    /// Whether `r` is in the set.
    pub fn has(self, r: ReasonCode) -> bool {
        self.0 & (1 << r.code()) != 0
    }
    /// Whether the set is empty.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }
    /// Union.
    pub fn or(self, o: Reasons) -> Reasons {
        Reasons(self.0 | o.0)
    }
}

/// What the intake may answer to one command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Expected {
    /// Reasons that certainly apply (non-empty: must reject).
    pub must: Reasons,
    /// Reasons that apply or not depending on rounding at a threshold.
    pub may: Reasons,
}

impl Expected {
    /// Whether `v` is a correct answer.
    pub fn allows(&self, v: Verdict) -> bool {
        match v {
            Verdict::Accepted => self.must.is_empty(),
            Verdict::Rejected(r) => self.must.or(self.may).has(r),
        }
    }
}

/// The model: configured limits, the goal-id memory, shutdown.
#[derive(Debug, Clone)]
pub struct Oracle {
    /// Configured (hardware) limits; overrides may only lower them.
    pub limits: LimitsConfig,
    memory: VecDeque<(u64, u64)>,
    capacity: usize,
    /// The daemon is shutting down: every well-formed command is refused.
    pub shutting_down: bool,
}

/// Norm of `v` without overflow or underflow (scaled), unlike the intake's
/// plain sum of squares.
fn scaled_norm(v: &[f64]) -> f64 {
    let m = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if m == 0.0 {
        return 0.0;
    }
    m * v.iter().map(|x| (x / m) * (x / m)).sum::<f64>().sqrt()
}

/// Whether `x` lies within a relative band of a few ulps around `edge`.
fn near(x: f64, edge: f64) -> bool {
    (x - edge).abs() <= 1e-9 * edge.abs().max(1e-300)
}

/// The nine override values in mask-bit order (object, fingertip, rolling × v, a, j).
pub fn override_values(c: &Command) -> [f64; 9] {
    let (o, f, r) = (&c.object_limits, &c.fingertip_limits, &c.rolling_limits);
    [
        o.velocity,
        o.acceleration,
        o.jerk,
        f.velocity,
        f.acceleration,
        f.jerk,
        r.velocity,
        r.acceleration,
        r.jerk,
    ]
}

/// The nine configured limits in mask-bit order.
pub fn configured_values(l: &LimitsConfig) -> [f64; 9] {
    [
        l.object.velocity,
        l.object.acceleration,
        l.object.jerk,
        l.fingertip.velocity,
        l.fingertip.acceleration,
        l.fingertip.jerk,
        l.rolling.velocity,
        l.rolling.acceleration,
        l.rolling.jerk,
    ]
}

impl Oracle {
    /// A model with `limits` remembering `capacity` goal ids.
    pub fn new(limits: LimitsConfig, capacity: usize) -> Self {
        Self {
            limits,
            memory: VecDeque::with_capacity(capacity),
            capacity: capacity.max(1),
            shutting_down: false,
        }
    }

    /// Reasons the bytes alone decide.
    fn bytes(&self, c: &Command) -> Expected {
        let (mut must, mut may) = (Reasons::default(), Reasons::default());
        must.add_if(c.reserved != 0, ReasonCode::NonZeroReserved);
        must.add_if(c.client_id == 0, ReasonCode::ZeroClientId);
        let Ok(kind) = CommandKind::try_from(c.kind) else {
            must.add(ReasonCode::UnknownCommandKind);
            return Expected { must, may };
        };
        let values = override_values(c);
        if kind != CommandKind::Goal {
            let unused_nonzero = c.frame != 0
                || c.limit_mask != 0
                || c.target.iter().chain(&values).any(|v| v.to_bits() != 0)
                || (kind != CommandKind::Cancel && c.goal_id != 0);
            must.add_if(unused_nonzero, ReasonCode::NonZeroReserved);
            return Expected { must, may };
        }
        must.add_if(c.goal_id == 0, ReasonCode::ZeroGoalId);
        match GoalFrame::try_from(c.frame) {
            Err(_) => must.add(ReasonCode::UnknownGoalFrame),
            Ok(GoalFrame::AxisAngle) => {
                let [angle, x, y, z] = c.target;
                if !c.target.iter().all(|v| v.is_finite()) || angle.abs() > MAX_ANGLE {
                    must.add(ReasonCode::BadAxisAngle);
                } else {
                    // Axis norm must lie in [1e-6, 1e6].
                    let n = scaled_norm(&[x, y, z]);
                    if near(n, 1e-6) || near(n, 1e6) {
                        may.add(ReasonCode::BadAxisAngle);
                    } else {
                        must.add_if(!(1e-6..=1e6).contains(&n), ReasonCode::BadAxisAngle);
                    }
                }
            }
            Ok(GoalFrame::Absolute | GoalFrame::Relative) => {
                if !c.target.iter().all(|v| v.is_finite()) {
                    must.add(ReasonCode::NonFiniteQuaternion);
                } else {
                    let n = scaled_norm(&c.target);
                    if near(n, 1e-6) {
                        may.add(ReasonCode::ZeroQuaternion);
                        may.add(ReasonCode::NonUnitQuaternion);
                    } else if n < 1e-6 {
                        // Below the zero threshold: "zero", though "not
                        // unit" is true as well.
                        must.add(ReasonCode::ZeroQuaternion);
                        may.add(ReasonCode::NonUnitQuaternion);
                    } else if near((n - 1.0).abs(), NORM_TOLERANCE) {
                        may.add(ReasonCode::NonUnitQuaternion);
                    } else {
                        must.add_if(
                            (n - 1.0).abs() > NORM_TOLERANCE,
                            ReasonCode::NonUnitQuaternion,
                        );
                    }
                }
            }
        }
        must.add_if(c.limit_mask >> OVERRIDES != 0, ReasonCode::BadLimitMask);
        for (bit, v) in values.iter().enumerate() {
            if c.limit_mask & (1 << bit) == 0 {
                must.add_if(v.to_bits() != 0, ReasonCode::NonZeroReserved);
            } else if !v.is_finite() {
                must.add(ReasonCode::NonFiniteLimit);
            } else {
                must.add_if(*v <= 0.0, ReasonCode::NonPositiveLimit);
            }
        }
        Expected { must, may }
    }

    /// Everything the intake may answer to `c` in the current state.
    pub fn expect(&self, c: &Command) -> Expected {
        let b = self.bytes(c);
        if !b.must.is_empty() {
            return b;
        }
        // Well-formed as far as the bytes go (unless rounding says no):
        // the daemon's own checks, which need its state.
        let mut state = Reasons::default();
        state.add_if(self.shutting_down, ReasonCode::ShuttingDown);
        if c.kind == CommandKind::Goal.code() {
            state.add_if(
                self.memory.contains(&(c.client_id, c.goal_id)),
                ReasonCode::DuplicateGoalId,
            );
            let set: Vec<(f64, f64)> = override_values(c)
                .iter()
                .zip(configured_values(&self.limits))
                .enumerate()
                .filter(|(bit, _)| c.limit_mask & (1 << bit) != 0)
                .map(|(_, (v, cfg))| (*v, cfg))
                .collect();
            state.add_if(
                set.iter().any(|(v, cfg)| v > cfg),
                ReasonCode::LimitAboveConfigured,
            );
            state.add_if(
                set.iter().any(|(v, cfg)| *v < MIN_OVERRIDE_FRACTION * cfg),
                ReasonCode::LimitBelowMinimum,
            );
        }
        if b.may.is_empty() {
            Expected {
                must: state,
                may: Reasons::default(),
            }
        } else if state.is_empty() {
            b
        } else {
            // Either a threshold reason or (the bytes passed) a state reason:
            // rejected in any case.
            Expected {
                must: state,
                may: b.may,
            }
        }
    }

    /// Updates the goal-id memory after the intake answered `v` to `c`: a
    /// goal id is remembered once the goal passed validation and the
    /// shutdown check and was not a duplicate (whatever came after).
    pub fn record(&mut self, c: &Command, v: Verdict) {
        if c.kind != CommandKind::Goal.code() {
            return;
        }
        let remembered = match v {
            Verdict::Accepted => true,
            Verdict::Rejected(r) => {
                r == ReasonCode::LimitAboveConfigured || r == ReasonCode::LimitBelowMinimum
            }
        };
        if remembered {
            if self.memory.len() == self.capacity {
                self.memory.pop_front();
            }
            self.memory.push_back((c.client_id, c.goal_id));
        }
    }
}

/// A controller that accepts everything and checks that what reaches it is
/// clean: finite, unit quaternions, unit axes, limits within the
/// configured ones, and exactly the command that was sent.
#[derive(Debug)]
pub struct Probe {
    /// Configured limits.
    pub limits: LimitsConfig,
    /// The command being fed (set by the driver before each input).
    pub sent: Command,
    /// Commands that reached the controller.
    pub received: u64,
}

impl Probe {
    fn check(&self, cmd: &ControlCommand) {
        let c = &self.sent;
        let cfg = configured_values(&self.limits);
        match *cmd {
            ControlCommand::Goal(g) => {
                assert_eq!((g.client_id, g.goal_id), (c.client_id, c.goal_id));
                match g.target {
                    ClientTarget::Absolute(q) | ClientTarget::Relative(q) => {
                        let v = q.quaternion().coords;
                        assert!(v.iter().all(|x| x.is_finite()), "{c:?}");
                        assert!((v.norm() - 1.0).abs() < 1e-12, "{c:?}");
                        let n = scaled_norm(&c.target);
                        let [w, x, y, z] = c.target.map(|t| t / n);
                        assert!((q.w - w).abs() < 1e-12 && (q.i - x).abs() < 1e-12, "{c:?}");
                        assert!((q.j - y).abs() < 1e-12 && (q.k - z).abs() < 1e-12, "{c:?}");
                        let want = if c.frame == GoalFrame::Absolute.code() {
                            matches!(g.target, ClientTarget::Absolute(_))
                        } else {
                            matches!(g.target, ClientTarget::Relative(_))
                        };
                        assert!(want, "frame kept: {c:?}");
                    }
                    ClientTarget::Rotation { axis, angle } => {
                        assert_eq!(c.frame, GoalFrame::AxisAngle.code());
                        assert!(axis.iter().all(|x| x.is_finite()), "{c:?}");
                        assert!((axis.norm() - 1.0).abs() < 1e-12, "{c:?}");
                        assert!(angle.is_finite() && angle.abs() <= MAX_ANGLE);
                        assert_eq!(angle.to_bits(), c.target[0].to_bits());
                    }
                }
                let got = configured_values(&g.limits);
                let over = override_values(c);
                for bit in 0..9 {
                    assert!(got[bit].is_finite() && got[bit] > 0.0, "{c:?}");
                    assert!(got[bit] <= cfg[bit], "{c:?}");
                    assert!(got[bit] >= MIN_OVERRIDE_FRACTION * cfg[bit], "{c:?}");
                    let want = if c.limit_mask & (1 << bit) != 0 {
                        over[bit]
                    } else {
                        cfg[bit]
                    };
                    assert_eq!(got[bit].to_bits(), want.to_bits(), "limit {bit}: {c:?}");
                }
            }
            ControlCommand::Cancel { client_id, goal_id } => {
                assert_eq!(c.kind, CommandKind::Cancel.code());
                assert_eq!((client_id, goal_id), (c.client_id, c.goal_id));
            }
            ControlCommand::Hold { client_id } => {
                assert_eq!(c.kind, CommandKind::Hold.code());
                assert_eq!(client_id, c.client_id);
            }
            ControlCommand::Reset { client_id } => {
                assert_eq!(c.kind, CommandKind::Reset.code());
                assert_eq!(client_id, c.client_id);
            }
        }
    }
}

impl Controller for Probe {
    fn command(&mut self, cmd: &ControlCommand, _ctx: &mut TickContext<'_>) -> Verdict {
        self.check(cmd);
        self.received += 1;
        Verdict::Accepted
    }
    fn tick(&mut self, _ctx: &mut TickContext<'_>, _out: &mut ControlOutput) {}
    fn begin_safe_hold(&mut self, _ctx: &mut TickContext<'_>) {}
    fn at_rest(&self) -> bool {
        true
    }
}

/// The daemon's intake, the model and the probe, fed one input at a time.
pub struct Rig {
    /// The daemon's intake.
    pub intake: Intake,
    /// The model.
    pub oracle: Oracle,
    /// The controller behind the intake.
    pub probe: Probe,
    events: TickEvents,
    /// Rejections per reason code.
    pub seen: [u64; 64],
    /// Accepted commands.
    pub accepted: u64,
}

impl Rig {
    /// The daemon's default config, nothing received yet.
    pub fn new() -> Self {
        let cfg = DaemonConfig::default();
        let memory = cfg.daemon.goal_id_memory as usize;
        Self {
            intake: Intake::new(memory, cfg.limits),
            oracle: Oracle::new(cfg.limits, memory),
            probe: Probe {
                limits: cfg.limits,
                sent: Command::ZERO,
                received: 0,
            },
            events: TickEvents::new(),
            seen: [0; 64],
            accepted: 0,
        }
    }

    /// From now on the daemon is shutting down.
    pub fn shutdown(&mut self) {
        self.intake.begin_shutdown();
        self.oracle.shutting_down = true;
    }

    /// One input through the daemon's path, checked against the model.
    pub fn feed(&mut self, bytes: &[u8; Command::SIZE]) -> Verdict {
        let cmd = Command::from_bytes(bytes);
        let want = self.oracle.expect(&cmd);
        self.probe.sent = cmd;
        let before = self.probe.received;
        let mut ctx = TickContext {
            now: 1,
            tick: 1,
            events: &mut self.events,
        };
        let verdict = self.intake.handle(&cmd, &mut self.probe, &mut ctx);
        assert!(
            want.allows(verdict),
            "{verdict:?} but the model allows must {:#x} may {:#x}: {cmd:?}",
            want.must.0,
            want.may.0
        );
        let reached = self.probe.received - before;
        match verdict {
            Verdict::Accepted => {
                assert_eq!(reached, 1, "accepted without reaching the controller");
                self.accepted += 1;
            }
            Verdict::Rejected(r) => {
                assert_eq!(reached, 0, "{r:?} but it reached the controller");
                self.seen[r.code() as usize] += 1;
            }
        }
        // The answer as the loop builds it decodes to the same verdict.
        let a = Answer::new(&cmd, verdict, 1, 1);
        assert_eq!(a.verdict(), Ok(verdict));
        assert_eq!((a.client_id, a.request_id), (cmd.client_id, cmd.request_id));
        for e in self.events.as_slice() {
            e.check().expect("events decode");
            assert!(e.value.is_finite());
        }
        self.events.clear();
        self.oracle.record(&cmd, verdict);
        verdict
    }
}

impl Default for Rig {
    fn default() -> Self {
        Self::new()
    }
}
