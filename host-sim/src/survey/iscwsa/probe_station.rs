//! Position uncertainty from the probe's own station surveys: each
//! station's inclination and azimuth 1-sigma (and their correlation), as
//! the navigator reports them, propagated to NEV covariance with the
//! engine's conventions (SPE 67616 balanced-tangential error vectors,
//! random and systematic sources; see [`super`]).
//!
//! How the stations' errors are correlated (docs/drilling-survey.md):
//! * azimuth: the probe carries its azimuth through drilling on the gyros
//!   from the tie-in (or its first gyrocompass), and each station's
//!   earth-rate updates may then pull part of it back. As a Kalman update
//!   of a scalar error that started the station with variance `s_pre^2`
//!   and ended it with `s_k^2`, the station keeps the fraction
//!   `a_k = s_k^2 / s_pre,k^2` of the error it started with and adds an
//!   independent part. The stations' errors are then a Markov chain:
//!   `e_k = a_k e_(k-1) + d_k u_k`, `u_k` independent unit normals,
//!   `d_k^2 = s_k^2 - a_k^2 s_(k-1)^2`, so `cov(e_j, e_k) = s_j^2 a_(j+1)
//!   ... a_k`. `s_pre,k` is the probe's azimuth sigma just before the
//!   station's first zero-velocity update ([`AngleSigma::azi_before`]).
//!   Where it is not known it is taken as the previous station's sigma:
//!   a growing sigma is then a random walk (`a_k = 1`, the covariance
//!   `min(s_j^2, s_k^2)`), a shrinking one a bias update that keeps
//!   `s_k^2 / s_(k-1)^2` of the error. `a_k` is held to at most 1 and to
//!   at most `s_k / s_(k-1)` (so `d_k^2 >= 0`): every station keeps its
//!   own sigma exactly and the covariance stays a linear map of
//!   independent sources (positive semi-definite by construction). One
//!   source per station, from that station on, decaying by the `a`s; the
//!   first is the tie-in's part;
//! * azimuth, when the probe's station links are at hand for every
//!   station ([`AngleSigma::link`]): the chain above forgets in one
//!   station what the filter's gyro bias estimates carry for several (the
//!   high-end MEMS grade's stations 2 and 4 apart are correlated 0.16 and
//!   0.10, the chain says 0.07 and 0.01; docs/lateral-study.md). The chain
//!   then runs in the link's three error states, azimuth and the x and z
//!   gyro biases, with the covariances the filter computed
//!   ([`super::link_chain`]): three sources per station;
//! * inclination: re-levelled at every station through the zero-velocity
//!   updates, so random from station to station, except for the part the
//!   filter correlates with that station's azimuth:
//!   `e_I,k = r_k (s_I,k / s_A,k) e_A,k + sqrt(1 - r_k^2) s_I,k v_k`,
//!   `v_k` independent unit normals. This holds each station's sigmas and
//!   correlation exactly and keeps the whole covariance a linear map of
//!   independent sources (positive semi-definite by construction);
//! * toolface does not enter the position;
//! * the angle errors' second order: a leg turned by a small angle theta
//!   is shorter along the hole by theta^2 / 2 of its length, whatever the
//!   sign. At a probe's azimuth sigmas after drilling (5-9 deg) that is
//!   ~1 m over 100 m, against centimetres of depth error along the hole:
//!   the first-order ellipse is a line across the hole, and 36 % of
//!   simulated TDs fell outside it (`study drilling-coverage`). It is one
//!   more source, systematic over the run (every leg shortens), of
//!   (sqrt(3) / 2)(s_I^2 + sin^2 I s_A^2) per unit length along the hole
//!   at each station: the RMS of theta^2 / 2 for a normal theta is
//!   sqrt(3) / 2 s^2, which covers its mean s^2 / 2 as well.
//!
//! The first station is the tie-on (its position given): an angle error
//! there acts over half the first leg, as at any other station (no
//! doubling: [`super::TieOn::Exact`]). Depth errors are separate sources
//! (the engine's DSF/DST, [`super::run`]).

use super::link_chain::LinkChain;
use super::{Cov6, Station};
use mwd_core::probe::StationLink;

/// One station's angle uncertainty (rad), as the probe sends it. `azi`
/// must be finite (an undetermined azimuth has no propagation: the caller
/// stops before it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngleSigma {
    pub inc: f64,
    pub azi: f64,
    /// Correlation of the inclination and azimuth errors (NaN: taken as 0).
    pub corr_inc_azi: f64,
    /// The azimuth sigma (rad) just before the station's first
    /// zero-velocity update: what its earth-rate updates started from.
    /// `None` (or not a finite number > 0): the previous station's sigma
    /// (module docs).
    pub azi_before: Option<f64>,
    /// The station's link to the previous station's errors, as the probe's
    /// filter computed it (`mwd_core::probe::station_link`). When every
    /// station has one, linked each to the one before, the azimuth chain
    /// runs in the link's three error states (`super::link_chain`) instead
    /// of the azimuth alone.
    pub link: Option<StationLink>,
}

/// Why a propagation was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum PropagationError {
    /// Different numbers of stations and sigmas.
    LengthMismatch,
    /// A sigma is negative, NaN or infinite (station index).
    BadSigma(usize),
    /// MD not strictly increasing at this station.
    MdNotIncreasing(usize),
}

impl std::fmt::Display for PropagationError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::LengthMismatch => f.write_str("one angle sigma per station is needed"),
            Self::BadSigma(k) => {
                write!(f, "station {k}: an angle sigma is not a finite number >= 0")
            }
            Self::MdNotIncreasing(k) => {
                write!(f, "station {k}: MD not beyond the previous station's")
            }
        }
    }
}

/// One independent unit source: its (inclination, azimuth) error at each
/// station, rad.
struct Source {
    weights: Vec<[f64; 2]>,
}

/// The NEV covariance (m^2) at every station from the stations' angle
/// errors, first station = tie-on (zero covariance there).
pub fn angle_covariance(
    stations: &[Station],
    sigmas: &[AngleSigma],
) -> Result<Vec<Cov6>, PropagationError> {
    checked(stations, sigmas)?;
    Ok(propagate(stations, sigmas, None))
}

/// [`angle_covariance`] at every station and, last, at the projection to
/// the bit: `stations` ends with it (beyond the last station, along that
/// station's inclination and azimuth), `sigmas` has one per station
/// before it. The projection's angles are the last station's, so are
/// their errors: every source's error at the last station acts over the
/// whole projected leg too.
pub fn angle_covariance_projected(
    stations: &[Station],
    sigmas: &[AngleSigma],
) -> Result<Vec<Cov6>, PropagationError> {
    let Some((bit, surveyed)) = stations.split_last() else {
        return Err(PropagationError::LengthMismatch);
    };
    checked(surveyed, sigmas)?;
    if surveyed
        .last()
        .is_some_and(|last| bit.md.is_nan() || bit.md <= last.md)
    {
        return Err(PropagationError::MdNotIncreasing(surveyed.len()));
    }
    Ok(propagate(stations, sigmas, Some(surveyed.len())))
}

/// One sigma per station, each a finite number >= 0, MD increasing.
fn checked(stations: &[Station], sigmas: &[AngleSigma]) -> Result<(), PropagationError> {
    if sigmas.len() != stations.len() {
        return Err(PropagationError::LengthMismatch);
    }
    for (k, s) in sigmas.iter().enumerate() {
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        if !(ok(s.inc) && ok(s.azi)) {
            return Err(PropagationError::BadSigma(k));
        }
        if k > 0 && stations[k].md <= stations[k - 1].md {
            return Err(PropagationError::MdNotIncreasing(k));
        }
    }
    Ok(())
}

/// The covariance at every one of `stations`; with `projected = Some(n)`
/// the stations from `n` on are the last sigma's station held straight
/// ahead (its errors repeated), `sigmas` covering the first `n`.
fn propagate(stations: &[Station], sigmas: &[AngleSigma], projected: Option<usize>) -> Vec<Cov6> {
    let n = stations.len();
    let own = projected.unwrap_or(n);
    // The sigma whose errors station k carries.
    let of = |k: usize| k.min(own - 1);
    let vectors = unit_vectors(stations);
    let mut total = vec![[0.0; 6]; n];
    for src in &sources(sigmas) {
        let per_length: Vec<[f64; 3]> = (0..n)
            .map(|k| {
                let [di, da] = src.weights[of(k)];
                let u = &vectors[k];
                std::array::from_fn(|j| u.di[j] * di + u.da[j] * da)
            })
            .collect();
        add_source(&mut total, &vectors, &per_length);
    }
    let shortening: Vec<[f64; 3]> = (0..n)
        .map(|k| {
            let (s, u) = (&sigmas[of(k)], &vectors[k]);
            let sin_inc = u.along[0].hypot(u.along[1]);
            let size = 0.5 * 3f64.sqrt() * (s.inc.powi(2) + (sin_inc * s.azi).powi(2));
            u.along.map(|t| -t * size)
        })
        .collect();
    add_source(&mut total, &vectors, &shortening);
    total
}

/// Adds one independent unit source's NEV covariance at every station,
/// from its displacement per unit length at each station (balanced
/// tangential: a station's share acts over half of each leg beside it).
fn add_source(total: &mut [Cov6], vectors: &[StationVectors], per_length: &[[f64; 3]]) {
    // running sum of the interior contributions of stations before k
    let mut sum = [0.0; 3];
    for (k, (u, d)) in vectors.iter().zip(per_length).enumerate() {
        if k > 0 {
            let e: [f64; 3] = std::array::from_fn(|j| sum[j] + u.h_last * d[j]);
            add_outer(&mut total[k], e);
        }
        for j in 0..3 {
            sum[j] += u.h_interior * d[j];
        }
    }
}

/// The independent sources of the module's model.
fn sources(sigmas: &[AngleSigma]) -> Vec<Source> {
    let n = sigmas.len();
    // inclination's share of each station's azimuth error
    let share: Vec<f64> = sigmas
        .iter()
        .map(|s| {
            let r = if s.corr_inc_azi.is_finite() {
                s.corr_inc_azi.clamp(-1.0, 1.0)
            } else {
                0.0
            };
            if s.azi > 0.0 {
                r * s.inc / s.azi
            } else {
                0.0
            }
        })
        .collect();
    let azimuth = match link_chain(sigmas) {
        Some(chain) => chain.azimuth_sources(),
        None => azimuth_chain_sources(sigmas),
    };
    let mut out = Vec::with_capacity(azimuth.len() + n);
    for azimuth in azimuth {
        let weights = azimuth
            .iter()
            .zip(&share)
            .map(|(a, s)| [s * a, *a])
            .collect();
        out.push(Source { weights });
    }
    for (k, s) in sigmas.iter().enumerate() {
        let r = if s.corr_inc_azi.is_finite() && s.azi > 0.0 {
            s.corr_inc_azi.clamp(-1.0, 1.0)
        } else {
            0.0
        };
        let size = s.inc * (1.0 - r * r).sqrt();
        if size == 0.0 {
            continue;
        }
        let mut weights = vec![[0.0, 0.0]; n];
        weights[k] = [size, 0.0];
        out.push(Source { weights });
    }
    out
}

/// The azimuth error each source of the chain in the azimuth alone makes
/// at every station (rad): u_j's share of e_k is d_j a_(j+1) ... a_k.
fn azimuth_chain_sources(sigmas: &[AngleSigma]) -> Vec<Vec<f64>> {
    let n = sigmas.len();
    let chain = azimuth_chain(sigmas);
    let mut out = Vec::with_capacity(n);
    for (j, link) in chain.iter().enumerate() {
        if link.fresh == 0.0 {
            continue;
        }
        let mut weights = vec![0.0; n];
        let mut w = link.fresh;
        for k in j..n {
            if k > j {
                w *= chain[k].carried;
            }
            weights[k] = w;
        }
        out.push(weights);
    }
    out
}

/// The correlation the module's azimuth chain gives the errors of
/// station `k` and station `k + lag`, for every `k` that has such a
/// partner: `(s_k / s_(k+lag)) a_(k+1) ... a_(k+lag)`, or with the
/// stations' links `(A_(k+lag) ... A_(k+1) Sigma_k)[0][0] / (s_k
/// s_(k+lag))` (0 where a sigma is 0). What the survey's position covariance assumes; `study lateral`
/// holds it against the Monte Carlo's.
pub fn azimuth_chain_correlations(sigmas: &[AngleSigma], lag: usize) -> Vec<f64> {
    if let Some(links) = link_chain(sigmas) {
        return (0..sigmas.len().saturating_sub(lag))
            .map(|k| {
                let (first, later) = (sigmas[k].azi, sigmas[k + lag].azi);
                if first > 0.0 && later > 0.0 {
                    links.azimuth_covariance(k, lag) / (first * later)
                } else {
                    0.0
                }
            })
            .collect();
    }
    let chain = azimuth_chain(sigmas);
    (0..sigmas.len().saturating_sub(lag))
        .map(|k| {
            let (first, later) = (sigmas[k].azi, sigmas[k + lag].azi);
            if first > 0.0 && later > 0.0 {
                let carried: f64 = chain[k + 1..=k + lag].iter().map(|l| l.carried).product();
                first / later * carried
            } else {
                0.0
            }
        })
        .collect()
}

/// Each station's link where it links back to the station before it in
/// `stations` (station number, link), the first's as it is; `None`
/// elsewhere (a station the survey skipped breaks the chain, and without
/// every link the survey keeps its chain in the azimuth alone).
pub fn links_in_order(stations: &[(u16, Option<StationLink>)]) -> Vec<Option<StationLink>> {
    stations
        .iter()
        .enumerate()
        .map(|(k, (number, link))| {
            let link = link.filter(|l| l.station == *number)?;
            match k.checked_sub(1) {
                None => Some(link),
                Some(before) => (link.previous == stations[before].0).then_some(link),
            }
        })
        .collect()
}

/// The chain in the links' three states, when every station has a link
/// (each but the first back to the one before, `super::link_chain`).
fn link_chain(sigmas: &[AngleSigma]) -> Option<LinkChain> {
    let links: Vec<Option<StationLink>> = sigmas.iter().map(|s| s.link).collect();
    if links.is_empty() {
        return None;
    }
    LinkChain::new(&links)
}

/// One link of the azimuth chain `e_k = a_k e_(k-1) + d_k u_k`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ChainLink {
    /// a_k: the fraction of the previous station's error carried here.
    carried: f64,
    /// d_k: the size of this station's independent part.
    fresh: f64,
}

/// The azimuth chain of the module docs: each station keeps its sigma
/// exactly (`a_k^2 s_(k-1)^2 + d_k^2 = s_k^2`).
fn azimuth_chain(sigmas: &[AngleSigma]) -> Vec<ChainLink> {
    let mut previous = 0.0; // s_(k-1)^2; none before the first station
    sigmas
        .iter()
        .map(|s| {
            let variance = s.azi.powi(2);
            let start = s
                .azi_before
                .filter(|b| b.is_finite() && *b > 0.0)
                .map_or(previous, |b| b * b);
            let mut carried = if start > 0.0 {
                (variance / start).min(1.0)
            } else {
                1.0
            };
            if previous > 0.0 {
                carried = carried.min((variance / previous).sqrt());
            }
            let fresh = (variance - carried * carried * previous).max(0.0).sqrt();
            previous = variance;
            ChainLink { carried, fresh }
        })
        .collect()
}

/// d dr/dI and d dr/dA per unit length at a station and the half course
/// lengths its angle error acts over (SPE 67616 balanced tangential: both
/// legs at an interior station, the leg before at the station of
/// interest).
struct StationVectors {
    di: [f64; 3],
    da: [f64; 3],
    /// The hole's direction (north, east, vertical).
    along: [f64; 3],
    h_interior: f64,
    h_last: f64,
}

fn unit_vectors(stations: &[Station]) -> Vec<StationVectors> {
    (0..stations.len())
        .map(|k| {
            let s = &stations[k];
            let (si, ci) = s.inc.sin_cos();
            let (sa, ca) = s.azi.sin_cos();
            let before = if k == 0 {
                0.0
            } else {
                s.md - stations[k - 1].md
            };
            let after = stations.get(k + 1).map_or(0.0, |nx| nx.md - s.md);
            StationVectors {
                di: [ci * ca, ci * sa, -si],
                da: [-si * sa, si * ca, 0.0],
                along: [si * ca, si * sa, ci],
                h_interior: 0.5 * (before + after),
                h_last: 0.5 * before,
            }
        })
        .collect()
}

fn add_outer(c: &mut Cov6, v: [f64; 3]) {
    c[0] += v[0] * v[0];
    c[1] += v[1] * v[1];
    c[2] += v[2] * v[2];
    c[3] += v[0] * v[1];
    c[4] += v[0] * v[2];
    c[5] += v[1] * v[2];
}

#[cfg(test)]
mod tests {
    use super::*;

    fn straight(n: usize, step: f64, inc_deg: f64, azi_deg: f64) -> Vec<Station> {
        (0..n)
            .map(|k| Station {
                md: 3000.0 + step * k as f64,
                inc: inc_deg.to_radians(),
                azi: azi_deg.to_radians(),
                tvd: 2450.0,
                toolface: None,
            })
            .collect()
    }

    fn sigma(inc: f64, azi: f64) -> AngleSigma {
        AngleSigma {
            inc,
            azi,
            corr_inc_azi: 0.0,
            azi_before: None,
            link: None,
        }
    }

    /// cov(e_j, e_k) of the chain, from its links.
    fn chain_covariance(sigmas: &[AngleSigma], j: usize, k: usize) -> f64 {
        let chain = azimuth_chain(sigmas);
        let (j, k) = (j.min(k), j.max(k));
        // e_k's part that is e_j: a_(j+1) ... a_k
        let carried: f64 = chain[j + 1..=k].iter().map(|l| l.carried).product();
        sigmas[j].azi.powi(2) * carried
    }

    #[test]
    fn every_station_keeps_its_own_azimuth_sigma_whatever_the_chain() {
        let before = |b: Option<f64>| AngleSigma {
            azi_before: b,
            link: None,
            ..sigma(0.0, 0.0)
        };
        // growing, shrinking, a start below the previous station's sigma,
        // a full re-find, an unknown and a bad start
        let azi = [0.02, 0.03, 0.01, 0.015, 0.005, 0.02, 0.02];
        let pre = [
            None,
            Some(0.04),
            Some(0.02),
            Some(0.012),
            Some(1.0),
            None,
            Some(f64::NAN),
        ];
        let s: Vec<AngleSigma> = azi
            .iter()
            .zip(pre)
            .map(|(&a, b)| AngleSigma {
                azi: a,
                ..before(b)
            })
            .collect();
        let chain = azimuth_chain(&s);
        let mut previous = 0.0;
        for (k, l) in chain.iter().enumerate() {
            assert!((0.0..=1.0).contains(&l.carried), "{k}: {l:?}");
            let variance = l.carried.powi(2) * previous + l.fresh.powi(2);
            assert!((variance - azi[k].powi(2)).abs() < 1e-15, "{k}: {l:?}");
            previous = variance;
        }
        // a_k = s_k^2 / s_pre^2 where the start is known and above the
        // previous sigma; 1 for an unknown start and a growing sigma
        assert!((chain[1].carried - (0.03f64 / 0.04).powi(2)).abs() < 1e-15);
        assert!((chain[2].carried - (0.01f64 / 0.02).powi(2)).abs() < 1e-15);
        assert!((chain[4].carried - 0.005f64.powi(2)).abs() < 1e-15);
        assert_eq!(chain[5].carried, 1.0);
        // a start below the previous sigma (0.012 < 0.015 after 0.01):
        // held to s_k / s_(k-1) so the fresh part is not negative
        assert!(chain[3].carried <= 1.0 && chain[3].fresh >= 0.0);
    }

    #[test]
    fn the_chains_correlations_are_its_covariances_over_the_sigmas() {
        let azi = [0.02, 0.03, 0.01, 0.015, 0.005, 0.02];
        let pre = [None, Some(0.04), Some(0.02), None, Some(0.03), None];
        let s: Vec<AngleSigma> = azi
            .iter()
            .zip(pre)
            .map(|(&a, b)| AngleSigma {
                azi_before: b,
                link: None,
                ..sigma(0.0, a)
            })
            .collect();
        for lag in 1..4 {
            let r = azimuth_chain_correlations(&s, lag);
            assert_eq!(r.len(), s.len() - lag);
            for (k, &rk) in r.iter().enumerate() {
                let expected = chain_covariance(&s, k, k + lag) / (azi[k] * azi[k + lag]);
                assert!(
                    (rk - expected).abs() < 1e-12,
                    "lag {lag}, {k}: {rk} {expected}"
                );
                assert!((0.0..=1.0).contains(&rk));
            }
        }
        // a random walk (growing sigma, no start known): s_j / s_k
        let walk: Vec<AngleSigma> = [0.01, 0.02, 0.04].map(|a| sigma(0.0, a)).to_vec();
        assert_eq!(azimuth_chain_correlations(&walk, 2), vec![0.25]);
        assert!(azimuth_chain_correlations(&walk, 3).is_empty());
    }

    #[test]
    fn a_station_that_refinds_its_azimuth_forgets_the_previous_error() {
        // 5 stations, each re-finding the azimuth to 0.01 from a start of
        // 0.1: a = 0.01, nearly independent errors, so the sideways TD
        // error adds in quadrature, far below the random walk's.
        let st = straight(5, 25.0, 90.0, 0.0);
        let s = 0.01;
        let refound: Vec<AngleSigma> = (0..5)
            .map(|_| AngleSigma {
                azi_before: Some(10.0 * s),
                link: None,
                ..sigma(0.0, s)
            })
            .collect();
        let c = angle_covariance(&st, &refound).unwrap();
        let h = [12.5, 25.0, 25.0, 25.0, 12.5];
        let var: f64 = (0..5)
            .flat_map(|j| (0..5).map(move |k| (j, k)))
            .map(|(j, k)| h[j] * h[k] * chain_covariance(&refound, j, k))
            .sum();
        assert!((c[4][1] - var).abs() < 1e-12 * var, "{} vs {var}", c[4][1]);
        let independent: f64 = h.iter().map(|h| (h * s).powi(2)).sum();
        assert!((c[4][1] / independent - 1.0).abs() < 0.05, "{}", c[4][1]);
        let systematic = c_systematic(&st, s);
        assert!(c[4][1] < 0.5 * systematic);
    }

    fn c_systematic(st: &[Station], s: f64) -> f64 {
        angle_covariance(st, &vec![sigma(0.0, s); st.len()]).unwrap()[st.len() - 1][1]
    }

    #[test]
    fn a_constant_azimuth_error_moves_a_straight_horizontal_well_sideways_by_length_times_sigma() {
        // azimuth north, horizontal: the error is east, L sigma at TD
        let st = straight(5, 25.0, 90.0, 0.0);
        let s = 0.01;
        let c = angle_covariance(&st, &[sigma(0.0, s); 5]).unwrap();
        let last = c[4];
        assert!((last[1].sqrt() - 100.0 * s).abs() < 1e-9, "{last:?}");
        assert!(last[2].abs() < 1e-18);
        // Along the hole (north) the second order only: 100 m of legs
        // shortened by up to sqrt(3)/2 s^2 each.
        assert!(
            (last[0].sqrt() - 100.0 * 0.5 * 3f64.sqrt() * s * s).abs() < 1e-12,
            "{last:?}"
        );
        assert_eq!(c[0], [0.0; 6]);
    }

    #[test]
    fn a_random_walk_grows_less_than_a_systematic_error_of_the_same_final_sigma() {
        let st = straight(5, 25.0, 90.0, 0.0);
        let walk: Vec<AngleSigma> = (0..5)
            .map(|k| sigma(0.0, 0.01 * (k as f64 / 4.0).sqrt()))
            .collect();
        let c = angle_covariance(&st, &walk).unwrap();
        // balanced tangential by hand: station k's error acts over h_k,
        // e_k the walk; var = sum_jk h_j h_k min(s_j^2, s_k^2)
        let h = [12.5, 25.0, 25.0, 25.0, 12.5];
        let var: f64 = (0..5)
            .flat_map(|j| (0..5).map(move |k| (j, k)))
            .map(|(j, k)| h[j] * h[k] * walk[j].azi.powi(2).min(walk[k].azi.powi(2)))
            .sum();
        assert!((c[4][1] - var).abs() < 1e-12 * var, "{} vs {var}", c[4][1]);
        assert!(c[4][1] < (100.0f64 * 0.01).powi(2));
    }

    #[test]
    fn random_inclination_errors_add_in_quadrature_and_a_correlation_couples_them() {
        let st = straight(3, 10.0, 90.0, 0.0);
        let c = angle_covariance(&st, &[sigma(0.001, 0.0); 3]).unwrap();
        // vertical: dr/dI = -sin I = -1 per unit length; h = 5, 10, 5
        let var = 0.001f64.powi(2) * (25.0 + 100.0 + 25.0);
        assert!((c[2][2] - var).abs() < 1e-15);
        let corr = vec![
            AngleSigma {
                inc: 0.001,
                azi: 0.002,
                corr_inc_azi: 0.9,
                azi_before: None,
                link: None,
            };
            3
        ];
        let c = angle_covariance(&st, &corr).unwrap();
        assert!(c[2][5].abs() > 0.0, "east-vertical coupled: {:?}", c[2]);
        // still a covariance: |ev| <= sqrt(ee vv)
        assert!(c[2][5].abs() <= (c[2][1] * c[2][2]).sqrt() * (1.0 + 1e-12));
    }

    #[test]
    fn bad_input_is_refused() {
        let st = straight(2, 10.0, 90.0, 0.0);
        assert_eq!(
            angle_covariance(&st, &[sigma(0.0, 0.1)]),
            Err(PropagationError::LengthMismatch)
        );
        assert_eq!(
            angle_covariance(&st, &[sigma(0.0, 0.1), sigma(f64::NAN, 0.1)]),
            Err(PropagationError::BadSigma(1))
        );
        let mut same = st.clone();
        same[1].md = same[0].md;
        assert_eq!(
            angle_covariance(&same, &[sigma(0.0, 0.1); 2]),
            Err(PropagationError::MdNotIncreasing(1))
        );
    }

    /// Stations linked by a chain whose biases remember: with the links
    /// the survey correlates stations 4 apart as the chain does, and the
    /// sideways position at the end grows; without them (one link that
    /// does not point back to the station before) it falls back to the
    /// azimuth chain.
    #[test]
    fn with_every_link_the_azimuth_chain_runs_in_the_links_states() {
        use nalgebra::Matrix3;
        let a = Matrix3::new(0.3, 2.0e5, -1.0e5, 0.0, 0.95, 0.0, 0.0, 0.0, 0.95);
        let q = Matrix3::new(4e-4, 0.0, 0.0, 0.0, 1e-13, 0.0, 0.0, 0.0, 1e-13);
        let arr =
            |m: Matrix3<f64>| std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)] as f32));
        let mut sigma = Matrix3::new(1e-4, 0.0, 0.0, 0.0, 1e-12, 0.0, 0.0, 0.0, 1e-12);
        let mut sigmas = Vec::new();
        let mut numbered = Vec::new();
        for k in 1..=10u16 {
            let cross = (k > 1).then(|| a * sigma);
            if k > 1 {
                sigma = a * sigma * a.transpose() + q;
            }
            let link = StationLink {
                station: k,
                previous: k - 1,
                covariance: arr(sigma),
                cross_previous: cross.map(arr),
            };
            numbered.push((k, Some(link)));
            sigmas.push((sigma, link));
        }
        let with: Vec<AngleSigma> = links_in_order(&numbered)
            .into_iter()
            .zip(&sigmas)
            .map(|(link, (s, _))| AngleSigma {
                inc: 0.001,
                azi: s[(0, 0)].sqrt(),
                corr_inc_azi: 0.0,
                // each station re-finds its azimuth from 3 sigmas: the
                // azimuth chain keeps 1/9 of the error it started with
                azi_before: Some(3.0 * s[(0, 0)].sqrt()),
                link,
            })
            .collect();
        assert!(with.iter().all(|s| s.link.is_some()));
        let mut apart = sigmas[2].0;
        for _ in 0..4 {
            apart = a * apart;
        }
        let want = apart[(0, 0)] / (with[2].azi * with[6].azi);
        let got = azimuth_chain_correlations(&with, 4)[2];
        assert!((got - want).abs() < 1e-4, "{got} against {want}");
        assert!(want > 0.1, "the test's memory is long: {want}");
        // station 5's link points elsewhere: no chain in the links' states
        numbered[4].1.as_mut().unwrap().previous = 9;
        let broken = links_in_order(&numbered);
        assert!(broken[4].is_none() && broken[5].is_some());
        let without: Vec<AngleSigma> = with
            .iter()
            .zip(&broken)
            .map(|(s, l)| AngleSigma { link: *l, ..*s })
            .collect();
        let scalar = azimuth_chain_correlations(&without, 4)[2];
        assert!(scalar < 0.5 * want, "{scalar}");
        let st = straight(10, 28.0, 90.0, 0.0);
        let east = |s: &[AngleSigma]| angle_covariance(&st, s).unwrap()[9][1];
        assert!(
            east(&with) > 1.1 * east(&without),
            "{} {}",
            east(&with),
            east(&without)
        );
    }

    /// `stations` and the last one held `ahead` m further.
    fn projected(stations: &[Station], ahead: f64) -> Vec<Station> {
        let last = *stations.last().unwrap();
        let mut out = stations.to_vec();
        out.push(Station {
            md: last.md + ahead,
            ..last
        });
        out
    }

    #[test]
    fn the_bit_carries_the_last_stations_angle_errors_over_the_projected_leg() {
        // Tie-on (exact) and one station L = 28 m on, horizontal, due
        // north; the station's inclination error alone (no azimuth
        // error): it tilts half the leg before the station (balanced
        // tangential) and the whole leg to the bit, d = 12 m.
        let (l, d, s_inc) = (28.0, 12.0, 0.01);
        let st = straight(2, l, 90.0, 0.0);
        let sig = [sigma(0.0, 0.0), sigma(s_inc, 0.0)];
        let ahead = angle_covariance_projected(&projected(&st, d), &sig).unwrap();
        let plain = angle_covariance(&st, &sig).unwrap();
        assert_eq!(ahead.len(), 3);
        assert_eq!(
            &ahead[..2],
            &plain[..],
            "the stations keep their covariance"
        );
        let vertical = ((0.5 * l + d) * s_inc).powi(2);
        assert!(
            (ahead[2][2] - vertical).abs() < 1e-12 * vertical.max(1.0),
            "{} against {vertical}",
            ahead[2][2]
        );
        assert!(
            ahead[2][2] > plain[1][2],
            "the bit is less certain than the station"
        );
        // and an azimuth error swings the bit sideways over the same lever
        let sig = [sigma(0.0, 0.0), sigma(0.0, 0.02)];
        let east = angle_covariance_projected(&projected(&st, d), &sig).unwrap()[2][1];
        let want = ((0.5 * l + d) * 0.02).powi(2);
        assert!((east - want).abs() < 1e-12, "{east} against {want}");
        assert!(angle_covariance_projected(&projected(&st, 0.0), &sig).is_err());
    }
}
