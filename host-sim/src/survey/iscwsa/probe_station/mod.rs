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
mod tests;
