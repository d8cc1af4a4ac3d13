//! Time series of one [`Frame`] (entity paths under `plots/`, one plot per
//! group): the grasp's force-closure margin and the load margin, the grip
//! forces commanded and measured per finger, the tracking errors as the
//! plant measures them, the tick's compute time, and the goal's remaining
//! angle. A series the frame does not have (a trace has no measurements) is
//! left out.

use crate::frame::Frame;
use rerun::RecordingStream;

/// Logs the series of `s` (at the time already set).
pub fn log(rec: &RecordingStream, s: &Frame) {
    let scalar = |path: &str, v: Option<f64>| {
        if let Some(v) = v.filter(|v| v.is_finite()) {
            let _ = rec.log(path, &rerun::Scalars::single(v));
        }
    };
    scalar("plots/margins/force_closure", s.fc_margin);
    scalar("plots/margins/load", s.load_margin);
    scalar("plots/goal/remaining_deg", s.remaining.map(f64::to_degrees));
    scalar("plots/tick/compute_us", s.compute_us);
    scalar(
        "plots/errors/object_deg",
        s.object_error.map(f64::to_degrees),
    );
    for (k, f) in s.fingers.iter().enumerate() {
        let name = format!("f{}", k + 1);
        scalar(&format!("plots/grip/commanded/{name}"), Some(f.force));
        scalar(&format!("plots/grip/measured/{name}"), f.measured_force);
        scalar(
            &format!("plots/errors/tip_mm/{name}"),
            f.tip_error.map(|e| e * 1e3),
        );
    }
}
