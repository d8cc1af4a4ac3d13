//! Per-identity command rate limit: a token bucket per identity, refilled
//! at `rate` per second up to `burst` (time injected, so tests need no clock).

use std::collections::HashMap;
use std::time::Instant;

/// One identity's bucket.
#[derive(Debug, Clone, Copy)]
struct Bucket {
    tokens: f64,
    at: Instant,
}

/// Token buckets by identity.
#[derive(Debug)]
pub struct RateLimiter {
    rate: f64,
    burst: f64,
    buckets: HashMap<String, Bucket>,
}

impl RateLimiter {
    /// `rate` commands per second sustained, `burst` at once.
    pub fn new(rate: f64, burst: u32) -> Self {
        Self {
            rate,
            burst: f64::from(burst.max(1)),
            buckets: HashMap::new(),
        }
    }

    /// Takes a token for `identity` at `now`; false when none is left.
    pub fn allow(&mut self, identity: &str, now: Instant) -> bool {
        let burst = self.burst;
        let b = self.buckets.entry(identity.to_owned()).or_insert(Bucket {
            tokens: burst,
            at: now,
        });
        let dt = now.saturating_duration_since(b.at).as_secs_f64();
        b.tokens = (b.tokens + dt * self.rate).min(burst);
        b.at = now;
        if b.tokens >= 1.0 {
            b.tokens -= 1.0;
            true
        } else {
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn burst_then_rate_per_identity() {
        let t0 = Instant::now();
        let mut r = RateLimiter::new(2.0, 3);
        assert!((0..3).all(|_| r.allow("a", t0)));
        assert!(!r.allow("a", t0));
        // Another identity has its own bucket.
        assert!(r.allow("b", t0));
        // Half a second at 2/s gives one more.
        assert!(r.allow("a", t0 + Duration::from_millis(500)));
        assert!(!r.allow("a", t0 + Duration::from_millis(500)));
        // Never more than the burst, however long the pause.
        let later = t0 + Duration::from_secs(3600);
        assert_eq!((0..10).filter(|_| r.allow("a", later)).count(), 3);
    }
}
