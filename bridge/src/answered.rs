//! The daemon's recent answers by (identity, request id), so that a command
//! sent again after a dropped link (its reply lost on the way; see
//! PROTOCOL.md, "Known issue") is answered again without reaching the
//! daemon twice: at most once to the daemon, at least once to the client.

use gaitd_client::Answer;
use shm_schema::Command;
use std::collections::{HashMap, VecDeque};

/// Answers kept (the oldest is forgotten first).
pub const KEPT: usize = 1024;

/// Recent answers (module docs).
#[derive(Debug, Default)]
pub struct Answered {
    by_key: HashMap<(String, u64), (Command, Answer)>,
    order: VecDeque<(String, u64)>,
}

impl Answered {
    /// The answer already given to `identity`'s `command`, if this is the
    /// same command again (same request id, same bytes).
    pub fn get(&self, identity: &str, command: &Command) -> Option<Answer> {
        self.by_key
            .get(&(identity.to_owned(), command.request_id))
            .filter(|(c, _)| c == command)
            .map(|(_, a)| *a)
    }

    /// Remembers the answer to `identity`'s `command`.
    pub fn insert(&mut self, identity: &str, command: &Command, answer: Answer) {
        let key = (identity.to_owned(), command.request_id);
        if self
            .by_key
            .insert(key.clone(), (*command, answer))
            .is_none()
        {
            self.order.push_back(key);
        }
        while self.order.len() > KEPT {
            if let Some(old) = self.order.pop_front() {
                self.by_key.remove(&old);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn answer(tick: u64) -> Answer {
        Answer {
            tick,
            ..Answer::default()
        }
    }

    fn hold(request_id: u64) -> Command {
        Command {
            request_id,
            ..Command::hold(1)
        }
    }

    #[test]
    fn the_same_command_again_gets_the_same_answer_and_the_oldest_go() {
        let mut a = Answered::default();
        a.insert("op", &hold(1), answer(10));
        a.insert("other", &hold(1), answer(11));
        assert_eq!(a.get("op", &hold(1)).map(|x| x.tick), Some(10));
        assert_eq!(a.get("other", &hold(1)).map(|x| x.tick), Some(11));
        assert_eq!(a.get("op", &hold(2)), None);
        // The same request id with other bytes is another command.
        let cancel = Command {
            request_id: 1,
            ..Command::cancel(1, 5)
        };
        assert_eq!(a.get("op", &cancel), None);
        for r in 2..=KEPT as u64 {
            a.insert("op", &hold(r), answer(r));
        }
        // KEPT + 1 answers given: the first one is forgotten.
        assert_eq!(a.get("op", &hold(1)), None);
        assert_eq!(a.get("other", &hold(1)).map(|x| x.tick), Some(11));
        let last = KEPT as u64;
        assert_eq!(a.get("op", &hold(last)).map(|x| x.tick), Some(last));
    }
}
