//! The stations' azimuth errors as a chain in three error states, from the
//! probe's station links (`mwd_core::probe::station_link`): z_k = (azimuth,
//! x gyro bias, z gyro bias) errors of station k, with `Sigma_k = cov(z_k)`
//! and `X_k = cov(z_k, z_(k-1))` as the probe's filter computed them.
//!
//! The chain `z_k = A_k z_(k-1) + w_k`, `A_k = X_k Sigma_(k-1)^-1`,
//! `Q_k = cov(w_k) = Sigma_k - A_k X_k^T`, with the `w_k` independent of
//! each other and of `z_0` (the Markov assumption: what ties a station to
//! the ones before it passes through z of the one before; the filter's
//! other states' memory is a few seconds, or, for the accelerometer
//! biases, restored at rest without correlation). It reproduces every
//! `Sigma_k` and `X_k` exactly; the covariance of stations further apart is
//! `cov(z_k, z_j) = A_k ... A_(j+1) Sigma_j`. As independent sources: each
//! `w_j` factored as `F_j F_j^T`, each column of `F_j` one source whose
//! azimuth error at station k >= j is the first entry of
//! `A_k ... A_(j+1) F_j[:, f]`.
//!
//! The inverses are taken in correlation form (the biases' variances are
//! ~1e-12 of the azimuth's, rad^2 against (rad/s)^2) and by
//! pseudo-inverse, so a state the filter knows exactly does not break the
//! chain; negative eigenvalues of `Q_k` (rounding of the probe's f32) are
//! dropped, so the covariance stays positive semi-definite.

use mwd_core::probe::StationLink;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// The chain's links, one per station: `Sigma_k`, `A_k` (zero for the
/// first) and the factor of `Q_k`.
pub(super) struct LinkChain {
    sigma: Vec<Matrix3<f64>>,
    carried: Vec<Matrix3<f64>>,
    fresh: Vec<Matrix3<f64>>,
}

fn matrix(m: &[[f32; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| f64::from(m[r][c]))
}

/// `1 / sqrt` of a covariance's diagonal (0 where it is not > 0).
fn inverse_scale(s: &Matrix3<f64>) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::from_fn(|i, _| {
        let v = s[(i, i)];
        if v > 0.0 && v.is_finite() {
            1.0 / v.sqrt()
        } else {
            0.0
        }
    }))
}

/// `Sigma^+` through its correlation form.
fn pseudo_inverse(s: &Matrix3<f64>) -> Matrix3<f64> {
    let d = inverse_scale(s);
    let c = d * s * d;
    let c_inv = c.pseudo_inverse(1e-9).unwrap_or_else(|_| Matrix3::zeros());
    d * c_inv * d
}

/// `F` with `F F^T = Q` (Q symmetrised, negative eigenvalues dropped),
/// in `Sigma`'s scale.
fn factor(q: &Matrix3<f64>, scale_of: &Matrix3<f64>) -> Matrix3<f64> {
    let d = inverse_scale(scale_of);
    let d_inv = Matrix3::from_diagonal(&Vector3::from_fn(|i, _| {
        let v = d[(i, i)];
        if v > 0.0 {
            1.0 / v
        } else {
            0.0
        }
    }));
    let scaled = d * (q + q.transpose()) * 0.5 * d;
    let eigen = SymmetricEigen::new(scaled);
    let roots = eigen.eigenvalues.map(|l| l.max(0.0).sqrt());
    d_inv * eigen.eigenvectors * Matrix3::from_diagonal(&roots)
}

impl LinkChain {
    /// The chain through `links` (one per station, in order); `None` when
    /// a station after the first has no link back to the one before, or a
    /// number is not finite.
    pub(super) fn new(links: &[Option<StationLink>]) -> Option<Self> {
        let mut sigmas: Vec<Matrix3<f64>> = Vec::with_capacity(links.len());
        let mut carried = Vec::with_capacity(links.len());
        let mut fresh = Vec::with_capacity(links.len());
        for link in links {
            let link = link.as_ref()?;
            let sigma = matrix(&link.covariance);
            if sigma.iter().any(|v| !v.is_finite()) {
                return None;
            }
            let (a, q) = match sigmas.last() {
                None => (Matrix3::zeros(), sigma),
                Some(before) => {
                    let x = matrix(&link.cross_previous?);
                    if x.iter().any(|v| !v.is_finite()) {
                        return None;
                    }
                    let a = x * pseudo_inverse(before);
                    (a, sigma - a * x.transpose())
                }
            };
            carried.push(a);
            fresh.push(factor(&q, &sigma));
            sigmas.push(sigma);
        }
        Some(Self {
            sigma: sigmas,
            carried,
            fresh,
        })
    }

    /// The azimuth error each independent source makes at every station
    /// (rad; three per station, from that station on).
    pub(super) fn azimuth_sources(&self) -> Vec<Vec<f64>> {
        let n = self.carried.len();
        let mut out = Vec::with_capacity(3 * n);
        for (j, f) in self.fresh.iter().enumerate() {
            for column in f.column_iter() {
                let mut v: Vector3<f64> = column.into_owned();
                if v.iter().all(|x| *x == 0.0) {
                    continue;
                }
                let mut weights = vec![0.0; n];
                weights[j] = v[0];
                for (a, w) in self.carried[j + 1..].iter().zip(&mut weights[j + 1..]) {
                    v = a * v;
                    *w = v[0];
                }
                out.push(weights);
            }
        }
        out
    }

    /// cov(azimuth_k, azimuth_(k + lag)) from the chain (rad^2).
    pub(super) fn azimuth_covariance(&self, k: usize, lag: usize) -> f64 {
        let mut m = self.sigma[k];
        for a in &self.carried[k + 1..=k + lag] {
            m = a * m;
        }
        m[(0, 0)]
    }
}

/// The link of `later` back past `superseded`, the station before it that
/// the survey drops (a later station at the same MD stands, e.g. the last
/// dwell of an indexed connection): `X = X_later Sigma_sup^-1 X_sup`, the
/// chain's own cov(z_later, z_before) through the dropped station (the
/// Markov assumption of the module docs). `None` when `later` does not
/// link back to `superseded`, or a number is not finite; a first station
/// superseded leaves `later` first (no link back).
pub fn through_superseded(superseded: &StationLink, later: &StationLink) -> Option<StationLink> {
    if later.previous != superseded.station {
        return None;
    }
    let cross_previous = match superseded.cross_previous {
        None => None,
        Some(before) => {
            let x_later = matrix(&later.cross_previous?);
            let m = x_later * pseudo_inverse(&matrix(&superseded.covariance)) * matrix(&before);
            if m.iter().any(|v| !v.is_finite()) {
                return None;
            }
            Some(std::array::from_fn(|r| {
                std::array::from_fn(|c| m[(r, c)] as f32)
            }))
        }
    };
    Some(StationLink {
        previous: superseded.previous,
        cross_previous,
        ..*later
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn link(station: u16, cov: Matrix3<f64>, cross: Option<Matrix3<f64>>) -> Option<StationLink> {
        let arr =
            |m: Matrix3<f64>| std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)] as f32));
        Some(StationLink {
            station,
            previous: station.saturating_sub(1),
            covariance: arr(cov),
            cross_previous: cross.map(arr),
        })
    }

    /// A true Markov chain z_k = A z_(k-1) + w_k in three states: the
    /// sources rebuild every station's covariance and the covariance of
    /// stations several apart, with the biases' tiny scale.
    #[test]
    fn the_sources_rebuild_a_markov_chains_covariance() {
        let a = Matrix3::new(0.3, 2.0e5, -1.0e5, 0.0, 0.9, 0.0, 0.0, 0.0, 0.8);
        let q = Matrix3::new(4e-4, 1e-9, 0.0, 1e-9, 1e-13, 0.0, 0.0, 0.0, 2e-13);
        let mut sigma = Matrix3::new(1e-4, 0.0, 0.0, 0.0, 1e-12, 0.0, 0.0, 0.0, 1e-12);
        let mut sigmas = vec![sigma];
        let mut links = vec![link(1, sigma, None)];
        for k in 2..=8 {
            let cross = a * sigma;
            sigma = a * sigma * a.transpose() + q;
            sigmas.push(sigma);
            links.push(link(k, sigma, Some(cross)));
        }
        let chain = LinkChain::new(&links).unwrap();
        let sources = chain.azimuth_sources();
        let cov = |i: usize, j: usize| -> f64 { sources.iter().map(|w| w[i] * w[j]).sum() };
        for (k, sigma) in sigmas.iter().enumerate() {
            let want = sigma[(0, 0)];
            assert!((cov(k, k) / want - 1.0).abs() < 1e-4, "station {k}");
        }
        // stations 1 and 5 apart: A^4 Sigma_1
        let want = (a.pow(4) * sigmas[1])[(0, 0)];
        assert!(
            (cov(1, 5) / want - 1.0).abs() < 1e-4,
            "{} against {want}",
            cov(1, 5)
        );
        assert!((chain.azimuth_covariance(1, 4) / want - 1.0).abs() < 1e-4);
        assert!(
            want.abs() > 0.05 * sigmas[5][(0, 0)],
            "the test's memory is long"
        );
    }

    /// A Markov chain's station 3 linked past station 2: the link says
    /// what the chain without station 2 says, cov(z_3, z_1) = A^2 Sigma_1.
    #[test]
    fn a_link_through_a_superseded_station_is_the_chains_two_steps() {
        let a = Matrix3::new(0.6, 1.0e5, 0.0, 0.0, 0.9, 0.0, 0.0, 0.1, 0.8);
        let q = Matrix3::new(4e-6, 0.0, 0.0, 0.0, 1e-13, 0.0, 0.0, 0.0, 2e-13);
        let s1 = Matrix3::new(1e-4, 0.0, 0.0, 0.0, 1e-12, 0.0, 0.0, 0.0, 1e-12);
        let s2 = a * s1 * a.transpose() + q;
        let s3 = a * s2 * a.transpose() + q;
        let l2 = link(2, s2, Some(a * s1)).unwrap();
        let l3 = link(3, s3, Some(a * s2)).unwrap();
        let through = through_superseded(&l2, &l3).unwrap();
        assert_eq!((through.station, through.previous), (3, 1));
        assert_eq!(through.covariance, l3.covariance);
        let want = a * a * s1;
        let got = matrix(&through.cross_previous.unwrap());
        for r in 0..3 {
            for c in 0..3 {
                // in correlation units: f32's rounding and the inverse's
                let scale = (s3[(r, r)] * s1[(c, c)]).sqrt();
                let (g, w) = (got[(r, c)], want[(r, c)]);
                assert!((g - w).abs() <= 1e-5 * scale, "({r}, {c}): {g} against {w}");
            }
        }
        // not linked to it: no link
        let l4 = link(4, s3, Some(a * s2)).unwrap();
        assert!(through_superseded(&l2, &l4).is_none());
        // a superseded first station: the later one becomes the first
        let first = link(2, s2, None).unwrap();
        let alone = through_superseded(&first, &l3).unwrap();
        assert_eq!((alone.previous, alone.cross_previous), (1, None));
    }

    #[test]
    fn a_missing_link_back_or_a_nan_leaves_no_chain() {
        let s = Matrix3::identity();
        assert!(LinkChain::new(&[link(1, s, None), link(2, s, None)]).is_none());
        assert!(LinkChain::new(&[link(1, s, None), None]).is_none());
        let mut bad = s;
        bad[(1, 1)] = f64::NAN;
        assert!(LinkChain::new(&[link(1, bad, None)]).is_none());
        assert!(LinkChain::new(&[link(1, s, None), link(2, s, Some(s * 0.5))]).is_some());
    }
}
