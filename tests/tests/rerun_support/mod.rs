//! Reading a Rerun recording (`.rrd`, as `gaitd-view --save` writes it)
//! back with Rerun's own decoder, for the tests that check what the view
//! recorded.

use rerun::external::re_log_encoding::Decoder;
use rerun::log::{Chunk, LogMsg};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// What the tests look at in a recording.
pub struct Recording {
    /// Every entity with data (blueprint aside).
    pub entities: BTreeSet<String>,
    /// Rows logged per entity (temporal data; blueprint aside).
    pub rows: BTreeMap<String, usize>,
    /// `world/object`'s rotations ([x, y, z, w]) with their time \[ns\].
    pub object: Vec<(i64, [f32; 4])>,
}

/// The recording at `path` (panics if Rerun cannot decode it).
pub fn read(path: &Path) -> Recording {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut rec = Recording {
        entities: BTreeSet::new(),
        rows: BTreeMap::new(),
        object: vec![],
    };
    let quat = rerun::archetypes::Transform3D::descriptor_quaternion().component;
    for msg in Decoder::<LogMsg>::decode_lazy(file) {
        let LogMsg::ArrowMsg(store, arrow) = msg.expect("a valid Rerun recording") else {
            continue;
        };
        if store.kind() != rerun::StoreKind::Recording {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(&arrow).unwrap();
        let entity = chunk.entity_path().to_string();
        let entity = entity.trim_start_matches('/').to_owned();
        if entity == "world/object" {
            let times = chunk
                .timelines()
                .get(&"daemon_time".into())
                .expect("frames on the daemon_time timeline")
                .times_raw()
                .to_vec();
            let rotations = chunk.iter_component::<rerun::components::RotationQuat>(quat);
            for (time, r) in times.into_iter().zip(rotations) {
                if let Some(r) = r.first() {
                    rec.object.push((time, r.0.0));
                }
            }
        }
        if !chunk.is_static() {
            *rec.rows.entry(entity.clone()).or_default() += chunk.num_rows();
        }
        rec.entities.insert(entity);
    }
    rec
}
