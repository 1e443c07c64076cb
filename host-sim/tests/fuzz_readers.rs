//! Fuzz targets for every reader of outside data: arbitrary bytes and
//! structure-aware mutations of a good file (bytes flipped, inserted and
//! deleted, lines duplicated and dropped, numbers replaced by huge, NaN,
//! negative or malformed values). Each reader must answer every input
//! without a panic, and refuse a bad one with an `Err` whose message says
//! something; the line-oriented readers name the line of a bad row.
//!
//! The number of cases per target is proptest's: 256 by default, or
//! `PROPTEST_CASES=N` (see `scripts/fuzz.sh`, which runs over a million).

use host_sim::analysis::ar_file::ArModelFile;
use host_sim::analysis::calibration_file::CalibrationFile;
use host_sim::analysis::csv_input::parse_columns;
use host_sim::formats::capture::{
    decode_bytes, write_simulated_probe, CaptureSummary, CaptureWriter, FrameStream, ProbeSetup,
};
use host_sim::formats::depth_log::DepthLog;
use host_sim::formats::samples_csv::{self, SimSample};
use host_sim::formats::station_csv::{read_stations_in, StationReading};
use host_sim::sim::{Plan, SensorModel, SensorModelFile};
use host_sim::study::grade::Grade;
use host_sim::study::lateral::wells::{DrillingOverrides, Well};
use host_sim::survey::iscwsa::parse_term_table;
use host_sim::survey::job::Job;
use mwd_core::conventions::{DrillingAngles, Euler};
use mwd_core::earth::Position;
use mwd_core::protocol::uplink::reply::decode_reply_body;
use mwd_core::protocol::uplink::{
    decode_command, encode_command_body, Command, MAX_COMMAND_BODY_LEN,
};
use nalgebra::Vector3;
use proptest::prelude::*;
use std::fmt::Display;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

// ---------------------------------------------------------------------
// Inputs: arbitrary bytes, or a good file with a few mutations.

/// Values a number in a good file is replaced by.
const BAD_NUMBERS: [&str; 16] = [
    "1e300",
    "-1e300",
    "1e309",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "-5",
    "-0",
    "0",
    "1e-320",
    "99999999999999999999999",
    "",
    "null",
    "\"1\"",
    "0x10",
];

#[derive(Clone, Debug)]
enum Mutation {
    FlipByte(usize, u8),
    InsertBytes(usize, Vec<u8>),
    DeleteRange(usize, usize),
    DuplicateLine(usize),
    DropLine(usize),
    ReplaceNumber(usize, usize),
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(at, b)| Mutation::FlipByte(at, b)),
        (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..8))
            .prop_map(|(at, b)| Mutation::InsertBytes(at, b)),
        (any::<usize>(), 1usize..40).prop_map(|(at, n)| Mutation::DeleteRange(at, n)),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        any::<usize>().prop_map(Mutation::DropLine),
        (any::<usize>(), any::<usize>()).prop_map(|(at, v)| Mutation::ReplaceNumber(at, v)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

/// Byte ranges of the lines of `text`, each with its newline.
fn lines(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, b) in text.iter().enumerate() {
        if *b == b'\n' {
            out.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < text.len() {
        out.push((start, text.len()));
    }
    out
}

/// Byte ranges of the number-like tokens of `text`.
fn numbers(text: &[u8]) -> Vec<(usize, usize)> {
    let is_part = |b: u8| b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'-' | b'+');
    let mut out = Vec::new();
    let mut i = 0;
    while i < text.len() {
        let starts = text[i].is_ascii_digit() || (text[i] == b'-' && i + 1 < text.len());
        let after_letter = i > 0 && (text[i - 1].is_ascii_alphabetic() || text[i - 1] == b'_');
        if starts && !after_letter {
            let mut j = i + 1;
            while j < text.len() && is_part(text[j]) {
                j += 1;
            }
            if text[i..j].iter().any(u8::is_ascii_digit) {
                out.push((i, j));
            }
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

fn apply(mut text: Vec<u8>, m: &Mutation) -> Vec<u8> {
    let at = |i: usize, len: usize| if len == 0 { 0 } else { i % len };
    match m {
        Mutation::FlipByte(i, b) => {
            if !text.is_empty() {
                let i = at(*i, text.len());
                text[i] ^= b | 1;
            }
        }
        Mutation::InsertBytes(i, bytes) => {
            let i = at(*i, text.len() + 1);
            text.splice(i..i, bytes.iter().copied());
        }
        Mutation::DeleteRange(i, n) => {
            let i = at(*i, text.len());
            let end = (i + n).min(text.len());
            text.drain(i..end);
        }
        Mutation::DuplicateLine(i) | Mutation::DropLine(i) => {
            let all = lines(&text);
            if !all.is_empty() {
                let (s, e) = all[at(*i, all.len())];
                let line = text[s..e].to_vec();
                if matches!(m, Mutation::DropLine(_)) {
                    text.drain(s..e);
                } else {
                    text.splice(e..e, line);
                }
            }
        }
        Mutation::ReplaceNumber(i, v) => {
            let all = numbers(&text);
            if !all.is_empty() {
                let (s, e) = all[at(*i, all.len())];
                let value = BAD_NUMBERS[v % BAD_NUMBERS.len()].as_bytes();
                text.splice(s..e, value.iter().copied());
            }
        }
        Mutation::Truncate(i) => {
            let i = at(*i, text.len() + 1);
            text.truncate(i);
        }
    }
    text
}

/// Arbitrary bytes (one case in five) or `seed` with one to four mutations.
fn input(seed: Vec<u8>) -> BoxedStrategy<Vec<u8>> {
    let mutated = proptest::collection::vec(mutation(), 1..5)
        .prop_map(move |ms| ms.iter().fold(seed.clone(), apply));
    prop_oneof![
        1 => proptest::collection::vec(any::<u8>(), 0..600),
        4 => mutated,
    ]
    .boxed()
}

/// `seed` with one number of a data row (past the header) replaced by a bad
/// value: the number and the 1-based line it is on.
fn bad_row_value(seed: &'static str) -> impl Strategy<Value = (String, usize)> {
    (any::<usize>(), 0..BAD_NUMBERS.len()).prop_map(move |(i, v)| {
        let header_end = seed.find('\n').map_or(0, |n| n + 1);
        let all = numbers(&seed.as_bytes()[header_end..]);
        let (s, e) = all[i % all.len()];
        let (s, e) = (s + header_end, e + header_end);
        let line = seed[..s].matches('\n').count() + 1;
        (
            format!("{}{}{}", &seed[..s], BAD_NUMBERS[v], &seed[e..]),
            line,
        )
    })
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A refusal must say something.
fn check<T, E: Display>(result: Result<T, E>) -> Result<(), TestCaseError> {
    if let Err(e) = result {
        let message = format!("{e:#}");
        prop_assert!(!message.trim().is_empty(), "an error without a message");
    }
    Ok(())
}

/// Also: a refused bad row names where it is. The value may be refused on
/// its own line, or (a time that is not after the one before) on the next
/// line (the header is line 1).
fn check_names_line<T, E: Display>(result: Result<T, E>, line: usize) -> Result<(), TestCaseError> {
    if let Err(e) = result {
        let message = format!("{e:#}");
        let named = [format!("line {line}"), format!("line {}", line + 1)];
        prop_assert!(
            named.iter().any(|n| message.contains(n.as_str())),
            "the error for a bad value on line {line} does not name where: {message}"
        );
    }
    Ok(())
}

/// A line-oriented reader: any input answered, and a bad value in a row
/// refused naming where it is.
fn line_reader<T>(
    read: impl Fn(&[u8]) -> anyhow::Result<T>,
    bytes: &[u8],
    bad: &str,
    line: usize,
) -> Result<(), TestCaseError> {
    check(read(bytes))?;
    check_names_line(read(bad.as_bytes()), line)
}

// ---------------------------------------------------------------------
// Good files the mutations start from.

fn manifest() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn file(relative: &str) -> Vec<u8> {
    let path = manifest().join(relative);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A short capture of a still probe: boot event, raw and navigation frames.
fn good_capture() -> &'static [u8] {
    static CAPTURE: OnceLock<Vec<u8>> = OnceLock::new();
    CAPTURE.get_or_init(|| {
        let samples = (0..60).map(|i| SimSample {
            time: f64::from(i + 1) * 0.05,
            gyro: Vector3::new(3e-5, f64::NAN, 5e-5),
            accel: Vector3::new(0.01, -0.02, 9.806),
            true_rate: Vector3::zeros(),
            true_accel: Vector3::new(0.0, 0.0, 9.806),
            truth: Euler::default(),
            position_code: None,
        });
        let mut writer = CaptureWriter::new(Vec::new());
        let probe = ProbeSetup::at(Position::from_degrees(45.0, 126.0, 100.0));
        write_simulated_probe(&mut writer, samples, &probe).expect("a capture in memory");
        writer.finish().expect("a capture in memory")
    })
}

const STATIONS: &str = "md_m,inc_deg,azi_deg\n1000,10,45\n1100,12,47\n1250,15,50\n1300,15.5,50.5\n";
const DEPTH_LOG: &str = "time_s,md_m\n0,3000\n10,3000.5\n20,3001.25\n30,3002\n";
const SAMPLES: &str = "time_s,gyro_x_rad_s,gyro_z_rad_s,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2\n\
    0.05,1e-5,2e-5,0.1,0.2,9.8\n0.1,1.1e-5,2.1e-5,0.11,0.21,9.81\n0.15,1e-5,2e-5,0.1,0.2,9.8\n";
const CALIBRATION: &str = r#"{"format":"mwd-calibration","version":1,"method":"ls","latitude_deg":45,"gravity":9.806,"accel":[{"columns":["ax","ay","az"],"bias":[0.01,0,0],"correction":[[1,0,0],[0,1,0],[0,0,1]]}],"gyro":[{"column":"gz","axis":"z","bias":1e-5,"scale":1.0}]}"#;

fn ar_models() -> String {
    let entry = |sensor: &str, quantity: &str, variance: f64| {
        format!(
            r#"{{"sensor":"{sensor}","quantity":"{quantity}","method":"yule-walker","order":4,"sample_rate_hz":20.0,"coefficients":[0.1,0,0,0],"noise_variance":{variance},"noise_variance_unit":"SI"}}"#
        )
    };
    let models = [
        entry("accel_x_m_s2", "specific-force", 0.003),
        entry("accel_y_m_s2", "specific-force", 0.003),
        entry("accel_z_m_s2", "specific-force", 0.003),
        entry("gyro_x_rad_s", "angular-rate", 1e-6),
        entry("gyro_z_rad_s", "angular-rate", 1e-6),
    ];
    format!(
        r#"{{"format":"mwd-ar-models","version":1,"models":[{}]}}"#,
        models.join(",")
    )
}

fn sensor_model() -> String {
    let file = SensorModelFile::from_model(&SensorModel::scc1300(5));
    serde_json::to_string_pretty(&file).expect("the built-in model as JSON")
}

fn job_folder() -> PathBuf {
    manifest().join("../examples/lateral-100m")
}

// ---------------------------------------------------------------------
// The capture: the host's frame and item layer over the probe's decoder.

proptest! {
    // The case count from PROPTEST_CASES (256 unset); a failure is printed
    // with its input, not saved beside the sources.
    #![proptest_config(ProptestConfig { failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn capture_bytes_never_panic(bytes in input(good_capture().to_vec())) {
        let capture = decode_bytes(&bytes);
        let summary = CaptureSummary::of(&capture);
        let mut stream = FrameStream::new(bytes.as_slice());
        let mut items = 0usize;
        while stream.next_item().map_err(|e| TestCaseError::fail(e.to_string()))?.is_some() {
            items += 1;
        }
        // The streamed and the in-memory reading see the same damage.
        prop_assert_eq!(stream.stats(), &capture.stats);
        prop_assert!(items >= capture.in_order().count());
        let _ = format!("{summary:?}");
    }

    /// Frames cut out at random: the rest still decodes, the loss counted.
    #[test]
    fn capture_with_frames_cut_out(cuts in proptest::collection::vec(any::<usize>(), 1..6)) {
        let good = decode_bytes(good_capture());
        let mut bytes = good_capture().to_vec();
        for cut in &cuts {
            let frames = decode_bytes(&bytes).in_order().count();
            bytes = host_sim::formats::capture::without_frame(&bytes, cut % frames.max(1));
        }
        let damaged = decode_bytes(&bytes);
        prop_assert!(damaged.in_order().count() < good.in_order().count());
    }

    // -----------------------------------------------------------------
    // The uplink: command bodies damaged with and without a good CRC.

    #[test]
    fn uplink_bodies_never_panic(
        which in 0usize..4,
        flips in proptest::collection::vec((any::<usize>(), any::<u8>()), 0..4),
        length in any::<usize>(),
        fix_crc in any::<bool>(),
        bits in any::<u64>(),
    ) {
        let value = f64::from_bits(bits);
        let command = match which {
            0 => Command::SetSite(Position::new(value, 1.0, 100.0)),
            1 => Command::SetTieIn {
                angles: DrillingAngles { inclination: value, azimuth: 0.5, toolface: 0.1 },
                sigma: DrillingAngles { inclination: 1e-3, azimuth: 1e-3, toolface: 1e-3 },
            },
            2 => Command::ClearTieIn,
            _ => Command::TakeStation,
        };
        let mut body = [0u8; MAX_COMMAND_BODY_LEN];
        let Ok(n) = encode_command_body(7, &command, &mut body) else {
            return Ok(());
        };
        for (at, b) in &flips {
            body[at % n] ^= b | 1;
        }
        let n = 1 + length % n.max(1);
        if fix_crc && n > 4 {
            let crc = mwd_core::protocol::crc::crc32c(&body[..n - 4]);
            body[n - 4..n].copy_from_slice(&crc.to_le_bytes());
        }
        check(decode_command(&body[..n]))?;
        let _ = decode_reply_body(&body[..n]);
    }

    // -----------------------------------------------------------------
    // Text tables.

    #[test]
    fn station_csv_never_panics(
        bytes in input(STATIONS.into()),
        (bad, line) in bad_row_value(STATIONS),
    ) {
        let read = |b: &[u8]| read_stations_in(b, StationReading::in_unit(None));
        line_reader(read, &bytes, &bad, line)?;
    }

    #[test]
    fn depth_log_never_panics(
        bytes in input(DEPTH_LOG.into()),
        (bad, line) in bad_row_value(DEPTH_LOG),
    ) {
        line_reader(|b: &[u8]| DepthLog::read(b), &bytes, &bad, line)?;
    }

    #[test]
    fn samples_csv_never_panics(
        bytes in input(SAMPLES.into()),
        (bad, line) in bad_row_value(SAMPLES),
    ) {
        line_reader(|b: &[u8]| samples_csv::read(b), &bytes, &bad, line)?;
    }

    #[test]
    fn analysis_columns_never_panic(bytes in input(SAMPLES.into())) {
        check(parse_columns(&text(&bytes)))?;
    }

    #[test]
    fn term_table_never_panics(
        bytes in input(file("data/probe_scc1300_terms.csv").into_iter().take(1500).collect())
    ) {
        check(parse_term_table(&text(&bytes), "terms.csv"))?;
    }

    // -----------------------------------------------------------------
    // JSON files.

    #[test]
    fn calibration_json_never_panics(bytes in input(CALIBRATION.into())) {
        check(CalibrationFile::parse(&text(&bytes)).and_then(|c| c.check().map(|_| c)))?;
    }

    #[test]
    fn ar_models_never_panic(bytes in input(ar_models().into())) {
        check(ArModelFile::parse(&text(&bytes)))?;
    }

    /// As `SensorModel::load` reads it, without the file.
    #[test]
    fn sensor_model_never_panics(bytes in input(sensor_model().into())) {
        let parsed = serde_json::from_str::<SensorModelFile>(&text(&bytes))
            .map_err(anyhow::Error::from)
            .and_then(|f| f.to_model(1));
        check(parsed)?;
    }

    /// As `Plan::load` reads it, without the file.
    #[test]
    fn well_plan_never_panics(bytes in input(file("data/plans/lateral-100m.json"))) {
        let parsed = serde_json::from_str::<Plan>(&text(&bytes))
            .map_err(anyhow::Error::from)
            .and_then(|p| p.build());
        check(parsed)?;
        check(Well::parse("plan", &text(&bytes), &DrillingOverrides::default()))?;
    }

    #[test]
    fn job_json_never_panics(bytes in input(file("../examples/lateral-100m/job.json"))) {
        check(Job::parse(&text(&bytes), &job_folder()))?;
    }

    #[test]
    fn grade_json_never_panics(bytes in input(file("data/grades/scc1300.json"))) {
        check(Grade::parse(&text(&bytes), "grade.json"))?;
    }
}
