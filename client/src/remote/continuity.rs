//! Per-instance continuity of the events a remote client receives
//! (PROTOCOL.md, "Events"): every event is identified by its daemon
//! `instance` and `seq`, and `seq` counts from 1 without gaps in an
//! instance. A bridge's history repeats events, a restarted bridge's cache
//! may fill a gap late: each event is delivered once, a hole in the
//! sequence is remembered until an event fills it, and what is still
//! missing is counted, so a client can say it missed events instead of
//! going on without them.

use std::collections::BTreeMap;

/// The events of the current instance seen so far (module docs).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Continuity {
    /// The instance the sequence belongs to (0: none yet).
    instance: u64,
    /// Highest `seq` seen.
    high: u64,
    /// Holes below `high`: first → last (inclusive).
    holes: BTreeMap<u64, u64>,
}

impl Continuity {
    /// Takes event (`instance`, `seq`): whether to deliver it (new, or
    /// filling a hole) rather than drop it as a repeat. A new instance (a
    /// daemon restart) starts a new sequence at its first event seen.
    pub fn accept(&mut self, instance: u64, seq: u64) -> bool {
        if instance != self.instance {
            *self = Self {
                instance,
                high: seq,
                holes: BTreeMap::new(),
            };
            return true;
        }
        if seq > self.high {
            if seq > self.high + 1 {
                self.holes.insert(self.high + 1, seq - 1);
            }
            self.high = seq;
            return true;
        }
        // A late event: only if it fills a hole.
        let Some((&first, &last)) = self.holes.range(..=seq).next_back() else {
            return false;
        };
        if seq > last {
            return false;
        }
        self.holes.remove(&first);
        if first < seq {
            self.holes.insert(first, seq - 1);
        }
        if seq < last {
            self.holes.insert(seq + 1, last);
        }
        true
    }

    /// Events of this instance still missing (holes not filled).
    pub fn missing(&self) -> u64 {
        self.holes.iter().map(|(a, b)| b - a + 1).sum()
    }

    /// The holes, oldest first: (instance, first seq, last seq).
    pub fn holes(&self) -> Vec<(u64, u64, u64)> {
        self.holes
            .iter()
            .map(|(a, b)| (self.instance, *a, *b))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holes_are_counted_filled_late_and_repeats_dropped() {
        let mut c = Continuity::default();
        assert!(c.accept(7, 444));
        assert!(c.accept(7, 445));
        // A bridge restart lost 446..=684; live events come on.
        assert!(c.accept(7, 685));
        assert_eq!(c.missing(), 239);
        assert_eq!(c.holes(), vec![(7, 446, 684)]);
        // Its cache fills part of it, with a repeat among them.
        assert!(c.accept(7, 600));
        assert!(!c.accept(7, 600));
        assert!(!c.accept(7, 445));
        for s in 601..=684 {
            assert!(c.accept(7, s));
        }
        assert_eq!(c.holes(), vec![(7, 446, 599)]);
        assert_eq!(c.missing(), 154);
        // Another daemon instance: a new sequence.
        assert!(c.accept(8, 1));
        assert_eq!(c.missing(), 0);
    }
}
