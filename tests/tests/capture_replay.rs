//! The committed capture of the QEMU probe (`tests/data/qemu-static-6s.bin`,
//! recorded by `scripts/make-test-capture.sh`) decodes cleanly and replays
//! through the host's copy of the probe's navigation to the probe's own
//! navigation frames bit for bit, both through the library and through the
//! `host-sim replay` summary it backs. No QEMU needed.

use host_sim::formats::capture;
use host_sim::replay::{self, ReplaySummary};
use mwd_core::earth::Position;
use mwd_core::protocol::frame::nav_mode;
use mwd_core::protocol::{EventKind, Payload};
use system_tests::workspace_root;

const SAMPLES: u64 = 6 * 20;
use mwd_core::timing::ALIGNMENT_SAMPLES;

#[test]
fn the_committed_capture_replays_to_the_probes_solutions_bit_for_bit() {
    let path = workspace_root().join("tests/data/qemu-static-6s.bin");
    let cap = capture::read_capture(&path).expect("the committed capture");
    let stats = cap.stats;
    // The committed capture predates kind 4 and holds none (6 s: no navigation).
    assert_eq!(stats.frames, [SAMPLES, SAMPLES, 1, 0], "{stats:?}");
    assert_eq!(
        (stats.corrupt(), stats.lost, stats.garbage_bytes),
        (0, 0, 0),
        "{stats:?}"
    );
    assert!(matches!(
        cap.frames.first().map(|f| f.payload),
        Some(Payload::Event(e)) if e.kind == EventKind::Boot
    ));

    let (rows, summary) = replay::replay(&cap.frames, Position::paper_site());
    assert_eq!(
        summary,
        ReplaySummary {
            raw_frames: SAMPLES,
            probe_solutions: SAMPLES,
            matched: SAMPLES,
            mismatched: 0,
            unchecked: 0,
            degraded: 0,
            restarts: 0,
        },
        "the replay no longer reproduces the recorded probe: if the navigation \
         changed on purpose, record the capture again (scripts/make-test-capture.sh)"
    );
    // The run covers the coarse alignment and the start of the fine one.
    for row in &rows {
        let n = row.solution.sample_counter;
        let expected = if n < ALIGNMENT_SAMPLES - 1 {
            nav_mode::COARSE_ALIGNMENT
        } else {
            nav_mode::FINE_ALIGNMENT
        };
        assert_eq!(row.solution.mode, expected, "sample {n}");
        assert_eq!(row.matches_probe, Some(true), "sample {n}");
    }
}

#[test]
fn a_lost_raw_frame_stops_the_comparison_and_a_restart_resumes_it() {
    let bytes = std::fs::read(workspace_root().join("tests/data/qemu-static-6s.bin")).unwrap();
    // Frame 139 is the raw frame of sample 69 (boot event, then raw and
    // navigation frame per sample); then the probe reboots and runs again.
    let mut damaged = capture::without_frame(&bytes, 139);
    damaged.extend_from_slice(&bytes);
    let cap = capture::decode_bytes(&damaged);
    assert_eq!(
        (cap.stats.lost, cap.stats.sequence_restarts),
        (1, 1),
        "{:?}",
        cap.stats
    );
    let mut replayer = replay::Replayer::new(Position::paper_site());
    for frame in &cap.frames {
        replayer.push(frame);
    }
    let losses = replayer.step_losses().to_vec();
    assert_eq!(losses.len(), 1);
    assert_eq!((losses[0].run, losses[0].from_sample), (0, 70));
    let (_, summary) = replayer.finish();
    assert_eq!(
        (
            summary.matched,
            summary.mismatched,
            summary.unchecked,
            summary.restarts
        ),
        (69 + SAMPLES, 0, 51, 1),
        "{summary:?}"
    );
}

/// The simulator's raw parts are what the probe's driver and
/// `firmware::app::raw_part` send for the same counts: a gyro beyond
/// +-300 deg/s is saturated and not valid (the driver's
/// `Error::Saturated`), an in-range one valid.
#[test]
fn simulated_raw_parts_carry_the_probes_flags() {
    use firmware::app::raw_part;
    use firmware::scc1300::{AccelCounts, Error, GyroCounts, PartReading, Slave};
    use host_sim::formats::capture::{raw_sample_from_si, SiSample};

    for rate_deg_s in [-400.0, -299.0, 0.5, 299.0, 301.0, 1000.0] {
        let sample = SiSample {
            index: 7,
            gyro_body_xz_rad_s: [f64::to_radians(rate_deg_s), 0.01],
            accel_body_m_s2: [[0.0, 0.0, 9.81]; 2],
            temperature_degc: 25.0,
        };
        let simulated = raw_sample_from_si(&sample).parts[0];
        let saturated = mwd_core::sensor_units::gyro_count_is_saturated(simulated.gyro_rate);
        let reading = PartReading {
            gyro: GyroCounts {
                rate: simulated.gyro_rate,
                temp: simulated.gyro_temp,
            },
            accel: AccelCounts {
                xyz: simulated.accel,
                temp: simulated.accel_temp,
            },
            gyro_s_ok: true,
            gyro_error: saturated.then_some(Error::Saturated(Slave::Gyro)),
            ..PartReading::default()
        };
        assert_eq!(simulated, raw_part(&reading), "{rate_deg_s} deg/s");
        assert_eq!(saturated, rate_deg_s.abs() > 300.0, "{rate_deg_s} deg/s");
    }
}
