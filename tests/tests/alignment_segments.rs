//! Near-vertical static data (5 deg inclination, 6 mg of
//! accelerometer noise per sample) must not be cut into pieces and dropped
//! silently. A 600 s static run is one segment with every whole block; an
//! indexed run (2 x 300 s, 180 deg apart) keeps both toolfaces and leaves
//! out no more than the turn and a block either side; every sample is
//! either in a segment or reported left out with its reason.
use host_sim::alignment::coarse::{self, LeftOutReason, BLOCK};
use host_sim::formats::samples_csv::Record;
use host_sim::sim::{Motion, SensorModel, SensorSimulator, Trajectory};
use mwd_core::conventions::{DrillingAngles, DEG};
use mwd_core::earth::Position;
use mwd_core::timing::SAMPLE_INTERVAL_S;

/// 6 mg (1 sigma per 20 Hz sample) of white accelerometer noise on top of
/// the SCC1300 model, no calibration errors (the segmentation sees raw
/// data either way).
fn noisy_model(seed: u64) -> SensorModel {
    let mut model = SensorModel::scc1300(seed);
    for axis in &mut model.noise.accel {
        axis.white_density = 6e-3 * 9.81 * SAMPLE_INTERVAL_S.sqrt();
    }
    model
}

fn run(motion: Motion, seconds: Option<f64>, seed: u64) -> Vec<Record> {
    let trajectory = Trajectory {
        position: Position::paper_site(),
        start: DrillingAngles {
            inclination: 5.0 * DEG,
            azimuth: 200.0 * DEG,
            toolface: (seed * 97 % 360) as f64 * DEG,
        }
        .to_euler(),
        motion,
    };
    let seconds = seconds.unwrap_or_else(|| trajectory.scripted_duration());
    let n = (seconds / SAMPLE_INTERVAL_S).round() as usize;
    SensorSimulator::new(trajectory, noisy_model(seed), SAMPLE_INTERVAL_S)
        .take(n)
        .map(|s| Record::from(&s))
        .collect()
}

/// Every sample is in exactly one segment or one left-out range.
fn assert_accounted(records: &[Record], seg: &coarse::Segmentation) {
    let mut owner = vec![0u8; records.len()];
    for r in seg.spans.iter().chain(seg.left_out.iter().map(|(r, _)| r)) {
        for o in &mut owner[r.clone()] {
            *o += 1;
        }
    }
    assert!(
        owner.iter().all(|&o| o == 1),
        "samples not accounted exactly once: {seg:?}"
    );
}

#[test]
fn near_vertical_static_run_is_one_segment() {
    for seed in 1..=10 {
        let records = run(Motion::Static, Some(600.0), seed);
        let seg = coarse::segment_run(&records);
        assert_accounted(&records, &seg);
        assert_eq!(
            seg.spans,
            vec![0..records.len() / BLOCK * BLOCK],
            "seed {seed}: {seg:?}"
        );
    }
}

#[test]
fn near_vertical_indexing_keeps_both_toolfaces() {
    let indexed = Motion::ToolfaceSteps {
        step: std::f64::consts::PI,
        turn_rate: 30.0 * DEG,
        dwell: 300.0,
        steps: 1,
    };
    for seed in 1..=10 {
        let records = run(indexed.clone(), None, seed);
        let seg = coarse::segment_run(&records);
        assert_accounted(&records, &seg);
        assert_eq!(seg.spans.len(), 2, "seed {seed}: {seg:?}");
        // Dwells 0-300 s and 306-606 s: the turn is 6 s (120 samples).
        let left: usize = seg.left_out.iter().map(|(r, _)| r.len()).sum();
        assert!(
            left <= 120 + 2 * BLOCK,
            "seed {seed}: {left} samples left out: {:?}",
            seg.left_out
        );
        assert!(seg
            .left_out
            .iter()
            .all(|(_, why)| *why == LeftOutReason::Moving));
        assert!(records[seg.spans[0].end - 1].time <= 300.0 + 1.0);
        assert!(records[seg.spans[1].start].time >= 306.0 - 1.0);
    }
}
