//! The view of a recorded trace (`gait-trajectory/1`, JSON lines or MCAP):
//! its samples decimated to the view's rate in the trace's own time, the
//! last one always, on the same timeline as a live view; where the hand's
//! activity (the samples' `phase`) changes, a line in the events log. A
//! trace knows what comes next, so each frame also draws the path ahead:
//! where the fingertips and the object's axes go in the next
//! [`AHEAD`] seconds (`world/ahead`). The frames go out as fast as they are
//! read: the viewer's time controls play them back.

use crate::frame::Frame;
use crate::scene::{Scene, log_ahead, note, rotation_columns};
use rerun::RecordingStream;
use trace_mcap::file::Trace;

/// The indices of `trace`'s samples shown at `rate` frames per second of
/// trace time: for each k the first sample at or after t₀ + k/rate (t₀ the
/// first sample's time), and the last sample.
pub fn shown(trace: &Trace, rate: f64) -> Vec<usize> {
    let mut out = Vec::new();
    let Some(t0) = trace.samples.first().map(|s| s.t) else {
        return out;
    };
    let mut k = 0.0;
    for (i, s) in trace.samples.iter().enumerate() {
        if s.t >= t0 + k / rate {
            out.push(i);
            // The next frame's time after this sample's (a sample period
            // longer than 1/rate skips frames, it does not repeat them).
            while s.t >= t0 + k / rate {
                k += 1.0;
            }
        }
    }
    let last = trace.samples.len() - 1;
    if out.last() != Some(&last) {
        out.push(last);
    }
    out
}

/// How far ahead a replay draws the path \[s\] (a few gaits: enough to
/// see where the hand is going, short enough to stay readable).
pub const AHEAD: f64 = 3.0;

/// Of the frames `shown`, the ones from the `j`-th up to [`AHEAD`] seconds
/// after it (indices into `shown`).
pub fn ahead(trace: &Trace, shown: &[usize], j: usize) -> std::ops::Range<usize> {
    let now = trace.samples[shown[j]].t;
    let n = shown[j..]
        .iter()
        .take_while(|&&i| trace.samples[i].t <= now + AHEAD)
        .count();
    j..j + n
}

/// Logs `trace`'s frames into `rec`; returns how many.
pub fn run(rec: &RecordingStream, trace: &Trace, rate: f64, friction: f64) -> u64 {
    let mut scene = Scene::new(friction);
    let mut phase: Option<&str> = None;
    let mut frames = 0;
    let shown = shown(trace, rate);
    // Where the axes' tips are drawn: as long as the live view's body axes.
    let axis_length = 1.4 * trace.object_radius;
    // Every change of activity, also between two frames.
    for s in &trace.samples {
        if let Some(p) = s.phase.as_deref()
            && phase != Some(p)
        {
            note(rec, s.t, &format!("{:.3} s: {p}", s.t), "INFO");
            phase = Some(p);
        }
    }
    for (j, &i) in shown.iter().enumerate() {
        let s = &trace.samples[i];
        scene.frame(rec, &Frame::from_sample(trace, s));
        let next = &shown[ahead(trace, &shown, j)];
        let tips: [Vec<[f64; 3]>; 3] = core::array::from_fn(|k| {
            next.iter()
                .map(|&i| trace.samples[i].fingers[k].p.into())
                .collect()
        });
        let axes: [Vec<[f64; 3]>; 3] = core::array::from_fn(|a| {
            next.iter()
                .map(|&i| {
                    let q = trace.samples[i].object.quaternion();
                    rotation_columns(&[q.w, q.i, q.j, q.k])[a].map(|x| x * axis_length)
                })
                .collect()
        });
        log_ahead(rec, &tips, &axes, trace.object_radius);
        frames += 1;
    }
    frames
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{UnitQuaternion, Vector3};
    use trace_mcap::file::{TraceFinger, TraceSample};

    fn trace(times: &[f64]) -> Trace {
        let finger = TraceFinger {
            p: Vector3::x() * 0.6,
            q: UnitQuaternion::identity(),
            contact: true,
            grip: 1.0,
            roll: 0.0,
            joints: None,
        };
        crate::frame::tests::trace_of(
            times
                .iter()
                .map(|&t| TraceSample {
                    t,
                    object: UnitQuaternion::identity(),
                    fingers: [finger; 3],
                    fc_margin: None,
                    load_margin: None,
                    remaining_angle: None,
                    phase: None,
                })
                .collect(),
        )
    }

    #[test]
    fn a_trace_is_shown_at_the_rate_in_its_own_time_with_its_last_sample() {
        // 1 kHz for 1 s at 30 frames per second: the first sample at or
        // after each k/30 s, k = 0..=30 (the last sample is the 30th).
        let times: Vec<f64> = (0..=1000).map(|i| i as f64 * 0.001 + 0.0005).collect();
        let t = trace(&times);
        let shown = shown(&t, 30.0);
        assert_eq!(shown.first(), Some(&0));
        assert_eq!(shown.last(), Some(&1000));
        assert_eq!(shown.len(), 31, "{shown:?}");
        for (k, &i) in shown.iter().enumerate() {
            let late = t.samples[i].t - (0.0005 + k as f64 / 30.0);
            assert!((-1e-12..0.001).contains(&late), "frame {k}: {late}");
        }
        // A last sample between two frames' times is shown too.
        let longer: Vec<f64> = (0..=1010).map(|i| i as f64 * 0.001 + 0.0005).collect();
        let shown = super::shown(&trace(&longer), 30.0);
        assert_eq!((shown.len(), shown[30], shown[31]), (32, 1000, 1010));
        // The path ahead: this frame and the next 3 s of frames.
        let r = ahead(&t, &super::shown(&t, 30.0), 3);
        assert_eq!(r.start, 3);
        assert_eq!(r.len(), 31 - 3, "1 s of trace: all the rest");
        let long: Vec<f64> = (0..=10_000).map(|i| i as f64 * 0.001).collect();
        let lt = trace(&long);
        let ls = super::shown(&lt, 30.0);
        let r = ahead(&lt, &ls, 10);
        let (first, last) = (lt.samples[ls[r.start]].t, lt.samples[ls[r.end - 1]].t);
        assert_eq!(first, lt.samples[ls[10]].t);
        assert!(
            last <= first + AHEAD && last > first + AHEAD - 1.0 / 30.0,
            "{first} {last}"
        );
        assert!(lt.samples[ls[r.end]].t > first + AHEAD);
        // Samples sparser than the frames: each shown once.
        assert_eq!(super::shown(&trace(&[0.0, 0.1, 0.2]), 30.0), vec![0, 1, 2]);
        assert_eq!(super::shown(&trace(&[0.0]), 30.0), vec![0]);
        assert!(super::shown(&trace(&[]), 30.0).is_empty());
    }

    #[test]
    fn every_change_of_activity_is_a_line_also_between_two_frames() {
        // 1 kHz for 0.2 s at 30 frames per second; "lift" lasts one sample,
        // between two frames.
        let times: Vec<f64> = (0..200).map(|i| i as f64 * 0.001).collect();
        let mut t = trace(&times);
        for (i, s) in t.samples.iter_mut().enumerate() {
            let p = match i {
                0..50 => "rotate",
                50 => "lift",
                _ => "place",
            };
            s.phase = Some(p.to_owned());
        }
        assert!(!super::shown(&t, 30.0).contains(&50));
        let (rec, storage) = rerun::RecordingStreamBuilder::new("test")
            .memory()
            .expect("a recording in memory");
        run(&rec, &t, 30.0, 0.35);
        rec.flush_blocking().expect("flushed");
        let lines: usize = storage
            .take()
            .iter()
            .filter_map(|m| match m {
                rerun::log::LogMsg::ArrowMsg(_, a) => rerun::log::Chunk::from_arrow_msg(a).ok(),
                _ => None,
            })
            .filter(|c| c.entity_path().to_string().trim_start_matches('/') == "events")
            .map(|c| c.num_rows())
            .sum();
        assert_eq!(lines, 3, "rotate, lift, place");
    }
}
