//! The SCC1300 driver against the register-level mock (hil-mock): start-up,
//! readings against the mock's source within one LSB, parity of every word
//! both ways, and every injected fault ending in the right error or a
//! recovery, never a panic.

mod common;

use common::*;
use firmware::scc1300::{Error, GyroRecovery, PartReading, Slave, Word};
use hil_mock::{Chance, DeadLevel, SimClock, SimDelay, Window};

#[test]
fn two_parts_start_and_read_the_source_within_one_lsb() {
    let clock = SimClock::new();
    let mut delay = SimDelay::new(&clock);
    let mocks = [mock_part(&clock, 0), mock_part(&clock, 1)];
    let mut parts = [driver(&mocks[0]), driver(&mocks[1])];
    let [first, second] = &mut parts;
    first.start(&mut delay).unwrap();
    second.start_powered(&mut delay).unwrap();
    for _ in 0..400 {
        clock.advance_ms(PERIOD_MS);
        for (part, mock) in parts.iter_mut().zip(&mocks) {
            let reading = part.sample();
            assert_eq!(reading.gyro_error, None);
            assert_eq!(reading.accel_error, None);
            assert_matches_truth(&reading, &mock.borrow_mut().truth());
        }
    }
    for mock in &mocks {
        let stats = mock.borrow().stats();
        // Every word the driver sent had the right parity (and length).
        assert_eq!(stats.gyro_mosi_errors, 0);
        assert_eq!(stats.accel_mosi_errors, 0);
        assert!(stats.gyro_frames > 800 && stats.accel_frames > 1200);
    }
}

#[test]
fn miso_parity_is_checked_on_every_word() {
    // Gyro word 1 or word 2 (the mock picks at random), and accel dPAR.
    let mut seen = std::collections::BTreeSet::new();
    for seed in 1..20 {
        with_seeded_part(seed, |clock, mock, part| {
            mock.borrow_mut().faults.gyro.miso_parity = Chance::next(1);
            mock.borrow_mut().faults.accel.miso_parity = Chance::next(1);
            let r = part.sample();
            let g = r.gyro_error.unwrap();
            assert!(matches!(g, Error::Parity(Slave::Gyro, _)), "{g:?}");
            seen.insert(format!("{g:?}"));
            assert_eq!(r.accel_error, Some(Error::Parity(Slave::Accel, Word::Data)));
            recovers(clock, mock, part, &r);
        });
    }
    assert_eq!(seen.len(), 2, "both gyro words: {seen:?}");
}

#[test]
fn mosi_parity_errors_are_seen_by_the_part_and_reported() {
    with_started_part(|clock, mock, part| {
        mock.borrow_mut().faults.gyro.mosi_bit_flip = Chance::next(1);
        mock.borrow_mut().faults.accel.mosi_bit_flip = Chance::next(1);
        let r = part.sample();
        // The gyro answers a rejected frame with an even-parity zero word.
        assert_eq!(r.gyro_error, Some(Error::Parity(Slave::Gyro, Word::Data)));
        // The accelerometer flags FRME in the next frame's status.
        assert_eq!(r.accel_error, Some(Error::FrameError));
        let stats = mock.borrow().stats();
        assert_eq!((stats.gyro_mosi_errors, stats.accel_mosi_errors), (1, 1));
        recovers(clock, mock, part, &r);
    });
}

#[test]
fn noisy_lines_never_let_a_wrong_reading_through() {
    with_started_part(|clock, mock, part| {
        mock.borrow_mut().faults.gyro.miso_bit_flip = Chance::per_million(200_000);
        mock.borrow_mut().faults.accel.miso_bit_flip = Chance::per_million(200_000);
        let (mut good, mut bad) = (0, 0);
        for _ in 0..500 {
            clock.advance_ms(PERIOD_MS);
            let r = part.sample();
            let truth = mock.borrow_mut().truth();
            if r.gyro_error.is_none() && r.accel_error.is_none() {
                assert_matches_truth(&r, &truth);
                good += 1;
            } else {
                bad += 1;
                if r.needs_recovery() {
                    // Noise may hit the recovery's own frames too: any
                    // outcome but a panic is fine; the next sample retries.
                    let _ = part.recover(&mut SimDelay::new(clock), &r);
                }
            }
        }
        assert!(good > 100 && bad > 100, "good {good} bad {bad}");
        let mut faults = mock.borrow().faults;
        faults.gyro.miso_bit_flip = Chance::NEVER;
        faults.accel.miso_bit_flip = Chance::NEVER;
        mock.borrow_mut().faults = faults;
        recovers(clock, mock, part, &PartReading::default());
    });
}

#[test]
fn stuck_bits_are_caught() {
    with_started_part(|clock, mock, part| {
        // Gyro data word bit 2 (the rate's LSB) stuck high: parity catches
        // every sample where it should have been 0; the others are right.
        mock.borrow_mut().faults.gyro.miso_stuck_high = 1 << 2;
        let mut parity = 0;
        for _ in 0..200 {
            clock.advance_ms(PERIOD_MS);
            let r = part.sample();
            match r.gyro_error {
                None => assert_matches_truth(&r, &mock.borrow_mut().truth()),
                Some(e) => {
                    assert_eq!(e, Error::Parity(Slave::Gyro, Word::Data));
                    parity += 1;
                }
            }
        }
        assert!(parity > 20, "{parity}");
        mock.borrow_mut().faults.gyro.miso_stuck_high = 0;
        // Accelerometer status bit 2 (fixed 0) stuck high.
        mock.borrow_mut().faults.accel.miso_stuck_high = 1 << 26;
        clock.advance_ms(PERIOD_MS);
        assert_eq!(part.sample().accel_error, Some(Error::BadStatus));
        mock.borrow_mut().faults.accel.miso_stuck_high = 0;
        recovers(clock, mock, part, &PartReading::default());
    });
}

#[test]
fn dead_chip_selects() {
    for level in [DeadLevel::Low, DeadLevel::High] {
        with_started_part(|clock, mock, part| {
            mock.borrow_mut().faults.gyro.dead = Some(level);
            mock.borrow_mut().faults.accel.dead = Some(level);
            clock.advance_ms(PERIOD_MS);
            let r = part.sample();
            assert_eq!(r.gyro_error, Some(Error::NoResponse(Slave::Gyro)));
            assert_eq!(r.accel_error, Some(Error::NoResponse(Slave::Accel)));
            mock.borrow_mut().faults.gyro.dead = None;
            mock.borrow_mut().faults.accel.dead = None;
            recovers(clock, mock, part, &r);
        });
    }
}

#[test]
fn s_ok_drop_is_a_transient() {
    with_started_part(|clock, mock, part| {
        let now = clock_ns(clock);
        mock.borrow_mut().faults.s_ok_drop = Some(Window {
            start_ns: now,
            end_ns: now + 30_000_000,
        });
        let r = part.sample();
        assert_eq!(r.gyro_error, Some(Error::NotReady));
        let report = part.recover(&mut SimDelay::new(clock), &r).unwrap();
        assert_eq!(report.gyro, Some(GyroRecovery::Transient));
        assert_eq!(mock.borrow().stats().soft_resets, 0);
        recovers(clock, mock, part, &PartReading::default());
    });
}

#[test]
fn loop_failure_leads_to_a_soft_reset() {
    with_started_part(|clock, mock, part| {
        mock.borrow_mut().faults.loop_failure_at_ns = Some(clock_ns(clock));
        let r = part.sample();
        assert_eq!(r.gyro_error, Some(Error::NotReady));
        let report = part.recover(&mut SimDelay::new(clock), &r).unwrap();
        assert_eq!(report.gyro, Some(GyroRecovery::SoftReset));
        assert_eq!(mock.borrow().stats().soft_resets, 1);
        recovers(clock, mock, part, &PartReading::default());
    });
}

#[test]
fn saturation_and_self_test() {
    with_started_part(|clock, mock, part| {
        mock.borrow_mut().faults.gyro_saturated = true;
        mock.borrow_mut().faults.accel_saturated = true;
        let r = part.sample();
        assert_eq!(r.gyro_error, Some(Error::Saturated(Slave::Gyro)));
        assert_eq!(r.gyro.rate, 8191, "the clipped count is kept");
        assert_eq!(r.accel_error, Some(Error::Saturated(Slave::Accel)));
        assert_eq!(mock.borrow().stats().sat_acknowledged, 2, "start + SAT");
        mock.borrow_mut().faults.gyro_saturated = false;
        mock.borrow_mut().faults.accel_saturated = false;
        recovers(clock, mock, part, &r);
        mock.borrow_mut().faults.accel_self_test_failed = true;
        assert_eq!(part.sample().accel_error, Some(Error::SelfTest));
        mock.borrow_mut().faults.accel_self_test_failed = false;
        recovers(clock, mock, part, &PartReading::default());
    });
}

#[test]
fn a_part_that_resets_mid_run_is_restarted() {
    with_started_part(|clock, mock, part| {
        mock.borrow_mut().faults.reset_at_ns = Some(clock_ns(clock));
        let r = part.sample();
        assert_eq!(r.gyro_error, Some(Error::NotReady));
        assert_eq!(r.accel_error, Some(Error::PowerOnReset));
        let report = part.recover(&mut SimDelay::new(clock), &r).unwrap();
        assert_eq!(report.gyro, Some(GyroRecovery::SoftReset));
        assert!(report.accel_restarted);
        recovers(clock, mock, part, &PartReading::default());
    });
}

#[test]
fn start_up_fails_cleanly_without_the_wait() {
    let clock = SimClock::new();
    let mock = mock_part(&clock, 0);
    let mut part = driver(&mock);
    assert_eq!(
        part.start_powered(&mut SimDelay::new(&clock)),
        Err(Error::NotReady)
    );
}

#[test]
fn ram_footprint_fits_the_probe() {
    use core::mem::size_of;
    use mwd_core::protocol::{Decoder, FrameEncoder, MAX_WIRE_LEN};
    let driver = size_of::<Driver>();
    let mock = size_of::<MockPart>();
    let reading = size_of::<PartReading>();
    let decoder = size_of::<Decoder>();
    println!(
        "driver part (mock SPI handles) {driver} B, mock part {mock} B, reading {reading} B, \
         decoder {decoder} B, encoder {} B, tx buffer {MAX_WIRE_LEN} B",
        size_of::<FrameEncoder>()
    );
    // Two parts, their mocks, a decoder and a transmit buffer: under
    // 1.5 KiB of the probe's 32 KiB (the decoder grew when it learned to
    // tell restarts and long outages apart by the raw frames' counters;
    // the probe's whole RAM is measured by scripts/probe-budgets.sh).
    assert!(2 * (driver + mock + reading) + decoder + MAX_WIRE_LEN < 1536);
}
