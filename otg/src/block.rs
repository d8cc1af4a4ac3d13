//! The set of feasible durations of one DoF: at least its time-optimal
//! duration `t_min`, minus up to two *blocked intervals* (durations that no
//! profile achieves when the target velocity or acceleration is non-zero).
//! Time synchronisation picks the earliest duration feasible for every DoF
//! (Berscheid & Kröger 2021, §IV-B).

use crate::profile::Profile;

/// A blocked interval `(left, right)` of durations; `profile` achieves `right`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Left end \[s\] (feasible).
    pub left: f64,
    /// Right end \[s\] (feasible).
    pub right: f64,
    /// The extremal profile of duration `right`.
    pub profile: Profile,
}

impl Interval {
    fn between(a: &Profile, b: &Profile) -> Self {
        let (da, db) = (a.duration(), b.duration());
        if da < db {
            Self {
                left: da,
                right: db,
                profile: *b,
            }
        } else {
            Self {
                left: db,
                right: da,
                profile: *a,
            }
        }
    }
}

/// Feasible durations of one DoF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Block {
    /// The time-optimal profile.
    pub p_min: Profile,
    /// Its duration \[s\] (including the brake).
    pub t_min: f64,
    /// First blocked interval.
    pub a: Option<Interval>,
    /// Second blocked interval.
    pub b: Option<Interval>,
}

impl Default for Block {
    fn default() -> Self {
        Self {
            p_min: Profile::default(),
            t_min: 0.0,
            a: None,
            b: None,
        }
    }
}

impl Block {
    pub(crate) fn set_min(&mut self, p: &Profile) {
        self.p_min = *p;
        self.t_min = p.duration();
        self.a = None;
        self.b = None;
    }

    /// Builds the block from the valid extremal profiles found in Step 1;
    /// `false` if their number cannot be interpreted (numerical trouble).
    pub(crate) fn build(&mut self, valid: &mut [Profile], mut n: usize) -> bool {
        let total = |p: &Profile| p.t_sum[6];
        match n {
            0 => return false,
            1 => {
                self.set_min(&valid[0]);
                return true;
            }
            2 => {
                let (i_min, i_other) =
                    if (total(&valid[0]) - total(&valid[1])).abs() < 8.0 * f64::EPSILON {
                        self.set_min(&valid[0]);
                        return true;
                    } else if total(&valid[0]) < total(&valid[1]) {
                        (0, 1)
                    } else {
                        (1, 0)
                    };
                self.set_min(&valid[i_min]);
                // An odd root was lost numerically; block up to the other
                // profile, but keep durations within rounding of t_min.
                let mut a = Interval::between(&valid[i_min], &valid[i_other]);
                a.left = a
                    .left
                    .max(self.t_min + crate::limits::close_tol(self.t_min));
                self.a = Some(a);
                return true;
            }
            4 => {
                // Duplicate solutions from both directions (numerical): drop one.
                let close = |i: usize, k: usize, tol: f64| {
                    (total(&valid[i]) - total(&valid[k])).abs() < tol * f64::EPSILON
                        && valid[i].direction != valid[k].direction
                };
                let drop = if close(0, 1, 32.0) {
                    1
                } else if close(2, 3, 256.0) || close(0, 3, 256.0) {
                    3
                } else {
                    return false;
                };
                for i in drop..n - 1 {
                    valid[i] = valid[i + 1];
                }
                n -= 1;
            }
            _ if n.is_multiple_of(2) => return false,
            _ => {}
        }

        let mut i_min = 0;
        for i in 1..n {
            if total(&valid[i]) < total(&valid[i_min]) {
                i_min = i;
            }
        }
        self.set_min(&valid[i_min]);
        let at = |k: usize| &valid[(i_min + k) % n];
        let ok = match n {
            3 => {
                self.a = Some(Interval::between(at(1), at(2)));
                true
            }
            5 => {
                if at(1).direction == at(2).direction {
                    self.a = Some(Interval::between(at(1), at(2)));
                    self.b = Some(Interval::between(at(3), at(4)));
                } else {
                    self.a = Some(Interval::between(at(1), at(4)));
                    self.b = Some(Interval::between(at(2), at(3)));
                }
                true
            }
            _ => false,
        };
        self.keep_near_t_min_feasible();
        ok
    }

    /// The valid profiles do not pair up into blocked intervals (a root was
    /// lost numerically, where Ruckig gives up): the shortest is optimal,
    /// and everything up to the longest is conservatively blocked.
    pub(crate) fn build_unpaired(&mut self, valid: &[Profile]) {
        let by_t = |a: &&Profile, b: &&Profile| a.t_sum[6].total_cmp(&b.t_sum[6]);
        let (Some(short), Some(long)) = (valid.iter().min_by(by_t), valid.iter().max_by(by_t))
        else {
            return;
        };
        self.set_min(short);
        self.a = Some(Interval::between(short, long));
        self.keep_near_t_min_feasible();
    }

    /// Durations within rounding of `t_min` use the optimal profile itself
    /// (see `limits::close_tol`), so no interval may block them: the
    /// same profile found twice (e.g. from both directions) would otherwise
    /// open a blocked interval right at `t_min`.
    fn keep_near_t_min_feasible(&mut self) {
        let floor = self.t_min + crate::limits::close_tol(self.t_min);
        for slot in [&mut self.a, &mut self.b] {
            if let Some(i) = slot {
                i.left = i.left.max(floor);
                if i.left >= i.right {
                    *slot = None;
                }
            }
        }
    }

    /// A profile shorter than the optimum was found after the fact (see the
    /// Step 1 repairs): it becomes the optimum, and the durations up to the
    /// former optimum are conservatively treated as blocked.
    pub(crate) fn merge_shorter(&mut self, best: &Profile) {
        let old = self.p_min;
        let merged = match (self.a, self.b) {
            (Some(a), Some(b)) => Some(if a.right >= b.right {
                Interval {
                    left: a.left.min(b.left),
                    ..a
                }
            } else {
                Interval {
                    left: a.left.min(b.left),
                    ..b
                }
            }),
            (a, _) => a,
        };
        self.set_min(best);
        self.a = Some(Interval {
            left: self.t_min,
            right: old.duration(),
            profile: old,
        });
        self.b = merged;
        self.keep_near_t_min_feasible();
    }

    /// Whether duration `t` is infeasible for this DoF.
    #[inline]
    pub fn is_blocked(&self, t: f64) -> bool {
        t < self.t_min - crate::limits::close_tol(self.t_min)
            || self.a.as_ref().is_some_and(|i| i.left < t && t < i.right)
            || self.b.as_ref().is_some_and(|i| i.left < t && t < i.right)
    }
}
