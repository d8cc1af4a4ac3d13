//! daemon → clients: [`PlanPath`] (`plan` service), the path of each plan
//! the daemon makes, for views.

use iceoryx2::prelude::ZeroCopySend;

/// Points in a [`PlanPath`].
pub const PATH_POINTS: usize = 256;

/// The hand at one instant of a plan.
///
/// Type name `gaitd::PathPoint.v8`, 120 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::PathPoint.v8")]
pub struct PathPoint {
    /// Time since the plan's first tick \[s\].
    pub t: f64,
    /// Object orientation, unit quaternion (w, x, y, z), object frame →
    /// hand frame.
    pub object_q: [f64; 4],
    /// Fingertip sphere centres, hand frame \[m\].
    pub tip_position: [[f64; 3]; 3],
    /// Bit k set: finger k grasps.
    pub touching: u32,
    /// Padding, 0.
    pub reserved: u32,
}

const _: () = assert!(core::mem::size_of::<PathPoint>() == 120);
const _: () = assert!(core::mem::align_of::<PathPoint>() == 8);

/// Where a plan takes the hand: [`PATH_POINTS`] or fewer points at equal
/// intervals from its first tick to its end, each the setpoint the daemon
/// will command then if nothing interrupts the plan (SPEC §4.2, §5).
/// Published when the plan is made, before it runs; the status's
/// `goal.eta` tells how far along it the hand is (`duration − eta`).
///
/// Type name `gaitd::PlanPath.v8`, 30 768 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::PlanPath.v8")]
pub struct PlanPath {
    /// Daemon instance id (as in [`Status::instance`](crate::Status)).
    pub instance: u64,
    /// The goal it was planned for.
    pub goal_id: u64,
    /// That goal's client.
    pub client_id: u64,
    /// Numbers the plans of this daemon instance, from 1: a goal planned
    /// again (after a drift) gets a larger one.
    pub sequence: u64,
    /// How long the plan runs \[s\] (the time of its last point).
    pub duration: f64,
    /// Points used, 1 ..= [`PATH_POINTS`].
    pub count: u32,
    /// Padding, 0.
    pub reserved: u32,
    /// The points, in time order; those past `count` are 0.
    pub points: [PathPoint; PATH_POINTS],
}

const _: () = assert!(core::mem::size_of::<PlanPath>() == 30_768);
const _: () = assert!(core::mem::align_of::<PlanPath>() == 8);

impl PlanPath {
    /// Size of the payload in bytes.
    pub const SIZE: usize = 30_768;

    /// The payload that `bytes` encode (e.g. as received from a bridge).
    /// Every bit pattern is a `PlanPath` (integers and floats only, no
    /// implicit padding); check it with [`PlanPath::checked`] before use.
    pub fn from_bytes(bytes: &[u8; Self::SIZE]) -> Self {
        // SAFETY: repr(C), exactly SIZE bytes of integers and floats without
        // implicit padding: any bytes are a valid value; read_unaligned
        // accepts the byte array's alignment of 1.
        unsafe { core::ptr::read_unaligned(bytes.as_ptr().cast::<PlanPath>()) }
    }

    /// The payload's bytes as they travel (native endianness, as in shared
    /// memory).
    pub fn to_bytes(&self) -> [u8; Self::SIZE] {
        // SAFETY: same layout facts as in `from_bytes`; no padding means no
        // uninitialised bytes are read.
        unsafe { core::mem::transmute::<PlanPath, [u8; Self::SIZE]>(*self) }
    }
}

impl Default for PlanPath {
    fn default() -> Self {
        Self {
            instance: 0,
            goal_id: 0,
            client_id: 0,
            sequence: 0,
            duration: 0.0,
            count: 0,
            reserved: 0,
            points: [PathPoint::default(); PATH_POINTS],
        }
    }
}

/// Why a received [`PlanPath`] cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathError {
    /// `count` is 0 or more than [`PATH_POINTS`].
    Count(u32),
    /// A point holds a non-finite number, or `duration` does.
    NotFinite(usize),
    /// A point's time is before the one before it, or outside
    /// 0 ..= `duration`.
    Order(usize),
    /// A point's object quaternion is not of unit length (within 1e-6).
    NotUnit(usize),
}

impl core::fmt::Display for PathError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Count(n) => write!(f, "plan path: {n} points (1 to {PATH_POINTS} expected)"),
            Self::NotFinite(i) => write!(f, "plan path: point {i} is not finite"),
            Self::Order(i) => write!(f, "plan path: point {i} is out of time order"),
            Self::NotUnit(i) => {
                write!(
                    f,
                    "plan path: point {i}'s orientation is not a unit quaternion"
                )
            }
        }
    }
}

impl core::error::Error for PathError {}

impl PlanPath {
    /// The points in use, once each is checked (finite, in time order
    /// within the duration, unit orientations).
    pub fn checked(&self) -> Result<&[PathPoint], PathError> {
        let n = self.count as usize;
        if n == 0 || n > PATH_POINTS {
            return Err(PathError::Count(self.count));
        }
        if !self.duration.is_finite() {
            return Err(PathError::NotFinite(0));
        }
        let points = &self.points[..n];
        let mut before = 0.0;
        for (i, p) in points.iter().enumerate() {
            let finite = p.t.is_finite()
                && p.object_q.iter().all(|x| x.is_finite())
                && p.tip_position.iter().flatten().all(|x| x.is_finite());
            if !finite {
                return Err(PathError::NotFinite(i));
            }
            if p.t < before || p.t > self.duration {
                return Err(PathError::Order(i));
            }
            before = p.t;
            let norm2: f64 = p.object_q.iter().map(|x| x * x).sum();
            if (norm2.sqrt() - 1.0).abs() > 1e-6 {
                return Err(PathError::NotUnit(i));
            }
        }
        Ok(points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path() -> PlanPath {
        let mut p = PlanPath {
            duration: 1.0,
            count: 3,
            ..PlanPath::default()
        };
        for (i, t) in [0.0, 0.5, 1.0].into_iter().enumerate() {
            p.points[i].t = t;
            p.points[i].object_q = [1.0, 0.0, 0.0, 0.0];
        }
        p
    }

    #[test]
    fn a_path_is_checked_point_by_point() {
        assert_eq!(path().checked().map(<[_]>::len), Ok(3));
        let mut p = path();
        p.count = 0;
        assert_eq!(p.checked(), Err(PathError::Count(0)));
        p.count = PATH_POINTS as u32 + 1;
        assert_eq!(p.checked(), Err(PathError::Count(257)));
        let mut p = path();
        p.points[1].tip_position[2][0] = f64::NAN;
        assert_eq!(p.checked(), Err(PathError::NotFinite(1)));
        let mut p = path();
        p.points[2].t = 0.25;
        assert_eq!(p.checked(), Err(PathError::Order(2)));
        let mut p = path();
        p.points[2].t = 1.5;
        assert_eq!(p.checked(), Err(PathError::Order(2)));
        let mut p = path();
        p.points[0].object_q = [0.9, 0.0, 0.0, 0.0];
        assert_eq!(p.checked(), Err(PathError::NotUnit(0)));
        // Points past `count` are not read.
        let mut p = path();
        p.points[3].t = f64::NAN;
        assert!(p.checked().is_ok());
    }

    #[test]
    fn bytes_round_trip() {
        let mut p = path();
        p.points[1].tip_position[2] = [0.1, -0.2, 0.3];
        p.sequence = 7;
        assert_eq!(PlanPath::from_bytes(&p.to_bytes()), p);
    }
}
