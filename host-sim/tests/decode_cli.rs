//! `host-sim decode` on a capture written through `capture.rs` and then
//! damaged: the summary counts what was done to it, and the CSV has one row
//! per good frame.

use std::process::Command;

use host_sim::formats::capture::{CaptureWriter, SiSample};
use mwd_core::protocol::example;

#[test]
fn decode_summarises_a_damaged_capture_and_exports_csv() {
    let dir = std::env::temp_dir().join(format!("host-sim-decode-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bin = dir.join("capture.bin");
    let csv = dir.join("capture.csv");

    let mut writer = CaptureWriter::new(Vec::new());
    writer.write(&example::boot_event()).unwrap();
    let mut frame_starts = vec![];
    for i in 0..40u32 {
        frame_starts.push(writer.bytes_written() as usize);
        let sample = SiSample {
            index: i,
            gyro_body_xz_rad_s: [0.01, -0.02],
            accel_body_m_s2: [[0.0, 0.0, 9.8]; 2],
            temperature_degc: 25.0,
        };
        writer.write_si_sample(&sample).unwrap();
        if i % 10 == 9 {
            writer.write(&example::nav_solution()).unwrap();
        }
    }
    let mut bytes = writer.finish().unwrap();
    // Damage: flip a bit in raw frame 5, cut raw frame 20 short (its closing
    // delimiter goes with it; the next frame opens with its own), and put
    // garbage in front.
    bytes[frame_starts[5] + 10] ^= 0x10;
    bytes.drain(frame_starts[20] + 20..frame_starts[21]);
    let mut damaged = b"noise".to_vec();
    damaged.extend(bytes);
    std::fs::write(&bin, &damaged).unwrap();

    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .arg("decode")
        .arg(&bin)
        .arg("--csv")
        .arg(&csv)
        .output()
        .unwrap();
    // Written (the summary, the CSV) but incomplete: frames were lost.
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("2 frames lost"));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("raw sample 38, navigation 4, event 1"),
        "{text}"
    );
    assert!(text.contains("2 frames lost"), "{text}");
    // Three chunks discarded: the garbage in front, the flipped frame (the
    // flip hits a COBS code byte at offset 10, so it fails as malformed
    // COBS before any CRC is computed) and the cut frame.
    assert!(
        text.contains("corrupt          0 CRC failures, 3 malformed"),
        "{text}"
    );
    let rows = std::fs::read_to_string(&csv).unwrap().lines().count();
    assert_eq!(rows, 1 + 38 + 4 + 1);
    std::fs::remove_dir_all(&dir).ok();
}
