//! The probe's firmware in QEMU, end to end: the `probe-qemu`
//! binary is cross-built, runs on the emulated mps2-an386 board for a
//! simulated minute with the two SCC1300 parts simulated by hil-mock behind
//! the real driver, and its UART bytes (QEMU `-serial file:`) are decoded
//! with the host's protocol decoder; the host then replays the raw frames
//! through the probe's own navigation code and must get the probe's
//! navigation frames bit for bit.
//!
//! Time is QEMU's virtual clock under `-icount shift=0,sleep=off`: one
//! instruction is one nanosecond and idle time is skipped, so the run is
//! deterministic and the simulated minute takes about a second. Nothing
//! here measures wall-clock time; a timeout only guards against a hung
//! emulator.
//!
//! qemu-system-arm must be installed (`scripts/test-all.sh` installs it):
//! without it this test fails, it does not skip.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

use hil_mock::StillProbe;
use mwd_core::earth::Position;
use mwd_core::probe::Navigator;
use mwd_core::protocol::frame::{nav_mode, raw_flags, MAX_BODY_LEN};
use mwd_core::protocol::{
    encode_body, Decoder, DecoderStats, Event, EventKind, Frame, NavSolution, Payload, RawSample,
};
use mwd_core::sensor_units::{accel_count_to_m_s2, PART_MOUNTINGS};
use mwd_core::timing;
use system_tests::{build_firmware, require_qemu, summary_value, wait_or_kill};

/// The firmware's default run length (`PROBE_QEMU_RUN_SECONDS`).
const RUN_SECONDS: u64 = 60;
const RATE_HZ: u64 = 20;
/// Samples of the coarse and of the fine alignment (mwd_core::timing).
const ALIGNMENT_SAMPLES: usize = timing::ALIGNMENT_SAMPLES as usize;
const FINE_ALIGNMENT_SAMPLES: usize = timing::FINE_ALIGNMENT_SAMPLES as usize;
/// Far above the ~1 s the run takes; only a hang reaches it.
const QEMU_TIMEOUT: Duration = Duration::from_secs(300);

/// What one QEMU run left: the probe's semihosting output and its UART.
struct Run {
    stdout: String,
    uart: Vec<u8>,
}

fn run_in_qemu(elf: &Path, name: &str) -> Run {
    let (run, status) = run_in_qemu_to_exit(elf, name);
    assert!(
        status.success(),
        "probe-qemu failed: {status}\n{}",
        run.stdout
    );
    run
}

/// Runs the probe until QEMU exits; returns what it left and its status.
fn run_in_qemu_to_exit(elf: &Path, name: &str) -> (Run, std::process::ExitStatus) {
    let serial = std::env::temp_dir().join(format!("probe-qemu-{name}-{}.bin", std::process::id()));
    let _ = std::fs::remove_file(&serial);
    let mut child = Command::new("qemu-system-arm")
        .args(["-M", "mps2-an386", "-cpu", "cortex-m4", "-nographic"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .arg("-serial")
        .arg(format!("file:{}", serial.display()))
        .args(["-icount", "shift=0,sleep=off", "-kernel"])
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start qemu-system-arm");
    let status = wait_or_kill(&mut child, "QEMU", QEMU_TIMEOUT);
    let output = child.wait_with_output().expect("qemu output");
    let mut stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    stdout += &String::from_utf8_lossy(&output.stderr);
    let uart = std::fs::read(&serial).expect("QEMU's serial capture");
    let _ = std::fs::remove_file(&serial);
    (Run { stdout, uart }, status)
}

fn decode(uart: &[u8]) -> (Vec<Frame>, DecoderStats) {
    let mut decoder = Decoder::new();
    let mut frames = Vec::new();
    decoder.feed(uart, |f| frames.push(f));
    (frames, *decoder.stats())
}

fn raw_samples(frames: &[Frame]) -> Vec<RawSample> {
    frames
        .iter()
        .filter_map(|f| match f.payload {
            Payload::Raw(r) => Some(r),
            _ => None,
        })
        .collect()
}

/// 20 raw frames in every simulated second, consecutive counters, the
/// timer's exact 50 ms spacing.
fn assert_twenty_per_simulated_second(raws: &[RawSample]) {
    assert_eq!(raws.len() as u64, RUN_SECONDS * RATE_HZ);
    let mut per_second = [0u64; RUN_SECONDS as usize];
    for (n, raw) in raws.iter().enumerate() {
        assert_eq!(raw.sample_counter as usize, n);
        assert_eq!(raw.time_us, n as u64 * 1_000_000 / RATE_HZ);
        per_second[(raw.time_us / 1_000_000) as usize] += 1;
    }
    assert!(per_second.iter().all(|&n| n == RATE_HZ), "{per_second:?}");
}

fn assert_clean_link(stats: &DecoderStats, stdout: &str) {
    assert_eq!(stats.corrupt(), 0, "{stats:?}");
    assert_eq!(stats.garbage_bytes, 0, "{stats:?}");
    assert_eq!(stats.lost, 0, "sequence gaps: {stats:?}");
    assert_eq!(stats.sequence_restarts, 0, "{stats:?}");
    assert_eq!(summary_value(stdout, "frames_dropped"), 0);
}

fn nav_bytes(nav: &NavSolution) -> Vec<u8> {
    let mut body = [0u8; MAX_BODY_LEN];
    let len = encode_body(0, &Payload::Nav(*nav), &mut body).expect("room for a frame");
    body[..len].to_vec()
}

#[test]
fn static_minute_streams_twenty_clean_raw_frames_per_simulated_second() {
    require_qemu();
    let elf = build_firmware("board-qemu", "static");
    let run = run_in_qemu(&elf, "static");
    let (frames, stats) = decode(&run.uart);
    let raws = raw_samples(&frames);

    // The link: every byte decoded, nothing lost or corrupt.
    assert_clean_link(&stats, &run.stdout);

    // First the boot event, then raw and navigation frames only: no faults
    // in this run.
    let Some(Payload::Event(boot)) = frames.first().map(|f| f.payload) else {
        panic!("the stream starts with the boot event")
    };
    assert_eq!(boot.kind, EventKind::Boot);
    let navs: Vec<NavSolution> = frames
        .iter()
        .filter_map(|f| match f.payload {
            Payload::Nav(n) => Some(n),
            _ => None,
        })
        .collect();
    assert_eq!(
        raws.len() + navs.len() + 1,
        frames.len(),
        "unexpected events"
    );
    assert_twenty_per_simulated_second(&raws);
    assert_eq!(summary_value(&run.stdout, "samples"), RUN_SECONDS * RATE_HZ);
    assert_eq!(summary_value(&run.stdout, "nav_samples_dropped"), 0);

    // One navigation solution per raw sample: 5 s of coarse alignment on
    // the still probe, fine alignment (the 39-state filter with zero
    // updates) to the end of the minute, then navigation. The simulated
    // parts sense `hil_mock::StillProbe::paper_test`: the paper's site and
    // attitude, earth rate, gravity, residual biases and white noise.
    assert_eq!(navs.len(), raws.len());
    let fine_end = ALIGNMENT_SAMPLES + FINE_ALIGNMENT_SAMPLES - 1;
    for (n, nav) in navs.iter().enumerate() {
        assert_eq!(nav.sample_counter as usize, n);
        let mode = if n < ALIGNMENT_SAMPLES - 1 {
            nav_mode::COARSE_ALIGNMENT
        } else if n < fine_end {
            nav_mode::FINE_ALIGNMENT
        } else {
            nav_mode::NAVIGATING
        };
        assert_eq!(nav.mode, mode, "solution {n}");
    }
    let truth = StillProbe::paper_test(1).attitude;
    let first = navs[ALIGNMENT_SAMPLES - 1];
    let last = navs[fine_end];
    // Roll and pitch inside 3 sigma of the truth, after the coarse and
    // after the fine alignment.
    for nav in [&first, &last] {
        for (axis, true_angle) in [truth.roll, truth.pitch].into_iter().enumerate() {
            let error = f64::from(nav.attitude[axis]) - true_angle;
            let sigma = f64::from(nav.attitude_std[axis]);
            assert!(
                sigma > 0.0 && error.abs() < 3.0 * sigma,
                "axis {axis}: {nav:?}"
            );
        }
        // One still minute cannot give the heading (gyro noise and bias
        // against 10.5 deg/h of horizontal earth rate): the probe says so.
        assert!(nav.attitude_std[2].is_infinite(), "{nav:?}");
    }
    // The fine alignment converged: velocity and position sigmas fell to a
    // fifth or less and the velocity is near zero; the tilt sigmas stay
    // near their floor (accelerometer bias / g: levelling with the same
    // accelerometers cannot separate tilt from bias).
    for i in 0..3 {
        assert!(
            last.velocity_std[i] < 0.2 * first.velocity_std[i],
            "{first:?} -> {last:?}"
        );
        assert!(
            last.position_std_ned[i] < 0.2 * first.position_std_ned[i],
            "{last:?}"
        );
        assert!(
            last.velocity_ned[i].abs() < 3.0 * last.velocity_std[i].max(1e-3),
            "{last:?}"
        );
    }
    for axis in 0..2 {
        assert!(
            last.attitude_std[axis] < 1.5 * first.attitude_std[axis],
            "{last:?}"
        );
    }

    // Replay parity: the host runs the probe's navigation code on the
    // recorded raw frames and gets the probe's solutions bit for bit
    // (compared as encoded frames, so NaN fields compare too).
    let mut navigator = Navigator::new(Position::paper_site());
    for (raw, on_board) in raws.iter().zip(&navs) {
        let replayed = navigator.step(raw);
        assert_eq!(
            nav_bytes(&replayed),
            nav_bytes(on_board),
            "sample {}: host {replayed:?} vs probe {on_board:?}",
            raw.sample_counter
        );
    }
    // The same through the host tool's replay (`host-sim replay`).
    let (_, summary) = host_sim::replay::replay(&frames, Position::paper_site());
    assert_eq!(
        (summary.matched, summary.mismatched),
        (navs.len() as u64, 0)
    );

    // The data are the probe at rest: both parts valid, and both
    // accelerometers, back in body axes, feel gravity's reaction at the
    // site (each sample within 4 counts: quantisation, 1 mg bias and
    // noise; the minute's mean within 1.5).
    let lsb = accel_count_to_m_s2(1);
    let g = mwd_core::earth::normal_gravity(truth_position().lat, truth_position().height) as f32;
    let mut sum = 0.0f64;
    for raw in &raws {
        for (part, mounting) in raw.parts.iter().zip(PART_MOUNTINGS) {
            let valid = raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID;
            assert_eq!(part.flags & valid, valid, "sample {}", raw.sample_counter);
            let body = mounting.sensor_to_body(part.accel.map(accel_count_to_m_s2));
            let norm = body.iter().map(|a| a * a).sum::<f32>().sqrt();
            assert!((norm - g).abs() <= 4.0 * lsb, "|f| = {norm}");
            sum += f64::from(norm);
        }
    }
    let mean = sum / (2 * raws.len()) as f64;
    assert!(
        (mean - f64::from(g)).abs() <= 1.5 * f64::from(lsb),
        "mean |f| = {mean}"
    );
}

fn truth_position() -> Position {
    StillProbe::paper_test(1).position
}

#[test]
fn injected_sensor_faults_become_events_and_the_stream_goes_on() {
    require_qemu();
    // Faults (firmware/src/bin/probe_qemu/mock_sensors.rs): part 0 gyro
    // parity errors at 10 s, part 1 gyro S_OK drop at 20 s, part 0
    // power-cycle at 30 s, part 1 at 200 degC from 40 to 41 s, both gyros
    // lose their loop at 50 s (the driver's worst recovery: the probe must
    // still send every navigation frame, docs/budgets.md).
    let elf = build_firmware("qemu-fault-demo", "faults");
    let run = run_in_qemu(&elf, "faults");
    let (frames, stats) = decode(&run.uart);
    assert_clean_link(&stats, &run.stdout);
    let raws = raw_samples(&frames);
    assert_twenty_per_simulated_second(&raws);

    let events: Vec<Event> = frames
        .iter()
        .filter_map(|f| match f.payload {
            Payload::Event(e) => Some(e),
            _ => None,
        })
        .collect();
    let seen = |kind: EventKind, part: u8, from_s: u64, to_s: u64| {
        events.iter().any(|e| {
            e.kind == kind && e.part == part && (from_s..to_s).contains(&(e.time_us / 1_000_000))
        })
    };
    assert!(seen(EventKind::SensorFault, 0, 10, 11), "{events:#?}");
    assert!(seen(EventKind::SensorFault, 1, 20, 21), "{events:#?}");
    assert!(seen(EventKind::SensorFault, 0, 30, 31), "{events:#?}");
    assert!(seen(EventKind::SensorFault, 0, 50, 51), "{events:#?}");
    assert!(seen(EventKind::SensorFault, 1, 50, 51), "{events:#?}");
    // The recoveries ran, succeeded and the stream resynchronised. A
    // power-cycled part takes its 800 ms start-up again: within 2 s. The
    // reset event says what the recovery did: 0 for part 1's transient
    // S_OK drop, the loop-failure code for part 0, whose gyro came back
    // from the power cycle with its loop off and was soft-reset.
    let loop_failure = firmware::app::fault_code(&firmware::scc1300::Error::LoopFailure);
    for (part, at_s, code) in [
        (1, 20, 0),
        (0, 30, loop_failure),
        (0, 50, loop_failure),
        (1, 50, loop_failure),
    ] {
        assert!(
            events.iter().any(|e| e.kind == EventKind::SensorReset
                && e.part == part
                && e.code == code
                && (at_s..at_s + 2).contains(&(e.time_us / 1_000_000))),
            "{events:#?}"
        );
    }
    assert_eq!(
        events
            .iter()
            .filter(|e| e.kind == EventKind::SensorReset)
            .count(),
        4,
        "{events:#?}"
    );
    // Each resynchronisation says how many samples its recovery cost.
    let resyncs: u64 = events
        .iter()
        .filter(|e| e.kind == EventKind::Resync)
        .map(|e| u64::from(e.value))
        .sum();
    // No fault outside the injected ones.
    let faults = events.iter().filter(|e| e.kind == EventKind::SensorFault);
    assert!(faults
        .clone()
        .all(|e| [10, 20, 30, 50, 51].contains(&(e.time_us / 1_000_000))));

    // Samples lost to recovery are marked (no valid flag), all within 2 s
    // of a fault, and the probe streams good data again after.
    let valid = raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID;
    let skipped: Vec<_> = raws
        .iter()
        .filter(|r| r.parts.iter().any(|p| p.flags & valid != valid))
        .map(|r| r.time_us / 1_000_000)
        .collect();
    assert!(!skipped.is_empty());
    assert!(
        skipped
            .iter()
            .all(|s| [10, 20, 21, 30, 31, 50, 51].contains(s)),
        "{skipped:?}"
    );
    let away = raws.iter().filter(|r| r.parts.iter().all(|p| p.flags == 0));
    assert_eq!(summary_value(&run.stdout, "skipped"), away.count() as u64);
    assert_eq!(summary_value(&run.stdout, "skipped"), resyncs);
    assert_eq!(summary_value(&run.stdout, "nav_samples_dropped"), 0);
    assert!(events.iter().all(|e| e.kind != EventKind::SamplesDropped));
    assert!(
        summary_value(&run.stdout, "nav_inbox_high_water") <= firmware::app::NAV_INBOX_LEN as u64
    );
    assert!(raws
        .iter()
        .filter(|r| (32_000_000..50_000_000).contains(&r.time_us) || r.time_us >= 52_000_000)
        .all(|r| r.parts.iter().all(|p| p.flags & valid == valid)));
    // The worst recovery blocked the main loop for most of 2 s: the inbox
    // held its samples, and every navigation frame went out (no sequence
    // gap, frames_dropped 0 above, one navigation frame per raw frame).
    let resync_at_50 = events
        .iter()
        .find(|e| e.kind == EventKind::Resync && e.time_us >= 50_000_000)
        .map_or(0, |e| e.value);
    assert!(resync_at_50 >= 30, "{events:#?}");
    assert!(summary_value(&run.stdout, "nav_inbox_high_water") >= 30);
    let navs = frames
        .iter()
        .filter(|f| matches!(f.payload, Payload::Nav(_)))
        .count();
    assert_eq!(navs, raws.len());

    // The overheated part: its raw frames flag every sample from 40 to
    // 41 s (values still valid), and two events say when it left its
    // operating range (code 1, above: the clipped count 8191) and came
    // back (code 2, its count at the simulated 25 degC).
    let hot: Vec<u32> = raws
        .iter()
        .filter(|r| r.parts[1].flags & raw_flags::TEMPERATURE_OUT_OF_RANGE != 0)
        .map(|r| r.sample_counter)
        .collect();
    assert_eq!(hot, (40 * 20..41 * 20).collect::<Vec<u32>>());
    assert!(raws
        .iter()
        .all(|r| r.parts[0].flags & raw_flags::TEMPERATURE_OUT_OF_RANGE == 0));
    let temperature_events: Vec<(u8, u16, i32, u64)> = events
        .iter()
        .filter(|e| e.kind == EventKind::Temperature)
        .map(|e| (e.part, e.code, e.value as i32, e.time_us))
        .collect();
    let back_count = i32::from(
        mwd_core::sensor_units::GYRO_TEMPERATURE
            .degc_to_count(StillProbe::paper_test(2).temperature_degc),
    );
    assert_eq!(
        temperature_events,
        [(1, 1, 8191, 40_000_000), (1, 2, back_count, 41_000_000)]
    );
}

#[test]
fn the_watchdog_ends_a_run_whose_main_loop_hangs() {
    require_qemu();
    // The main loop stops at 10 s (the acquisition interrupt goes on); the
    // watchdog (firmware::app::WATCHDOG_TIMEOUT_MS, sized in
    // firmware/src/app/watchdog.rs) must catch it and the probe reports it
    // and fails.
    let elf = build_firmware("qemu-stall-demo", "stall");
    let (run, status) = run_in_qemu_to_exit(&elf, "stall");
    assert!(!status.success(), "{}", run.stdout);
    assert!(
        run.stdout.contains("watchdog: the main loop stalled"),
        "{}",
        run.stdout
    );
    // Streaming went on until the watchdog acted, one timeout after the
    // main loop's last feed just after 10 s (QEMU's watchdog clock is
    // exact): the last raw frame is within one sample period before that.
    let (frames, stats) = decode(&run.uart);
    assert_eq!((stats.corrupt(), stats.lost), (0, 0), "{stats:?}");
    let raws = raw_samples(&frames);
    let last_us = raws.last().map_or(0, |r| r.time_us);
    let fired_us = 10_000_000 + u64::from(firmware::app::WATCHDOG_TIMEOUT_MS) * 1_000;
    assert!(
        last_us <= fired_us + timing::SAMPLE_PERIOD_US
            && last_us + 2 * timing::SAMPLE_PERIOD_US >= fired_us,
        "last raw frame at {last_us} us, watchdog due at {fired_us} us"
    );
}
