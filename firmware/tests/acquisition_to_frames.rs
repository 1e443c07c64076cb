//! The whole chain the probe will run (the board binaries bind it for real): two
//! mocked parts fed by one body-frame motion, the driver's 20 Hz samples,
//! raw-sample frames on the "UART", the host's decoder, and the counts
//! turned back into body-frame SI through `sensor_units`. Checks that the
//! mock, the driver and the host agree on units and mounting.

use core::cell::RefCell;

use firmware::app::raw_part;
use firmware::scc1300::Part;
use hil_mock::{
    AccelSpi, BodySource, Chance, Generator, GyroSpi, MountedSource, Scc1300, SimClock, SimDelay,
    TimeSource, SAMPLE_PERIOD_NS,
};
use mwd_core::protocol::frame::raw_flags;
use mwd_core::protocol::{Decoder, FrameEncoder, Payload, RawSample, MAX_WIRE_LEN};
use mwd_core::sensor_units::{accel_count_to_m_s2, gyro_count_to_rad_s, BodyAxis, PART_MOUNTINGS};

#[test]
fn driver_samples_travel_as_frames_and_come_back_in_body_axes() {
    let motion = Generator {
        wobble_rad_s: 0.3,
        roll_rate_rad_s: 0.2,
        ..Generator::default()
    };
    let clock = SimClock::new();
    let mocks = [0, 1].map(|i| {
        let source = MountedSource {
            body: motion,
            mounting: PART_MOUNTINGS[i],
        };
        RefCell::new(Scc1300::new(&clock, source, 7 + i as u32))
    });
    let mut parts = [0, 1].map(|i| Part::new(GyroSpi::new(&mocks[i]), AccelSpi::new(&mocks[i])));
    let mut delay = SimDelay::new(&clock);
    let [first, second] = &mut parts;
    first.start(&mut delay).unwrap();
    second.start_powered(&mut delay).unwrap();

    let mut encoder = FrameEncoder::new();
    let mut uart = Vec::new();
    let mut truths = Vec::new();
    for n in 0..200u32 {
        clock.advance_ns(SAMPLE_PERIOD_NS);
        if n == 100 {
            // One corrupted gyro answer on part 2: flagged, not hidden.
            mocks[1].borrow_mut().faults.gyro.miso_parity = Chance::next(1);
        }
        let readings = parts.each_mut().map(|p| p.sample());
        let sample = RawSample {
            time_us: clock.now_ns() / 1000,
            sample_counter: n,
            parts: readings.map(|r| raw_part(&r)),
        };
        let mut buf = [0u8; MAX_WIRE_LEN];
        let len = encoder.encode(&Payload::Raw(sample), &mut buf).unwrap();
        uart.extend_from_slice(&buf[..len]);
        let mut body = motion;
        truths.push(body.body_sample(clock.now_ns()));
    }

    let mut decoder = Decoder::new();
    let mut received = Vec::new();
    decoder.feed(&uart, |f| received.push(f));
    assert_eq!(decoder.stats().frames, [200, 0, 0, 0]);
    assert_eq!(decoder.stats().lost, 0);

    let lsb_rate = gyro_count_to_rad_s(1);
    let lsb_acc = accel_count_to_m_s2(1);
    for (frame, truth) in received.iter().zip(&truths) {
        let Payload::Raw(raw) = frame.payload else {
            panic!("raw frames only")
        };
        let [p1, p2] = raw.parts;
        // Part 1's gyro is body +x, part 2's body +z (the project mounting).
        assert_eq!(PART_MOUNTINGS[1].gyro_axis().axis, BodyAxis::Z);
        assert!((gyro_count_to_rad_s(p1.gyro_rate) - truth.rate_rad_s[0]).abs() <= lsb_rate);
        if raw.sample_counter == 100 {
            assert_eq!(p2.flags & raw_flags::GYRO_VALID, 0);
            assert_ne!(p2.flags & raw_flags::PARITY_ERROR, 0);
        } else {
            assert_ne!(p2.flags & raw_flags::GYRO_VALID, 0);
            assert!((gyro_count_to_rad_s(p2.gyro_rate) - truth.rate_rad_s[2]).abs() <= lsb_rate);
        }
        // Both accelerometers, back in body axes, see the same force.
        for (part, mounting) in [p1, p2].iter().zip(PART_MOUNTINGS) {
            assert_ne!(part.flags & raw_flags::ACCEL_VALID, 0);
            let body = mounting.sensor_to_body(part.accel.map(accel_count_to_m_s2));
            for (b, t) in body.iter().zip(truth.specific_force_m_s2) {
                assert!((b - t).abs() <= lsb_acc, "{b} vs {t}");
            }
        }
    }
}
