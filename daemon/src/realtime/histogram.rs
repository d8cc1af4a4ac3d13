//! Fixed-size log-linear histogram of nanosecond durations (compute time,
//! wake-up jitter): allocated once, `record` is O(1) and allocation-free.
//!
//! Values below 64 ns get their own bucket; above, every power of two is
//! split into 32 linear sub-buckets, so a bucket's width is at most 1/32 of
//! its lower edge (≈ 3 % relative resolution) up to 2^40 ns (≈ 18 min);
//! larger values land in the last bucket. Percentiles report the bucket's
//! upper edge (never under-estimate), clamped to the exact maximum.

const SUB_BITS: u32 = 5;
const SUB: usize = 1 << SUB_BITS; // 32 sub-buckets per octave
const LINEAR: u64 = 64; // values < 64 are exact
const MAX_EXP: u32 = 40;
const BUCKETS: usize = LINEAR as usize + (MAX_EXP as usize - 6) * SUB;

/// Log-linear histogram with exact count, sum and max.
#[derive(Clone)]
pub struct Histogram {
    counts: Box<[u64; BUCKETS]>,
    count: u64,
    sum: u128,
    max: u64,
}

impl std::fmt::Debug for Histogram {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Histogram")
            .field("count", &self.count)
            .field("max", &self.max)
            .finish()
    }
}

impl Default for Histogram {
    fn default() -> Self {
        Self::new()
    }
}

fn bucket_of(v: u64) -> usize {
    if v < LINEAR {
        return v as usize;
    }
    let exp = 63 - v.leading_zeros(); // ≥ 6
    if exp >= MAX_EXP {
        return BUCKETS - 1;
    }
    let sub = ((v >> (exp - SUB_BITS)) as usize) & (SUB - 1);
    LINEAR as usize + (exp as usize - 6) * SUB + sub
}

/// Upper edge (exclusive) of bucket `b`.
fn bucket_upper(b: usize) -> u64 {
    if b < LINEAR as usize {
        return b as u64 + 1;
    }
    let i = b - LINEAR as usize;
    let exp = (i / SUB) as u32 + 6;
    let sub = (i % SUB) as u64;
    let width = 1u64 << (exp - SUB_BITS);
    (1u64 << exp) + (sub + 1) * width
}

impl Histogram {
    /// An empty histogram (one allocation, here and never again).
    pub fn new() -> Self {
        Self {
            counts: Box::new([0; BUCKETS]),
            count: 0,
            sum: 0,
            max: 0,
        }
    }

    /// Adds one value.
    pub fn record(&mut self, v: u64) {
        self.counts[bucket_of(v)] += 1;
        self.count += 1;
        self.sum += u128::from(v);
        self.max = self.max.max(v);
    }

    /// Number of values.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Largest value (0 if empty).
    pub fn max(&self) -> u64 {
        self.max
    }

    /// Mean (0 if empty).
    pub fn mean(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            self.sum as f64 / self.count as f64
        }
    }

    /// The `q`-quantile (0 < q ≤ 1): the smallest bucket upper edge below
    /// which at least a fraction q of the values lie, at most the maximum.
    /// Scans the buckets: call it every few ticks, not every tick.
    pub fn quantile(&self, q: f64) -> u64 {
        if self.count == 0 {
            return 0;
        }
        let rank = ((q.clamp(0.0, 1.0) * self.count as f64).ceil() as u64).max(1);
        let mut seen = 0;
        for (b, &c) in self.counts.iter().enumerate() {
            seen += c;
            if seen >= rank {
                return bucket_upper(b).saturating_sub(1).min(self.max);
            }
        }
        self.max
    }

    /// Forgets every value.
    pub fn clear(&mut self) {
        self.counts.fill(0);
        self.count = 0;
        self.sum = 0;
        self.max = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn buckets_are_contiguous_and_ordered() {
        let mut prev_upper = 0;
        for b in 0..BUCKETS - 1 {
            let up = bucket_upper(b);
            assert!(up > prev_upper);
            assert_eq!(bucket_of(up - 1), b, "bucket {b}");
            assert_eq!(bucket_of(up), b + 1, "bucket {b}");
            prev_upper = up;
        }
        assert_eq!(bucket_of(u64::MAX), BUCKETS - 1);
    }

    /// Seeded sweep: the reported quantile is never below the exact one and
    /// at most 1/32 above it (the bucket resolution).
    #[test]
    fn quantiles_bracket_the_exact_ones() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(42);
        for _ in 0..20 {
            let mut h = Histogram::new();
            let n = rng.random_range(1..5000);
            let scale = 10f64.powi(rng.random_range(1..9));
            let mut v: Vec<u64> = (0..n)
                .map(|_| (rng.random::<f64>().powi(3) * scale) as u64)
                .collect();
            for &x in &v {
                h.record(x);
            }
            v.sort_unstable();
            for q in [0.5, 0.9, 0.99, 1.0] {
                let exact = v[((q * n as f64).ceil() as usize).max(1) - 1];
                let got = h.quantile(q);
                assert!(got >= exact, "q={q} got {got} < exact {exact}");
                assert!(
                    got as f64 <= exact as f64 * (1.0 + 1.0 / 32.0) + 1.0,
                    "q={q} got {got} exact {exact}"
                );
            }
            assert_eq!(h.max(), *v.last().unwrap());
            assert_eq!(h.count(), n as u64);
        }
    }
}
