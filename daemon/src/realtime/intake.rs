//! Command intake, the loop's preprocess phase (SPEC §7.3, §12): every
//! command is decoded and checked before the controller sees it. Bytes that
//! fail [`Command::validate`] are answered with their reason and go no
//! further; then the daemon's own checks (shutdown, duplicate goal ids,
//! limit overrides above the configured limits); only then the controller.

use crate::control::controller::{ControlCommand, Controller, TickContext};
use crate::control::convert::control_command;
use gait::config::LimitsConfig;
use shm_schema::{Command, GoalState, ReasonCode, ValidCommand, Verdict};

/// Remembers the last `capacity` (client, goal id) pairs to refuse
/// duplicates (SPEC §6.4: goal ids are unique per client).
///
/// A ring in arrival order (the oldest is forgotten first) plus an
/// open-addressing hash index into it, both allocated once: `contains` is
/// O(1) instead of a scan of the whole ring (16 KiB at the default 1024
/// entries, several µs per goal on the loop thread under a goal flood).
/// Linear probing with backward-shift deletion, so no tombstones build up.
#[derive(Debug, Clone)]
pub struct GoalIdMemory {
    ring: Box<[(u64, u64)]>,
    len: usize,
    next: usize,
    /// Ring position + 1 of each entry, 0 = empty slot; a power of two at
    /// least twice the capacity (load factor ≤ 1/2).
    index: Box<[u32]>,
}

fn slot_hash(key: (u64, u64)) -> usize {
    // Fibonacci hashing of a cheap mix; the top bits are the best ones.
    let h = (key.0 ^ key.1.rotate_left(29)).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    (h ^ (h >> 32)) as usize
}

impl GoalIdMemory {
    /// Remembers the last `capacity` goals (allocated here, once).
    pub fn new(capacity: usize) -> Self {
        let capacity = capacity.clamp(1, u32::MAX as usize / 4);
        Self {
            ring: vec![(0, 0); capacity].into_boxed_slice(),
            len: 0,
            next: 0,
            index: vec![0; (2 * capacity).next_power_of_two()].into_boxed_slice(),
        }
    }

    fn mask(&self) -> usize {
        self.index.len() - 1
    }

    /// Whether the pair was seen.
    pub fn contains(&self, client_id: u64, goal_id: u64) -> bool {
        let key = (client_id, goal_id);
        let mut i = slot_hash(key) & self.mask();
        loop {
            match self.index[i] {
                0 => return false,
                p if self.ring[p as usize - 1] == key => return true,
                _ => i = (i + 1) & self.mask(),
            }
        }
    }

    /// Records a pair, forgetting the oldest when full.
    pub fn insert(&mut self, client_id: u64, goal_id: u64) {
        if self.len == self.ring.len() {
            self.unindex(self.next);
        } else {
            self.len += 1;
        }
        let key = (client_id, goal_id);
        self.ring[self.next] = key;
        let mut i = slot_hash(key) & self.mask();
        while self.index[i] != 0 {
            i = (i + 1) & self.mask();
        }
        self.index[i] = self.next as u32 + 1;
        self.next = (self.next + 1) % self.ring.len();
    }

    /// Removes ring position `pos` from the index (backward-shift deletion).
    fn unindex(&mut self, pos: usize) {
        let mask = self.mask();
        let mut hole = slot_hash(self.ring[pos]) & mask;
        while self.index[hole] as usize != pos + 1 {
            hole = (hole + 1) & mask;
        }
        let mut j = hole;
        loop {
            j = (j + 1) & mask;
            let p = self.index[j];
            if p == 0 {
                break;
            }
            // An entry may move back into the hole unless its home slot
            // lies cyclically in (hole, j].
            let home = slot_hash(self.ring[p as usize - 1]) & mask;
            let stays = if hole <= j {
                hole < home && home <= j
            } else {
                hole < home || home <= j
            };
            if !stays {
                self.index[hole] = p;
                hole = j;
            }
        }
        self.index[hole] = 0;
    }
}

/// Decides every command's answer.
#[derive(Debug, Clone)]
pub struct Intake {
    ids: GoalIdMemory,
    limits: LimitsConfig,
    shutting_down: bool,
    received: u64,
    rejected: u64,
}

impl Intake {
    /// Intake remembering `goal_id_memory` goals, checking overrides
    /// against `limits`.
    pub fn new(goal_id_memory: usize, limits: LimitsConfig) -> Self {
        Self {
            ids: GoalIdMemory::new(goal_id_memory),
            limits,
            shutting_down: false,
            received: 0,
            rejected: 0,
        }
    }

    /// From now on every command is refused with `ShuttingDown`.
    pub fn begin_shutdown(&mut self) {
        self.shutting_down = true;
    }

    /// Commands received since start.
    pub fn received(&self) -> u64 {
        self.received
    }

    /// Commands rejected since start.
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Decides one command, handing it to `controller` if it passes.
    pub fn handle<C: Controller>(
        &mut self,
        cmd: &Command,
        controller: &mut C,
        ctx: &mut TickContext<'_>,
    ) -> Verdict {
        self.received += 1;
        let verdict = self.decide(cmd, controller, ctx);
        if verdict != Verdict::Accepted {
            self.rejected += 1;
        }
        verdict
    }

    fn decide<C: Controller>(
        &mut self,
        cmd: &Command,
        controller: &mut C,
        ctx: &mut TickContext<'_>,
    ) -> Verdict {
        // Malformed bytes: answered, not recorded anywhere else (a flood of
        // garbage must not wash the event history away).
        let valid = match cmd.validate() {
            Ok(v) => v,
            Err(reason) => return Verdict::Rejected(reason),
        };
        let goal = match valid {
            ValidCommand::Goal(g) => Some((g.client_id, g.goal_id)),
            _ => None,
        };
        let verdict = self.decide_valid(&valid, goal, controller, ctx);
        if let (Some((client_id, goal_id)), Verdict::Rejected(reason)) = (goal, verdict) {
            ctx.events
                .goal_transition(client_id, goal_id, GoalState::Rejected, reason, 0.0, None);
        }
        verdict
    }

    fn decide_valid<C: Controller>(
        &mut self,
        valid: &ValidCommand,
        goal: Option<(u64, u64)>,
        controller: &mut C,
        ctx: &mut TickContext<'_>,
    ) -> Verdict {
        if self.shutting_down {
            return Verdict::Rejected(ReasonCode::ShuttingDown);
        }
        if let Some((client_id, goal_id)) = goal {
            if self.ids.contains(client_id, goal_id) {
                return Verdict::Rejected(ReasonCode::DuplicateGoalId);
            }
            self.ids.insert(client_id, goal_id);
        }
        let cmd: ControlCommand = match control_command(valid, &self.limits) {
            Ok(c) => c,
            Err(reason) => return Verdict::Rejected(reason),
        };
        controller.command(&cmd, ctx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::tick_events::TickEvents;
    use crate::hold::HoldController;
    use gait::HandConfig;
    use shm_schema::{EventKind, GoalFrame, LimitKind, LimitOrder};

    const Q: [f64; 4] = [1.0, 0.0, 0.0, 0.0];

    #[test]
    fn every_check_in_order() {
        let cfg = HandConfig::default();
        let mut ctl = HoldController::new(&cfg);
        let mut intake = Intake::new(16, cfg.limits);
        let mut events = TickEvents::new();
        let mut ctx = TickContext {
            now: 0,
            tick: 1,
            events: &mut events,
        };
        let mut run = |c: Command, ctx: &mut TickContext<'_>| intake.handle(&c, &mut ctl, ctx);
        let goal = |id| Command::goal(5, id, GoalFrame::Absolute, Q);
        assert_eq!(
            run(
                Command {
                    kind: 42,
                    ..goal(1)
                },
                &mut ctx
            ),
            Verdict::Rejected(ReasonCode::UnknownCommandKind)
        );
        assert_eq!(
            run(goal(1), &mut ctx),
            Verdict::Rejected(ReasonCode::PlannerUnavailable)
        );
        assert_eq!(
            run(goal(1), &mut ctx),
            Verdict::Rejected(ReasonCode::DuplicateGoalId)
        );
        // Same id from another client is fine.
        assert_eq!(
            run(Command::goal(6, 1, GoalFrame::Absolute, Q), &mut ctx),
            Verdict::Rejected(ReasonCode::PlannerUnavailable)
        );
        assert_eq!(
            run(
                goal(2).with_limit(LimitKind::Fingertip, LimitOrder::Jerk, 1e3),
                &mut ctx
            ),
            Verdict::Rejected(ReasonCode::LimitAboveConfigured)
        );
        assert_eq!(run(Command::hold(5), &mut ctx), Verdict::Accepted);
        let kinds: Vec<_> = ctx
            .events
            .as_slice()
            .iter()
            .map(|e| (e.kind().unwrap(), e.reason().unwrap()))
            .collect();
        assert_eq!(
            kinds,
            vec![
                (EventKind::GoalTransition, ReasonCode::PlannerUnavailable),
                (EventKind::GoalTransition, ReasonCode::DuplicateGoalId),
                (EventKind::GoalTransition, ReasonCode::PlannerUnavailable),
                (EventKind::GoalTransition, ReasonCode::LimitAboveConfigured),
                (EventKind::Hold, ReasonCode::HoldRequested),
            ]
        );
        intake.begin_shutdown();
        assert_eq!(
            intake.handle(&Command::hold(5), &mut ctl, &mut ctx),
            Verdict::Rejected(ReasonCode::ShuttingDown)
        );
        assert_eq!((intake.received(), intake.rejected()), (7, 6));
    }

    #[test]
    fn memory_forgets_the_oldest() {
        let mut m = GoalIdMemory::new(2);
        m.insert(1, 1);
        m.insert(1, 2);
        m.insert(1, 3);
        assert!(!m.contains(1, 1));
        assert!(m.contains(1, 2) && m.contains(1, 3));
    }

    /// Seeded sweep against a plain FIFO model: same answers for every
    /// capacity, with keys from small pools so that probes collide, entries
    /// are evicted mid-cluster and ids repeat.
    #[test]
    fn memory_agrees_with_a_fifo_model() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for capacity in [1, 2, 3, 16, 100, 1024] {
            let mut m = GoalIdMemory::new(capacity);
            let mut model = std::collections::VecDeque::new();
            for _ in 0..20_000 {
                let key = (
                    rng.random_range(0..4u64),
                    rng.random_range(0..3 * capacity as u64),
                );
                let seen = model.contains(&key);
                assert_eq!(m.contains(key.0, key.1), seen, "capacity {capacity}");
                if !seen || rng.random_bool(0.1) {
                    m.insert(key.0, key.1);
                    if model.len() == capacity {
                        model.pop_front();
                    }
                    model.push_back(key);
                }
            }
        }
    }
}
