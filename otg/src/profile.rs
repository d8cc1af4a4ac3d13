//! One DoF's kinematic profile: up to seven constant-jerk phases, preceded by
//! an optional two-phase brake (SPEC.md §5; Berscheid & Kröger 2021, §III).
//!
//! A candidate profile is filled with phase durations by a closed-form
//! solution and then *checked*: non-negative durations, the boundary state
//! reached, and velocity/acceleration limits respected inside. The check is
//! what makes the closed forms safe to try in any order.

use crate::brake::Brake;
use crate::motion::integrate;
use crate::roots::EPS;

const V_EPS: f64 = 1e-12;
const A_EPS: f64 = 1e-12;
const J_EPS: f64 = 1e-12;
const P_PRECISION: f64 = 1e-8;
const V_PRECISION: f64 = 1e-8;
const A_PRECISION: f64 = 1e-10;
/// Longer profiles are numerically meaningless.
const T_MAX: f64 = 1e12;

/// Which limits a profile reaches (its shape), for the seven phases
/// j⁺ a⁺ j⁻ v j⁻ a⁻ j⁺ (UDDU) or j⁺ a⁺ j⁻ v j⁺ a⁻ j⁻ (UDUD).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReachedLimits {
    /// Both acceleration plateaus and the velocity plateau.
    Acc0Acc1Vel,
    /// Velocity plateau only.
    Vel,
    /// First acceleration plateau only.
    Acc0,
    /// Second acceleration plateau only.
    Acc1,
    /// Both acceleration plateaus.
    Acc0Acc1,
    /// First acceleration plateau and velocity plateau.
    Acc0Vel,
    /// Second acceleration plateau and velocity plateau.
    Acc1Vel,
    /// No plateau.
    None,
}

/// Sign of the first jerk phase relative to the nominal (maximum) limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// Starts towards the maximum limits.
    Up,
    /// Starts towards the minimum limits.
    Down,
}

/// Jerk sign pattern of the four jerk phases.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlSigns {
    /// Up, down, down, up.
    Uddu,
    /// Up, down, up, down.
    Udud,
}

/// A single-DoF jerk-limited profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    /// Phase durations \[s\].
    pub t: [f64; 7],
    /// Cumulative phase end times \[s\] (without the brake).
    pub t_sum: [f64; 7],
    /// Jerk of each phase.
    pub j: [f64; 7],
    /// Acceleration at each phase boundary (index 0 = start, 7 = end).
    pub a: [f64; 8],
    /// Velocity at each phase boundary.
    pub v: [f64; 8],
    /// Position at each phase boundary.
    pub p: [f64; 8],
    /// Brake pre-trajectory (zero duration unless the start violates a limit).
    pub brake: Brake,
    /// Target position.
    pub pf: f64,
    /// Target velocity.
    pub vf: f64,
    /// Target acceleration.
    pub af: f64,
    /// Shape of the profile.
    pub limits: ReachedLimits,
    /// Direction of the profile.
    pub direction: Direction,
    /// Jerk sign pattern.
    pub signs: ControlSigns,
}

impl Default for Profile {
    fn default() -> Self {
        Self {
            t: [0.0; 7],
            t_sum: [0.0; 7],
            j: [0.0; 7],
            a: [0.0; 8],
            v: [0.0; 8],
            p: [0.0; 8],
            brake: Brake::default(),
            pf: 0.0,
            vf: 0.0,
            af: 0.0,
            limits: ReachedLimits::None,
            direction: Direction::Up,
            signs: ControlSigns::Uddu,
        }
    }
}

impl Profile {
    /// Total duration including the brake.
    #[inline]
    pub fn duration(&self) -> f64 {
        self.t_sum[6] + self.brake.duration
    }

    /// Copies start state, target and brake from `other`.
    #[inline]
    pub(crate) fn set_boundary_from(&mut self, other: &Profile) {
        self.p[0] = other.p[0];
        self.v[0] = other.v[0];
        self.a[0] = other.a[0];
        self.pf = other.pf;
        self.vf = other.vf;
        self.af = other.af;
        self.brake = other.brake;
    }

    /// Sets the cumulative times and the jerks; `false` on a negative phase.
    #[inline]
    fn fill_times(&mut self, signs: ControlSigns, jf: f64) -> bool {
        if self.t[0] < 0.0 {
            return false;
        }
        self.t_sum[0] = self.t[0];
        for i in 0..6 {
            if self.t[i + 1] < 0.0 {
                return false;
            }
            self.t_sum[i + 1] = self.t_sum[i] + self.t[i + 1];
        }
        let pick = |t: f64, j: f64| if t > 0.0 { j } else { 0.0 };
        let (j4, j6) = match signs {
            ControlSigns::Uddu => (-jf, jf),
            ControlSigns::Udud => (jf, -jf),
        };
        self.j = [
            pick(self.t[0], jf),
            0.0,
            pick(self.t[2], -jf),
            0.0,
            pick(self.t[4], j4),
            0.0,
            pick(self.t[6], j6),
        ];
        true
    }

    /// Validates a third-order position profile whose durations are in `t`:
    /// integrates it, and checks the target and the limits (with the
    /// direction's limits `v_max`, `v_min`, `a_max`, `a_min`, jerk `jf`).
    /// `pin_acc` snaps plateau accelerations to the limit they sit on.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(crate) fn check(
        &mut self,
        signs: ControlSigns,
        limits: ReachedLimits,
        pin_acc: bool,
        jf: f64,
        v_max: f64,
        v_min: f64,
        a_max: f64,
        a_min: f64,
    ) -> bool {
        if !self.fill_times(signs, jf) {
            return false;
        }
        use ReachedLimits as L;
        let has_vel = matches!(limits, L::Acc0Acc1Vel | L::Acc0Vel | L::Acc1Vel | L::Vel);
        if has_vel && self.t[3] < EPS {
            return false;
        }
        if matches!(limits, L::Acc0 | L::Acc0Acc1) && self.t[1] < EPS {
            return false;
        }
        if matches!(limits, L::Acc1 | L::Acc0Acc1) && self.t[5] < EPS {
            return false;
        }
        if self.t_sum[6] > T_MAX {
            return false;
        }

        self.direction = if v_max > 0.0 {
            Direction::Up
        } else {
            Direction::Down
        };
        let (v_upp, v_low) = match self.direction {
            Direction::Up => (v_max + V_EPS, v_min - V_EPS),
            Direction::Down => (v_min + V_EPS, v_max - V_EPS),
        };
        let zero_a3 = has_vel || limits == L::Acc0Acc1;

        for i in 0..7 {
            let (t, j) = (self.t[i], self.j[i]);
            let (a, v, p) = (self.a[i], self.v[i], self.p[i]);
            self.a[i + 1] = a + t * j;
            self.v[i + 1] = v + t * (a + t * j / 2.0);
            self.p[i + 1] = p + t * (v + t * (a / 2.0 + t * j / 6.0));

            if i == 2 && zero_a3 {
                self.a[3] = 0.0;
            }
            if pin_acc {
                if limits == L::Acc1 && i == 2 {
                    self.a[3] = a_min;
                }
                if limits == L::Acc0Acc1 {
                    if i == 0 {
                        self.a[1] = a_max;
                    }
                    if i == 4 {
                        self.a[5] = a_min;
                    }
                }
            }
            // A velocity extremum inside a phase where the acceleration
            // changes sign must also respect the limits.
            if i > 1 && self.a[i + 1] * self.a[i] < -EPS {
                let v_ext = self.v[i] - self.a[i] * self.a[i] / (2.0 * self.j[i]);
                if v_ext > v_upp || v_ext < v_low {
                    return false;
                }
            }
        }
        self.signs = signs;
        self.limits = limits;

        let (a_upp, a_low) = match self.direction {
            Direction::Up => (a_max + A_EPS, a_min - A_EPS),
            Direction::Down => (a_min + A_EPS, a_max - A_EPS),
        };
        let (a, v) = (&self.a, &self.v);
        (self.p[7] - self.pf).abs() < P_PRECISION
            && (v[7] - self.vf).abs() < V_PRECISION
            && (a[7] - self.af).abs() < A_PRECISION
            && [a[1], a[3], a[5]].iter().all(|&x| x >= a_low && x <= a_upp)
            && [v[3], v[4], v[5], v[6]]
                .iter()
                .all(|&x| x <= v_upp && x >= v_low)
    }

    /// [`Profile::check`] for a synchronised profile with a free jerk `jf`
    /// that must not exceed `j_max` in magnitude.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(crate) fn check_jerk(
        &mut self,
        signs: ControlSigns,
        limits: ReachedLimits,
        jf: f64,
        v_max: f64,
        v_min: f64,
        a_max: f64,
        a_min: f64,
        j_max: f64,
    ) -> bool {
        jf.abs() < j_max.abs() + J_EPS
            && self.check(signs, limits, false, jf, v_max, v_min, a_max, a_min)
    }

    /// Validates a velocity-interface profile (target velocity and
    /// acceleration, position free).
    #[inline]
    pub(crate) fn check_velocity(
        &mut self,
        signs: ControlSigns,
        limits: ReachedLimits,
        jf: f64,
        a_max: f64,
        a_min: f64,
    ) -> bool {
        if !self.fill_times(signs, jf) {
            return false;
        }
        if limits == ReachedLimits::Acc0 && self.t[1] < EPS {
            return false;
        }
        if self.t_sum[6] > T_MAX {
            return false;
        }
        for i in 0..7 {
            let (t, j) = (self.t[i], self.j[i]);
            let (a, v, p) = (self.a[i], self.v[i], self.p[i]);
            self.a[i + 1] = a + t * j;
            self.v[i + 1] = v + t * (a + t * j / 2.0);
            self.p[i + 1] = p + t * (v + t * (a / 2.0 + t * j / 6.0));
        }
        self.signs = signs;
        self.limits = limits;
        self.direction = if a_max > 0.0 {
            Direction::Up
        } else {
            Direction::Down
        };
        let (a_upp, a_low) = match self.direction {
            Direction::Up => (a_max + A_EPS, a_min - A_EPS),
            Direction::Down => (a_min + A_EPS, a_max - A_EPS),
        };
        let a = &self.a;
        (self.v[7] - self.vf).abs() < V_PRECISION
            && (a[7] - self.af).abs() < A_PRECISION
            && [a[1], a[3], a[5]].iter().all(|&x| x >= a_low && x <= a_upp)
    }

    /// [`Profile::check_velocity`] with a free jerk bounded by `j_max`.
    #[inline]
    pub(crate) fn check_velocity_jerk(
        &mut self,
        signs: ControlSigns,
        limits: ReachedLimits,
        jf: f64,
        a_max: f64,
        a_min: f64,
        j_max: f64,
    ) -> bool {
        jf.abs() < j_max.abs() + J_EPS && self.check_velocity(signs, limits, jf, a_max, a_min)
    }

    /// State at `t` of this profile as part of a trajectory of duration
    /// `total`: a profile that ends at `total` (up to rounding of its phase
    /// sums) is evaluated from its own end once `t ≥ total`, so the final
    /// state is exactly the profile's end state.
    #[inline]
    pub fn state_in(&self, t: f64, total: f64) -> (f64, f64, f64, f64) {
        let own = self.duration();
        if t >= total && (own - total).abs() <= 1e-9 * total.max(1.0) {
            // From the end state itself: `own - brake` need not round back
            // to `t_sum[6]`, and a jerk of 1e4 turns 1e-13 s into 1e-9.
            let (p, v, a) = integrate(t - total, self.p[7], self.v[7], self.a[7], 0.0);
            (p, v, a, 0.0)
        } else {
            self.state_at(t)
        }
    }

    /// State `(p, v, a, j)` at time `t` after the start of the brake
    /// (`t` may exceed the duration: constant acceleration afterwards).
    #[inline]
    pub fn state_at(&self, t: f64) -> (f64, f64, f64, f64) {
        let mut t = t;
        let b = &self.brake;
        if b.duration > 0.0 {
            if t < b.duration {
                let k = if t < b.t[0] { 0 } else { 1 };
                if k == 1 {
                    t -= b.t[0];
                }
                let (p, v, a) = integrate(t, b.p[k], b.v[k], b.a[k], b.j[k]);
                return (p, v, a, b.j[k]);
            }
            t -= b.duration;
        }
        if t >= self.t_sum[6] {
            let (p, v, a) = integrate(t - self.t_sum[6], self.p[7], self.v[7], self.a[7], 0.0);
            return (p, v, a, 0.0);
        }
        // First phase whose cumulative end time exceeds t.
        let mut k = 0;
        while k < 6 && self.t_sum[k] <= t {
            k += 1;
        }
        if k > 0 {
            t -= self.t_sum[k - 1];
        }
        let (p, v, a) = integrate(t, self.p[k], self.v[k], self.a[k], self.j[k]);
        (p, v, a, self.j[k])
    }
}
