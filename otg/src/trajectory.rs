//! A calculated multi-DoF trajectory: one profile per DoF, sampled at any time.

use crate::profile::Profile;

/// Position, velocity, acceleration and jerk of all DoFs at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State<const N: usize> {
    /// Position.
    pub position: [f64; N],
    /// Velocity.
    pub velocity: [f64; N],
    /// Acceleration.
    pub acceleration: [f64; N],
    /// Jerk.
    pub jerk: [f64; N],
}

/// The synchronised trajectory of `N` DoFs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trajectory<const N: usize> {
    /// Per-DoF profiles (each including its brake pre-trajectory).
    pub profiles: [Profile; N],
    /// Synchronised duration \[s\].
    pub duration: f64,
    /// Time-optimal duration of each DoF on its own \[s\] (Step 1).
    pub independent_min_durations: [f64; N],
    /// The DoF whose time-optimal (or extremal) profile sets the duration;
    /// `None` when the minimum duration does, or for an empty trajectory.
    pub limiting_dof: Option<usize>,
}

impl<const N: usize> Default for Trajectory<N> {
    fn default() -> Self {
        Self {
            profiles: [Profile::default(); N],
            duration: 0.0,
            independent_min_durations: [0.0; N],
            limiting_dof: None,
        }
    }
}

impl<const N: usize> Trajectory<N> {
    /// The state at time `t` (clamped to `t ≥ 0`). After the end every DoF
    /// continues with its final acceleration and zero jerk.
    #[inline]
    pub fn at_time(&self, t: f64) -> State<N> {
        let t = if t > 0.0 { t } else { 0.0 };
        let mut s = State {
            position: [0.0; N],
            velocity: [0.0; N],
            acceleration: [0.0; N],
            jerk: [0.0; N],
        };
        for (i, p) in self.profiles.iter().enumerate() {
            let (x, v, a, j) = p.state_in(t, self.duration);
            s.position[i] = x;
            s.velocity[i] = v;
            s.acceleration[i] = a;
            s.jerk[i] = j;
        }
        s
    }
}
