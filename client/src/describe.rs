//! Events and codes as people read them: one line per event, a decoded
//! code's name (or its raw number), the fingers as the paper names them.
//! What `gaitctl events`, `gaitctl watch` and the live view print.

use shm_schema::{Event, EventKind};

/// A name for a decoded code, or the raw number.
pub fn code<T: std::fmt::Display, E>(r: Result<T, E>, raw: u32) -> String {
    r.map_or_else(|_| format!("?{raw}"), |v| v.to_string())
}

/// A finger as the status views and the paper name it (f1, f2, f3).
pub fn finger_name(k: u32) -> String {
    if k < 3 {
        format!("f{}", k + 1)
    } else {
        format!("finger {k}")
    }
}

/// The fingers of an event's `count` bits (Substitution: the finger that
/// took over; Rewind: the relocated ones), named; `None` if there are none
/// (a daemon that predates the Substitution bit).
pub fn counted_fingers(e: &Event) -> Option<String> {
    let named: Vec<String> = (0..3)
        .filter(|k| e.count & (1 << k) != 0)
        .map(finger_name)
        .collect();
    (!named.is_empty()).then(|| named.join(" and "))
}

/// One line describing an event.
pub fn event_line(e: &Event) -> String {
    let kind = code(e.kind(), e.kind);
    let t = e.time_ns as f64 / 1e9;
    let mut s = format!(
        "#{:<6} tick {:<9} t {:>12.6} s  {kind:<15}",
        e.seq, e.tick, t
    );
    match e.kind() {
        Ok(EventKind::GoalTransition) => {
            s += &format!(
                " goal {:x}/{} -> {} ({})",
                e.client_id,
                e.goal_id,
                code(e.state(), e.state),
                code(e.reason(), e.reason)
            );
        }
        Ok(EventKind::Place | EventKind::Lift | EventKind::Roll) => {
            s += &format!(" {} goal {}", finger_name(e.finger), e.goal_id);
        }
        Ok(EventKind::Substitution) => {
            let by = counted_fingers(e).unwrap_or_else(|| "another finger".into());
            s += &format!(
                " {by} took over from {}, goal {}",
                finger_name(e.finger),
                e.goal_id
            );
        }
        Ok(EventKind::Rewind) => {
            s += &format!(
                " {} moved back with {}'s help, goal {}",
                counted_fingers(e).unwrap_or_default(),
                finger_name(e.finger),
                e.goal_id
            );
        }
        Ok(EventKind::Fault) => {
            s += &format!(" {}", code(e.fault(), e.fault));
            if e.finger < 3 {
                s += &format!(" ({})", finger_name(e.finger));
            }
        }
        Ok(EventKind::Overrun) => s += &format!(" {} periods missed", e.count),
        Ok(EventKind::ClientsCleaned) => s += &format!(" {} dead nodes", e.count),
        Ok(EventKind::Hold) => s += &format!(" by client {:x}", e.client_id),
        Ok(EventKind::NearLimit) => {
            let who = if e.finger < 3 {
                format!(" {}", finger_name(e.finger))
            } else {
                String::new()
            };
            s += &format!(
                "{who} near {}: replanning (replan {})",
                code(e.fault(), e.fault),
                e.count
            )
        }
        Ok(EventKind::Drift) => {
            s += &format!(" {}: replanning (drift {})", finger_name(e.finger), e.count)
        }
        _ => {}
    }
    s
}
