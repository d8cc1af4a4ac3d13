//! Motion under constant jerk, in closed form: the brake, the profiles and
//! the solver steps all integrate their phases with it.

/// Position, velocity and acceleration after `t` of constant jerk `j`.
#[inline]
pub fn integrate(t: f64, p: f64, v: f64, a: f64, j: f64) -> (f64, f64, f64) {
    (
        p + t * (v + t * (a / 2.0 + t * j / 6.0)),
        v + t * (a + t * j / 2.0),
        a + t * j,
    )
}
