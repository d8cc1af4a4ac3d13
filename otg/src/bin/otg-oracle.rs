//! `otg-oracle`: reads `ruckig-oracle/1` cases (JSON lines, as printed by
//! `tests/oracles/ruckig_oracle.py gen`) on stdin and prints, per case, a
//! JSON line with the same result keys computed by this crate, so that the
//! two can be diffed.

use std::io::{BufRead, Write};

use serde_json::{Value, json};

#[path = "../../oracle/case.rs"]
#[allow(dead_code)]
mod case;

fn result_json(c: &case::Case) -> Value {
    let r = case::solve(c, None);
    let status = case::status_name(&r);
    match r {
        Err(e) => json!({
            "status": status, "code": null, "error": e.to_string(), "duration": null,
            "independent_min_durations": null, "limiting_dofs": null,
            "phase_synced": null, "samples": null,
        }),
        Ok(s) => {
            let t = s.duration;
            let limiting: Vec<usize> = s
                .independent_min_durations
                .iter()
                .enumerate()
                .filter(|(_, d)| (*d - t).abs() <= 1e-12 * t.max(1.0))
                .map(|(i, _)| i)
                .collect();
            let samples: Vec<Value> = case::FRACTIONS
                .iter()
                .map(|&f| {
                    let (p, v, a) = s.at(f * t);
                    json!({"f": f, "t": f * t, "p": p, "v": v, "a": a})
                })
                .collect();
            let phase =
                (c.synchronization == otg::Synchronization::Phase).then(|| case::phase_synced(&s));
            json!({
                "status": status, "code": 0, "error": null, "duration": t,
                "independent_min_durations": s.independent_min_durations,
                "limiting_dofs": limiting, "phase_synced": phase, "samples": samples,
            })
        }
    }
}

fn main() {
    let stdin = std::io::stdin();
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    for (n, line) in stdin.lock().lines().enumerate() {
        let Ok(line) = line else { break };
        if line.trim().is_empty() {
            continue;
        }
        let value = match case::parse(&line) {
            Ok(c) => {
                let mut v = c.raw.clone();
                v["result"] = result_json(&c);
                if let Some(o) = v.as_object_mut() {
                    o.remove("profiles");
                }
                v
            }
            Err(e) => json!({"schema": "ruckig-oracle/1", "line": n + 1, "parse_error": e}),
        };
        if writeln!(out, "{value}").is_err() {
            break;
        }
    }
    let _ = out.flush();
}
