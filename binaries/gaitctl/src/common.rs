//! Connection flags and formatting shared by the subcommands.

pub use gaitd_client::describe::{code, counted_fingers, event_line, finger_name};
use gaitd_client::{Event, Status, Verdict};
use std::process::ExitCode;

pub use gaitd_client::cli::ConnArgs;

/// Exit code for a verdict: 0 accepted, 1 rejected.
pub fn verdict_exit(what: &str, v: Verdict) -> ExitCode {
    match v {
        Verdict::Accepted => {
            println!("{what}: accepted");
            ExitCode::SUCCESS
        }
        Verdict::Rejected(r) => {
            println!("{what}: rejected ({r})");
            ExitCode::from(1)
        }
    }
}

/// Microseconds from nanoseconds, for display.
pub fn us(ns: u64) -> f64 {
    ns as f64 / 1e3
}

/// Degrees from radians.
pub fn deg(rad: f64) -> f64 {
    rad.to_degrees()
}

/// An event as JSON (every field, codes decoded to names, unknown codes
/// as `?N`; no finger or goal state as null).
pub fn event_json(e: &Event) -> serde_json::Value {
    serde_json::json!({
        "seq": e.seq,
        "tick": e.tick,
        "time_ns": e.time_ns,
        "instance": format!("{:016x}", e.instance),
        "kind": code(e.kind(), e.kind),
        "finger": (e.finger < 3).then_some(e.finger),
        "state": (e.state != 0).then(|| code(e.state(), e.state)),
        "reason": code(e.reason(), e.reason),
        "goal_id": e.goal_id,
        "client_id": format!("{:x}", e.client_id),
        "fault": code(e.fault(), e.fault),
        "count": e.count,
        "value": e.value,
    })
}

/// The names of the measured fields a status holds ([`shm_schema::measured`]).
pub fn measured_names(mask: u32) -> Vec<&'static str> {
    use shm_schema::measured;
    [
        (measured::OBJECT, "object"),
        (measured::TIPS, "tips"),
        (measured::CONTACTS, "contacts"),
        (measured::FORCES, "forces"),
    ]
    .into_iter()
    .filter(|(bit, _)| mask & bit != 0)
    .map(|(_, name)| name)
    .collect()
}

/// The object orientation as the plant measured it, or the commanded one
/// when the status holds no measurement.
pub fn object_q(s: &Status) -> [f64; 4] {
    if s.measured_mask & shm_schema::measured::OBJECT != 0 {
        s.measured_object_q
    } else {
        s.commanded_object_q
    }
}

/// The name of a [`Status::hand`] code.
pub fn hand_name(code: u32) -> String {
    match code {
        shm_schema::status::hand::FINGERTIPS => "fingertips".into(),
        shm_schema::status::hand::CHAINS => "chains".into(),
        other => format!("unknown({other})"),
    }
}

/// The status as JSON (every field, codes decoded to names).
pub fn status_json(s: &Status) -> serde_json::Value {
    use serde_json::json;
    let fingers: Vec<_> = s
        .fingers
        .iter()
        .map(|f| {
            json!({
                "state": code(f.phase(), f.state),
                "contact_hand": f.contact_hand,
                "contact_object": f.contact_object,
                "commanded_tip_position": f.commanded_tip_position,
                "commanded_tip_orientation": f.commanded_tip_orientation,
                "tip_contact": f.tip_contact,
                "roll": f.roll,
                "workspace_margin": f.workspace_margin,
                "commanded_normal_force": f.commanded_normal_force,
                "measured_contact": f.measured_contact == 1,
                "measured_tip_position": f.measured_tip_position,
                "measured_tip_orientation": f.measured_tip_orientation,
                "measured_normal_force": f.measured_normal_force,
                "tip_error": f.tip_error,
                "commanded_joints": f.commanded_joints,
                "tip_margin": f.tip_margin,
                "link_clearance": f.link_clearance,
            })
        })
        .collect();
    let t = &s.timing;
    json!({
        "tick": s.tick,
        "time_ns": s.time_ns,
        "publish_time_ns": s.publish_time_ns,
        "instance": format!("{:016x}", s.instance),
        "daemon_state": code(s.daemon_state(), s.daemon_state),
        "hand": hand_name(s.hand),
        "phase": code(s.phase(), s.phase),
        "fault": code(s.fault(), s.fault),
        "grasp": code(s.grasp(), s.grasp),
        "grasp_margin": s.grasp_margin,
        // +∞ (no grip holds the load) is JSON null.
        "load_grip": s.load_grip,
        "load_margin": s.load_margin,
        "commanded_object_q": s.commanded_object_q,
        "commanded_object_omega": s.commanded_object_omega,
        "measured_object_q": s.measured_object_q,
        "object_error": s.object_error,
        "measured_tick": s.measured_tick,
        "measured": measured_names(s.measured_mask),
        "goal": {
            "goal_id": s.goal.goal_id,
            "client_id": format!("{:x}", s.goal.client_id),
            "state": code(s.goal_state(), s.goal.state),
            "reason": code(s.goal_reason(), s.goal.reason),
            "remaining_angle": s.goal.remaining_angle,
            "eta": s.goal.eta,
            "gaits_done": s.goal.gaits_done,
            "gaits_planned": s.goal.gaits_planned,
            "active_finger": s.goal.active_finger,
        },
        "fingers": fingers,
        "timing": {
            "period_ns": t.period_ns,
            "compute_last_ns": t.compute_last_ns,
            "compute_p50_ns": t.compute_p50_ns,
            "compute_p99_ns": t.compute_p99_ns,
            "compute_max_ns": t.compute_max_ns,
            "jitter_last_ns": t.jitter_last_ns,
            "jitter_p99_ns": t.jitter_p99_ns,
            "jitter_max_ns": t.jitter_max_ns,
            "overruns": t.overruns,
            "jitter_hist": t.jitter_hist,
            "plant_commands_late": t.plant_commands_late,
            "plant_commands_repeated": t.plant_commands_repeated,
            "plant_measurements_late": t.plant_measurements_late,
            "plant_measurements_repeated": t.plant_measurements_repeated,
            "plant_misses_in_row": t.plant_misses_in_row,
            "plant_misses_in_row_max": t.plant_misses_in_row_max,
        },
        "commands": s.commands,
        "rejected": s.rejected,
        "clients": s.clients,
    })
}

/// The flag [`stop_on_signal`] sets.
static SIGNALLED: std::sync::OnceLock<&'static std::sync::atomic::AtomicBool> =
    std::sync::OnceLock::new();

extern "C" fn on_signal(_: libc::c_int) {
    if let Some(f) = SIGNALLED.get() {
        f.store(true, std::sync::atomic::Ordering::Release);
    }
}

/// SIGINT and SIGTERM set `flag` instead of killing the process (so a
/// long-running command ends cleanly and prints its summary).
pub fn stop_on_signal(flag: &'static std::sync::atomic::AtomicBool) {
    let _ = SIGNALLED.set(flag);
    // SAFETY: the handler only stores to an atomic (async-signal-safe).
    unsafe {
        libc::signal(libc::SIGINT, on_signal as *const () as libc::sighandler_t);
        libc::signal(libc::SIGTERM, on_signal as *const () as libc::sighandler_t);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gaitd_client::EventKind;
    use gaitd_client::shm_schema::{FaultCode, NO_FINGER};

    #[test]
    fn a_fault_line_names_its_finger_if_it_has_one() {
        let mut e = Event::new(EventKind::Fault);
        e.fault = FaultCode::StuckFinger.code();
        e.finger = 2;
        assert!(
            event_line(&e).ends_with("StuckFinger (f3)"),
            "{}",
            event_line(&e)
        );
        assert_eq!(event_json(&e)["finger"], 2);
        e.finger = NO_FINGER;
        assert!(
            event_line(&e).ends_with("StuckFinger"),
            "{}",
            event_line(&e)
        );
        assert!(event_json(&e)["finger"].is_null());
    }
}
