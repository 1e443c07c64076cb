//! The lateral study's figures from its results (`study lateral --plots
//! DIR`): per well the station azimuth error and the horizontal position
//! error along MD, per grade, against the predicted sigmas (the Monte
//! Carlo's RMS and median sigma; covariance analysis alone: the predicted
//! sigmas only), and per well the sweep's contour map
//! ([`super::plots`] draws them).

use super::plots::{plot_error_along_md, plot_sweep_contour, AlongMdSeries, Sweep};
use super::run::LateralStudy;
use super::summary::POSITION_LIMIT_M_PER_1000_M;
use anyhow::Result;
use std::path::{Path, PathBuf};

/// Writes every figure of `study` into `dir`; the files written.
pub fn plots(study: &LateralStudy, dir: &Path) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for well in &study.wells {
        let label = &well.label;
        let (azimuth, position) = along_md_series(study, label);
        let stem = dir.join(format!("azimuth-along-md-{}", file_label(label)));
        let title = format!("Station azimuth error along MD, {label} lateral");
        written.extend(plot_error_along_md(
            &stem,
            &title,
            "azimuth error, deg (RMS; predicted 1 and 2 sigma)",
            &azimuth,
        )?);
        let stem = dir.join(format!("position-along-md-{}", file_label(label)));
        let title = format!("Horizontal position error along MD, {label} lateral");
        written.extend(plot_error_along_md(
            &stem,
            &title,
            "horizontal error, m (RMS; predicted 1 and 2 sigma)",
            &position,
        )?);
    }
    let marks: Vec<(String, f64, f64)> = study
        .grades
        .iter()
        .map(|g| {
            let gyro = &g.file.gyro;
            (
                g.file.name.clone(),
                gyro.bias_instability_deg_per_h,
                gyro.arw_deg_per_sqrt_h,
            )
        })
        .collect();
    for sweep in &study.sweeps {
        let value: Vec<Vec<f64>> = sweep
            .td_sigma_per_1000_m
            .iter()
            .map(|row| row.iter().map(|v| v.unwrap_or(f64::NAN)).collect())
            .collect();
        let title = format!(
            "TD horizontal 1-sigma per 1000 m, {} lateral ({} accelerometers, covariance analysis)",
            sweep.well, sweep.base_grade
        );
        let stem = dir.join(format!("sweep-{}", file_label(&sweep.well)));
        written.extend(plot_sweep_contour(
            &stem,
            &Sweep {
                title: &title,
                bias_deg_per_h: &sweep.grid.bias_deg_per_h,
                arw_deg_per_sqrt_h: &sweep.grid.arw_deg_per_sqrt_h,
                value: &value,
                requirement: POSITION_LIMIT_M_PER_1000_M,
                label: "TD horizontal 1-sigma, m per 1000 m",
                grades: &marks,
            },
        )?);
    }
    Ok(written)
}

/// A well's label as a file name part.
fn file_label(label: &str) -> String {
    label
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect()
}

/// Per grade the (azimuth, horizontal position) series on well `label`:
/// the Monte Carlo's where it ran, else the covariance analysis's
/// predicted sigmas with no errors (NaN).
fn along_md_series(study: &LateralStudy, label: &str) -> (Vec<AlongMdSeries>, Vec<AlongMdSeries>) {
    let none = f64::NAN;
    let (mut azimuth, mut position) = (Vec::new(), Vec::new());
    for g in &study.grades {
        let grade = g.file.name.clone();
        if let Some(m) = study
            .summaries
            .iter()
            .find(|m| m.grade == grade && m.well == label)
        {
            let md: Vec<f64> = m.along_md.iter().map(|a| a.truth_md_m).collect();
            azimuth.push(AlongMdSeries {
                grade: grade.clone(),
                md_m: md.clone(),
                rms_error: m
                    .along_md
                    .iter()
                    .map(|a| a.rms_azimuth_error_deg.unwrap_or(none))
                    .collect(),
                predicted_sigma: m
                    .along_md
                    .iter()
                    .map(|a| a.median_azimuth_sigma_deg.unwrap_or(none))
                    .collect(),
            });
            position.push(AlongMdSeries {
                grade,
                md_m: md,
                rms_error: m
                    .along_md
                    .iter()
                    .map(|a| a.rms_horizontal_error_m.unwrap_or(none))
                    .collect(),
                predicted_sigma: m
                    .along_md
                    .iter()
                    .map(|a| a.median_horizontal_sigma_m.unwrap_or(none))
                    .collect(),
            });
        } else if let Some(c) = study
            .covariance
            .iter()
            .find(|c| c.grade == grade && c.well == label)
        {
            let md: Vec<f64> = c.along_md.iter().map(|a| a.0).collect();
            let nan = vec![none; md.len()];
            azimuth.push(AlongMdSeries {
                grade: grade.clone(),
                md_m: md.clone(),
                rms_error: nan.clone(),
                predicted_sigma: c.along_md.iter().map(|a| a.1.unwrap_or(none)).collect(),
            });
            position.push(AlongMdSeries {
                grade,
                md_m: md,
                rms_error: nan,
                predicted_sigma: c.along_md.iter().map(|a| a.2.unwrap_or(none)).collect(),
            });
        }
    }
    (azimuth, position)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn well_labels_make_file_names() {
        assert_eq!(file_label("1000m"), "1000m");
        assert_eq!(file_label("plans/my well.json"), "plans_my_well_json");
    }
}
