//! Replay of a probe capture on the host: the raw-sample frames go through
//! the probe's own navigation code (`mwd_core::probe::Navigator`, the same
//! source the firmware runs), and where the capture also holds the probe's
//! navigation frames, each replayed solution is compared with the probe's
//! bit for bit (as encoded frames, so NaN fields compare too).

use std::collections::HashMap;
use std::io::{self, Write};

use mwd_core::earth::Position;
use mwd_core::probe::Navigator;
use mwd_core::protocol::frame::{nav_flags, MAX_BODY_LEN};
use mwd_core::protocol::{encode_body, Frame, NavSolution, Payload};

/// One replayed solution and, if the capture had one, whether the probe's
/// own solution for the same sample was identical.
#[derive(Debug, Clone, Copy)]
pub struct ReplayRow {
    pub solution: NavSolution,
    pub matches_probe: Option<bool>,
}

/// What a replay did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReplaySummary {
    pub raw_frames: u64,
    pub probe_solutions: u64,
    /// Replayed solutions identical to the probe's / different from it.
    pub matched: u64,
    pub mismatched: u64,
    /// Raw frames with a part's data not valid (skipped or faulty samples).
    pub degraded: u64,
}

/// Replays every raw frame of `frames` through the navigation, starting at
/// `position` (the probe's configured site), with uncalibrated sensors.
pub fn replay(frames: &[Frame], position: Position) -> (Vec<ReplayRow>, ReplaySummary) {
    replay_with(frames, Navigator::new(position))
}

/// The same through a given navigator (e.g. one holding the probe's
/// calibration, `Navigator::with_calibration`).
pub fn replay_with(frames: &[Frame], navigator: Navigator) -> (Vec<ReplayRow>, ReplaySummary) {
    let mut replayer = Replayer::with_navigator(navigator);
    for frame in frames {
        replayer.push(frame);
    }
    replayer.finish()
}

/// The replay one frame at a time, for a live stream: a raw frame is
/// replayed as soon as it arrives. The probe sends a sample's navigation
/// frame after its raw frame, but nothing here relies on that order: a
/// solution waits for its partner on either side.
pub struct Replayer {
    navigator: Navigator,
    rows: Vec<ReplayRow>,
    /// Rows (index into `rows`) of replayed samples the probe's solution
    /// has not arrived for yet.
    awaiting_probe: HashMap<u32, usize>,
    /// The probe's solutions whose raw frame has not arrived yet.
    early_probe: HashMap<u32, NavSolution>,
    summary: ReplaySummary,
}

impl Replayer {
    pub fn new(position: Position) -> Self {
        Self::with_navigator(Navigator::new(position))
    }

    pub fn with_navigator(navigator: Navigator) -> Self {
        Self {
            navigator,
            rows: Vec::new(),
            awaiting_probe: HashMap::new(),
            early_probe: HashMap::new(),
            summary: ReplaySummary::default(),
        }
    }

    /// Takes one decoded frame; returns the replayed solution if it was a
    /// raw sample.
    pub fn push(&mut self, frame: &Frame) -> Option<NavSolution> {
        match frame.payload {
            Payload::Nav(on_board) => {
                self.summary.probe_solutions += 1;
                match self.awaiting_probe.remove(&on_board.sample_counter) {
                    Some(index) => self.compare(index, &on_board),
                    None => {
                        self.early_probe.insert(on_board.sample_counter, on_board);
                    }
                }
                None
            }
            Payload::Raw(raw) => {
                self.summary.raw_frames += 1;
                let solution = self.navigator.step(&raw);
                if solution.flags & nav_flags::SENSOR_DEGRADED != 0 {
                    self.summary.degraded += 1;
                }
                let index = self.rows.len();
                self.rows.push(ReplayRow {
                    solution,
                    matches_probe: None,
                });
                match self.early_probe.remove(&raw.sample_counter) {
                    Some(on_board) => self.compare(index, &on_board),
                    None => {
                        self.awaiting_probe.insert(raw.sample_counter, index);
                    }
                }
                Some(solution)
            }
            _ => None,
        }
    }

    fn compare(&mut self, index: usize, on_board: &NavSolution) {
        let row = &mut self.rows[index];
        let same = encoded(on_board) == encoded(&row.solution);
        row.matches_probe = Some(same);
        if same {
            self.summary.matched += 1;
        } else {
            self.summary.mismatched += 1;
        }
    }

    /// The replay so far.
    pub fn summary(&self) -> &ReplaySummary {
        &self.summary
    }

    /// The replayed rows (one per raw frame, in arrival order) and the
    /// summary.
    pub fn finish(self) -> (Vec<ReplayRow>, ReplaySummary) {
        (self.rows, self.summary)
    }
}

fn encoded(nav: &NavSolution) -> Vec<u8> {
    let mut body = [0u8; MAX_BODY_LEN];
    let len = encode_body(0, &Payload::Nav(*nav), &mut body).unwrap_or(0);
    body[..len].to_vec()
}

/// CSV columns of [`write_csv`]: SI inside, degrees at this edge.
pub const CSV_HEADER: &str = "sample,time_s,mode,flags,roll_deg,pitch_deg,heading_deg,\
vn_m_s,ve_m_s,vd_m_s,lat_deg,lon_deg,height_m,roll_std_deg,pitch_std_deg,heading_std_deg,\
matches_probe";

/// Writes the replayed solutions as CSV, one row per raw frame.
pub fn write_csv(rows: &[ReplayRow], mut out: impl Write) -> io::Result<()> {
    writeln!(out, "{CSV_HEADER}")?;
    for row in rows {
        let s = &row.solution;
        let deg = |a: f32| f64::from(a).to_degrees();
        let [roll, pitch, heading] = s.attitude.map(deg);
        let [roll_std, pitch_std, heading_std] = s.attitude_std.map(deg);
        let [vn, ve, vd] = s.velocity_ned;
        let matches = match row.matches_probe {
            Some(true) => "yes",
            Some(false) => "no",
            None => "",
        };
        writeln!(
            out,
            "{},{:.6},{},{},{roll:.6},{pitch:.6},{heading:.6},{vn},{ve},{vd},{:.9},{:.9},{},\
             {roll_std:.6},{pitch_std:.6},{heading_std:.6},{matches}",
            s.sample_counter,
            s.time_us as f64 * 1e-6,
            s.mode,
            s.flags,
            s.latitude.to_degrees(),
            s.longitude.to_degrees(),
            s.height,
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::protocol::frame::raw_flags;
    use mwd_core::protocol::{RawPart, RawSample};
    use mwd_core::sensor_units::{m_s2_to_accel_count, PART_MOUNTINGS, STANDARD_GRAVITY_M_S2};

    fn raw(n: u32) -> Frame {
        let parts = PART_MOUNTINGS.map(|m| RawPart {
            accel: m
                .body_to_sensor([0.0, 0.0, STANDARD_GRAVITY_M_S2])
                .map(m_s2_to_accel_count),
            flags: raw_flags::GYRO_VALID | raw_flags::ACCEL_VALID,
            ..RawPart::default()
        });
        Frame {
            seq: n as u16,
            payload: Payload::Raw(RawSample {
                time_us: u64::from(n) * 50_000,
                sample_counter: n,
                parts,
            }),
        }
    }

    #[test]
    fn replay_matches_the_same_code_and_catches_a_changed_solution() {
        let site = Position::paper_site();
        let raws: Vec<Frame> = (0..150).map(raw).collect();
        // The "probe's" solutions: the same navigation run once already.
        let (first, _) = replay(&raws, site);
        let mut capture = Vec::new();
        for (frame, row) in raws.iter().zip(&first) {
            capture.push(*frame);
            let mut nav = row.solution;
            if nav.sample_counter == 120 {
                nav.attitude[2] += 1e-6;
            }
            capture.push(Frame {
                seq: 0,
                payload: Payload::Nav(nav),
            });
        }
        let (rows, summary) = replay(&capture, site);
        assert_eq!(rows.len(), 150);
        assert_eq!(
            summary,
            ReplaySummary {
                raw_frames: 150,
                probe_solutions: 150,
                matched: 149,
                mismatched: 1,
                degraded: 0,
            }
        );
        let mut csv = Vec::new();
        write_csv(&rows, &mut csv).unwrap();
        let text = String::from_utf8(csv).unwrap();
        assert_eq!(text.lines().count(), 151);
        assert!(text.lines().nth(121).unwrap().ends_with(",no"));
    }

    #[test]
    fn a_replay_applies_the_probes_calibration() {
        use mwd_core::calibration::{ProbeCalibration, TriadCalibration};
        // The same still, level samples; a calibration claiming a body-x
        // accelerometer bias of 10 counts tilts the replayed roll by
        // atan(bias / g), as the probe with that calibration would.
        let site = Position::paper_site();
        let raws: Vec<Frame> = (0..120).map(raw).collect();
        let bias = 10.0 * f64::from(STANDARD_GRAVITY_M_S2) / 650.0;
        let triad = TriadCalibration {
            bias: [bias, 0.0, 0.0],
            ..TriadCalibration::IDENTITY
        };
        let calibration = ProbeCalibration {
            accel: [triad; 2],
            ..ProbeCalibration::default()
        };
        let (plain, _) = replay(&raws, site);
        let (calibrated, _) = replay_with(&raws, Navigator::with_calibration(site, calibration));
        let roll = |rows: &[ReplayRow]| f64::from(rows[110].solution.attitude[0]);
        let expected = (bias / f64::from(STANDARD_GRAVITY_M_S2)).atan();
        assert!(roll(&plain).abs() < 1e-3, "{}", roll(&plain));
        assert!((roll(&calibrated).abs() - expected).abs() < 0.05 * expected);
    }
}
