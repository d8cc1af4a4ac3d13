//! Whether the start grasp can hold the load (SPEC §1.3 I1'): a
//! configuration whose object is too heavy for its fingertips is valid,
//! but every goal would be refused (`LoadInfeasible`). It is said at
//! `--check-config` and at start-up, with the numbers, instead of only
//! when the first goal is refused.

use gait::HandState;
use gait::config::LoadConfig;
use gait::grasp::grip::GripModel;
use nalgebra::Vector3;

use crate::config::DaemonConfig;

/// The load the paper's start grasp (where the embedded hand and
/// `gaitctl plant sim` start) must hold, at rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartLoad {
    /// The largest normal force it needs (F*) \[N\]; +∞ when no grip holds
    /// the load.
    pub peak: f64,
    /// `load.max_grip` \[N\].
    pub max_grip: f64,
}

impl StartLoad {
    /// Whether the grasp holds the load within `load.max_grip`.
    pub fn holds(&self) -> bool {
        self.peak <= self.max_grip
    }
}

/// F* of the paper's start grasp under `cfg`'s load (every grasping finger
/// carries, object still: the controller's own grip model).
pub fn paper_start_load(cfg: &DaemonConfig) -> StartLoad {
    let hand = cfg.hand();
    let grip = GripModel::new(&hand).grip(&HandState::paper_start(&hand), &Vector3::zeros());
    StartLoad {
        peak: grip.peak,
        max_grip: hand.load.max_grip,
    }
}

/// The warning for a grasp that needs `peak` \[N\] under `load` (one line).
pub fn warning(which: &str, peak: f64, load: &LoadConfig) -> String {
    let need = if peak.is_finite() {
        format!("F* = {peak:.1} N of normal force at a fingertip")
    } else {
        "F* = inf N: no grip holds it".to_owned()
    };
    let g = Vector3::from(load.gravity).norm();
    format!(
        "{which} cannot hold the load (SPEC §1.3 I1'): it needs {need}, load.max_grip = {} N \
         (object_mass = {} kg, |gravity| = {g} m/s², disturbance_force = {} N, \
         disturbance_torque = {} N·m); every goal will be refused (LoadInfeasible): lighten \
         the load or raise load.max_grip",
        load.max_grip, load.object_mass, load.disturbance_force, load.disturbance_torque
    )
}

/// The note for a chain hand whose commanded grip is capped at its motors
/// (the status's `load_margin` < 0 with `peak` \[N\] needed, `max_grip`
/// \[N\] allowed): the closed-form grip the executor commands is a normal
/// push per finger, and the motors give less there; plans are certified by
/// the torque box (SPEC §14.1), whose tangential forces share the load.
pub fn capped_note(peak: f64, margin: f64, max_grip: f64) -> String {
    let push = peak + margin;
    format!(
        "the grip is capped at the motors: its closed-form forces need F* = {peak:.2} N at a \
         fingertip, the weakest grasping finger's motors push {push:.2} N there (effort \
         through the finger's Jacobian, the links' weight held; load.max_grip = {max_grip} N); \
         goals are planned with the torque box (SPEC §14.1), which lets the contact forces' \
         tangential parts share the load"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_load_is_held_and_ten_kilograms_are_not() {
        let mut cfg = DaemonConfig::default();
        let light = paper_start_load(&cfg);
        assert!(light.holds(), "{light:?}");
        cfg.load.object_mass = 10.0;
        let heavy = paper_start_load(&cfg);
        assert!(!heavy.holds(), "{heavy:?}");
        let w = warning("the start grasp", heavy.peak, &cfg.load);
        assert!(w.contains("object_mass = 10 kg"), "{w}");
        assert!(w.contains("load.max_grip = 20 N"), "{w}");
        assert!(warning("x", f64::INFINITY, &cfg.load).contains("F* = inf N"));
    }

    #[test]
    fn a_capped_chain_grip_names_the_motors_push() {
        let n = capped_note(3.1, -0.7, 20.0);
        assert!(n.contains("F* = 3.10 N"), "{n}");
        assert!(n.contains("push 2.40 N"), "{n}");
        assert!(!n.contains("refused"), "{n}");
    }
}
