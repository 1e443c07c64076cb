//! Shared set-up of the driver-against-mock tests: a mocked part fed by
//! the deterministic generator, the driver on its two chip selects, and
//! the checks against the mock's source.
#![allow(dead_code)] // Each test file uses a different subset.

use core::cell::RefCell;

use firmware::scc1300::datasheet::{DparScope, ACCEL_DPAR_SCOPE};
use firmware::scc1300::{Accel, Gyro, Part, PartReading};
use hil_mock::{
    AccelSpi, Generator, GyroSpi, MountedSource, PhysicalSample, Scc1300, SimClock, SimDelay,
};
use mwd_core::sensor_units::{
    accel_count_to_m_s2, gyro_count_to_rad_s, ACCEL_TEMPERATURE, GYRO_TEMPERATURE, PART_MOUNTINGS,
};

pub type MockPart<'c> = Scc1300<&'c SimClock, MountedSource<Generator>>;
pub type Driver<'p, 'c> = Part<
    GyroSpi<'p, &'c SimClock, MountedSource<Generator>>,
    AccelSpi<'p, &'c SimClock, MountedSource<Generator>>,
>;

/// The probe's sample period.
pub const PERIOD_MS: u64 = hil_mock::SAMPLE_PERIOD_NS / 1_000_000;

pub fn mock_part(clock: &SimClock, index: usize) -> RefCell<MockPart<'_>> {
    seeded_mock_part(clock, index, 100 + index as u32)
}

pub fn seeded_mock_part(clock: &SimClock, index: usize, seed: u32) -> RefCell<MockPart<'_>> {
    let source = MountedSource {
        body: Generator {
            // Big enough to exercise the sign and many LSBs.
            wobble_rad_s: 0.5,
            ..Generator::default()
        },
        mounting: PART_MOUNTINGS[index],
    };
    let mut part = Scc1300::new(clock, source, seed);
    // The driver's one dPAR switch decides what the mock models too.
    part.dpar_scope = mock_dpar_scope(ACCEL_DPAR_SCOPE);
    RefCell::new(part)
}

/// The mock's model of the driver's dPAR reading.
pub fn mock_dpar_scope(scope: DparScope) -> hil_mock::DparScope {
    match scope {
        DparScope::PreviousFrame => hil_mock::DparScope::PreviousFrame,
        DparScope::SameFrame => hil_mock::DparScope::SameFrame,
    }
}

/// Both readings of the spec's dPAR.
pub const DPAR_SCOPES: [DparScope; 2] = [DparScope::PreviousFrame, DparScope::SameFrame];

pub fn driver<'p, 'c>(part: &'p RefCell<MockPart<'c>>) -> Driver<'p, 'c> {
    Part::new(GyroSpi::new(part), AccelSpi::new(part))
}

/// [`with_seeded_part`] with driver and mock both set to `scope`.
pub fn with_dpar_scope(
    scope: DparScope,
    seed: u32,
    scenario: impl FnOnce(&SimClock, &RefCell<MockPart>, &mut Driver),
) {
    let clock = SimClock::new();
    let mock = seeded_mock_part(&clock, 0, seed);
    mock.borrow_mut().dpar_scope = mock_dpar_scope(scope);
    let mut part = Part {
        gyro: Gyro::new(GyroSpi::new(&mock)),
        accel: Accel::with_dpar_scope(AccelSpi::new(&mock), scope),
    };
    part.start(&mut SimDelay::new(&clock)).unwrap();
    clock.advance_ms(PERIOD_MS);
    let first = part.sample();
    assert_eq!((first.gyro_error, first.accel_error), (None, None));
    scenario(&clock, &mock, &mut part);
}

/// Checks a good reading against the source, within one LSB.
pub fn assert_matches_truth(reading: &PartReading, truth: &PhysicalSample) {
    let lsb_rate = gyro_count_to_rad_s(1);
    let rate = reading.rate_rad_s().expect("gyro valid");
    assert!(
        (rate - truth.rate_rad_s).abs() <= lsb_rate,
        "rate {rate} vs {}",
        truth.rate_rad_s
    );
    let lsb_acc = accel_count_to_m_s2(1);
    let acc = reading.accel_m_s2().expect("accel valid");
    for (a, t) in acc.iter().zip(truth.accel_m_s2) {
        assert!((a - t).abs() <= lsb_acc, "accel {a} vs {t}");
    }
    let gyro_t = GYRO_TEMPERATURE.count_to_degc(reading.gyro.temp);
    let acc_t = ACCEL_TEMPERATURE.count_to_degc(reading.accel.temp);
    let lsb_t = 1.0 / GYRO_TEMPERATURE.counts_per_degc;
    assert!((gyro_t - truth.temperature_degc).abs() <= lsb_t);
    assert!((acc_t - truth.temperature_degc).abs() <= lsb_t);
}

/// A started part, its mock and the clock, for one fault scenario.
pub fn with_started_part(scenario: impl FnOnce(&SimClock, &RefCell<MockPart>, &mut Driver)) {
    with_seeded_part(1, scenario)
}

pub fn with_seeded_part(
    seed: u32,
    scenario: impl FnOnce(&SimClock, &RefCell<MockPart>, &mut Driver),
) {
    let clock = SimClock::new();
    let mock = seeded_mock_part(&clock, 0, seed);
    let mut part = driver(&mock);
    part.start(&mut SimDelay::new(&clock)).unwrap();
    clock.advance_ms(PERIOD_MS);
    assert_eq!(part.sample().gyro_error, None);
    scenario(&clock, &mock, &mut part);
}

/// After a fault is cleared: recover if asked, then read good data again.
pub fn recovers(clock: &SimClock, mock: &RefCell<MockPart>, part: &mut Driver, last: &PartReading) {
    if last.needs_recovery() {
        part.recover(&mut SimDelay::new(clock), last).unwrap();
    }
    clock.advance_ms(PERIOD_MS);
    // The first sample may still report what the previous one left behind
    // (a dPAR or FRME about the frame before); the second must be clean.
    let _ = part.sample();
    clock.advance_ms(PERIOD_MS);
    let reading = part.sample();
    assert_eq!((reading.gyro_error, reading.accel_error), (None, None));
    assert_matches_truth(&reading, &mock.borrow_mut().truth());
}

pub fn clock_ns(clock: &SimClock) -> u64 {
    use hil_mock::TimeSource;
    clock.now_ns()
}
