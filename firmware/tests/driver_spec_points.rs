//! The driver against hil-mock on the points of `docs/scc1300.md`
//! where the two could share a wrong assumption: what the accelerometer's
//! dPAR covers (both readings), the gyro loop failure of TN92 step 4, the
//! gyro's specified range, SAT acknowledgement through INT_STATUS in every
//! case, and the accelerometer's 10 ms settling after CTRL = 0.

mod common;

use core::cell::{Cell, RefCell};

use common::*;
use embedded_hal::spi::{ErrorType, Operation, SpiDevice};
use firmware::app::{fault_code, raw_part, AcquisitionCycle, FrameQueue};
use firmware::scc1300::datasheet::{DparScope, ACCEL_DPAR_SCOPE, ACCEL_SETTLE_MS};
use firmware::scc1300::{Accel, Error, Gyro, GyroRecovery, Part, PartReading, Slave, Word};
use hil_mock::{
    AccelSpi, Chance, Constant, Faults, GyroSpi, MockBusError, PhysicalSample, Scc1300, SimClock,
    SimDelay, TimeSource, Window, ACCEL_SETTLE_NS, DEFAULT_DPAR_SCOPE, START_UP_NS,
};
use mwd_core::protocol::frame::raw_flags;
use mwd_core::protocol::{Decoder, EventKind, Payload};
use mwd_core::sensor_units::{GYRO_LSB_PER_DEG_S, GYRO_RANGE_DEG_S};

// ---- dPAR --------------------------------------------------------------

#[test]
fn driver_and_mock_default_to_the_same_dpar_reading() {
    assert_eq!(mock_dpar_scope(ACCEL_DPAR_SCOPE), DEFAULT_DPAR_SCOPE);
}

#[test]
fn both_dpar_readings_work_when_driver_and_mock_agree() {
    for scope in DPAR_SCOPES {
        with_dpar_scope(scope, 3, |clock, mock, part| {
            for _ in 0..100 {
                clock.advance_ms(PERIOD_MS);
                let r = part.sample();
                assert_eq!((r.gyro_error, r.accel_error), (None, None), "{scope:?}");
                assert_matches_truth(&r, &mock.borrow_mut().truth());
            }
            // A flipped dPAR is caught in either reading.
            mock.borrow_mut().faults.accel.miso_parity = Chance::next(1);
            clock.advance_ms(PERIOD_MS);
            let r = part.sample();
            assert_eq!(
                r.accel_error,
                Some(Error::Parity(Slave::Accel, Word::Data)),
                "{scope:?}"
            );
            recovers(clock, mock, part, &r);
        });
    }
}

#[test]
fn noisy_lines_never_let_a_wrong_reading_through_in_either_dpar_reading() {
    for scope in DPAR_SCOPES {
        with_dpar_scope(scope, 5, |clock, mock, part| {
            mock.borrow_mut().faults.accel.miso_bit_flip = Chance::per_million(300_000);
            let (mut good, mut bad) = (0, 0);
            for _ in 0..400 {
                clock.advance_ms(PERIOD_MS);
                let r = part.sample();
                if r.accel_error.is_none() {
                    assert_matches_truth(&r, &mock.borrow_mut().truth());
                    good += 1;
                } else {
                    bad += 1;
                    if r.needs_recovery() {
                        let _ = part.recover(&mut SimDelay::new(clock), &r);
                    }
                }
            }
            assert!(good > 50 && bad > 50, "{scope:?}: good {good} bad {bad}");
        });
    }
}

#[test]
fn a_driver_on_the_other_dpar_reading_than_the_part_sees_parity_errors() {
    // The switch matters: each side really honours it.
    for (driver, part_scope) in [
        (DparScope::PreviousFrame, hil_mock::DparScope::SameFrame),
        (DparScope::SameFrame, hil_mock::DparScope::PreviousFrame),
    ] {
        let clock = SimClock::new();
        let mock = seeded_mock_part(&clock, 0, 9);
        mock.borrow_mut().dpar_scope = part_scope;
        let mut part = Part {
            gyro: Gyro::new(GyroSpi::new(&mock)),
            accel: Accel::with_dpar_scope(AccelSpi::new(&mock), driver),
        };
        let _ = part.start(&mut SimDelay::new(&clock));
        let mut parity = 0;
        for _ in 0..100 {
            clock.advance_ms(PERIOD_MS);
            if part.sample().accel_error == Some(Error::Parity(Slave::Accel, Word::Data)) {
                parity += 1;
            }
        }
        assert!(parity > 20, "{driver:?} vs {part_scope:?}: {parity}");
    }
}

// ---- gyro loop failure -------------------------------------------------

#[test]
fn loop_failure_is_reported_with_reset_seen_after_the_soft_reset() {
    with_started_part(|clock, mock, part| {
        mock.borrow_mut().faults.loop_failure_at_ns = Some(clock_ns(clock));
        let r = part.sample();
        assert_eq!(r.gyro_error, Some(Error::NotReady));
        let report = part.recover(&mut SimDelay::new(clock), &r).unwrap();
        assert_eq!(report.gyro, Some(GyroRecovery::SoftReset));
        assert_eq!(mock.borrow().stats().soft_resets, 1);

        clock.advance_ms(PERIOD_MS);
        let r = part.sample();
        assert_eq!(r.gyro_error, Some(Error::LoopFailure));
        assert_ne!(raw_part(&r).flags & raw_flags::RESET_SEEN, 0);
        assert_eq!(raw_part(&r).flags & raw_flags::GYRO_VALID, 0);
        assert_eq!(r.rate_rad_s(), None);
        assert!(!r.needs_recovery(), "the recovery has been run");
        assert_eq!(r.accel_error, None);

        // Reported once: the next sample is clean.
        clock.advance_ms(PERIOD_MS);
        let r = part.sample();
        assert_eq!((r.gyro_error, r.accel_error), (None, None));
        assert_eq!(raw_part(&r).flags & raw_flags::RESET_SEEN, 0);
        assert_matches_truth(&r, &mock.borrow_mut().truth());
    });
}

#[test]
fn loop_failure_reaches_the_raw_frame_and_an_event() {
    with_started_part(|clock, mock, part| {
        let mut cycle = AcquisitionCycle::new();
        let mut queue = FrameQueue::<1024>::new();
        mock.borrow_mut().faults.loop_failure_at_ns = Some(clock_ns(clock));
        let r = part.sample();
        let report = cycle.run(Some([r, PartReading::default()]), &mut queue);
        assert!(report.recovery_needed[0]);
        part.recover(&mut SimDelay::new(clock), &r).unwrap();
        clock.advance_ms(PERIOD_MS);
        let r = part.sample();
        let report = cycle.run(Some([r, PartReading::default()]), &mut queue);
        assert!(!report.recovery_needed[0]);
        let mut decoder = Decoder::new();
        let mut frames = Vec::new();
        while let Some(b) = queue.pop() {
            decoder.feed(&[b], |f| frames.push(f));
        }
        let raw_flags_seen: Vec<u16> = frames
            .iter()
            .filter_map(|f| match f.payload {
                Payload::Raw(raw) => Some(raw.parts[0].flags),
                _ => None,
            })
            .collect();
        assert_eq!(raw_flags_seen.len(), 2);
        assert_eq!(raw_flags_seen[0] & raw_flags::RESET_SEEN, 0);
        assert_ne!(raw_flags_seen[1] & raw_flags::RESET_SEEN, 0);
        let codes: Vec<u16> = frames
            .iter()
            .filter_map(|f| match f.payload {
                Payload::Event(e) if e.kind == EventKind::SensorFault && e.part == 0 => {
                    Some(e.code)
                }
                _ => None,
            })
            .collect();
        assert_eq!(
            codes,
            [
                fault_code(&Error::NotReady),
                fault_code(&Error::LoopFailure)
            ]
        );
    });
}

#[test]
fn a_transient_s_ok_drop_is_not_a_loop_failure() {
    with_started_part(|clock, mock, part| {
        let now = clock_ns(clock);
        mock.borrow_mut().faults.s_ok_drop = Some(Window {
            start_ns: now,
            end_ns: now + 30_000_000,
        });
        let r = part.sample();
        let report = part.recover(&mut SimDelay::new(clock), &r).unwrap();
        assert_eq!(report.gyro, Some(GyroRecovery::Transient));
        clock.advance_ms(PERIOD_MS);
        let r = part.sample();
        assert_eq!(r.gyro_error, None);
        assert_eq!(raw_part(&r).flags & raw_flags::RESET_SEEN, 0);
    });
}

#[test]
fn a_power_cycled_part_is_not_reported_as_a_gyro_loop_failure() {
    with_started_part(|clock, mock, part| {
        mock.borrow_mut().faults.reset_at_ns = Some(clock_ns(clock));
        let r = part.sample();
        assert_eq!(r.gyro_error, Some(Error::NotReady));
        assert_eq!(r.accel_error, Some(Error::PowerOnReset));
        assert_ne!(raw_part(&r).flags & raw_flags::RESET_SEEN, 0, "PORST tells");
        let report = part.recover(&mut SimDelay::new(clock), &r).unwrap();
        // The gyro was still in its start-up (LOOPF_OK clear): TN92 step 4
        // soft-resets it, but the cause was the power cycle.
        assert_eq!(report.gyro, Some(GyroRecovery::SoftReset));
        clock.advance_ms(PERIOD_MS);
        let r = part.sample();
        assert_eq!((r.gyro_error, r.accel_error), (None, None));
        assert_eq!(raw_part(&r).flags & raw_flags::RESET_SEEN, 0);
    });
}

// ---- gyro range --------------------------------------------------------

type ConstPart<'c> = Scc1300<&'c SimClock, Constant>;

fn started_constant_part<'p, 'c>(
    clock: &'c SimClock,
    mock: &'p RefCell<ConstPart<'c>>,
) -> Part<GyroSpi<'p, &'c SimClock, Constant>, AccelSpi<'p, &'c SimClock, Constant>> {
    let mut part = Part::new(GyroSpi::new(mock), AccelSpi::new(mock));
    part.start(&mut SimDelay::new(clock)).unwrap();
    part
}

#[test]
fn gyro_rates_beyond_the_specified_300_deg_s_are_flagged_saturated() {
    let clock = SimClock::new();
    let mock = RefCell::new(Scc1300::new(&clock, Constant::default(), 4));
    let mut part = started_constant_part(&clock, &mock);
    let range_counts = (GYRO_RANGE_DEG_S * GYRO_LSB_PER_DEG_S) as i16;
    for (deg_s, count, flagged) in [
        (250.0f32, 4500, false),
        (300.0, range_counts, false),
        (-300.0, -range_counts, false),
        (300.1, 5402, true),
        (-350.0, -6300, true),
        (440.0, 7920, true),
    ] {
        mock.borrow_mut().source_mut().0.rate_rad_s = deg_s.to_radians();
        clock.advance_ms(PERIOD_MS);
        let r = part.sample();
        assert_eq!(r.gyro.rate, count, "{deg_s} deg/s: count kept");
        if flagged {
            assert_eq!(r.gyro_error, Some(Error::Saturated(Slave::Gyro)), "{deg_s}");
            assert_ne!(raw_part(&r).flags & raw_flags::GYRO_SATURATED, 0);
            assert_eq!(raw_part(&r).flags & raw_flags::GYRO_VALID, 0);
            assert_eq!(r.rate_rad_s(), None);
        } else {
            assert_eq!(r.gyro_error, None, "{deg_s}");
            assert_eq!(raw_part(&r).flags & raw_flags::GYRO_SATURATED, 0);
        }
    }
}

// ---- SAT acknowledgement -----------------------------------------------

/// An accelerometer chip select that lets a test change the mock's faults
/// just before a chosen frame: `plan(index, faults)` runs before every
/// frame, `index` counting from when the test sets `frames` to 0.
struct Hooked<'p, 'c> {
    inner: AccelSpi<'p, &'c SimClock, Constant>,
    mock: &'p RefCell<ConstPart<'c>>,
    frames: &'p Cell<u32>,
    plan: fn(u32, &mut Faults),
}

impl ErrorType for Hooked<'_, '_> {
    type Error = MockBusError;
}

impl SpiDevice for Hooked<'_, '_> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), MockBusError> {
        let index = self.frames.get();
        self.frames.set(index.saturating_add(1));
        (self.plan)(index, &mut self.mock.borrow_mut().faults);
        self.inner.transaction(operations)
    }
}

/// The frames of one sample: 0 axes, 1 temperature, 2 STATUS, then the
/// INT_STATUS read that acknowledges SAT.
const AXES: u32 = 0;
const TEMP: u32 = 1;
const STATUS: u32 = 2;
const IDLE: u32 = u32::MAX / 2;

/// Runs one sample with `plan`; returns the reading and how many
/// INT_STATUS reads the mock saw during it.
fn sample_with(plan: fn(u32, &mut Faults)) -> (PartReading, u32, PartReading) {
    let clock = SimClock::new();
    let mock = RefCell::new(Scc1300::new(&clock, Constant::default(), 8));
    let frames = Cell::new(IDLE);
    let accel = Hooked {
        inner: AccelSpi::new(&mock),
        mock: &mock,
        frames: &frames,
        plan,
    };
    let mut part = Part::new(GyroSpi::new(&mock), accel);
    part.start(&mut SimDelay::new(&clock)).unwrap();
    clock.advance_ms(PERIOD_MS);
    let acks_before = mock.borrow().stats().sat_acknowledged;
    frames.set(0);
    let r = part.sample();
    let acks = mock.borrow().stats().sat_acknowledged - acks_before;
    frames.set(IDLE);
    mock.borrow_mut().faults = Faults::default();
    // Acknowledged means the latch is clear: the next sample is clean.
    clock.advance_ms(PERIOD_MS);
    let _ = part.sample(); // may still see FRME/dPAR about the frame before
    clock.advance_ms(PERIOD_MS);
    let next = part.sample();
    (r, acks, next)
}

fn check_acknowledged(what: &str, plan: fn(u32, &mut Faults), error: Error) {
    let (r, acks, next) = sample_with(plan);
    assert_eq!(r.accel_error, Some(error), "{what}");
    assert_ne!(
        raw_part(&r).flags & raw_flags::ACCEL_SATURATED,
        0,
        "{what}: SAT flagged"
    );
    assert_eq!(raw_part(&r).flags & raw_flags::ACCEL_VALID, 0, "{what}");
    assert_eq!(acks, 1, "{what}: INT_STATUS read once");
    assert_eq!(next.accel_error, None, "{what}: latch cleared");
}

#[test]
fn sat_first_shown_in_the_temperature_frame_is_acknowledged() {
    check_acknowledged(
        "temperature frame",
        |i, f| f.accel_saturated = i == TEMP,
        Error::Saturated(Slave::Accel),
    );
}

#[test]
fn sat_first_shown_in_the_status_frame_is_acknowledged() {
    check_acknowledged(
        "STATUS frame",
        |i, f| f.accel_saturated = i == STATUS,
        Error::Saturated(Slave::Accel),
    );
}

#[test]
fn sat_with_st_is_acknowledged() {
    check_acknowledged(
        "SAT + ST",
        |i, f| {
            f.accel_saturated = i == AXES;
            f.accel_self_test_failed = i <= STATUS;
        },
        Error::SelfTest,
    );
}

#[test]
fn sat_with_frme_is_acknowledged() {
    // The axes command is corrupted on its way in (the part flags FRME in
    // the next frame) and SAT rises at the temperature frame.
    check_acknowledged(
        "SAT + FRME",
        |i, f| {
            if i == AXES {
                f.accel.mosi_bit_flip = Chance::next(1);
            }
            f.accel_saturated = i == TEMP;
        },
        Error::FrameError,
    );
}

#[test]
fn sat_with_a_bad_dpar_is_acknowledged() {
    check_acknowledged(
        "SAT + dPAR",
        |i, f| {
            if i == TEMP {
                f.accel.miso_parity = Chance::next(1);
            }
            f.accel_saturated = i == TEMP;
        },
        Error::Parity(Slave::Accel, Word::Data),
    );
}

#[test]
fn sat_in_the_axes_frame_is_acknowledged() {
    check_acknowledged(
        "axes frame",
        |i, f| f.accel_saturated = i == AXES,
        Error::Saturated(Slave::Accel),
    );
}

// ---- accelerometer settling after CTRL = 0 -----------------------------

/// A delay that does not wait: the driver's waits cost no part time.
struct NoWait;

impl embedded_hal::delay::DelayNs for NoWait {
    fn delay_ns(&mut self, _ns: u32) {}
}

fn truth_counts(mock: &RefCell<ConstPart>) -> [i16; 3] {
    mock.borrow_mut()
        .truth()
        .accel_m_s2
        .map(mwd_core::sensor_units::m_s2_to_accel_count)
}

#[test]
fn the_accelerometer_start_waits_out_the_10_ms_settling() {
    assert_eq!(u64::from(ACCEL_SETTLE_MS) * 1_000_000, ACCEL_SETTLE_NS);
    let g = mwd_core::sensor_units::STANDARD_GRAVITY_M_S2;
    let source = Constant(PhysicalSample {
        accel_m_s2: [0.3 * g, -0.2 * g, 0.9 * g],
        ..Default::default()
    });
    let clock = SimClock::new();
    let mock = RefCell::new(Scc1300::new(&clock, source, 2));
    clock.advance_ns(START_UP_NS);
    // Start and read at once, the part's time moved only by the driver's
    // own wait: the first reading is already settled.
    let mut accel = Accel::new(AccelSpi::new(&mock));
    let before = clock.now_ns();
    accel.start(&mut SimDelay::new(&clock)).unwrap();
    assert!(clock.now_ns() - before >= ACCEL_SETTLE_NS);
    assert_eq!(accel.read_counts().map(|c| c.xyz), Ok(truth_counts(&mock)));
    assert_eq!(mock.borrow().stats().accel_output_reads_while_settling, 0);

    // Without the wait the same sequence reads unsettled outputs that no
    // status bit flags: the wait is what makes the first reading right.
    let clock = SimClock::new();
    let mock = RefCell::new(Scc1300::new(&clock, source, 2));
    clock.advance_ns(START_UP_NS);
    let mut accel = Accel::new(AccelSpi::new(&mock));
    accel.start(&mut NoWait).unwrap();
    let early = accel.read_counts().map(|c| c.xyz);
    assert_ne!(early, Ok(truth_counts(&mock)));
    // The axes frame and the temperature frame both came too early.
    assert_eq!(mock.borrow().stats().accel_output_reads_while_settling, 2);
}

#[test]
fn the_restart_after_a_power_on_reset_waits_out_the_settling() {
    with_started_part(|clock, mock, part| {
        mock.borrow_mut().faults.reset_at_ns = Some(clock_ns(clock));
        let r = part.sample();
        assert_eq!(r.accel_error, Some(Error::PowerOnReset));
        part.recover(&mut SimDelay::new(clock), &r).unwrap();
        // Sample straight after the recovery, no extra time: the
        // accelerometer's restart has already waited out its settling.
        let r = part.sample();
        assert_eq!(r.accel_error, None);
        let truth = mock.borrow_mut().truth().accel_m_s2;
        let lsb = mwd_core::sensor_units::accel_count_to_m_s2(1);
        for (a, t) in r.accel_m_s2().unwrap_or_default().iter().zip(truth) {
            assert!((a - t).abs() <= lsb, "{a} vs {t}");
        }
        assert_eq!(mock.borrow().stats().accel_output_reads_while_settling, 0);
    });
}
