//! The set of valid candidate profiles found while searching Step 1.

use crate::profile::Profile;

/// How accepted candidate profiles are kept.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Keep {
    /// All of them (up to six), in the order found.
    All,
    /// Only the shortest; with `exact`, only profiles that reach the target
    /// to rounding precision (not merely within the check's tolerances).
    Shortest {
        /// Require an exact final state.
        exact: bool,
        /// Whether the final position counts (position interface).
        position: bool,
    },
}

/// Valid extremal profiles: up to five (plus a spare for numerical
/// duplicates), or only the shortest one.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Valid {
    pub list: [Profile; 7],
    pub n: usize,
    keep: Keep,
    /// Candidates at least this long (phase sum) are not worth checking.
    bound: f64,
}

impl Valid {
    pub(crate) fn new(boundary: &Profile) -> Self {
        Self::with(boundary, Keep::All)
    }

    pub(crate) fn with(boundary: &Profile, keep: Keep) -> Self {
        let mut v = Self {
            list: [Profile::default(); 7],
            n: 0,
            keep,
            bound: f64::INFINITY,
        };
        v.reset(boundary, keep, f64::INFINITY);
        v
    }

    /// Starts over on `boundary` (reusing the memory: no re-initialisation).
    #[inline]
    pub(crate) fn reset(&mut self, boundary: &Profile, keep: Keep, bound: f64) {
        // Only the boundary matters: every candidate assigns its phase
        // durations and the check recomputes everything else.
        self.list[0].set_boundary_from(boundary);
        if keep != Keep::All {
            self.list[1].set_boundary_from(boundary);
        }
        self.n = 0;
        self.keep = keep;
        self.bound = bound;
    }

    /// Starts over after a search on the same boundary: every slot up to
    /// `n + 1` already holds that boundary (`accept` copies it forward), so
    /// nothing is copied.
    #[inline]
    pub(crate) fn restart(&mut self, keep: Keep, bound: f64) {
        if self.n == 0 {
            self.list[1] = self.list[0];
        }
        self.n = 0;
        self.keep = keep;
        self.bound = bound;
    }

    /// Whether a candidate's phases are short enough to be worth checking.
    #[inline]
    pub(crate) fn admits(p: &Profile, bound: f64) -> bool {
        bound == f64::INFINITY || p.t.iter().sum::<f64>() < bound
    }

    /// The current duration bound.
    #[inline]
    pub(crate) fn bound(&self) -> f64 {
        self.bound
    }

    /// The profile being filled.
    #[inline]
    pub(crate) fn cur(&mut self) -> &mut Profile {
        &mut self.list[self.n]
    }

    /// Whether a reduced shape should stop after its first valid profile.
    #[inline]
    pub(crate) fn first_only(&self) -> bool {
        self.keep == Keep::All
    }

    /// Accepts the current profile; the next candidate keeps its boundary.
    #[inline]
    pub(crate) fn accept(&mut self) {
        match self.keep {
            Keep::All => {
                if self.n < 6 {
                    self.n += 1;
                    let (done, next) = self.list.split_at_mut(self.n);
                    next[0].set_boundary_from(&done[self.n - 1]);
                }
            }
            Keep::Shortest { exact, position } => {
                let c = &self.list[self.n];
                let tight =
                    |x: f64, target: f64| (x - target).abs() <= 1e-12 * target.abs().max(1.0);
                let p_ok = !position || tight(c.p[7], c.pf);
                if exact && !(p_ok && tight(c.v[7], c.vf) && tight(c.a[7], c.af)) {
                    return;
                }
                if self.n == 0 {
                    self.n = 1;
                } else if self.list[1].t_sum[6] < self.list[0].t_sum[6] {
                    self.list.swap(0, 1);
                }
            }
        }
    }
}
