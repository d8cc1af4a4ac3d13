//! libFuzzer target: the input is a sequence of 144-byte commands fed
//! through the daemon's intake with its state carried (duplicate ids,
//! shutdown), each answer checked against the model of
//! `daemon/tests/support/intake_oracle.rs` — the same check as the stable
//! `intake_fuzz` test, but coverage-guided.

#![no_main]

#[path = "../../tests/support/intake_oracle.rs"]
mod oracle;

use libfuzzer_sys::fuzz_target;
use shm_schema::Command;

fuzz_target!(|data: &[u8]| {
    let mut rig = oracle::Rig::new();
    // The first byte's low bit: shut down half-way through.
    let shutdown_at = match data.first() {
        Some(b) if b & 1 == 1 => data.len() / Command::SIZE / 2,
        _ => usize::MAX,
    };
    for (i, chunk) in data.get(1..).unwrap_or(&[]).chunks_exact(Command::SIZE).enumerate() {
        if i == shutdown_at {
            rig.shutdown();
        }
        let bytes: &[u8; Command::SIZE] = chunk.try_into().expect("exact chunk");
        rig.feed(bytes);
    }
});
