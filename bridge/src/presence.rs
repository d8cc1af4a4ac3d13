//! Which remote clients are there: their liveliness tokens
//! (`P/clients/<identity>/<session>`) and their beats (puts on the same
//! key), counted per identity, and what to do when an identity's last
//! session has been gone for the grace period ([`ClientLostPolicy`]).
//!
//! A session is there while its token is and it beats: one silent for
//! `client_beat_timeout_ms` is gone whatever its Zenoh lease (a client's
//! lease, 10 s by Zenoh's default, would otherwise decide how long a dead
//! operator's goal runs on). The grace period is there because a token also
//! vanishes when a link drops and Zenoh reconnects the same session at once
//! (milliseconds later): such a blip must not stop the operator's goal. A
//! client that is really gone is lost after the beat timeout (or its lease,
//! if shorter) plus the grace.
//!
//! A bridge that (re)starts knows no session yet; it expects every operator
//! ([`Presence::expect`]): one that does not connect within the reconnect
//! wait counts as gone then, and the daemon's status says whether a goal of
//! its runs (the goal's `client_id` is the identity's).

use crate::config::ClientLostPolicy;
use gaitd_client::remote::protocol as proto;
use shm_schema::{Command, GoalState, Status};
use std::collections::HashMap;
use std::time::{Duration, Instant};

/// Sessions present, by identity, and identities whose last session
/// vanished (since when).
#[derive(Debug, Default)]
pub struct Presence {
    /// Sessions by identity: when each last beat (or appeared).
    sessions: HashMap<String, HashMap<String, Instant>>,
    vanished: HashMap<String, Instant>,
}

impl Presence {
    /// A token appeared (`true`) or vanished at `now`. An identity whose
    /// last session vanishes is remembered until [`Presence::lost`] reports
    /// it or one of its sessions comes back (returns `true` then: it is
    /// back within the grace period).
    pub fn update(&mut self, identity: &str, session: &str, present: bool, now: Instant) -> bool {
        if present {
            self.sessions
                .entry(identity.to_owned())
                .or_default()
                .insert(session.to_owned(), now);
            return self.vanished.remove(identity).is_some();
        }
        let Some(set) = self.sessions.get_mut(identity) else {
            return false;
        };
        if set.remove(session).is_some() && set.is_empty() {
            self.sessions.remove(identity);
            self.vanished.insert(identity.to_owned(), now);
        }
        false
    }

    /// A beat of `identity`'s `session` at `now` (a session that beats is
    /// there, token or not yet). Returns `true` as [`Presence::update`].
    pub fn beat(&mut self, identity: &str, session: &str, now: Instant) -> bool {
        self.update(identity, session, true, now)
    }

    /// Sessions silent for `timeout` at `now` are gone (as if their token
    /// vanished then).
    pub fn expire_silent(&mut self, now: Instant, timeout: Duration) {
        let mut gone = Vec::new();
        for (id, set) in &self.sessions {
            for (s, last) in set {
                if now.saturating_duration_since(*last) >= timeout {
                    gone.push((id.clone(), s.clone()));
                }
            }
        }
        for (id, s) in gone {
            self.update(&id, &s, false, now);
        }
    }

    /// `identity` is expected (the bridge just started): unless one of its
    /// sessions shows up, it counts as gone at `at` (in the future: the
    /// time it has to reconnect).
    pub fn expect(&mut self, identity: &str, at: Instant) {
        if !self.sessions.contains_key(identity) {
            self.vanished.insert(identity.to_owned(), at);
        }
    }

    /// The identities gone for at least `grace` at `now` (each reported
    /// once), in name order.
    pub fn lost(&mut self, now: Instant, grace: Duration) -> Vec<String> {
        let mut due: Vec<String> = self
            .vanished
            .iter()
            .filter(|(_, t)| now.saturating_duration_since(**t) >= grace)
            .map(|(id, _)| id.clone())
            .collect();
        due.sort();
        for id in &due {
            self.vanished.remove(id);
        }
        due
    }

    /// When the next vanished identity is due, given `grace`.
    pub fn next_due(&self, grace: Duration) -> Option<Instant> {
        self.vanished.values().map(|t| *t + grace).min()
    }

    /// Sessions of `identity` present now.
    pub fn sessions(&self, identity: &str) -> usize {
        self.sessions.get(identity).map_or(0, HashMap::len)
    }
}

/// The command the policy sends when `identity`'s last session vanished,
/// given the daemon's latest status: only if that identity's goal is still
/// running (another client's goal is never stopped).
pub fn on_lost(
    policy: ClientLostPolicy,
    identity: &str,
    status: Option<&Status>,
) -> Option<Command> {
    let s = status?;
    let id = proto::client_id_for(identity);
    let running = matches!(
        s.goal_state(),
        Ok(GoalState::Accepted | GoalState::Planning | GoalState::Executing)
    );
    if s.goal.client_id != id || !running {
        return None;
    }
    match policy {
        ClientLostPolicy::Hold => Some(Command::hold(id)),
        ClientLostPolicy::Cancel => Some(Command::cancel(id, s.goal.goal_id)),
        ClientLostPolicy::None => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_schema::CommandKind;

    #[test]
    fn the_last_session_counts_after_the_grace_period() {
        let t0 = Instant::now();
        let at = |ms| t0 + Duration::from_millis(ms);
        let grace = Duration::from_millis(1000);
        let mut p = Presence::default();
        assert!(!p.update("op", "s1", true, at(0)));
        assert!(!p.update("op", "s2", true, at(0)));
        assert_eq!(p.sessions("op"), 2);
        assert!(!p.update("op", "s1", false, at(10)));
        assert!(!p.update("op", "s1", false, at(10)));
        assert_eq!(p.lost(at(5000), grace), Vec::<String>::new());
        assert!(!p.update("op", "s2", false, at(100)));
        assert_eq!(p.next_due(grace), Some(at(1100)));
        assert_eq!(p.lost(at(1099), grace), Vec::<String>::new());
        assert_eq!(p.lost(at(1100), grace), vec!["op".to_owned()]);
        // Reported once.
        assert_eq!(p.lost(at(9000), grace), Vec::<String>::new());
        assert_eq!(p.next_due(grace), None);
        assert!(!p.update("ghost", "s", false, at(0)));
        assert_eq!(p.lost(at(9000), grace), Vec::<String>::new());
    }

    #[test]
    fn a_session_back_within_the_grace_period_is_not_lost() {
        let t0 = Instant::now();
        let at = |ms| t0 + Duration::from_millis(ms);
        let grace = Duration::from_millis(1000);
        let mut p = Presence::default();
        p.update("op", "s1", true, at(0));
        p.update("op", "s1", false, at(100));
        // The same session, reconnected by Zenoh 3 ms later.
        assert!(p.update("op", "s1", true, at(103)));
        assert_eq!(p.lost(at(5000), grace), Vec::<String>::new());
        // Gone for good this time.
        p.update("op", "s1", false, at(6000));
        assert_eq!(p.lost(at(7000), grace), vec!["op".to_owned()]);
    }

    #[test]
    fn a_silent_session_is_gone_whatever_its_token() {
        let t0 = Instant::now();
        let at = |ms| t0 + Duration::from_millis(ms);
        let (grace, beat) = (Duration::from_millis(1000), Duration::from_millis(1500));
        let mut p = Presence::default();
        p.update("op", "s1", true, at(0));
        p.beat("op", "s1", at(1000));
        p.expire_silent(at(2400), beat);
        assert_eq!(p.sessions("op"), 1);
        // Killed after its beat at 1 s: its token (a 10 s lease) stays.
        p.expire_silent(at(2500), beat);
        assert_eq!(p.sessions("op"), 0);
        assert_eq!(p.lost(at(3499), grace), Vec::<String>::new());
        assert_eq!(p.lost(at(3500), grace), vec!["op".to_owned()]);
    }

    #[test]
    fn an_expected_operator_that_does_not_come_back_is_lost() {
        let t0 = Instant::now();
        let at = |ms| t0 + Duration::from_millis(ms);
        let grace = Duration::from_millis(1000);
        let mut p = Presence::default();
        p.expect("op", at(2000));
        p.expect("back", at(2000));
        p.update("back", "s", true, at(500));
        assert_eq!(p.lost(at(2999), grace), Vec::<String>::new());
        assert_eq!(p.lost(at(3000), grace), vec!["op".to_owned()]);
    }

    #[test]
    fn only_the_lost_clients_running_goal_is_stopped() {
        let mut s = Status::default();
        s.goal.client_id = proto::client_id_for("op");
        s.goal.goal_id = 9;
        s.goal.state = GoalState::Executing.code();
        let c = on_lost(ClientLostPolicy::Cancel, "op", Some(&s)).unwrap();
        assert_eq!((c.kind, c.goal_id), (CommandKind::Cancel.code(), 9));
        assert_eq!(c.client_id, proto::client_id_for("op"));
        let h = on_lost(ClientLostPolicy::Hold, "op", Some(&s)).unwrap();
        assert_eq!(h.kind, CommandKind::Hold.code());
        assert_eq!(on_lost(ClientLostPolicy::None, "op", Some(&s)), None);
        assert_eq!(on_lost(ClientLostPolicy::Cancel, "other", Some(&s)), None);
        s.goal.state = GoalState::Succeeded.code();
        assert_eq!(on_lost(ClientLostPolicy::Cancel, "op", Some(&s)), None);
        assert_eq!(on_lost(ClientLostPolicy::Cancel, "op", None), None);
    }
}
