//! Contact kinematics of a fingertip sphere on the object sphere
//! (SPEC.md §2.2–2.3, paper §3.2).
//!
//! - [`state`]: the state of one contact ([`ContactState`]: object
//!   orientation, fingertip pose, contact normal, roll τ), its conversions to
//!   and from [`crate::FingerState`], to chart coordinates (contact points on
//!   both bodies and the contact angle ψ), and its object-frame view
//!   [`RelativeContact`] used by rolling paths;
//! - [`mod@montana`]: Montana's equations in the general form (slip and spin)
//!   and the sphere–sphere rolling specialisation (paper eq. (3), (4));
//! - [`vector`]: the coordinate-free vector form (SPEC §2.3) and the map
//!   between hand-frame body rates and Montana's contact-frame twist;
//! - [`integrate`]: fixed-step integrators for both forms — a
//!   Runge–Kutta–Munthe-Kaas scheme of order 4 on SO(3) × SO(3) × S² for
//!   the vector form, an exact step for constant body rates, and classical
//!   RK4 in chart coordinates with hysteresis chart switching.
//!
//! # Frame conventions
//! Hand frame H, object centre O at the origin (SPEC §1.1). n is the outward
//! object normal at the contact (hand frame); the fingertip centre is
//! p_f = (R + r) n. The object contact frame C_o is the object chart's Gauss
//! frame at n_o = Q_oᵀ n, mapped to H by Q_o (its z is n); the fingertip
//! contact frame C_f is the fingertip chart's Gauss frame at m = Q_fᵀ(−n),
//! mapped by Q_f (its z is −n). The contact angle ψ is defined by
//! x_o = cos ψ x_f − sin ψ y_f, y_o = −sin ψ x_f − cos ψ y_f (then z_o = −z_f),
//! so R_ψ maps tangent coordinates in C_f to coordinates in C_o.
//!
//! Montana's relative motion (v, ω) is the body velocity of a frame fixed
//! in the fingertip, coinciding with C_f, relative to a frame fixed in the
//! object, coinciding with C_o — expressed in C_f:
//!   ω = C_fᵀ (ω_f − ω_o),   v = C_fᵀ (v_fp − v_op),
//! where v_fp = ṗ_f + ω_f × (−r n) and v_op = ω_o × (R n) are the
//! velocities of the two material points at the contact. Pure rolling is
//! v = 0, ω_z = 0; the normal component v_z is always 0 (contact kept).

pub mod integrate;
pub mod montana;
pub mod state;
pub mod vector;

pub use integrate::{ChartIntegrator, VectorIntegrator};
pub use montana::{
    ChartContact, ChartRates, ContactTwist, montana, r_psi, rolling_finger_rates,
    rolling_object_rates, rolling_psi_rate,
};
pub use state::{ContactError, ContactGeometry, ContactState, RelativeContact};
pub use vector::{
    BodyRates, ContactRates, body_rates_from_twist, contact_rates, twist_from_body_rates,
};
