//! Tests of the capture's writer, decoding and CSV.

use super::*;
use mwd_core::earth::Position;
use mwd_core::protocol::example;
use mwd_core::protocol::frame::{raw_flags, Payload};
use mwd_core::protocol::Frame;
use mwd_core::sensor_units::GYRO_TEMPERATURE;
use mwd_core::sensor_units::{accel_count_to_m_s2, gyro_count_to_rad_s, STANDARD_GRAVITY};

fn sample(i: u32) -> SiSample {
    let g = STANDARD_GRAVITY;
    SiSample {
        index: i,
        gyro_body_xz_rad_s: [1e-3 * f64::from(i), -0.2],
        accel_body_m_s2: [[0.1, 0.2, g], [0.3, -0.2, g + 0.01]],
        temperature_degc: 30.0,
    }
}

#[test]
fn si_sample_becomes_counts_through_the_mounting() {
    let s = sample(7);
    let raw = raw_sample_from_si(&s);
    assert_eq!(raw.time_us, 350_000);
    assert_eq!(raw.sample_counter, 7);
    let lsb_rate = f64::from(gyro_count_to_rad_s(1));
    let lsb_acc = f64::from(accel_count_to_m_s2(1));
    let [p1, p2] = raw.parts;
    // Part 1 senses body x; part 2 body z.
    assert!((f64::from(gyro_count_to_rad_s(p1.gyro_rate)) - 7e-3).abs() <= lsb_rate / 2.0);
    assert!((f64::from(gyro_count_to_rad_s(p2.gyro_rate)) + 0.2).abs() <= lsb_rate / 2.0);
    // Part 2: X = body z, Y = body y, Z = -body x.
    let expect2 = [s.accel_body_m_s2[1][2], -0.2, -0.3];
    for (c, e) in p2.accel.iter().zip(expect2) {
        assert!((f64::from(accel_count_to_m_s2(*c)) - e).abs() <= lsb_acc / 2.0);
    }
    assert_eq!(p1.accel[2], 650);
    assert_eq!(p1.flags & raw_flags::GYRO_SATURATED, 0);
    assert!((f64::from(GYRO_TEMPERATURE.count_to_degc(p1.gyro_temp)) - 30.0).abs() < 0.02);
}

#[test]
fn a_saturated_gyro_is_flagged_as_the_driver_flags_it_and_samples_are_stamped_n_x_50_ms() {
    let mut s = sample(3);
    // 400 deg/s about body x: beyond the specified +-300 deg/s.
    s.gyro_body_xz_rad_s = [400f64.to_radians(), -0.2];
    let raw = raw_sample_from_si(&s);
    let [p1, p2] = raw.parts;
    // The driver reports Error::Saturated: no GYRO_VALID, the
    // saturation bit, S_OK as read (firmware::app::raw_part).
    assert_eq!(
        p1.flags,
        raw_flags::GYRO_SATURATED | raw_flags::GYRO_S_OK | raw_flags::ACCEL_VALID
    );
    assert_eq!(
        p2.flags,
        raw_flags::GYRO_VALID | raw_flags::GYRO_S_OK | raw_flags::ACCEL_VALID
    );
    assert_eq!(raw.time_us, 150_000);
    // 7 g along body y: both parts' accelerometers flag SAT (6 g range).
    let mut s = sample(3);
    s.accel_body_m_s2 = [[0.0, 7.0 * 9.80665, 0.0]; 2];
    for p in raw_sample_from_si(&s).parts {
        assert_eq!(
            p.flags,
            raw_flags::GYRO_VALID | raw_flags::GYRO_S_OK | raw_flags::ACCEL_SATURATED
        );
    }
    // The simulator's own capture: sample 0 at 0 us, as the probe.
    let samples = crate::sim::SensorSimulator::new(
        crate::sim::Trajectory::paper_static(mwd_core::conventions::Euler::new(0.0, 0.0, 0.0)),
        crate::sim::SensorModel::ideal(),
        mwd_core::timing::SAMPLE_INTERVAL_S,
    )
    .take(3);
    let mut w = CaptureWriter::new(Vec::new());
    write_simulated_probe(&mut w, samples, &ProbeSetup::at(Position::paper_site())).unwrap();
    let cap = decode_bytes(&w.finish().unwrap());
    let stamps: Vec<u64> = cap
        .frames
        .iter()
        .filter_map(|f| match f.payload {
            Payload::Raw(r) => Some(r.time_us),
            _ => None,
        })
        .collect();
    assert_eq!(stamps, [0, 50_000, 100_000]);
}

#[test]
fn written_captures_decode_back() {
    let mut w = CaptureWriter::new(Vec::new());
    w.write(&example::boot_event()).unwrap();
    for i in 0..100 {
        w.write_si_sample(&sample(i)).unwrap();
    }
    w.write(&example::nav_solution()).unwrap();
    let n = w.bytes_written();
    let bytes = w.finish().unwrap();
    assert_eq!(bytes.len() as u64, n);
    assert_eq!(n, 27 + 100 * 51 + 106);
    let cap = decode_reader(&bytes[..]).unwrap();
    assert_eq!(cap.stats.frames, [100, 1, 1, 0]);
    assert_eq!(cap.stats.lost, 0);
    assert_eq!(
        cap.frames[5].payload,
        Payload::Raw(raw_sample_from_si(&sample(4)))
    );
    let text = cap.to_string();
    assert!(
        text.contains("raw sample 100, navigation 1, event 1"),
        "{text}"
    );
    assert!(text.contains("0 frames lost"), "{text}");
}

#[test]
fn the_frame_csv_shows_an_azimuth_only_when_determined_in_0_to_2_pi() {
    use mwd_core::protocol::NavSolution;
    let nav = |azimuth: f32, sigma: f32| Frame {
        seq: 0,
        payload: Payload::Nav(NavSolution {
            attitude: [0.1, 0.2, azimuth],
            attitude_std: [0.01, 0.01, sigma],
            ..NavSolution::default()
        }),
    };
    let mut lost = nav(-1.0, f32::INFINITY);
    if let Payload::Nav(n) = &mut lost.payload {
        n.flags = mwd_core::protocol::frame::nav_flags::HEADING_LOST;
    }
    let station = |flags: u16| Frame {
        seq: 0,
        payload: Payload::Station(mwd_core::protocol::StationSurvey {
            flags,
            angles: [1.5, 2.0, 0.3],
            angles_std: [0.001, 0.01, 0.002],
            ..mwd_core::protocol::StationSurvey::default()
        }),
    };
    use mwd_core::protocol::frame::station_flags;
    let frames = [
        nav(-1.0, f32::INFINITY),
        nav(-1.0, 0.01),
        nav(f32::NAN, f32::NAN),
        lost,
        station(0),
        station(station_flags::AZIMUTH_UNDETERMINED),
        station(station_flags::AZIMUTH_UNDETERMINED | station_flags::HEADING_LOST),
    ];
    let mut out = Vec::new();
    write_csv(&frames, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    let rows: Vec<Vec<&str>> = text.lines().map(|l| l.split(',').collect()).collect();
    let col = |name: &str| rows[0].iter().position(|c| *c == name).unwrap();
    let (az, status) = (col("azimuth_rad"), col("azimuth_status"));
    assert_eq!((rows[1][az], rows[1][status]), ("", "undetermined"));
    let wrapped: f64 = rows[2][az].parse().unwrap();
    assert!(
        (wrapped - (std::f64::consts::TAU - 1.0)).abs() < 1e-6,
        "{wrapped}"
    );
    assert_eq!(rows[2][status], "determined");
    assert_eq!((rows[3][az], rows[3][status]), ("", "n/a"));
    assert_eq!((rows[4][az], rows[4][status]), ("", "lost"));
    assert_eq!(rows[1][col("roll_rad")], "0.1");
    let (st_az, st_status) = (col("st_azimuth_rad"), col("st_azimuth_status"));
    assert_eq!((rows[5][st_az], rows[5][st_status]), ("2", "determined"));
    assert_eq!((rows[6][st_az], rows[6][st_status]), ("", "undetermined"));
    assert_eq!((rows[7][st_az], rows[7][st_status]), ("", "lost"));
}

#[test]
fn csv_has_one_row_per_frame_and_fixed_columns() {
    let frames = decode_bytes(&{
        let mut w = CaptureWriter::new(Vec::new());
        w.write(&example::raw_sample()).unwrap();
        w.write(&example::nav_solution()).unwrap();
        w.write(&example::boot_event()).unwrap();
        w.write(&example::station_survey()).unwrap();
        w.finish().unwrap()
    })
    .frames;
    let mut out = Vec::new();
    write_csv(&frames, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 5);
    let columns = CSV_HEADER.split(',').count();
    for line in &lines {
        assert_eq!(line.split(',').count(), columns, "{line}");
    }
    assert!(lines[1].starts_with("0,raw,61700000,1234,18,-1625,0,-3,650,"));
    assert!(lines[2].starts_with("1,nav,61700000,1234,"));
    assert!(lines[3].starts_with("2,event,0,,"));
    assert!(lines[3].contains(",1,255,1,0,"));
    assert!(
        lines[4].starts_with("3,station,1379950000,27599,"),
        "{}",
        lines[4]
    );
    assert!(
        lines[4].ends_with(",3,1,24000,27599,0.7853982,2.0943952,determined,5.2359877,0.0008727,0.020944,0.0012217,0.12,-0.35,0.05,1.02"),
        "{}",
        lines[4]
    );
}
