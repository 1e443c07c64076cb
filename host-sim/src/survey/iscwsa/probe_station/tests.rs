//! The probe station model's chains, sources and the projection to the bit.

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
    let arr = |m: Matrix3<f64>| std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)] as f32));
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
