//! The remote side of [`Client`]: what arrived from the bridge, the
//! requests in flight sent again after a dropped link
//! ([`InFlight`](crate::remote::inflight::InFlight)), and why a remote
//! connection is silent.

use super::{Client, EVENT_BACKLOG, Transport};
use crate::error::Error;
use crate::remote::RemoteError;
use crate::remote::transport::ReplyOutcome;
use shm_schema::Answer;
use std::time::{Duration, Instant};

/// A query that ended without a reply while the bridge was out of sight.
pub(super) fn lost(endpoint: &str) -> RemoteError {
    RemoteError::Unreachable {
        endpoint: endpoint.to_owned(),
        why: "the connection to the bridge is lost (reconnecting)".into(),
    }
}

impl Client {
    /// Takes what arrived from the bridge: events, status, replies (a
    /// query that ended without one may be sent again, see
    /// [`InFlight`](crate::remote::inflight::InFlight)); sends again what
    /// is due.
    pub(super) fn pump_remote(&mut self) {
        let Transport::Remote(r) = &mut self.conn else {
            return;
        };
        let d = r.drain();
        let (bridge, daemon) = r.alive();
        let linked = r.linked();
        let waited = r.query_timeout();
        self.bad_samples += d.bad_samples;
        self.reconnects += d.bridge_returns;
        // The link dropped (PROTOCOL.md, "Known issue"): every request
        // still in flight may have lost its query or its reply with it.
        // Each is sent again when the link is back, with the same request
        // id: the bridge answers a repeated one as before, without sending
        // it to the daemon twice.
        let now = Instant::now();
        if d.link_drops > 0 {
            let answers = &self.answers;
            self.inflight
                .link_dropped(now, waited, |id| answers.iter().any(|a| a.request_id == id));
        }
        for e in d.events {
            if self.events.len() == EVENT_BACKLOG {
                self.events.pop_front();
            }
            self.events.push_back(e);
        }
        for (id, outcome) in d.replies {
            if !self.outstanding.iter().any(|&(_, r)| r == id) {
                continue;
            }
            let failure = match outcome {
                ReplyOutcome::Answer(a) => {
                    self.answers.push_back(Answer {
                        request_id: id,
                        ..a
                    });
                    continue;
                }
                ReplyOutcome::Refused(r) => RemoteError::Refused(r),
                ReplyOutcome::Bad(why) => RemoteError::BadReply(why),
                ReplyOutcome::NoReply
                    if self
                        .inflight
                        .no_reply(id, now, waited, bridge && daemon && linked) =>
                {
                    continue;
                }
                ReplyOutcome::NoReply => RemoteError::NoAnswer {
                    command: String::new(),
                    identity: String::new(),
                    waited,
                },
            };
            self.fail(id, failure);
        }
        if let Some(s) = d.status {
            self.last_status = Some(s);
        }
        while let Some(id) = self.inflight.unanswered(now) {
            let no = RemoteError::NoAnswer {
                command: String::new(),
                identity: String::new(),
                waited,
            };
            self.fail(id, no);
        }
        if bridge && daemon {
            self.send_again();
        }
    }

    /// Sends the requests due to be sent again, once the link to the bridge
    /// is up.
    fn send_again(&mut self) {
        use crate::remote::protocol as proto;
        let Transport::Remote(r) = &self.conn else {
            return;
        };
        if !r.linked() {
            return;
        }
        let mut failed = Vec::new();
        for (id, name, cmd) in self.inflight.take_due(Instant::now()) {
            if r.send(name, cmd.to_bytes().to_vec(), proto::COMMAND_SCHEMA, id)
                .is_err()
            {
                failed.push((id, lost(&r.endpoint)));
            }
        }
        for (id, why) in failed {
            self.fail(id, why);
        }
    }

    /// Records why request `id` ended without an answer.
    pub(super) fn fail(&mut self, id: u64, why: RemoteError) {
        if self.failures.len() == 64 {
            self.failures.pop_front();
        }
        self.failures.push_back((id, why));
    }

    /// Why a remote connection shows no fresh status.
    pub(super) fn remote_silence(&self, waited: Duration) -> Error {
        let Transport::Remote(r) = &self.conn else {
            return Error::Invalid("not remote");
        };
        Error::Remote(match r.alive() {
            (false, _) => RemoteError::NoBridge {
                endpoint: r.endpoint.clone(),
                identity: r.identity.clone(),
                prefix: r.prefix.clone(),
                waited,
            },
            (true, false) => RemoteError::NoDaemonBehindBridge {
                endpoint: r.endpoint.clone(),
                waited,
            },
            (true, true) => RemoteError::BadReply(format!(
                "the bridge at {} sees gaitd but sent no status within {waited:?}",
                r.endpoint
            )),
        })
    }
}
