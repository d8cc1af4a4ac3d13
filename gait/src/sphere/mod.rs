//! Sphere geometry (SPEC.md §2.1, paper eq. (1)–(2)).
//!
//! - [`chart`]: the spherical chart f(u, v) = ρ (cos u cos v, −cos u sin v,
//!   sin u), its Gauss frame and the metric M, curvature K and torsion T
//!   that enter Montana's equations;
//! - [`atlas`]: the two-chart atlas (the second chart f̄ = Q f has a
//!   singular set disjoint from the first's) with hysteresis switching;
//! - [`rotation`]: small exact helpers on S² and SO(3) (rotation about an
//!   axis, great-circle arcs, angles, the exponential map's inverse
//!   differential) shared by the contact integrators and rolling paths.
//!
//! Chart coordinates are computed on the unit sphere; the radius ρ only
//! scales points and enters M, K, T.

pub mod atlas;
pub mod chart;
pub mod rotation;

pub use atlas::{ChartSwitch, SWITCH_LATITUDE, best_chart, frame_angle, hysteresis};
pub use chart::{ChartId, ChartPoint, curvature, metric, torsion};
