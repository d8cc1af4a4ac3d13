//! Grasp analysis for a sphere (paper §3.1, SPEC.md §3).
//!
//! - [`facts`]: the closed forms — Fact 1 (force-closure region of a point
//!   is the 2θ cap around its antipode), Fact 2 (maximal independent
//!   regions), Fact 3 (two soft contacts: separation > π − 2θ), Fact 4
//!   (three hard contacts, sufficient: acute triangle, plane closer to O
//!   than R sin θ), and the shortest way to Fact 3 (paper Fig. 1).
//! - [`contact`]: contact frames, friction, the normalised grasp map G and
//!   its numerical rank.
//! - [`planar`]: a fast certificate for three hard contacts (explicit
//!   internal forces found by clipping nine half-planes in the contact
//!   plane), exact up to vanishing margins; what the per-tick check uses
//!   before falling back to the conic test.
//! - [`conic`]: the exact test and margin t* of SPEC §3.2 for any number of
//!   hard or soft contacts (Clarabel SOCP, built once, re-solved).
//! - [`forces`]: grip forces that hold the weight plus a disturbance margin
//!   with the smallest largest normal force (SPEC §3.3), and the exact
//!   largest normal force a grasp needs for a set of loads
//!   ([`forces::LoadSolver`], the reference of [`hold`]).
//! - [`hold`]: the closed-form load model of SPEC §1.3 I1' — grip forces
//!   for two soft or three hard contacts against the weight, the
//!   acceleration torque and every disturbance of the configured size, and
//!   the largest normal force that needs (per tick and while planning).
//!
//! # Allocation and determinism of the conic re-solve
//! Problems are built once per contact-kind sequence (allocating) and
//! re-solved after `update_A`/`update_b` with presolve off and structural
//! zeros kept. Measured with a counting global allocator
//! (`gait/tests/allocations.rs`, 1000 random re-solves each), a re-solve
//! through [`conic::ConicSolver::margin`] or
//! [`forces::GraspForceSolver::solve`] performs **exactly one heap
//! allocation of 404 bytes (and one free)**, inside clarabel 0.11.1's
//! `solve`: its internal timers reset a nested `HashMap<&str, Timer>` at
//! every solve, dropping and re-creating the innermost map. Our own code
//! allocates nothing on a re-solve (the build does one warm-up solve so
//! the timer maps are at their steady state). Clarabel also reads the
//! monotonic clock for those timers; that never changes a result because
//! the time limit is infinite and the iteration cap
//! ([`MAX_ITERATIONS`]) bounds the work. A build starts from a fixed
//! nominal layout, so Clarabel's one-time equilibration — and therefore
//! every result — depends only on the current input, not on call history
//! (tested bit for bit).

pub mod conic;
pub mod contact;
pub mod facts;
pub mod forces;
pub mod grip;
pub mod hold;
mod load_socp;
pub mod planar;
mod socp;
pub mod torque_box;

pub use conic::{ClosureMargin, ConicSolver, closure_margin};
pub use contact::{Contact, ContactFrame, ContactKind, Friction, grasp_rank};
pub use forces::{ContactForce, ForceSolution, GraspForceSolver, Load, LoadSolution, LoadSolver};
pub use hold::{Accel, Hold, HoldModel, Loads};
pub use socp::MAX_ITERATIONS;
pub use torque_box::{FingerStatics, TorqueBoxSolution, TorqueBoxSolver};

/// Why a grasp computation gave no answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum GraspError {
    /// The contact list is empty.
    #[error("no contacts")]
    NoContacts,
    /// A normal, friction or load value is non-finite, zero or negative.
    #[error("contact normal, friction or load is not finite and positive")]
    BadInput,
    /// The output slice does not have one entry per contact.
    #[error("output slice length differs from the contact count")]
    OutputLength,
    /// Clarabel refused to build or update the problem.
    #[error("conic solver setup failed")]
    SolverSetup,
    /// Clarabel stopped without a solution (iteration cap, numerics).
    #[error("conic solver stopped after {iterations} iterations without a solution")]
    SolverFailed {
        /// Iterations run.
        iterations: u32,
    },
    /// The grasp cannot hold the load (no grip forces exist).
    #[error("the grasp cannot hold the load")]
    Infeasible,
}
