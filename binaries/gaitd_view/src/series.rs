//! Time series of one status (entity paths under `plots/`, one plot per
//! group): the grasp's force-closure margin and the load margin, the grip
//! forces commanded and measured per finger, the tracking errors as the
//! plant measures them, the tick's compute time, and the goal's remaining
//! angle.

use gaitd_client::Status;
use rerun::RecordingStream;
use shm_schema::status::measured;

/// Logs the series of `s` (at the time already set).
pub fn log(rec: &RecordingStream, s: &Status) {
    let scalar = |path: &str, v: f64| {
        if v.is_finite() {
            let _ = rec.log(path, &rerun::Scalars::single(v));
        }
    };
    scalar("plots/margins/force_closure", s.grasp_margin);
    scalar("plots/margins/load", s.load_margin);
    scalar(
        "plots/goal/remaining_deg",
        s.goal.remaining_angle.to_degrees(),
    );
    scalar(
        "plots/tick/compute_us",
        s.timing.compute_last_ns as f64 * 1e-3,
    );
    if s.measured_mask & measured::OBJECT != 0 {
        scalar("plots/errors/object_deg", s.object_error.to_degrees());
    }
    for (k, f) in s.fingers.iter().enumerate() {
        let name = format!("f{}", k + 1);
        scalar(
            &format!("plots/grip/commanded/{name}"),
            f.commanded_normal_force,
        );
        if s.measured_mask & measured::FORCES != 0 {
            scalar(
                &format!("plots/grip/measured/{name}"),
                f.measured_normal_force,
            );
        }
        if s.measured_mask & measured::TIPS != 0 {
            scalar(&format!("plots/errors/tip_mm/{name}"), f.tip_error * 1e3);
        }
    }
}
