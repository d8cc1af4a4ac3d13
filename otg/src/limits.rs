//! The limits of one DoF in the forms the solver steps take, the longest
//! duration accepted, and the tolerance on durations: the bottom layer that
//! every step and the calculator share, so that none of them needs another
//! for these.

/// Longest trajectory accepted \[s\] (as Ruckig).
pub const MAX_DURATION: f64 = 7.6e3;

/// Kinematic limits of one DoF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DofLimits {
    /// Maximum velocity (> 0).
    pub v_max: f64,
    /// Minimum velocity (< 0).
    pub v_min: f64,
    /// Maximum acceleration (> 0).
    pub a_max: f64,
    /// Minimum acceleration (< 0).
    pub a_min: f64,
    /// Maximum jerk (> 0).
    pub j_max: f64,
}

impl DofLimits {
    /// Symmetric limits.
    pub fn symmetric(v_max: f64, a_max: f64, j_max: f64) -> Self {
        Self {
            v_max,
            v_min: -v_max,
            a_max,
            a_min: -a_max,
            j_max,
        }
    }

    pub(crate) fn lim(&self) -> Lim {
        Lim {
            v_max: self.v_max,
            v_min: self.v_min,
            a_max: self.a_max,
            a_min: self.a_min,
            j: self.j_max,
        }
    }

    pub(crate) fn acc(&self) -> AccLim {
        AccLim {
            a_max: self.a_max,
            a_min: self.a_min,
            j: self.j_max,
        }
    }
}

/// Limits as seen by one direction of motion (swapped for "down").
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lim {
    pub v_max: f64,
    pub v_min: f64,
    pub a_max: f64,
    pub a_min: f64,
    pub j: f64,
}

impl Lim {
    /// The same limits seen from the opposite direction.
    #[inline]
    pub(crate) fn flip(self) -> Self {
        Self {
            v_max: self.v_min,
            v_min: self.v_max,
            a_max: self.a_min,
            a_min: self.a_max,
            j: -self.j,
        }
    }
}

/// Acceleration limits and jerk of one direction.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AccLim {
    pub a_max: f64,
    pub a_min: f64,
    pub j: f64,
}

impl AccLim {
    /// The same limits seen from the opposite direction.
    #[inline]
    pub(crate) fn flip(self) -> Self {
        Self {
            a_max: self.a_min,
            a_min: self.a_max,
            j: -self.j,
        }
    }
}

/// Durations this close to an extremal profile's use that profile as is.
#[inline]
pub(crate) fn close_tol(t: f64) -> f64 {
    1e-12 * t.max(1.0)
}
