//! The layout document, `shm_schema/LAYOUT.md`, generated from
//! [`super::layouts`] and [`super::code_tables`] (a test checks the file
//! equals it).

use super::{code_tables, layouts};
use crate::command::{LIMIT_OVERRIDES, QUATERNION_NORM_TOLERANCE};
use crate::*;
use std::fmt::Write as _;

/// The layout document (`shm_schema/LAYOUT.md`).
pub fn layout_markdown() -> String {
    let mut s = String::new();
    let names = ServiceNames::new(DEFAULT_PREFIX);
    let _ = writeln!(
        s,
        "# gaitd shared-memory schema v{SCHEMA_VERSION}\n\n\
         Generated from `shm_schema` by `cargo test -p shm_schema` (set `GAITD_BLESS=1` to\n\
         rewrite it); a test fails when this file and the code disagree.\n\n\
         This file is the bytes. How to connect (iceoryx2 root path, file prefix, environment\n\
         variables), the service settings a client must match, when the daemon is ready, how\n\
         to choose ids and what the progress counters count, with a walk-through in Python:\n\
         [CLIENT-GUIDE.md](CLIENT-GUIDE.md).\n\n\
         All payloads are `#[repr(C)]`, little-endian as the host, with explicit padding\n\
         (fields named `reserved`, always 0). Enums travel as `u32` codes (tables below);\n\
         readers must refuse unknown codes. iceoryx2 {ICEORYX2_VERSION} compares the type name,\n\
         size and alignment when a service is opened: a C or Python mirror must use the\n\
         same type names. Quaternions are `[w, x, y, z]` Hamilton, unit norm.\n\n\
         Frames: the hand frame has its origin at the object centre. A fingertip's orientation\n\
         Q_f maps fingertip → hand; its pole axis a_f = Q_f e_z is the centre of the hemisphere\n\
         that may touch, and its roll τ about a_f is the integral of τ̇ = ω_f · a_f (ω_f its\n\
         angular velocity, hand frame), 0 in the start grasp: [PLANT-GUIDE.md](PLANT-GUIDE.md),\n\
         \"The start grasp and the fingertip frame\".\n\n\
         A chain hand (`Status.hand` = 1) is described in its URDF's frame, where the object\n\
         centre is at O (the description's `object.centre`): positions here are the URDF\n\
         frame's less O, in its axes; the fingertip orientations and rolls carry no meaning\n\
         (the joints, `commanded_joints`, set the tip's orientation).\n\n\
         ## Services (prefix `{DEFAULT_PREFIX}`, configurable)\n\n\
         | service | pattern | payload | notes |\n|---|---|---|---|\n\
         | `{}` | publish-subscribe | `Command` | client → daemon, one publisher per client |\n\
         | `{}` | publish-subscribe | `Answer` | one per command, match `client_id` + `request_id` |\n\
         | `{}` | publish-subscribe | `Status` | every tick, history 1, latest value |\n\
         | `{}` | publish-subscribe | `Event` | with history |\n\
         | `{}` | event | — | wake-ups, ids below |\n\
         | `{}` | publish-subscribe | `PlanPath` | each plan's path, when it is made; history 1, latest value |\n\
         | `{}` | publish-subscribe | `PlantCommand` | daemon → plant, every tick |\n\
         | `{}` | publish-subscribe | `PlantMeasurement` | plant → daemon |\n\
         | `{}` | event | — | daemon → plant: a command was published (id 1) |\n\
         | `{}` | event | — | plant → daemon: a measurement was published (id 1) |\n\
         | `{}` | event | — | attributes `{VERSION_ATTRIBUTE_SCHEMA}`, `{VERSION_ATTRIBUTE_BUILD}`: the daemon's schema and build; never changes |\n",
        names.commands,
        names.answers,
        names.status,
        names.events,
        names.notify,
        names.plan,
        names.plant_command,
        names.plant_measurement,
        names.plant_commanded,
        names.plant_measured,
        names.version
    );
    let _ = writeln!(
        s,
        "Notification ids on `{}`: {} = status published, {} = event published, \
         {} = answer sent, {} = daemon node found dead.\n\
         These four are every id the daemon sends; the service is created with {} as its\n\
         largest id (`EVENT_ID_MAX`, an opener must not ask for more), so 5 to {} stay unused.\n",
        names.notify,
        EVENT_ID_STATUS,
        EVENT_ID_EVENT,
        EVENT_ID_ANSWER,
        EVENT_ID_DAEMON_DEAD,
        EVENT_ID_MAX,
        EVENT_ID_MAX
    );
    s.push_str(&format!(
        "## Schema versions\n\n\
         Every payload's type name carries the version (`gaitd::Status.v{SCHEMA_VERSION}`): a client of\n\
         another version cannot open the services (iceoryx2 answers `IncompatibleTypes`).\n\
         So a client first opens the event service `version` (no payload type: any\n\
         version opens it) and reads its attributes: `gaitd.schema`, the daemon's\n\
         schema version in decimal, and `gaitd.build` (e.g. `gaitd 0.1.0`). A daemon\n\
         without that service speaks v3 or older. What each version changed, newest first:\n\n",
    ));
    for (v, what) in SCHEMA_CHANGES {
        let _ = writeln!(s, "- **v{v}**: {what}");
    }
    s.push_str("- **v1**: the first.\n\n");
    s.push_str("## Payloads\n\n");
    for t in layouts() {
        let _ = writeln!(
            s,
            "### `{}` (`{}`, {} bytes, align {})\n\n\
             | offset | size | field | type | unit | meaning |\n|---:|---:|---|---|---|---|",
            t.name, t.type_name, t.size, t.align
        );
        for f in &t.fields {
            let _ = writeln!(
                s,
                "| {} | {} | `{}` | `{}` | {} | {} |",
                f.offset, f.size, f.name, f.ty, f.unit, f.doc
            );
        }
        s.push('\n');
    }
    let _ = writeln!(
        s,
        "## Command validation\n\n\
         What the daemon accepts in a `Command` (anything else is rejected with the\n\
         reason code in brackets):\n\n\
         - quaternion targets (`Absolute`, `Relative`): finite [`NonFiniteQuaternion`],\n\
         \x20 norm ≥ 1e-6 [`ZeroQuaternion`], |norm − 1| ≤ {QUATERNION_NORM_TOLERANCE:e}\n\
         \x20 [`NonUnitQuaternion`]; the daemon renormalises;\n\
         - axis-angle targets `[angle, x, y, z]`: finite, |angle| ≤ 64π = {MAX_AXIS_ANGLE} rad,\n\
         \x20 axis norm in [1e-6, 1e6] [`BadAxisAngle`];\n\
         - motion-limit overrides: only bits 0–{} of `limit_mask` [`BadLimitMask`]; a set\n\
         \x20 override finite [`NonFiniteLimit`] and > 0 [`NonPositiveLimit`], at most the\n\
         \x20 configured limit [`LimitAboveConfigured`] and at least {MIN_LIMIT_OVERRIDE_FRACTION} × the\n\
         \x20 configured limit [`LimitBelowMinimum`]; plans are timed with the limits in effect,\n\
         \x20 so ETA and plan cost hold under an override;\n\
         - every field a command kind does not use, and every unset override, is 0\n\
         \x20 [`NonZeroReserved`].\n",
        LIMIT_OVERRIDES - 1
    );
    s.push_str("## Codes\n\n");
    for (name, rows) in code_tables() {
        let _ = writeln!(
            s,
            "### `{name}`\n\n| code | name | meaning |\n|---:|---|---|"
        );
        for r in rows {
            let _ = writeln!(s, "| {} | `{}` | {} |", r.code, r.name, r.doc);
        }
        s.push('\n');
    }
    s.truncate(s.trim_end().len());
    s.push('\n');
    s
}
