//! Every run's stations, one row each (`study lateral --stations-csv`):
//! what the summaries average, for an engineer who wants to see which
//! runs and stations make a figure (a signed error, where a sigma stops
//! holding, a run that went astray).

use super::csv::csv_field;
use crate::study::drilling_run::RunOutcome;
use crate::survey::listing::drilling::{azimuth_determined, station_valid};

/// One station of one run; angles in degrees, errors signed (estimate
/// less truth, wrapped). Undetermined or invalid values are empty fields
/// in the CSV, never a number.
#[derive(Clone, Debug, PartialEq)]
pub struct StationRow {
    pub seed: u64,
    pub station: u16,
    pub truth_md_m: f64,
    pub valid: bool,
    pub azimuth_determined: bool,
    pub azimuth_deg: f64,
    pub azimuth_error_deg: f64,
    pub azimuth_sigma_deg: f64,
    /// The solution just before the station's first still sample.
    pub start_azimuth_error_deg: Option<f64>,
    pub start_azimuth_sigma_deg: Option<f64>,
    pub inclination_error_deg: f64,
    pub inclination_sigma_deg: f64,
}

/// The rows of one grade's runs on one well, seed and station order.
pub fn station_rows(results: &[(u64, Result<RunOutcome, String>)]) -> Vec<StationRow> {
    let deg = f64::to_degrees;
    let mut rows = Vec::new();
    for (seed, run) in results {
        let Ok(run) = run else { continue };
        for st in &run.stations {
            let s = &st.survey;
            rows.push(StationRow {
                seed: *seed,
                station: s.station,
                truth_md_m: st.truth_md,
                valid: station_valid(s),
                azimuth_determined: azimuth_determined(s),
                azimuth_deg: deg(f64::from(s.angles[1])),
                azimuth_error_deg: deg(st.error[1]),
                azimuth_sigma_deg: deg(f64::from(s.angles_std[1])),
                start_azimuth_error_deg: st.azimuth_error_before.map(deg),
                start_azimuth_sigma_deg: st.azimuth_sigma_before.map(deg),
                inclination_error_deg: deg(st.error[0]),
                inclination_sigma_deg: deg(f64::from(s.angles_std[0])),
            });
        }
    }
    rows
}

/// The CSV: a header, then one line per (grade, well, row).
pub fn stations_csv<'a>(
    tables: impl Iterator<Item = (&'a str, &'a str, &'a [StationRow])>,
) -> String {
    let mut out = String::from(
        "grade,well,seed,station,truth_md_m,valid,azimuth_determined,azimuth_deg,azimuth_error_deg,azimuth_sigma_deg,start_azimuth_error_deg,start_azimuth_sigma_deg,inclination_error_deg,inclination_sigma_deg\n",
    );
    let f = |v: Option<f64>| {
        v.filter(|v| v.is_finite())
            .map_or_else(String::new, |v| format!("{v:.6}"))
    };
    for (grade, well, rows) in tables {
        for r in rows {
            // an undetermined azimuth is no number; an invalid station
            // has no angle at all
            let azimuth = |v: f64| (r.valid && r.azimuth_determined).then_some(v);
            let inclination = |v: f64| r.valid.then_some(v);
            let fields = [
                csv_field(grade),
                csv_field(well),
                r.seed.to_string(),
                r.station.to_string(),
                format!("{:.3}", r.truth_md_m),
                r.valid.to_string(),
                r.azimuth_determined.to_string(),
                f(azimuth(r.azimuth_deg)),
                f(azimuth(r.azimuth_error_deg)),
                f(azimuth(r.azimuth_sigma_deg)),
                f(r.start_azimuth_error_deg),
                f(r.start_azimuth_sigma_deg),
                f(inclination(r.inclination_error_deg)),
                f(inclination(r.inclination_sigma_deg)),
            ];
            out.push_str(&(fields.join(",") + "\n"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::drilling_run::StationCheck;
    use mwd_core::protocol::frame::station_flags;
    use mwd_core::protocol::StationSurvey;

    fn check(number: u16, flags: u16) -> StationCheck {
        StationCheck {
            survey: StationSurvey {
                station: number,
                flags,
                angles: [1.5, 2.0, 0.0],
                angles_std: [0.001, 0.1, 0.001],
                ..StationSurvey::default()
            },
            error: [0.0005, -0.05, 0.0],
            truth_md: 3000.0 + f64::from(number),
            azimuth_sigma_before: Some(0.12),
            azimuth_error_before: None,
            link: None,
            position: None,
        }
    }

    #[test]
    fn a_row_per_station_with_undetermined_values_left_empty() {
        let runs = vec![
            (
                7,
                Ok(RunOutcome::of_stations(
                    7,
                    vec![check(1, 0), check(2, station_flags::AZIMUTH_UNDETERMINED)],
                )),
            ),
            (8, Err("failed".to_string())),
        ];
        let rows = station_rows(&runs);
        assert_eq!(rows.len(), 2);
        assert!((rows[0].azimuth_error_deg + 0.05f64.to_degrees()).abs() < 1e-9);
        assert!(!rows[1].azimuth_determined);
        let csv = stations_csv([("scc1300", "100m", rows.as_slice())].into_iter());
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 3);
        let width = lines[0].split(',').count();
        assert!(lines.iter().all(|l| l.split(',').count() == width));
        // the determined station's error is a number; the start error is
        // unknown: empty
        let first: Vec<&str> = lines[1].split(',').collect();
        assert!(first[8].starts_with("-2.86"), "{}", lines[1]);
        assert_eq!(first[10], "");
        // the undetermined azimuth: empty, never a number
        let second: Vec<&str> = lines[2].split(',').collect();
        assert_eq!((second[7], second[8], second[9]), ("", "", ""));
        assert!(!second[12].is_empty(), "the inclination is still known");
        // a grade file's name with a comma stays one field (RFC 4180)
        let quoted = stations_csv([("lab, bench", "100m", &rows[..1])].into_iter());
        assert!(quoted
            .lines()
            .nth(1)
            .unwrap()
            .starts_with("\"lab, bench\",100m,7,"));
    }
}
