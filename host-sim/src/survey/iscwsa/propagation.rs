//! The propagation of every source's error vectors to the NEV covariance
//! at each station (SPE 67616): the balanced-tangential derivatives of the
//! legs around a station, each source's error vector from its weighting,
//! and the sums (random sources: of `e e^T`; systematic, per-well and
//! global sources: of `e`, then its outer product).
use super::stations::{Site, SiteTerms, Station, StationTrig};
use super::term_table::{ErrorTerm, Propagation};
use super::weighting::{implemented, weighting, xcl_vector, XclAzimuth};
use std::collections::BTreeMap;

/// NEV covariance, m^2: `[nn, ee, vv, ne, nv, ev]`.
pub type Cov6 = [f64; 6];

/// A [`Cov6`] as the symmetric 3x3 matrix of (north, east, vertical).
pub fn cov_matrix(c: &Cov6) -> nalgebra::Matrix3<f64> {
    let [nn, ee, vv, ne, nv, ev] = *c;
    nalgebra::Matrix3::new(nn, ne, nv, ne, ee, ev, nv, ev, vv)
}

pub(super) fn outer(v: [f64; 3]) -> Cov6 {
    [
        v[0] * v[0],
        v[1] * v[1],
        v[2] * v[2],
        v[0] * v[1],
        v[0] * v[2],
        v[1] * v[2],
    ]
}

fn tangent(t: &StationTrig) -> [f64; 3] {
    [t.sin_inc * t.cos_azi, t.sin_inc * t.sin_azi, t.cos_inc]
}

/// What every source's error vector at a station needs from the well's
/// geometry, computed once per station for all sources. In the
/// balanced-tangential form (SPE 67616, the derivatives of
/// `dr_k = (D_k - D_{k-1})/2 (t_{k-1} + t_k)`):
/// * depth: `d dr_k/dD_k = (t_{k-1} + t_k)/2`,
///   `d dr_{k+1}/dD_k = -(t_k + t_{k+1})/2`;
/// * inclination and azimuth: `d dr/dI = L/2 (cos I cos A, cos I sin A,
///   -sin I)`, `d dr/dA = L/2 (-sin I sin A, sin I cos A, 0)`, the same at
///   either end of a leg of length L.
///
/// "interior": station k with the legs before and after it; "last": k as
/// the station of interest, the leg before it only.
#[derive(Clone, Copy, Debug)]
struct Leg {
    /// Depth derivative, interior and last.
    dd_interior: [f64; 3],
    dd_last: [f64; 3],
    /// Half the course lengths the angle errors act over, interior and last.
    h_interior: f64,
    h_last: f64,
    /// d t/dI and d t/dA (per unit length, times 2: `h` carries the 1/2).
    di: [f64; 3],
    da: [f64; 3],
    /// MD from the previous station, m.
    course: f64,
}

impl Leg {
    /// Station `w.cur` from the trigonometry of the stations before it, at
    /// it and after it (`next`: `None` at the last station).
    fn at(
        w: &Window,
        prev: &StationTrig,
        cur: &StationTrig,
        next: Option<&StationTrig>,
        opts: Options,
    ) -> Self {
        let s = w.cur;
        let course = s.md - w.prev.md;
        let len_b = if w.k == 1 && opts.tie_on == TieOn::CarriedByFirstStation {
            // the tie-on's inclination/azimuth error is carried here
            2.0 * (s.md - w.first_md)
        } else {
            course
        };
        let len_a = w.next.map_or(0.0, |n| n.md - s.md);
        let t = tangent(cur);
        let tp = tangent(prev);
        let tn = next.map_or(t, tangent);
        let dd_b: [f64; 3] = std::array::from_fn(|j| 0.5 * (tp[j] + t[j]));
        let (si, ci) = (cur.sin_inc, cur.cos_inc);
        let (sa, ca) = (cur.sin_azi, cur.cos_azi);
        Leg {
            dd_interior: std::array::from_fn(|j| dd_b[j] - 0.5 * (t[j] + tn[j])),
            dd_last: dd_b,
            h_interior: len_b / 2.0 + len_a / 2.0,
            h_last: len_b / 2.0,
            di: [ci * ca, ci * sa, -si],
            da: [-si * sa, si * ca, 0.0],
            course,
        }
    }
}

/// Per-source and total covariances at every station.
#[derive(Clone, Debug)]
pub struct ModelResult {
    /// Per implemented source code: covariance at each station.
    pub per_source: BTreeMap<String, Vec<Cov6>>,
    /// Sum of the implemented sources at each station.
    pub total: Vec<Cov6>,
    /// Codes of sources whose weighting function is not implemented (not
    /// included in `total`).
    pub missing: Vec<String>,
}

/// How the tie-on's own inclination/azimuth error is counted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TieOn {
    /// Rev 5 workbooks: station 1 carries it (its leg-before weight covers
    /// the whole first course length).
    CarriedByFirstStation,
    /// Rev 4 workbook: the tie-on is exact; station 1's leg-before weight
    /// is half the first course length, as at every other station.
    Exact,
}

/// Conventions that differ between model revisions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    pub tie_on: TieOn,
    pub xcl_azimuth: XclAzimuth,
}

impl Options {
    /// Rev 5.10 (HPT Rev 5.1 diagnostics, WB5.10 calculation sheets).
    pub const REV5_10: Self = Self {
        tie_on: TieOn::CarriedByFirstStation,
        xcl_azimuth: XclAzimuth::Sine,
    };
    /// The workbook diagnostic block (Rev 5 before the 5.10 XCLA change).
    pub const REV5_DIAGNOSTIC: Self = Self {
        tie_on: TieOn::CarriedByFirstStation,
        xcl_azimuth: XclAzimuth::Angle,
    };
    /// Rev 4 (no XCL terms).
    pub const REV4: Self = Self {
        tie_on: TieOn::Exact,
        xcl_azimuth: XclAzimuth::Angle,
    };
}

/// The stations around station `k` (>= 1) of a survey, as the
/// propagation at `k` needs them.
#[derive(Clone, Copy, Debug)]
struct Window<'s> {
    k: usize,
    /// MD of the survey's first station (the tie-on).
    first_md: f64,
    prev: &'s Station,
    cur: &'s Station,
    next: Option<&'s Station>,
}

/// Error vectors of one source at station `w.cur`: (as an interior
/// station, as the station of interest); `None`: weighting function not
/// implemented.
#[inline]
fn error_vector(
    term: &ErrorTerm,
    w: &Window,
    trig: &StationTrig,
    leg: &Leg,
    site: &SiteTerms,
    opts: Options,
) -> Option<([f64; 3], [f64; 3])> {
    let sig = term.magnitude_si;
    let s = w.cur;
    if term.weighting.starts_with("XCL") {
        let v = xcl_vector(
            &term.weighting,
            s,
            w.prev,
            trig,
            sig,
            site,
            opts.xcl_azimuth,
        )?;
        return Some((v, v));
    }
    let wt = weighting(&term.weighting, s, trig, leg.course, site)?;
    // the angle part: d dr/dI w_I + d dr/dA w_A per unit half-length, or at
    // a vertical station the tabulated singularity vector
    let u: [f64; 3] = match (wt.singular, s.inc < site.vertical_limit) {
        (Some(sv), true) => sv,
        _ => std::array::from_fn(|j| leg.di[j] * wt.w[1] + leg.da[j] * wt.w[2]),
    };
    Some((
        std::array::from_fn(|j| sig * (leg.dd_interior[j] * wt.w[0] + leg.h_interior * u[j])),
        std::array::from_fn(|j| sig * (leg.dd_last[j] * wt.w[0] + leg.h_last * u[j])),
    ))
}

/// One implemented source while the stations are walked: its running sum
/// (SPE 67616: random sources add their covariances, the others their
/// error vectors) and its covariance at the last station propagated.
struct Source<'a> {
    term: &'a ErrorTerm,
    random: bool,
    /// Random: the covariance sum `[nn, ee, vv, ne, nv, ev]`; otherwise the
    /// vector sum in the first three.
    sum: [f64; 6],
    last: Cov6,
}

/// The model run one station at a time, holding only the sources' running
/// sums and the last two stations: a survey of any length in constant
/// memory. Each station's covariance is known once the station after it
/// is (the balanced-tangential legs reach one station ahead), so
/// [`Propagator::push`] gives the covariance of the station before the one
/// pushed, and [`Propagator::finish`] the last one's.
pub struct Propagator<'a> {
    sources: Vec<Source<'a>>,
    missing: Vec<String>,
    site: SiteTerms,
    opts: Options,
    first_md: f64,
    /// Stations k-1 and k (k the next to propagate), with their trigonometry.
    prev: (Station, StationTrig),
    cur: Option<(Station, StationTrig)>,
    k: usize,
}

impl<'a> Propagator<'a> {
    /// Starts at the survey's first station (the tie-on: no error).
    pub fn new(terms: &'a [ErrorTerm], first: Station, site: &Site, opts: Options) -> Self {
        let site = SiteTerms::of(site);
        let trig = StationTrig::of(&first, &site);
        let mut sources = Vec::with_capacity(terms.len());
        let mut missing = Vec::new();
        for term in terms {
            if !implemented(term, &first, &trig, &site) {
                missing.push(term.code.clone());
                continue;
            }
            sources.push(Source {
                term,
                random: term.propagation == Propagation::Random,
                sum: [0.0; 6],
                // the tie-on carries no error
                last: [0.0; 6],
            });
        }
        Self {
            sources,
            missing,
            site,
            opts,
            first_md: first.md,
            prev: (first, trig),
            cur: None,
            k: 1,
        }
    }

    /// Codes of the sources whose weighting function is not implemented
    /// (left out of every covariance).
    pub fn missing(&self) -> &[String] {
        &self.missing
    }

    /// The sources' codes, in the order of [`Propagator::source_covariances`].
    pub fn source_codes(&self) -> impl Iterator<Item = &str> {
        self.sources.iter().map(|s| s.term.code.as_str())
    }

    /// Each source's covariance at the last station propagated.
    pub fn source_covariances(&self) -> impl Iterator<Item = &Cov6> {
        self.sources.iter().map(|s| &s.last)
    }

    /// Takes the next station; returns the covariance of the station
    /// before it, if that one is not the first.
    pub fn push(&mut self, station: Station) -> Option<Cov6> {
        let trig = StationTrig::of(&station, &self.site);
        let done = self.cur.map(|(cur, cur_trig)| {
            let c = self.step(&cur, &cur_trig, Some((&station, &trig)));
            self.prev = (cur, cur_trig);
            c
        });
        self.cur = Some((station, trig));
        done
    }

    /// The covariance of the last station pushed (none if only the first
    /// was given).
    pub fn finish(&mut self) -> Option<Cov6> {
        let (cur, cur_trig) = self.cur.take()?;
        let c = self.step(&cur, &cur_trig, None);
        self.prev = (cur, cur_trig);
        Some(c)
    }

    fn step(
        &mut self,
        cur: &Station,
        trig: &StationTrig,
        next: Option<(&Station, &StationTrig)>,
    ) -> Cov6 {
        let (site, opts) = (&self.site, self.opts);
        let w = Window {
            k: self.k,
            first_md: self.first_md,
            prev: &self.prev.0,
            cur,
            next: next.map(|n| n.0),
        };
        let leg = Leg::at(&w, &self.prev.1, trig, next.map(|n| n.1), opts);
        let mut tot = [0.0; 6];
        for src in &mut self.sources {
            // `implemented` said the name is known: a station cannot change
            // that (the dispatch is by name)
            let (interior, last) =
                error_vector(src.term, &w, trig, &leg, site, opts).unwrap_or(([0.0; 3], [0.0; 3]));
            let c = if src.random {
                let c = outer(last);
                let c: Cov6 = std::array::from_fn(|j| src.sum[j] + c[j]);
                for (a, e) in src.sum.iter_mut().zip(outer(interior)) {
                    *a += e;
                }
                c
            } else {
                let c = outer(std::array::from_fn(|j| src.sum[j] + last[j]));
                for (a, e) in src.sum.iter_mut().zip(interior) {
                    *a += e;
                }
                c
            };
            src.last = c;
            for j in 0..6 {
                tot[j] += c[j];
            }
        }
        self.k += 1;
        tot
    }
}

/// Runs the model over a survey (first station = tie-on), with the Rev
/// 5.10 conventions.
pub fn run(terms: &[ErrorTerm], stations: &[Station], site: &Site) -> ModelResult {
    run_with(terms, stations, site, Options::REV5_10)
}

/// Runs the model with explicit conventions, keeping every source's
/// covariance at every station ([`Propagator`] keeps none).
pub fn run_with(
    terms: &[ErrorTerm],
    stations: &[Station],
    site: &Site,
    opts: Options,
) -> ModelResult {
    let n = stations.len();
    let Some(first) = stations.first() else {
        return ModelResult {
            per_source: BTreeMap::new(),
            total: Vec::new(),
            missing: Vec::new(),
        };
    };
    let mut propagator = Propagator::new(terms, *first, site, opts);
    let mut covs: Vec<Vec<Cov6>> = propagator
        .source_covariances()
        .map(|c| {
            let mut v = Vec::with_capacity(n);
            v.push(*c);
            v
        })
        .collect();
    let mut total = Vec::with_capacity(n);
    total.push([0.0; 6]);
    let mut keep = |p: &Propagator, c: Cov6| {
        for (v, s) in covs.iter_mut().zip(p.source_covariances()) {
            v.push(*s);
        }
        total.push(c);
    };
    for s in &stations[1..] {
        if let Some(c) = propagator.push(*s) {
            keep(&propagator, c);
        }
    }
    if let Some(c) = propagator.finish() {
        keep(&propagator, c);
    }
    let per_source = propagator
        .source_codes()
        .map(String::from)
        .zip(covs)
        .collect();
    ModelResult {
        per_source,
        total,
        missing: propagator.missing().to_vec(),
    }
}
