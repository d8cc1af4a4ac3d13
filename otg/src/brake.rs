//! Brake pre-trajectory: when the current state violates a limit (or will
//! inevitably violate it, because the acceleration cannot be removed before
//! the velocity overshoots), at most two jerk-limited phases bring the state
//! back inside the limits before the time-optimal profile starts
//! (SPEC.md §5; Ruckig's "brake trajectory").

use crate::motion::integrate;

/// Margin that pushes the braked state strictly inside the limits.
const BRAKE_EPS: f64 = 2.2e-14;

/// Up to two constant-jerk phases run before the main profile.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Brake {
    /// Total brake duration \[s\].
    pub duration: f64,
    /// Phase durations.
    pub t: [f64; 2],
    /// Phase jerks.
    pub j: [f64; 2],
    /// Acceleration at each phase start.
    pub a: [f64; 2],
    /// Velocity at each phase start.
    pub v: [f64; 2],
    /// Position at each phase start.
    pub p: [f64; 2],
}

#[inline]
fn v_after(v0: f64, a0: f64, j: f64, t: f64) -> f64 {
    v0 + t * (a0 + j * t / 2.0)
}

/// Velocity reached when the acceleration `a0` is ramped to zero with jerk `-j`.
#[inline]
pub(crate) fn v_at_a_zero(v0: f64, a0: f64, j: f64) -> f64 {
    v0 + a0 * a0 / (2.0 * j)
}

impl Brake {
    /// Position interface: plans the brake for start state `(v0, a0)` under
    /// the limits (jerk `j_max > 0`, all limits non-zero).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn position(
        &mut self,
        v0: f64,
        a0: f64,
        v_max: f64,
        v_min: f64,
        a_max: f64,
        a_min: f64,
        j_max: f64,
    ) {
        *self = Brake::default();
        if a0 > a_max {
            self.acceleration(v0, a0, v_max, v_min, a_max, a_min, j_max);
        } else if a0 < a_min {
            self.acceleration(v0, a0, v_min, v_max, a_min, a_max, -j_max);
        } else if (v0 > v_max && v_at_a_zero(v0, a0, -j_max) > v_min)
            || (a0 > 0.0 && v_at_a_zero(v0, a0, j_max) > v_max)
        {
            self.velocity(v0, a0, v_max, v_min, a_min, j_max);
        } else if (v0 < v_min && v_at_a_zero(v0, a0, j_max) < v_max)
            || (a0 < 0.0 && v_at_a_zero(v0, a0, -j_max) < v_min)
        {
            self.velocity(v0, a0, v_min, v_max, a_max, -j_max);
        }
    }

    /// Velocity interface: only the acceleration has to be brought inside.
    pub(crate) fn velocity_interface(&mut self, a0: f64, a_max: f64, a_min: f64, j_max: f64) {
        *self = Brake::default();
        if a0 > a_max {
            self.j[0] = -j_max;
            self.t[0] = (a0 - a_max) / j_max + BRAKE_EPS;
        } else if a0 < a_min {
            self.j[0] = j_max;
            self.t[0] = -(a0 - a_min) / j_max + BRAKE_EPS;
        }
    }

    /// The acceleration exceeds its limit: ramp it down (then, if needed,
    /// hold the limit acceleration so the velocity stays inside).
    #[allow(clippy::too_many_arguments)]
    fn acceleration(
        &mut self,
        v0: f64,
        a0: f64,
        v_max: f64,
        v_min: f64,
        a_max: f64,
        a_min: f64,
        j_max: f64,
    ) {
        self.j[0] = -j_max;
        let t_to_a_max = (a0 - a_max) / j_max;
        let t_to_a_zero = a0 / j_max;
        let v_at_a_max = v_after(v0, a0, -j_max, t_to_a_max);
        let v_at_zero = v_after(v0, a0, -j_max, t_to_a_zero);

        if (v_at_zero > v_max && j_max > 0.0) || (v_at_zero < v_max && j_max < 0.0) {
            self.velocity(v0, a0, v_max, v_min, a_min, j_max);
        } else if (v_at_a_max < v_min && j_max > 0.0) || (v_at_a_max > v_min && j_max < 0.0) {
            let t_to_v_min = -(v_at_a_max - v_min) / a_max;
            let t_to_v_max = -a_max / (2.0 * j_max) - (v_at_a_max - v_max) / a_max;
            self.t[0] = t_to_a_max + BRAKE_EPS;
            self.t[1] = t_to_v_min.min(t_to_v_max - BRAKE_EPS).max(0.0);
        } else {
            self.t[0] = t_to_a_max + BRAKE_EPS;
        }
    }

    /// The velocity exceeds (or will exceed) its limit: decelerate at full
    /// jerk, holding the minimum acceleration if it is reached first.
    fn velocity(&mut self, v0: f64, a0: f64, v_max: f64, v_min: f64, a_min: f64, j_max: f64) {
        self.j[0] = -j_max;
        let t_to_a_min = (a0 - a_min) / j_max;
        let t_to_v_max = a0 / j_max + (a0 * a0 + 2.0 * j_max * (v0 - v_max)).sqrt() / j_max.abs();
        let t_to_v_min = a0 / j_max + (a0 * a0 / 2.0 + j_max * (v0 - v_min)).sqrt() / j_max.abs();
        let t_min_to_v = t_to_v_max.min(t_to_v_min);

        if t_to_a_min < t_min_to_v {
            let v_at_a_min = v_after(v0, a0, -j_max, t_to_a_min);
            let t_hold_v_max = -(v_at_a_min - v_max) / a_min;
            let t_hold_v_min = a_min / (2.0 * j_max) - (v_at_a_min - v_min) / a_min;
            self.t[0] = (t_to_a_min - BRAKE_EPS).max(0.0);
            self.t[1] = t_hold_v_max.min(t_hold_v_min).max(0.0);
        } else {
            self.t[0] = (t_min_to_v - BRAKE_EPS).max(0.0);
        }
    }

    /// Integrates the brake from `(p, v, a)`, recording phase start states,
    /// and advances the state to the end of the brake.
    pub(crate) fn finalize(&mut self, p: &mut f64, v: &mut f64, a: &mut f64) {
        if self.t[0] <= 0.0 && self.t[1] <= 0.0 {
            self.duration = 0.0;
            return;
        }
        self.duration = self.t[0];
        self.p[0] = *p;
        self.v[0] = *v;
        self.a[0] = *a;
        (*p, *v, *a) = integrate(self.t[0], *p, *v, *a, self.j[0]);
        if self.t[1] > 0.0 {
            self.duration += self.t[1];
            self.p[1] = *p;
            self.v[1] = *v;
            self.a[1] = *a;
            (*p, *v, *a) = integrate(self.t[1], *p, *v, *a, self.j[1]);
        }
    }
}
