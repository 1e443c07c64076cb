//! From the probe's downlink to the survey's stations, in one place: each
//! station survey frame with the azimuth sigma its still period started
//! from (the probe's 20 Hz solutions just before it), a station frame sent
//! again taken with the start it had the first time, and the whole
//! positioned by minimum curvature from the job's tie-on with the probe's
//! own uncertainty. The capture survey, the dashboard and the drilling
//! studies all collect their stations here, so they list the same stations
//! at the same positions with the same sigmas.

use std::collections::HashMap;

use anyhow::Result;
use mwd_core::probe::StationLink;
use mwd_core::protocol::{Frame, NavSolution, Payload, StationSurvey};

use crate::formats::depth_log::DepthLog;
use crate::survey::job::Job;
pub use crate::survey::listing::drilling::SurveySetup;
use crate::survey::listing::drilling::{self, AzimuthSigmaTrack, DrillingSurvey, StationStart};
use crate::survey::listing::{LengthUnit, TieOnInput};

/// The stations of one run as they come, each with its start.
#[derive(Debug, Clone, Default)]
pub struct StationCollector {
    /// The solutions since the last station, for the next one's start.
    track: AzimuthSigmaTrack,
    stations: Vec<StationSurvey>,
    starts: Vec<Option<StationStart>>,
    /// The start each station (number, first sample) was given, so that a
    /// frame sent again starts where the first did.
    seen: HashMap<(u16, u32), Option<StationStart>>,
    /// The oldest stations were forgotten ([`Self::drop_oldest`]): the
    /// numbers before the oldest held are not lost ones.
    forgot_oldest: bool,
}

impl StationCollector {
    /// Takes in one downlink frame: a navigation solution or a station.
    pub fn push_frame(&mut self, frame: &Frame) {
        match &frame.payload {
            Payload::Nav(n) => self.push_solution(n),
            Payload::Station(st) => {
                self.push_station(st);
            }
            _ => {}
        }
    }

    /// Takes in one 20 Hz solution.
    pub fn push_solution(&mut self, solution: &NavSolution) {
        self.track.push(solution);
    }

    /// Takes in one station survey; returns the solution its still period
    /// started from, if that is known (a finite sigma no more than a second
    /// before it).
    pub fn push_station(&mut self, station: &StationSurvey) -> Option<StationStart> {
        let track = &mut self.track;
        let start = *self
            .seen
            .entry((station.station, station.start_sample))
            .or_insert_with(|| track.station_start_solution(station));
        self.stations.push(*station);
        self.starts.push(start);
        start
    }

    /// Forgets the oldest station (a display that holds a bounded number).
    pub fn drop_oldest(&mut self) {
        if !self.stations.is_empty() {
            self.stations.remove(0);
            self.starts.remove(0);
            self.forgot_oldest = true;
        }
    }

    /// The stations, in the order they came.
    pub fn stations(&self) -> &[StationSurvey] {
        &self.stations
    }

    /// Each station's azimuth sigma at its start (rad), in the same order.
    pub fn azimuth_sigma_before(&self) -> Vec<Option<f64>> {
        self.starts.iter().map(|s| s.map(|s| s.sigma)).collect()
    }

    /// The stations positioned with their uncertainty (`links`: the
    /// stations' error links, from the probe's navigator or the capture's
    /// replay, one per station; empty when there are none).
    pub fn survey(
        &self,
        links: &[Option<StationLink>],
        setup: &SurveySetup,
        depth: &DepthLog,
    ) -> Result<DrillingSurvey> {
        let from_oldest;
        let setup = match (self.forgot_oldest, self.stations.first()) {
            (true, Some(oldest)) => {
                from_oldest = SurveySetup {
                    first_station: oldest.station,
                    ..setup.clone()
                };
                &from_oldest
            }
            _ => setup,
        };
        drilling::survey(
            &self.stations,
            &self.azimuth_sigma_before(),
            links,
            depth,
            setup,
        )
    }
}

/// The job's tie-on in metres; without a job (or without a tie-on in it),
/// the surface: N 0, E 0, TVD 0 at the first station's MD.
pub fn job_tie_on(job: Option<&Job>) -> TieOnInput {
    let t = job.map(|j| j.survey.tie_on.in_unit(LengthUnit::Metre));
    let t = t.as_ref();
    TieOnInput {
        md: t.and_then(|t| t.md),
        tvd: t.and_then(|t| t.tvd).unwrap_or(0.0),
        north: t.and_then(|t| t.north).unwrap_or(0.0),
        east: t.and_then(|t| t.east).unwrap_or(0.0),
        covariance: t.and_then(|t| t.covariance),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mwd_core::protocol::example;

    fn station(number: u16, start: u32, end: u32) -> StationSurvey {
        let Payload::Station(mut s) = example::station_survey() else {
            unreachable!("the example station is a station")
        };
        s.station = number;
        s.start_sample = start;
        s.end_sample = end;
        s
    }

    fn solution(counter: u32, sigma: f32) -> NavSolution {
        let Payload::Nav(mut n) = example::nav_solution() else {
            unreachable!("the example solution is a solution")
        };
        n.sample_counter = counter;
        n.attitude_std[2] = sigma;
        n
    }

    #[test]
    fn a_station_starts_from_the_solution_before_its_still_period() {
        let mut c = StationCollector::default();
        for k in 0..100 {
            c.push_solution(&solution(k, 0.01 + k as f32 * 1e-4));
        }
        let start = c.push_station(&station(1, 90, 99)).expect("a start");
        assert_eq!(start.sample_counter, 89);
        assert_eq!(
            c.azimuth_sigma_before(),
            vec![Some(f64::from(0.01 + 89.0 * 1e-4_f32))]
        );
    }

    #[test]
    fn a_station_sent_again_keeps_its_first_start_and_a_late_one_has_none() {
        let mut c = StationCollector::default();
        for k in 0..100 {
            c.push_solution(&solution(k, 0.02));
        }
        let first = c.push_station(&station(1, 90, 99));
        // The track forgot what came before the station's end: sent again,
        // the station would otherwise find no start.
        assert_eq!(c.push_station(&station(1, 90, 99)), first);
        // A station whose still period began long after the last solution.
        assert_eq!(c.push_station(&station(2, 500, 600)), None);
        assert_eq!(c.stations().len(), 3);
        assert_eq!(c.azimuth_sigma_before()[2], None);
    }

    #[test]
    fn without_a_job_the_tie_on_is_the_surface() {
        let t = job_tie_on(None);
        assert_eq!((t.md, t.tvd, t.north, t.east), (None, 0.0, 0.0, 0.0));
    }
}
