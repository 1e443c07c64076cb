//! Random mixes of injected faults against the driver: no panic, no wrong
//! reading let through, and recovery once the faults stop.

mod common;

use common::*;
use firmware::scc1300::PartReading;
use hil_mock::{Chance, DeadLevel, SimDelay, Window};

/// One line fault per link at a time: parity can only promise to catch a
/// single flipped bit per word, and two mechanisms together can flip two.
fn random_link() -> impl proptest::strategy::Strategy<Value = hil_mock::LinkFaults> {
    use proptest::prelude::*;
    (0u8..7, 0u32..300_000, 0u32..32).prop_map(|(which, p, bit)| {
        let mut link = hil_mock::LinkFaults::default();
        match which {
            0 => link.miso_parity = Chance::per_million(p),
            1 => link.mosi_bit_flip = Chance::per_million(p),
            2 => link.miso_bit_flip = Chance::per_million(p),
            3 => link.miso_stuck_high = 1 << bit,
            4 => link.miso_stuck_low = 1 << bit,
            5 => {
                link.dead = Some(if p % 2 == 0 {
                    DeadLevel::Low
                } else {
                    DeadLevel::High
                })
            }
            _ => {}
        }
        link
    })
}

/// A random mix of link faults and part faults.
fn random_faults() -> impl proptest::strategy::Strategy<Value = hil_mock::Faults> {
    use proptest::prelude::*;
    (
        random_link(),
        random_link(),
        any::<[bool; 6]>(),
        0u64..2_000_000_000,
    )
        .prop_map(|(gyro, accel, on, at)| hil_mock::Faults {
            gyro,
            accel,
            s_ok_drop: on[0].then_some(Window {
                start_ns: at,
                end_ns: at + 100_000_000,
            }),
            loop_failure_at_ns: on[1].then_some(at),
            reset_at_ns: on[2].then_some(at),
            gyro_saturated: on[3] && on[4],
            accel_saturated: on[4] && on[5],
            accel_self_test_failed: on[5] && on[0],
            // A part out of its temperature range (the count clipped).
            temperature: (on[1] && on[2]).then_some(hil_mock::TemperatureExcursion {
                window: Window {
                    start_ns: at,
                    end_ns: at + 500_000_000,
                },
                degc: if on[3] { 200 } else { -60 },
            }),
        })
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(128))]

    /// Any mix of faults: no panic, every reading that claims to be good
    /// is within one LSB of the truth, and once the faults stop the part
    /// comes back by itself through `recover`; under either reading of the
    /// accelerometer's dPAR (driver and mock set alike).
    #[test]
    fn any_fault_mix_is_survived(
        faults in random_faults(),
        seed in 1u32..1000,
        scope in proptest::sample::select(DPAR_SCOPES.to_vec()),
    ) {
        with_dpar_scope(scope, seed, |clock, mock, part| {
            mock.borrow_mut().faults = faults;
            for _ in 0..60 {
                clock.advance_ms(PERIOD_MS);
                let r = part.sample();
                let truth = mock.borrow_mut().truth();
                if r.gyro_error.is_none() && r.accel_error.is_none() {
                    assert_matches_truth(&r, &truth);
                }
                if r.needs_recovery() {
                    let _ = part.recover(&mut SimDelay::new(clock), &r);
                }
            }
            mock.borrow_mut().faults = hil_mock::Faults::default();
            // Recovery may need a few rounds (a reset during a recovery).
            let mut last = PartReading::default();
            for _ in 0..5 {
                if last.needs_recovery()
                    || last.gyro_error.is_some()
                    || last.accel_error.is_some()
                {
                    let _ = part.recover(&mut SimDelay::new(clock), &last);
                }
                clock.advance_ms(PERIOD_MS);
                last = part.sample();
            }
            assert_eq!((last.gyro_error, last.accel_error), (None, None));
            assert_matches_truth(&last, &mock.borrow_mut().truth());
        });
    }
}
