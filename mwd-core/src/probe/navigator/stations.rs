//! Station surveys within navigation (module docs of `navigator`, item 4):
//! each navigation cycle starts, extends or ends the station; every block
//! of [`SURVEY_SETTLE_EPOCHS`] still cycles gets a rate gyrocompass
//! (derivation section 4e) behind its consistency gate
//! ([`EARTH_RATE_GATE`]); the station's survey is the filter's attitude as
//! drilling angles with their covariance (`crate::probe::station`).

use super::heading::AZIMUTH_SIGMA_LIMIT_RAD;
use super::state::{Navigator, Station};
use crate::aid_sources::{long_run_variance, EarthRate};
use crate::attitude::NEAR_VERTICAL;
use crate::conventions::{dcm_from_quat, DrillingAngles};
use crate::earth::earth_rate_n;
use crate::error_model::{ATT, TILT_SIGMA_LIMIT_RAD};
use crate::kalman::{FilterScalar, SparseRow, LINKED};
use crate::probe::station_link::{
    link_covariance, link_rows, StationLink, CHECKPOINT, PREVIOUS, SETTLED,
};
use crate::probe::still::Z_STAY;
use crate::probe_sample::GYRO_AXES;
use crate::protocol::frame::{nav_flags, station_flags};
use crate::protocol::StationSurvey;
use crate::timing::SAMPLE_INTERVAL_S;

/// Still cycles per block of the station's survey checkpoints: a station
/// sends the survey of the older of its last two checkpoints, 40 to 80
/// cycles (2-4 s) before its last still cycle (or its last still cycle
/// when it was shorter than 80). The still detector ends a station only
/// when the motion exceeds its stay threshold, and the orienter's turn
/// begins slowly: in the drilling simulator the toolface had moved by up
/// to 1.5 deg between 40 samples before the last still cycle and it,
/// twenty times the station's toolface sigma.
pub const SURVEY_SETTLE_EPOCHS: u32 = 40;

/// The fewest still cycles with both gyros in a block of
/// [`SURVEY_SETTLE_EPOCHS`] whose means make a rate-gyrocompass update
/// (`aid_sources::EarthRate`): three quarters of the block.
pub const MIN_BIAS_UPDATE_SAMPLES: u32 = SURVEY_SETTLE_EPOCHS * 3 / 4;

/// The rate gyrocompass's consistency gate: the largest normalised
/// innovation squared of a block's two scalars (x and z gyro, each against
/// the filter's covariance before either is used) a still tool passes,
/// `Z_STAY^2` (`crate::probe::still`: two-sided 2e-7 per gyro and block, about
/// 2e-3 over the 5,500 blocks of a 1000 m lateral's 37 stations). A block beyond it is a tool that
/// turns while the still detector sees no motion: a smooth slide at the
/// rate of penetration has no acceleration and turns at the build and walk
/// rates, 5-15 deg/h, which the detector cannot see against the SCC1300's
/// per-sample noise, but a block mean reads as earth rate (15 deg/h at
/// most). Unchecked, a quiet slide became an hour of stations whose
/// gyrocompass turned the heading by tens of degrees under 0.05 deg sigmas
/// (docs/lateral-study.md, "A slide without vibration"). The block is not
/// used, and the station ends there (station flag
/// [`MOTION_SEEN`](crate::protocol::frame::station_flags::MOTION_SEEN)).
/// Gyros too noisy to see the turn (a block mean's noise is ~40 deg/h for
/// the SCC1300, ~5 deg/h for the high-end MEMS grade, whose bias
/// instability enters as rate noise) pass it, and their gyrocompass weighs
/// it as little as the noise says.
pub const EARTH_RATE_GATE: f64 = Z_STAY * Z_STAY;

/// The snapshot slot (`kalman::CrossCovariances`) holding the state's
/// covariance with the sums of the current block's x and z gyro noise
/// (columns 0 and 1): the samples whose means make the block's rate
/// gyrocompass also turned the attitude, by -C_b^n n dt each, so the
/// block's measurement noise is correlated with the attitude error it is
/// compared against (the accelerometers, through the zero-velocity
/// updates, see that turn as tilt). Uncounted, a station took the gyros'
/// information about the heading twice (docs/filter-derivation.md 4k).
const BLOCK_NOISE: usize = 3;

/// What a station's block did with the rate gyrocompass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Gyrocompass {
    /// Too few still cycles with both gyros, or no valid covariance.
    Skipped,
    Used,
    /// The means failed [`EARTH_RATE_GATE`]: the tool turned.
    Turning,
}

impl<T: FilterScalar> Navigator<T> {
    /// A navigation cycle, `still` or not: starts, extends or ends the
    /// station.
    pub(super) fn track_station(&mut self, still: bool) {
        if !still {
            self.station_capped = false;
            self.finish_station(0);
            return;
        }
        if self.station_capped {
            return;
        }
        let statistics = self.still.statistics();
        let quality = statistics
            .rate
            .max(statistics.force)
            .max(statistics.gravity);
        let start = self.sample_counter;
        if self.station.is_none() {
            let (_, snapshots) = self.filter.snapshots_mut();
            snapshots.start_zero(BLOCK_NOISE);
            self.stations = self.stations.wrapping_add(1);
            self.station = Some(Station {
                epochs: 0,
                quality_sum: 0.0,
                survey: StationSurvey::default(),
                gyro_sum: [0.0; 2],
                gyro_epochs: 0,
                checkpoint: None,
                settled: None,
                link: None,
                checkpoint_link: None,
                settled_link: None,
            });
        }
        let Some(station) = self.station.as_mut() else {
            return;
        };
        station.epochs += 1;
        station.quality_sum += quality;
        let gyro = self.still_gyro;
        if let Some(g) = gyro {
            station.gyro_sum[0] += g[0];
            station.gyro_sum[1] += g[1];
            station.gyro_epochs += 1;
        }
        let block_done = station.epochs % SURVEY_SETTLE_EPOCHS == 0;
        if gyro.is_some() {
            self.add_block_noise();
        }
        // Each block's means are one rate-gyrocompass update, before the
        // block's survey is taken, so a station's survey holds the heading
        // and the rate biases (and through them the heading drift of the
        // drilling before it) from all its still cycles but the last
        // block's.
        if block_done && self.gyrocompass_block() == Gyrocompass::Turning {
            // Not still: the station sends its last checkpoint (before
            // this block) and ends.
            self.finish_station(station_flags::MOTION_SEEN);
            self.station_capped = true;
            return;
        }
        let (survey, rows) = self.station_survey();
        let rows = rows.filter(|_| self.station_links);
        let number = self.stations;
        let link = rows.as_ref().map(|rows| self.link_now(number, rows));
        if block_done {
            // The checkpoint before becomes the settled one, and this
            // cycle's a new checkpoint (`station_link`).
            let (p, snapshots) = self.filter.snapshots_mut();
            snapshots.move_to(CHECKPOINT, SETTLED);
            match &rows {
                Some(rows) => snapshots.start(CHECKPOINT, p, rows),
                None => snapshots.clear(CHECKPOINT),
            }
        }
        let Some(station) = self.station.as_mut() else {
            return;
        };
        station.link = link;
        let start_sample = if station.epochs == 1 {
            start
        } else {
            station.survey.start_sample
        };
        station.survey = StationSurvey {
            station: number,
            start_sample,
            still_quality: station.quality_sum / station.epochs as f32,
            ..survey
        };
        if block_done {
            station.settled = station.checkpoint.replace(station.survey);
            station.settled_link = core::mem::replace(&mut station.checkpoint_link, link);
        }
        if station.epochs >= self.max_station_samples {
            self.finish_station(station_flags::MAX_DURATION);
            self.station_capped = true;
        }
    }

    fn finish_station(&mut self, flags: u16) {
        if let Some(station) = self.station.take() {
            let mut survey = station.to_send();
            survey.flags |= flags;
            self.finished_station = Some(survey);
            // The sent survey's snapshot is the next station's previous
            // one. A station with fewer than two checkpoints sends its
            // last still cycle's survey, of which no snapshot was kept
            // (a station shorter than 4 s): no link, and none to it.
            let link = station.settled.and(station.settled_link);
            let (_, snapshots) = self.filter.snapshots_mut();
            snapshots.move_to(SETTLED, PREVIOUS);
            snapshots.clear(CHECKPOINT);
            snapshots.clear(BLOCK_NOISE);
            if link.is_none() {
                snapshots.clear(PREVIOUS);
            }
            self.linked_station = survey.station;
            self.finished_link = link;
        }
    }

    /// The link of the survey at this cycle (`station_link`), from the
    /// rows of its z.
    fn link_now(&self, number: u16, rows: &[SparseRow<T>; LINKED]) -> StationLink {
        let snapshots = self.filter.snapshots();
        let cross = snapshots
            .with(PREVIOUS, rows)
            .map(|m| m.map(|row| row.map(|v| v.as_f64() as f32)));
        StationLink {
            station: number,
            previous: if cross.is_some() {
                self.linked_station
            } else {
                0
            },
            covariance: link_covariance(&self.filter.filter().p, rows),
            cross_previous: cross,
        }
    }

    /// The rate gyrocompass (`aid_sources::EarthRate`, derivation section
    /// 4e) from the still cycles' gyro sums since the last one, which it
    /// clears: one update per block of [`SURVEY_SETTLE_EPOCHS`] still
    /// cycles, in the block's last still cycle (after its step and
    /// zero-velocity update, before its survey checkpoint). The residual
    /// is the block means less the earth rate at the attitude of now (the
    /// tool is still: its true rate is the same in every cycle, so the
    /// means' error is the filter's attitude error of now, not a mix of
    /// the block's estimates, which the zero-velocity updates moved); the
    /// attitude rows are taken at the error model's linearisation point
    /// (fixed from the station's second block on, derivation section 4i).
    /// R is the gyros' noise only: the attitude error is a state of the
    /// row. The blocks' gyro noise is independent from block to block (the
    /// AR models' memory is a few samples).
    ///
    /// A block whose means fail [`EARTH_RATE_GATE`] is not used: the tool
    /// turned ([`Gyrocompass::Turning`]).
    fn gyrocompass_block(&mut self) -> Gyrocompass {
        let outcome = self.gyrocompass_block_means();
        // The next block's noise is not yet in the state.
        let (_, snapshots) = self.filter.snapshots_mut();
        snapshots.start_zero(BLOCK_NOISE);
        outcome
    }

    /// This cycle's x and z gyro noise turned the attitude: adds its
    /// covariance with the block's noise sums, E[(-r_a n_a dt) n_a] = -r_a
    /// q_a per axis a (r_a = C_b^n e_a, q_a the white noise's density
    /// squared, the attitude process noise's gyro part), to the
    /// [`BLOCK_NOISE`] columns.
    fn add_block_noise(&mut self) {
        // The DCM alone (not the cycle's readout): on a block's last cycle
        // the rate gyrocompass then moves the attitude, and a readout made
        // here would be made again after it, in the busiest cycle.
        let c_bn = dcm_from_quat(&self.filter.state().attitude);
        let noise = self.noise.gyro;
        let (_, snapshots) = self.filter.snapshots_mut();
        for (column, axis) in GYRO_AXES.iter().enumerate() {
            let q = noise[*axis].white_density * noise[*axis].white_density;
            let Some(sum) = snapshots.column_mut(BLOCK_NOISE, column) else {
                return;
            };
            for i in 0..3 {
                sum[ATT + i] -= T::of(c_bn[(i, *axis)] * q);
            }
        }
    }

    /// [`gyrocompass_block`](Self::gyrocompass_block)'s update from the
    /// block's sums, which it clears.
    fn gyrocompass_block_means(&mut self) -> Gyrocompass {
        let Some(station) = self.station.as_mut() else {
            return Gyrocompass::Skipped;
        };
        let n = station.gyro_epochs;
        let sum = station.gyro_sum;
        station.gyro_sum = [0.0; 2];
        station.gyro_epochs = 0;
        if n < MIN_BIAS_UPDATE_SAMPLES || self.covariance_invalid {
            return Gyrocompass::Skipped;
        }
        let mean = sum.map(|v| v / f64::from(n));
        let state = self.filter.state();
        let omega = earth_rate_n(state.position.lat);
        let measurement = EarthRate::from_block(
            mean,
            n,
            &dcm_from_quat(&state.attitude),
            &dcm_from_quat(&self.filter.linearization_attitude()),
            &omega,
            GYRO_AXES.map(|axis| long_run_variance(&self.noise.gyro[axis], SAMPLE_INTERVAL_S)),
        );
        let measurement = measurement.cast::<T>();
        let gate = T::of(EARTH_RATE_GATE);
        if self
            .filter
            .largest_normalized_innovation(&measurement)
            .is_some_and(|nis| nis > gate)
        {
            return Gyrocompass::Turning;
        }
        self.filter.aid_correlated(&measurement, BLOCK_NOISE, n);
        Gyrocompass::Used
    }

    /// The station survey at this cycle: the filter's attitude as drilling
    /// angles, their covariance J P_phi J^T (`crate::probe::station`), the flags.
    /// Everything but the station number, start and quality. With the rows
    /// of its link's z (`station_link`) where the covariance is valid.
    pub(super) fn station_survey(&mut self) -> (StationSurvey, Option<[SparseRow<T>; LINKED]>) {
        let readout = self.readout();
        let angles = DrillingAngles::from_euler(&readout.euler);
        let jacobian = readout.drilling_jacobian();
        let mut flags = station_flags::MAGNETIC_FREE;
        if self.is_uncalibrated() {
            flags |= station_flags::UNCALIBRATED;
        }
        let inclination = angles.inclination;
        if !(NEAR_VERTICAL..=core::f64::consts::PI - NEAR_VERTICAL).contains(&inclination) {
            flags |= station_flags::NEAR_VERTICAL;
        }
        let mut survey = StationSurvey {
            time_us: self.time_us,
            end_sample: self.sample_counter,
            angles: [angles.inclination, angles.azimuth, angles.toolface].map(|a| a as f32),
            angles_std: [f32::NAN; 3],
            correlations: [f32::NAN; 3],
            ..StationSurvey::default()
        };
        if self.covariance_invalid {
            survey.flags = flags | station_flags::SOLUTION_INVALID;
            return (survey, None);
        }
        let u = readout.drilling_uncertainty();
        survey.angles_std = u.sigma.map(|s| s as f32);
        survey.correlations = u.correlation.map(|r| r as f32);
        // Lost: since the last tie-in, or now by the frames' own test
        // (`note_heading_loss`, which runs after this cycle's station).
        let euler_std = readout.euler_std();
        let lost = self.heading_lost || self.loses_heading(euler_std.z);
        if lost {
            flags |= station_flags::HEADING_LOST;
        }
        // The navigation frames' rule for the azimuth (see `solution`).
        let determined = !lost
            && self.coarse_std[2].is_finite()
            && self.flags & nav_flags::SINGLE_PART == 0
            && flags & station_flags::NEAR_VERTICAL == 0
            && u.sigma[1] <= AZIMUTH_SIGMA_LIMIT_RAD;
        if !determined {
            flags |= station_flags::AZIMUTH_UNDETERMINED;
            survey.angles_std[1] = f32::INFINITY;
            survey.correlations[0] = f32::NAN;
            survey.correlations[2] = f32::NAN;
        }
        if !(euler_std.x <= TILT_SIGMA_LIMIT_RAD && euler_std.y <= TILT_SIGMA_LIMIT_RAD) {
            flags |= station_flags::SOLUTION_INVALID;
        }
        survey.flags = flags;
        (survey, Some(link_rows(&jacobian)))
    }
}
