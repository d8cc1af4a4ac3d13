//! Commands in flight on a remote link, and which to send again.
//!
//! A Zenoh link to the bridge may drop with a query in flight and come back
//! at once (bridge/PROTOCOL.md, "Known issue"): its query or its reply is
//! lost. Such a request is sent again, with the same request id and bytes,
//! when the link is back; the bridge answers a repeat as before, without
//! sending it to the daemon twice. Time is passed in, so this is plain
//! bookkeeping the client drives.

#![cfg_attr(not(feature = "remote"), allow(dead_code))]

use shm_schema::Command;
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// Requests remembered (the oldest is forgotten first).
const KEPT: usize = 256;

/// How long a query that ended early without a reply, the link up, waits
/// for a link drop to be reported before it counts as unanswered.
const UNANSWERED_WAIT: Duration = Duration::from_millis(200);

/// The least time between two sends of one request.
const RESEND_PAUSE: Duration = Duration::from_millis(50);

/// One request as sent.
#[derive(Debug, Clone, Copy)]
struct Sent {
    id: u64,
    /// Its command key chunk.
    name: &'static str,
    command: Command,
    /// When it was (last) sent.
    at: Instant,
}

/// The requests of a remote client still waiting for an answer (module docs).
#[derive(Debug, Default)]
pub(crate) struct InFlight {
    sent: VecDeque<Sent>,
    /// To be sent again when the link is up.
    resend: VecDeque<u64>,
    /// Sent again at least once.
    resent: VecDeque<u64>,
    /// Ended early without a reply while everything was in sight, and when.
    unanswered: VecDeque<(u64, Instant)>,
}

impl InFlight {
    /// Request `id` (command `command` to key chunk `name`) was sent at `now`.
    pub fn sent(&mut self, id: u64, name: &'static str, command: Command, now: Instant) {
        if self.sent.len() == KEPT {
            self.sent.pop_front();
        }
        self.sent.push_back(Sent {
            id,
            name,
            command,
            at: now,
        });
    }

    /// The command key chunk of request `id`.
    pub fn name(&self, id: u64) -> Option<&'static str> {
        self.find(id).map(|s| s.name)
    }

    fn find(&self, id: u64) -> Option<&Sent> {
        self.sent.iter().find(|s| s.id == id)
    }

    /// The link dropped: every request sent within a query's timeout
    /// `waited` and not `answered` may have lost its query or its reply.
    pub fn link_dropped(&mut self, now: Instant, waited: Duration, answered: impl Fn(u64) -> bool) {
        for s in &self.sent {
            let in_flight = now.saturating_duration_since(s.at) < waited;
            if in_flight && !answered(s.id) && !self.resend.contains(&s.id) {
                self.resend.push_back(s.id);
            }
        }
        self.unanswered.clear();
    }

    /// Request `id`'s query ended at `now` without a reply; `in_sight`:
    /// bridge, daemon and link all up. Returns `false` if it is unanswered
    /// now, `true` if that is decided later (it waits a moment for a link
    /// drop to be reported, or is sent again).
    pub fn no_reply(&mut self, id: u64, now: Instant, waited: Duration, in_sight: bool) -> bool {
        if self.resend.contains(&id) {
            // Sent again: the new query's reply decides.
            return true;
        }
        if in_sight {
            let early = self
                .find(id)
                .is_some_and(|s| now.saturating_duration_since(s.at) < waited.mul_f64(0.9));
            if early {
                self.unanswered.push_back((id, now));
            }
            return early;
        }
        // The link is down: sent again when it is back.
        self.resend.push_back(id);
        true
    }

    /// A request that ended early without a reply and no link drop was
    /// reported within [`UNANSWERED_WAIT`]: unanswered.
    pub fn unanswered(&mut self, now: Instant) -> Option<u64> {
        let &(id, at) = self.unanswered.front()?;
        if now.saturating_duration_since(at) < UNANSWERED_WAIT {
            return None;
        }
        self.unanswered.pop_front();
        Some(id)
    }

    /// The requests to send again now (the link is up), each at most every
    /// [`RESEND_PAUSE`]: id, key chunk, command.
    pub fn take_due(&mut self, now: Instant) -> Vec<(u64, &'static str, Command)> {
        let mut due = Vec::new();
        let mut later = VecDeque::new();
        while let Some(id) = self.resend.pop_front() {
            let Some(s) = self.sent.iter_mut().find(|s| s.id == id) else {
                continue;
            };
            if now.saturating_duration_since(s.at) < RESEND_PAUSE {
                later.push_back(id);
                continue;
            }
            s.at = now;
            due.push((id, s.name, s.command));
            if !self.resent.contains(&id) {
                if self.resent.len() == KEPT {
                    self.resent.pop_front();
                }
                self.resent.push_back(id);
            }
        }
        self.resend = later;
        due
    }

    /// Whether request `id` waits for the link or was sent again (a timeout
    /// then means the link was lost).
    pub fn hit_by_a_drop(&self, id: u64) -> bool {
        self.resend.contains(&id) || self.resent.contains(&id)
    }

    /// Request `id` is done with (answered, failed or given up).
    pub fn done(&mut self, id: u64) {
        self.sent.retain(|s| s.id != id);
        self.resend.retain(|&r| r != id);
        self.unanswered.retain(|&(r, _)| r != id);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WAITED: Duration = Duration::from_secs(10);

    fn ms(t0: Instant, ms: u64) -> Instant {
        t0 + Duration::from_millis(ms)
    }

    #[test]
    fn a_link_drop_sends_the_unanswered_requests_again_once_each_pause() {
        let t0 = Instant::now();
        let mut f = InFlight::default();
        f.sent(1, "hold", Command::hold(7), t0);
        f.sent(2, "cancel", Command::cancel(7, 3), t0);
        f.sent(3, "hold", Command::hold(7), t0);
        assert_eq!(f.name(2), Some("cancel"));
        // 3 is answered already; none was sent more than WAITED ago.
        f.link_dropped(ms(t0, 100), WAITED, |id| id == 3);
        let due: Vec<u64> = f.take_due(ms(t0, 100)).iter().map(|d| d.0).collect();
        assert_eq!(due, [1, 2]);
        assert!(f.hit_by_a_drop(1) && !f.hit_by_a_drop(3));
        // The new query of 1 ends without a reply too, the link down again:
        // not before the pause.
        assert!(f.no_reply(1, ms(t0, 120), WAITED, false));
        assert!(f.take_due(ms(t0, 120)).is_empty());
        assert_eq!(f.take_due(ms(t0, 150))[0].0, 1);
        f.done(1);
        assert_eq!(f.name(1), None);
        assert!(f.take_due(ms(t0, 500)).iter().all(|d| d.0 != 1));
    }

    #[test]
    fn an_early_end_in_sight_waits_for_a_drop_then_is_unanswered() {
        let t0 = Instant::now();
        let mut f = InFlight::default();
        f.sent(1, "hold", Command::hold(7), t0);
        assert!(f.no_reply(1, ms(t0, 5), WAITED, true));
        assert_eq!(f.unanswered(ms(t0, 204)), None);
        assert_eq!(f.unanswered(ms(t0, 205)), Some(1));
        // A drop reported in time sends it again instead.
        f.sent(2, "hold", Command::hold(7), t0);
        assert!(f.no_reply(2, ms(t0, 5), WAITED, true));
        f.link_dropped(ms(t0, 50), WAITED, |_| false);
        assert_eq!(f.unanswered(ms(t0, 500)), None);
        assert!(f.take_due(ms(t0, 500)).iter().any(|d| d.0 == 2));
        // A query that ran out its timeout in sight is unanswered at once.
        f.sent(4, "hold", Command::hold(7), t0);
        assert!(!f.no_reply(4, ms(t0, 9_500), WAITED, true));
    }
}
