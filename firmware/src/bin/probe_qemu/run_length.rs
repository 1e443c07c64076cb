//! How long the QEMU probe runs: `PROBE_QEMU_RUN_SECONDS` simulated seconds
//! (read when the binary is built), counted in samples.

use mwd_core::timing::SAMPLE_RATE_HZ;

/// Simulated seconds of streaming before the probe exits.
pub const RUN_SECONDS: u32 = parse_seconds(option_env!("PROBE_QEMU_RUN_SECONDS"), 60);
#[cfg_attr(feature = "qemu-drilling", allow(dead_code))]
pub const SAMPLES_TO_RUN: u32 = RUN_SECONDS * SAMPLES_PER_SECOND;
/// The sample rate, for counting seconds in samples.
pub const SAMPLES_PER_SECOND: u32 = SAMPLE_RATE_HZ as u32;

const fn parse_seconds(text: Option<&str>, default: u32) -> u32 {
    let Some(text) = text else { return default };
    let bytes = text.as_bytes();
    let mut value = 0u32;
    let mut i = 0;
    while i < bytes.len() {
        let digit = bytes[i].wrapping_sub(b'0');
        assert!(digit < 10, "PROBE_QEMU_RUN_SECONDS must be a number");
        value = value * 10 + digit as u32;
        i += 1;
    }
    value
}
