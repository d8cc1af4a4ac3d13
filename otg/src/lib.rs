//! # otg — jerk-limited online trajectory generation
//!
//! Pure library (no I/O, no clocks, no threads, no allocation after
//! construction) computing time-optimal, jerk-limited trajectories for N
//! degrees of freedom (SPEC.md §5), in the manner of Ruckig (Berscheid &
//! Kröger, RSS 2021).
