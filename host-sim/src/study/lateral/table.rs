//! The lateral study's terminal tables and CSV ([`super`]).
//! Undetermined figures print as "-" in tables (with the reason in the
//! notes under them) and as empty fields in the CSV, never as a number.

use super::correlation::LAGS;
use super::csv::csv_field;
use super::run::LateralStudy;
use super::summary::{GradeWellSummary, ATTITUDE_LIMIT_DEG, POSITION_LIMIT_M_PER_1000_M};
use crate::study::drilling_coverage::Fraction;

/// Columns aligned: the first `left` columns to the left, the rest (numbers)
/// to the right; a rule under the header.
fn aligned(header: &[&str], rows: &[Vec<String>], left: usize) -> String {
    let mut widths: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for row in rows {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    let line = |cells: &mut dyn Iterator<Item = &str>| -> String {
        let parts: Vec<String> = cells
            .zip(&widths)
            .enumerate()
            .map(|(i, (c, w))| {
                if i < left {
                    format!("{c:<w$}")
                } else {
                    format!("{c:>w$}")
                }
            })
            .collect();
        parts.join("  ").trim_end().to_string() + "\n"
    };
    let mut out = line(&mut header.iter().copied());
    let rule: Vec<String> = widths.iter().map(|w| "-".repeat(*w)).collect();
    out.push_str(&(rule.join("  ") + "\n"));
    for row in rows {
        out.push_str(&line(&mut row.iter().map(String::as_str)));
    }
    out
}

pub(super) fn num(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "-".into(), |v| format!("{v:.decimals$}"))
}

/// [`Fraction::text`], or "-" without cases.
pub(super) fn fraction(f: &Fraction) -> String {
    f.text().unwrap_or_else(|| "-".into())
}

fn met(v: Option<bool>) -> String {
    match v {
        Some(true) => "yes".into(),
        Some(false) => "no".into(),
        None => "undetermined".into(),
    }
}

fn station_row(s: &GradeWellSummary) -> Vec<String> {
    vec![
        s.grade.clone(),
        s.well.clone(),
        format!("{}/{}", s.runs - s.failed_runs.len(), s.runs),
        s.stations.to_string(),
        format!(
            "{} ({})/{}",
            s.azimuth_undetermined_stations, s.azimuth_lost_stations, s.invalid_stations
        ),
        num(s.rms_station_azimuth_deg, 3),
        fraction(&s.azimuth_within_2_sigma),
        num(s.rms_station_inclination_deg, 3),
        fraction(&s.inclination_within_2_sigma),
        held_to(s),
        met(s.requirement.attitude_met),
    ]
}

/// How far the heading held in 95 % of the runs: its true MD, "none"
/// when more than 5 % lost it at the first station; with the count of
/// runs that held it to their last station.
pub(super) fn held_to(s: &GradeWellSummary) -> String {
    let ok = s.runs - s.failed_runs.len();
    let depth = s
        .heading_held_to_md_m
        .map_or_else(|| "none".to_string(), |md| format!("{md:.0}"));
    format!("{depth} ({}/{ok} to TD)", s.heading_held_runs)
}

fn td_row(s: &GradeWellSummary) -> Vec<String> {
    let t = &s.td;
    vec![
        s.grade.clone(),
        s.well.clone(),
        format!("{}/{}", t.runs_checked, s.runs),
        num(t.rms_horizontal_error_m, 2),
        num(t.p95_horizontal_error_m, 2),
        num(t.predicted_1_sigma_m, 2),
        num(t.predicted_2_sigma_m, 2),
        fraction(&t.inside_95_ellipse),
        num(t.semi_major_1_sigma_per_1000_m, 2),
        num(s.requirement.rms_td_error_per_1000_m, 2),
        num(s.requirement.p95_td_error_per_1000_m, 2),
        met(s.requirement.position_met),
        num(s.epochs_per_core_second, 0),
    ]
}

/// The TD split into the survey method's own error and the rest (the
/// sensors' and the depth log's), each against its part of the covariance.
fn method_split_table(study: &LateralStudy) -> String {
    let mut out = String::from(
        "\nTD without the survey method (error less minimum curvature's own through the true angles; covariance less XCLA/XCLH)\n",
    );
    let rows: Vec<Vec<String>> = study
        .summaries
        .iter()
        .map(|s| {
            let t = &s.td;
            let w = &t.without_method;
            let ratio = study
                .agreement
                .iter()
                .find(|a| a.grade == s.grade && a.well == s.well)
                .and_then(|a| a.td_without_method_ratio);
            vec![
                s.grade.clone(),
                s.well.clone(),
                num(t.method_rms_error_m, 3),
                num(t.method_predicted_1_sigma_m, 3),
                fraction(&t.method_inside_95_ellipse),
                num(w.rms_horizontal_error_m, 3),
                num(w.predicted_1_sigma_m, 3),
                fraction(&w.inside_95_ellipse),
                num(ratio, 2),
            ]
        })
        .collect();
    out.push_str(&aligned(
        &[
            "grade",
            "well",
            "method error RMS (m)",
            "XCL 1s (m)",
            "method inside XCL 95 % ellipse",
            "rest RMS (m)",
            "rest pred 1s (m)",
            "rest inside 95 % ellipse",
            "covariance analysis / MC (rest)",
        ],
        &rows,
        2,
    ));
    out
}

/// The stations' azimuth errors' correlation by distance, Monte Carlo
/// against the survey's chain (`super::correlation`).
fn correlation_table(study: &LateralStudy) -> String {
    let mut out = String::from(
        "\nstation azimuth errors' correlation k stations apart: Monte Carlo / the survey's chain (which the TD covariance assumes)\n",
    );
    let rows: Vec<Vec<String>> = study
        .summaries
        .iter()
        .map(|s| {
            let mut row = vec![s.grade.clone(), s.well.clone()];
            row.extend(
                s.azimuth_correlation
                    .iter()
                    .map(|c| format!("{} / {}", num(c.monte_carlo, 2), num(c.survey_chain, 2))),
            );
            row
        })
        .collect();
    let lags: Vec<String> = LAGS.iter().map(|k| format!("k = {k}")).collect();
    let mut header = vec!["grade", "well"];
    header.extend(lags.iter().map(String::as_str));
    out.push_str(&aligned(&header, &rows, 2));
    out
}

/// The azimuth sigma's consistency through the stations and the drilling
/// between them (`super::consistency`).
fn consistency_table(study: &LateralStudy) -> String {
    let mut out = String::from(
        "\nazimuth sigma through stations and drilling (RMS of the normalised change: 1 when the sigma holds; above 1: over-confident)\n",
    );
    let rows: Vec<Vec<String>> = study
        .summaries
        .iter()
        .map(|s| {
            let c = &s.azimuth_consistency;
            vec![
                s.grade.clone(),
                s.well.clone(),
                c.stations.to_string(),
                num(c.station_correction_ratio, 2),
                num(c.station_variance_removed.map(|v| 100.0 * v), 1),
                c.drilling_stretches.to_string(),
                num(c.drilling_growth_ratio, 2),
                num(c.start_error_ratio, 2),
                num(c.end_error_ratio, 2),
            ]
        })
        .collect();
    out.push_str(&aligned(
        &[
            "grade",
            "well",
            "stations",
            "station correction / its variance",
            "variance removed (%)",
            "stretches",
            "drilling growth / its variance",
            "error / sigma at station start",
            "at station end",
        ],
        &rows,
        2,
    ));
    out
}

/// The terminal tables: stations and the attitude requirement, TD and the
/// position requirement, then the error growth along MD per grade and well.
pub fn table(study: &LateralStudy) -> String {
    let mut out = String::new();
    if let Some(i) = &study.interrupted {
        out.push_str(&format!(
            "INTERRUPTED after {} of {} jobs: every figure below is over the runs done (\"runs ok\")\n\n",
            i.jobs_done, i.jobs
        ));
    }
    out.push_str(&format!(
        "stations (azimuth over the determined ones; undetermined (of them lost since the tie-in)/invalid counted; heading held to: the true MD 95 % of the runs reached with every station's azimuth determined, and the runs that held it to TD; attitude: the larger RMS < {ATTITUDE_LIMIT_DEG} deg, no azimuth withheld)\n"
    ));
    let rows: Vec<Vec<String>> = study.summaries.iter().map(station_row).collect();
    out.push_str(&aligned(
        &[
            "grade",
            "well",
            "runs ok",
            "stations",
            "undet (lost)/inv",
            "azi RMS (deg)",
            "azi within 2 sigma",
            "inc RMS (deg)",
            "inc within 2 sigma",
            "heading held to, 95 % (MD m)",
            "attitude met",
        ],
        &rows,
        2,
    ));
    out.push_str(&format!(
        "\nTD horizontal position (predicted 1-sigma: RMS of sqrt(trace NE cov); position: RMS < {POSITION_LIMIT_M_PER_1000_M} m per 1000 m, every TD positioned)\n"
    ));
    let rows: Vec<Vec<String>> = study.summaries.iter().map(td_row).collect();
    out.push_str(&aligned(
        &[
            "grade",
            "well",
            "TD checked",
            "RMS (m)",
            "p95 (m)",
            "pred 1s (m)",
            "pred 2s (m)",
            "inside 95 % ellipse",
            "semi-major 1s (m/1000 m)",
            "RMS (m/1000 m)",
            "p95 (m/1000 m)",
            "position met",
            "epochs/s/core (CPU)",
        ],
        &rows,
        2,
    ));
    out.push_str(&method_split_table(study));
    out.push_str(&correlation_table(study));
    out.push_str(&consistency_table(study));
    for s in &study.summaries {
        if s.motion_seen_stations > 0 {
            out.push_str(&format!(
                "  {} {}: {} of {} stations ended when the gyros saw the tool turn while the still detector saw no motion (a smooth slide)\n",
                s.grade, s.well, s.motion_seen_stations, s.stations
            ));
        }
        for (reason, n) in &s.td_unchecked {
            out.push_str(&format!(
                "  {} {}: TD not checked in {n} runs: {reason}\n",
                s.grade, s.well
            ));
        }
        for e in s.failed_runs.iter().take(3) {
            out.push_str(&format!("  {} {}: failed: {e}\n", s.grade, s.well));
        }
    }
    for s in &study.summaries {
        out.push_str(&format!(
            "\nalong MD: {} on the {} well (azimuth over the determined stations; horizontal over the positioned ones)\n",
            s.grade, s.well
        ));
        let rows: Vec<Vec<String>> = s
            .along_md
            .iter()
            .map(|a| {
                vec![
                    a.station.to_string(),
                    format!("{:.1}", a.truth_md_m),
                    a.stations.to_string(),
                    a.azimuth_undetermined.to_string(),
                    num(a.rms_azimuth_error_deg, 3),
                    num(a.median_azimuth_sigma_deg, 3),
                    a.azimuth_within_2_sigma
                        .fraction
                        .map_or_else(|| "-".into(), |p| format!("{:.1}", 100.0 * p)),
                    num(a.rms_inclination_error_deg, 3),
                    num(a.median_inclination_sigma_deg, 3),
                    a.positioned.to_string(),
                    num(a.rms_horizontal_error_m, 2),
                    num(a.median_horizontal_sigma_m, 2),
                    num(a.station_correction_ratio, 2),
                    num(a.drilling_growth_ratio, 2),
                    num(a.start_error_ratio, 2),
                ]
            })
            .collect();
        out.push_str(&aligned(
            &[
                "station",
                "MD (m)",
                "n",
                "undet",
                "azi RMS (deg)",
                "azi median sigma (deg)",
                "within 2 sigma (%)",
                "inc RMS (deg)",
                "inc median sigma (deg)",
                "positioned",
                "horiz RMS (m)",
                "horiz median 1s (m)",
                "station corr / sigma",
                "drilling growth / sigma",
                "start error / sigma",
            ],
            &rows,
            0,
        ));
    }
    out.push_str(&covariance_table(study));
    out
}

/// The covariance analysis (one error-free run per grade and well), its
/// agreement with the Monte Carlo, the OWSG models and the sweeps.
fn covariance_table(study: &LateralStudy) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "\ncovariance analysis (one error-free run each; ratio: predicted / Monte Carlo RMS, check |ratio - 1| <= 10 %; position: semi-major 1s < {POSITION_LIMIT_M_PER_1000_M} m per 1000 m)\n"
    ));
    let rows: Vec<Vec<String>> = study
        .covariance
        .iter()
        .map(|c| {
            let a = study
                .agreement
                .iter()
                .find(|a| a.grade == c.grade && a.well == c.well);
            vec![
                c.grade.clone(),
                c.well.clone(),
                num(c.rms_station_azimuth_sigma_deg, 4),
                num(c.rms_station_inclination_sigma_deg, 4),
                c.azimuth_undetermined_stations.to_string(),
                num(c.td_horizontal_1_sigma_m, 3),
                num(c.td_semi_major_1_sigma_per_1000_m, 3),
                num(c.method_td_error_m, 3),
                num(c.td_method_1_sigma_m, 3),
                num(c.td_without_method_1_sigma_m, 3),
                num(a.and_then(|a| a.azimuth_ratio), 2),
                num(a.and_then(|a| a.td_ratio), 2),
                met(a.and_then(|a| a.within_10_percent)),
                num(c.cpu_s, 1),
            ]
        })
        .collect();
    out.push_str(&aligned(
        &[
            "grade",
            "well",
            "azi sigma RMS (deg)",
            "inc sigma RMS (deg)",
            "azi undet",
            "TD pred 1s (m)",
            "semi-major 1s (m/1000 m)",
            "method TD error (m)",
            "XCL 1s (m)",
            "TD 1s w/o XCL (m)",
            "azi ratio",
            "TD ratio",
            "within 10 %",
            "CPU (s)",
        ],
        &rows,
        2,
    ));
    for c in &study.covariance {
        if let Some(note) = &c.td_note {
            out.push_str(&format!("  {} {}: no TD figure: {note}\n", c.grade, c.well));
        }
    }
    for w in &study.owsg {
        for m in &w.models {
            out.push_str(&format!(
                "  OWSG {} on the {} well: {}\n",
                m.model,
                w.well,
                m.cell()
            ));
        }
    }
    for sweep in &study.sweeps {
        out.push_str(&format!(
            "\nsweep on the {} well ({} but the gyros): TD horizontal 1-sigma per 1000 m (m); rows: bias instability (deg/h), columns: ARW (deg/sqrt(h))\n",
            sweep.well, sweep.base_grade
        ));
        let mut header = vec!["bias \\ ARW".to_string()];
        header.extend(
            sweep
                .grid
                .arw_deg_per_sqrt_h
                .iter()
                .map(|a| format!("{a:.3}")),
        );
        let rows: Vec<Vec<String>> = sweep
            .grid
            .bias_deg_per_h
            .iter()
            .zip(&sweep.td_sigma_per_1000_m)
            .map(|(b, row)| {
                let mut r = vec![format!("{b:.3}")];
                r.extend(row.iter().map(|v| num(*v, 2)));
                r
            })
            .collect();
        let header: Vec<&str> = header.iter().map(String::as_str).collect();
        out.push_str(&aligned(&header, &rows, 0));
        for f in sweep.failures.iter().take(3) {
            out.push_str(&format!("  failed: {f}\n"));
        }
    }
    out
}

/// CSV: one row per grade and well, units in the header, undetermined
/// fields empty.
pub fn csv(study: &LateralStudy) -> String {
    let header = [
        "grade",
        "well",
        "lateral_length_m",
        "runs",
        "failed_runs",
        "stations",
        "invalid_stations",
        "azimuth_undetermined_stations",
        "azimuth_lost_stations",
        "motion_seen_stations",
        "heading_held_to_md_m",
        "heading_held_runs",
        "rms_station_azimuth_deg",
        "azimuth_within_2_sigma",
        "azimuth_within_2_sigma_se",
        "rms_station_inclination_deg",
        "inclination_within_2_sigma",
        "inclination_within_2_sigma_se",
        "td_runs_checked",
        "td_rms_horizontal_error_m",
        "td_p95_horizontal_error_m",
        "td_predicted_1_sigma_m",
        "td_predicted_2_sigma_m",
        "td_inside_95_ellipse_k",
        "td_inside_95_ellipse_n",
        "td_inside_95_ellipse",
        "td_inside_95_ellipse_se",
        "td_semi_major_1_sigma_m",
        "td_semi_major_1_sigma_per_1000_m",
        "td_method_rms_error_m",
        "td_method_predicted_1_sigma_m",
        "td_without_method_rms_error_m",
        "td_without_method_predicted_1_sigma_m",
        "td_without_method_inside_95_ellipse_k",
        "td_without_method_inside_95_ellipse_n",
        "attitude_error_deg",
        "attitude_met",
        "rms_td_error_per_1000_m",
        "p95_td_error_per_1000_m",
        "position_met",
        "samples",
        "epochs_per_core_second",
        "epochs_per_thread_wall_second",
    ];
    let f = |v: Option<f64>| v.map_or_else(String::new, |v| format!("{v}"));
    let b = |v: Option<bool>| v.map_or_else(String::new, |v| v.to_string());
    let mut header: Vec<String> = header.iter().map(|h| h.to_string()).collect();
    for k in LAGS {
        header.push(format!("azimuth_correlation_{k}_apart_monte_carlo"));
        header.push(format!("azimuth_correlation_{k}_apart_survey_chain"));
    }
    header.extend(
        [
            "station_correction_ratio",
            "station_variance_removed",
            "drilling_growth_ratio",
            "start_error_ratio",
            "end_error_ratio",
        ]
        .map(String::from),
    );
    let mut out = header.join(",") + "\n";
    for s in &study.summaries {
        let t = &s.td;
        let fields = [
            csv_field(&s.grade),
            csv_field(&s.well),
            format!("{}", s.lateral_length_m),
            s.runs.to_string(),
            s.failed_runs.len().to_string(),
            s.stations.to_string(),
            s.invalid_stations.to_string(),
            s.azimuth_undetermined_stations.to_string(),
            s.azimuth_lost_stations.to_string(),
            s.motion_seen_stations.to_string(),
            f(s.heading_held_to_md_m),
            s.heading_held_runs.to_string(),
            f(s.rms_station_azimuth_deg),
            f(s.azimuth_within_2_sigma.fraction),
            f(s.azimuth_within_2_sigma.standard_error),
            f(s.rms_station_inclination_deg),
            f(s.inclination_within_2_sigma.fraction),
            f(s.inclination_within_2_sigma.standard_error),
            t.runs_checked.to_string(),
            f(t.rms_horizontal_error_m),
            f(t.p95_horizontal_error_m),
            f(t.predicted_1_sigma_m),
            f(t.predicted_2_sigma_m),
            t.inside_95_ellipse.inside.to_string(),
            t.inside_95_ellipse.total.to_string(),
            f(t.inside_95_ellipse.fraction),
            f(t.inside_95_ellipse.standard_error),
            f(t.semi_major_1_sigma_m),
            f(t.semi_major_1_sigma_per_1000_m),
            f(t.method_rms_error_m),
            f(t.method_predicted_1_sigma_m),
            f(t.without_method.rms_horizontal_error_m),
            f(t.without_method.predicted_1_sigma_m),
            t.without_method.inside_95_ellipse.inside.to_string(),
            t.without_method.inside_95_ellipse.total.to_string(),
            f(s.requirement.attitude_error_deg),
            b(s.requirement.attitude_met),
            f(s.requirement.rms_td_error_per_1000_m),
            f(s.requirement.p95_td_error_per_1000_m),
            b(s.requirement.position_met),
            s.samples.to_string(),
            f(s.epochs_per_core_second),
            f(s.epochs_per_thread_wall_second),
        ];
        let mut fields = fields.to_vec();
        for k in LAGS {
            let c = s.azimuth_correlation.iter().find(|c| c.stations_apart == k);
            fields.push(f(c.and_then(|c| c.monte_carlo)));
            fields.push(f(c.and_then(|c| c.survey_chain)));
        }
        let c = &s.azimuth_consistency;
        fields.push(f(c.station_correction_ratio));
        fields.push(f(c.station_variance_removed));
        fields.push(f(c.drilling_growth_ratio));
        fields.push(f(c.start_error_ratio));
        fields.push(f(c.end_error_ratio));
        out.push_str(&(fields.join(",") + "\n"));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::drilling_run::Scalar;
    use crate::study::lateral::summary::summarise;

    fn study() -> LateralStudy {
        LateralStudy {
            runs_per_grade_and_well: 1,
            first_seed: 1,
            threads: 1,
            tie_in_azimuth_sigma_deg: 0.5,
            filter_scalar: Scalar::F64,
            wall_s: 1.0,
            interrupted: None,
            grades: Vec::new(),
            wells: Vec::new(),
            summaries: vec![summarise(
                "a",
                "my,plan.json",
                100.0,
                &[(1, Err("x".into()))],
            )],
            covariance: Vec::new(),
            agreement: Vec::new(),
            owsg: Vec::new(),
            sweeps: Vec::new(),
            errors: Vec::new(),
        }
    }

    #[test]
    fn undetermined_is_a_dash_or_an_empty_field_never_a_number() {
        let s = study();
        let text = table(&s);
        assert!(text.contains("undetermined"), "{text}");
        let lines: Vec<&str> = text.lines().collect();
        // header and rule have the same width
        assert_eq!(
            lines[1].len(),
            lines[2].trim_end().len().max(lines[1].len())
        );
        let csv = csv(&s);
        let rows: Vec<&str> = csv.lines().collect();
        assert_eq!(rows.len(), 2);
        let header = rows[0].split(',').count();
        assert!(
            rows[1].starts_with("a,\"my,plan.json\",100,1,1,"),
            "{}",
            rows[1]
        );
        // the quoted comma is one field
        assert_eq!(rows[1].split(',').count(), header + 1);
        assert!(
            rows[1].contains(",,"),
            "empty fields for undetermined: {}",
            rows[1]
        );
    }
}
