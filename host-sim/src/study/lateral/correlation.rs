//! How the stations' azimuth errors are correlated along a run, measured
//! against what the survey assumes ([`super`]).
//!
//! The survey's TD covariance correlates the stations' azimuth errors as
//! a Markov chain (`survey_error::probe_station`, docs/drilling-survey.md):
//! in the azimuth alone, or, with the probe's station links, in the
//! azimuth and the x and z gyro biases. Whether the probe's errors follow
//! it is a question for the Monte Carlo: where the filter carries more
//! from station to station than the chain holds, they stay correlated
//! longer, and then the TD ellipse is too small (docs/lateral-study.md,
//! "Why the high-end grade's TD is over-confident"). For each `lag`, over
//! every pair of determined stations `lag` apart in every run:
//!
//! * Monte Carlo: the pooled correlation of the normalised errors
//!   `x = e / s`, `sum(x_k x_(k+lag)) / sqrt(sum(x_k^2) sum(x_(k+lag)^2))`;
//! * the survey's chain: the mean of its correlation over the same pairs.
//!
//! Were the errors distributed as the chain says, the two would agree
//! within the Monte Carlo's spread.

use crate::study::drilling_run::RunOutcome;
use crate::survey::iscwsa::probe_station::{
    azimuth_chain_correlations, links_in_order, AngleSigma,
};
use crate::survey::listing::drilling::azimuth_usable;
use serde::Serialize;

/// The station distances the study reports.
pub const LAGS: [usize; 4] = [1, 2, 4, 8];

/// The azimuth errors' correlation between stations `stations_apart`
/// apart; `None` without pairs (undetermined, never 0).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct LagCorrelation {
    pub stations_apart: usize,
    pub pairs: usize,
    pub monte_carlo: Option<f64>,
    pub survey_chain: Option<f64>,
}

/// One run's determined azimuths in station order: (error, sigma, the
/// survey chain's input), rad.
fn determined(o: &RunOutcome) -> Vec<(f64, AngleSigma)> {
    let kept: Vec<_> = o
        .stations
        .iter()
        .filter(|st| {
            azimuth_usable(&st.survey) && st.survey.angles_std[1] > 0.0 && st.error[1].is_finite()
        })
        .collect();
    let numbered: Vec<_> = kept.iter().map(|st| (st.survey.station, st.link)).collect();
    kept.iter()
        .zip(links_in_order(&numbered))
        .map(|(st, link)| {
            let sigma = AngleSigma {
                inc: 0.0,
                azi: f64::from(st.survey.angles_std[1]),
                corr_inc_azi: 0.0,
                azi_before: st.azimuth_sigma_before,
                link,
            };
            (st.error[1], sigma)
        })
        .collect()
}

/// Sums over one lag's pairs.
#[derive(Default)]
struct PairSums {
    xy: f64,
    xx: f64,
    yy: f64,
    chain: f64,
    pairs: usize,
}

/// The correlations at [`LAGS`] over the runs that finished.
pub fn azimuth_lag_correlations<'a>(
    runs: impl IntoIterator<Item = &'a RunOutcome>,
) -> Vec<LagCorrelation> {
    let mut sums: [PairSums; LAGS.len()] = Default::default();
    for o in runs {
        let stations = determined(o);
        let sigmas: Vec<AngleSigma> = stations.iter().map(|(_, s)| *s).collect();
        let normalised: Vec<f64> = stations.iter().map(|(e, s)| e / s.azi).collect();
        for (sum, &lag) in sums.iter_mut().zip(&LAGS) {
            for (k, r) in azimuth_chain_correlations(&sigmas, lag).iter().enumerate() {
                let (x, y) = (normalised[k], normalised[k + lag]);
                sum.xy += x * y;
                sum.xx += x * x;
                sum.yy += y * y;
                sum.chain += r;
                sum.pairs += 1;
            }
        }
    }
    sums.iter()
        .zip(LAGS)
        .map(|(s, lag)| {
            let norm = (s.xx * s.yy).sqrt();
            LagCorrelation {
                stations_apart: lag,
                pairs: s.pairs,
                monte_carlo: (s.pairs > 0 && norm > 0.0).then(|| s.xy / norm),
                survey_chain: (s.pairs > 0).then(|| s.chain / s.pairs as f64),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::drilling_run::StationCheck;
    use mwd_core::protocol::frame::station_flags;
    use mwd_core::protocol::StationSurvey;

    fn station(number: u16, error: f64, sigma: f32, before: Option<f64>) -> StationCheck {
        StationCheck {
            survey: StationSurvey {
                station: number,
                angles_std: [0.001, sigma, 0.001],
                ..StationSurvey::default()
            },
            error: [0.0, error, 0.0],
            truth_md: 3000.0 + f64::from(number) * 28.0,
            azimuth_error_before: None,
            azimuth_sigma_before: before,
            link: None,
            position: None,
        }
    }

    fn run(seed: u64, stations: Vec<StationCheck>) -> RunOutcome {
        RunOutcome::of_stations(seed, stations)
    }

    #[test]
    fn errors_that_keep_their_sign_along_a_run_are_fully_correlated() {
        // every run's errors one draw times the sigma: correlation 1; the
        // stations re-find their azimuth (start 2 s, a = 1/4): the chain's
        // correlation is 1/4 per station apart
        let runs: Vec<RunOutcome> = [1.3, -0.4, 2.1, -1.7]
            .iter()
            .enumerate()
            .map(|(seed, &z)| {
                let stations = (0..12)
                    // (the start twice the frame's f32 sigma exactly)
                    .map(|k| station(k + 1, z * 0.01, 0.01, Some(2.0 * f64::from(0.01f32))))
                    .collect();
                run(seed as u64, stations)
            })
            .collect();
        let c = azimuth_lag_correlations(&runs);
        assert_eq!(c.len(), LAGS.len());
        for (c, lag) in c.iter().zip(LAGS) {
            assert_eq!(c.stations_apart, lag);
            assert_eq!(c.pairs, 4 * (12 - lag));
            assert!((c.monte_carlo.unwrap() - 1.0).abs() < 1e-12, "{c:?}");
            let chain = 0.25f64.powi(lag as i32);
            assert!((c.survey_chain.unwrap() - chain).abs() < 1e-12, "{c:?}");
        }
    }

    #[test]
    fn alternating_errors_are_anticorrelated_and_undetermined_ones_left_out() {
        let mut stations: Vec<StationCheck> = (0..6)
            .map(|k| {
                let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
                station(k + 1, sign * 0.02, 0.01, None)
            })
            .collect();
        // an undetermined azimuth is no pair's member
        let mut lost = station(7, 0.5, f32::INFINITY, None);
        lost.survey.flags = station_flags::AZIMUTH_UNDETERMINED;
        stations.push(lost);
        let c = azimuth_lag_correlations(&[run(1, stations)]);
        assert_eq!(c[0].pairs, 5);
        assert!((c[0].monte_carlo.unwrap() + 1.0).abs() < 1e-12);
        assert!((c[1].monte_carlo.unwrap() - 1.0).abs() < 1e-12);
        // equal sigmas, no start known: a random walk, correlation 1
        assert!((c[0].survey_chain.unwrap() - 1.0).abs() < 1e-12);
        // 8 apart: no pair among 6 stations, undetermined, never 0
        assert_eq!(c[3].pairs, 0);
        assert_eq!(c[3].monte_carlo, None);
        assert_eq!(c[3].survey_chain, None);
    }
}
