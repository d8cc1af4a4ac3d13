//! Per-instance continuity of the events a remote client receives
//! (PROTOCOL.md, "Events"): every event is identified by its daemon
//! `instance` and `seq`, and `seq` counts from 1 without gaps in an
//! instance. A bridge's history repeats events, a restarted bridge's cache
//! may fill a gap late: each event is delivered once, a hole in the
//! sequence is remembered until an event fills it, and what is still
//! missing is counted, so a client can say it missed events instead of
//! going on without them. A late joiner's history may arrive after the
//! first live event: events older than the oldest seen are new too (a
//! low-water mark), so a history that comes second is not dropped as
//! repeats.

use std::collections::BTreeMap;

/// The events of the current instance seen so far (module docs).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Continuity {
    /// The instance the sequence belongs to (0: none yet).
    instance: u64,
    /// The first `seq` received of this instance.
    first: u64,
    /// Lowest `seq` seen (nothing below it was seen: all of it is new).
    low: u64,
    /// Highest `seq` seen.
    high: u64,
    /// Holes below `high`: first → last (inclusive).
    holes: BTreeMap<u64, u64>,
}

impl Continuity {
    /// Takes event (`instance`, `seq`): whether to deliver it (new, or
    /// filling a hole, or older than any seen) rather than drop it as a
    /// repeat. A new instance (a daemon restart) starts a new sequence at
    /// its first event seen.
    pub fn accept(&mut self, instance: u64, seq: u64) -> bool {
        if instance != self.instance {
            *self = Self {
                instance,
                first: seq,
                low: seq,
                high: seq,
                holes: BTreeMap::new(),
            };
            return true;
        }
        if seq < self.low {
            // History arriving after a later event: what lies between it
            // and the oldest seen is a hole until its own events come.
            if seq + 1 < self.low {
                self.holes.insert(seq + 1, self.low - 1);
            }
            self.low = seq;
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

    /// Whether events of this instance older than the first one received
    /// may still be owed: it did not start the sequence (seq 1) and
    /// nothing older arrived (no history yet).
    pub fn history_owed(&self) -> bool {
        self.instance != 0 && self.low > 1 && self.low == self.first
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
        assert!(c.history_owed(), "nothing older than 444 came");
        // Another daemon instance: a new sequence.
        assert!(c.accept(8, 1));
        assert_eq!(c.missing(), 0);
        assert!(!c.history_owed(), "seq 1 has no history");
    }

    #[test]
    fn a_history_arriving_after_the_first_live_event_is_delivered() {
        let mut c = Continuity::default();
        // A late joiner: the live event 28 comes before the cache's 1..=27.
        assert!(c.accept(3, 28));
        assert!(c.history_owed());
        assert!(c.accept(3, 5));
        assert!(!c.history_owed());
        assert_eq!(c.holes(), vec![(3, 6, 27)]);
        for s in 6..=27 {
            assert!(c.accept(3, s), "{s}");
        }
        assert!(c.accept(3, 4));
        assert_eq!(c.missing(), 0);
        // Repeats of all of it are dropped.
        for s in 4..=28 {
            assert!(!c.accept(3, s), "{s} delivered twice");
        }
        assert!(c.accept(3, 29));
    }
}
