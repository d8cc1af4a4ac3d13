//! Which remote clients are there: their liveliness tokens
//! (`P/clients/<identity>/<session>`), counted per identity, and what to do
//! when an identity's last session vanishes ([`ClientLostPolicy`]).

use crate::config::ClientLostPolicy;
use gaitd_client::remote::protocol as proto;
use shm_schema::{Command, GoalState, Status};
use std::collections::{HashMap, HashSet};

/// Sessions present, by identity.
#[derive(Debug, Default)]
pub struct Presence {
    sessions: HashMap<String, HashSet<String>>,
}

impl Presence {
    /// A token appeared (`true`) or vanished; returns the identity whose
    /// last session just vanished, if that is what happened.
    pub fn update(&mut self, identity: &str, session: &str, present: bool) -> Option<String> {
        if present {
            self.sessions
                .entry(identity.to_owned())
                .or_default()
                .insert(session.to_owned());
            return None;
        }
        let set = self.sessions.get_mut(identity)?;
        if !set.remove(session) || !set.is_empty() {
            return None;
        }
        self.sessions.remove(identity);
        Some(identity.to_owned())
    }

    /// Sessions of `identity` present now.
    pub fn sessions(&self, identity: &str) -> usize {
        self.sessions.get(identity).map_or(0, HashSet::len)
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
    fn the_last_session_counts() {
        let mut p = Presence::default();
        assert_eq!(p.update("op", "s1", true), None);
        assert_eq!(p.update("op", "s2", true), None);
        assert_eq!(p.sessions("op"), 2);
        assert_eq!(p.update("op", "s1", false), None);
        assert_eq!(p.update("op", "s1", false), None);
        assert_eq!(p.update("op", "s2", false), Some("op".into()));
        assert_eq!(p.update("ghost", "s", false), None);
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
