//! Tests of the lateral study's figures (`super`).

use super::along_md::drawable_runs;
use super::log_axis::tick;
use super::sweep::{viridis, LEVELS};
use super::*;
use plotters::style::RGBColor;
use std::path::PathBuf;

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A];

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lateral-plots-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// The SVG's text, checked to be an SVG, and the PNG checked by its
/// signature.
fn read_pair(files: &[PathBuf; 2]) -> String {
    let svg = std::fs::read_to_string(&files[0]).expect("svg written");
    assert!(svg.starts_with("<svg"), "{}", &svg[..svg.len().min(80)]);
    assert!(svg.trim_end().ends_with("</svg>"));
    let png = std::fs::read(&files[1]).expect("png written");
    assert!(png.len() > 1000 && png[..8] == PNG_SIGNATURE);
    svg
}

fn series(grade: &str, scale: f64) -> AlongMdSeries {
    let md_m: Vec<f64> = (0..6).map(|k| 3000.0 + 28.0 * k as f64).collect();
    AlongMdSeries {
        grade: grade.into(),
        rms_error: md_m.iter().map(|m| scale * (m - 2990.0) / 10.0).collect(),
        predicted_sigma: md_m.iter().map(|m| scale * (m - 2990.0) / 12.0).collect(),
        md_m,
    }
}

#[test]
fn along_md_writes_svg_and_png_and_skips_undetermined_points() {
    let dir = temp_dir("along");
    let mut a = series("scc1300", 1.0);
    a.rms_error[2] = f64::NAN;
    a.predicted_sigma[4] = f64::NAN;
    let b = series("navigation", 1e-4);
    let files = plot_error_along_md(
        &dir.join("azimuth"),
        "station azimuth error",
        "azimuth error (deg)",
        &[a, b],
    )
    .expect("written");
    assert_eq!(files[0], dir.join("azimuth.svg"));
    assert_eq!(files[1], dir.join("azimuth.png"));
    let svg = read_pair(&files);
    assert!(svg.contains("scc1300") && svg.contains("navigation"));
    assert!(svg.contains("predicted 2-sigma"));
    // markers: 5 + 6 determined RMS points, one legend marker per grade
    // and the key's
    assert_eq!(svg.matches("<circle").count(), 5 + 6 + 2 + 1);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn along_md_refuses_series_of_unequal_length() {
    let dir = temp_dir("unequal");
    let mut a = series("tactical", 1.0);
    a.predicted_sigma.pop();
    let err = plot_error_along_md(&dir.join("x"), "t", "y", &[a]).expect_err("refused");
    assert!(format!("{err}").contains("grade tactical"), "{err}");
    let err = plot_error_along_md(&dir.join("x"), "t", "y", &[]).expect_err("nothing");
    assert!(format!("{err:#}").contains("nothing to plot"), "{err:#}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn runs_break_at_undetermined_and_non_positive_values() {
    let x = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    let y = [1.0, f64::NAN, 2.0, 3.0, 0.0, 4.0];
    let runs = drawable_runs(&x, &y);
    assert_eq!(
        runs,
        vec![
            vec![(1.0, 1.0)],
            vec![(3.0, 2.0), (4.0, 3.0)],
            vec![(6.0, 4.0)]
        ]
    );
    assert!(drawable_runs(&x, &[f64::NAN; 6]).is_empty());
}

#[test]
fn tick_labels() {
    assert_eq!(tick(0.3), "0.3");
    assert_eq!(tick(100.0), "100");
    assert_eq!(tick(0.015), "0.015");
    assert_eq!(tick(0.001), "1e-3");
    assert_eq!(tick(30000.0), "3e4");
}

/// A power law like the TD error's: value = 600 bias + 300 ARW (m per
/// 1000 m, for illustration), on 1-3-10 grids.
fn grid() -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    let bias = vec![0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0];
    let arw = vec![0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 1.0];
    let value = bias
        .iter()
        .map(|b| arw.iter().map(|a| 600.0 * b + 300.0 * a).collect())
        .collect();
    (bias, arw, value)
}

fn sweep<'a>(
    bias: &'a [f64],
    arw: &'a [f64],
    value: &'a [Vec<f64>],
    grades: &'a [(String, f64, f64)],
) -> Sweep<'a> {
    Sweep {
        title: "TD horizontal 1-sigma over gyro bias and ARW",
        bias_deg_per_h: bias,
        arw_deg_per_sqrt_h: arw,
        value,
        requirement: 1.0,
        label: "m per 1000 m",
        grades,
    }
}

#[test]
fn sweep_writes_svg_and_png_with_the_requirement_bold_and_blank_nan_cells() {
    let dir = temp_dir("sweep");
    let (bias, arw, mut value) = grid();
    let grades = vec![
        ("SCC1300".to_string(), 2.0, 0.9),
        ("navigation".to_string(), 0.003, 0.002),
    ];
    let files = plot_sweep_contour(&dir.join("full"), &sweep(&bias, &arw, &value, &grades))
        .expect("written");
    let full = read_pair(&files);
    assert!(full.contains("SCC1300") && full.contains("navigation"));
    assert!(full.contains("requirement 1 (m per 1000 m)"));
    // the requirement's contour: bold lines in its colour
    assert!(full.contains("stroke=\"#D62728\"") && full.contains("stroke-width=\"3\""));
    value[3][2] = f64::NAN;
    let files = plot_sweep_contour(&dir.join("hole"), &sweep(&bias, &arw, &value, &grades))
        .expect("written");
    let hole = read_pair(&files);
    // one cell fewer (blank), everything else as before
    assert_eq!(
        full.matches("<rect").count(),
        hole.matches("<rect").count() + 1
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sweep_says_when_the_requirement_is_met_nowhere() {
    let (bias, arw, value) = grid();
    let high: Vec<Vec<f64>> = value
        .iter()
        .map(|r| r.iter().map(|v| v + 5.0).collect())
        .collect();
    let s = sweep(&bias, &arw, &high, &[]);
    let fig = sweep::SweepFigure::new(&s).expect("figure");
    let dir = temp_dir("nowhere");
    let files = plot_sweep_contour(&dir.join("s"), &s).expect("written");
    assert!(read_pair(&files).contains("met nowhere in the sweep"));
    drop(fig);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sweep_refuses_bad_grids() {
    let dir = temp_dir("bad");
    let (bias, arw, value) = grid();
    let stem = dir.join("s");
    let mut rev = bias.clone();
    rev.swap(0, 1);
    assert!(plot_sweep_contour(&stem, &sweep(&rev, &arw, &value, &[])).is_err());
    assert!(plot_sweep_contour(&stem, &sweep(&bias, &arw[1..], &value, &[])).is_err());
    assert!(plot_sweep_contour(&stem, &sweep(&bias[..1], &arw, &value[..1], &[])).is_err());
    let nan: Vec<Vec<f64>> = value.iter().map(|r| vec![f64::NAN; r.len()]).collect();
    let err = plot_sweep_contour(&stem, &sweep(&bias, &arw, &nan, &[])).expect_err("no values");
    assert!(format!("{err}").contains("undetermined"), "{err}");
    let mut s = sweep(&bias, &arw, &value, &[]);
    s.requirement = f64::NAN;
    assert!(plot_sweep_contour(&stem, &s).is_err());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn colour_map_and_levels() {
    assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
    assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
    assert_eq!(viridis(0.5), RGBColor(33, 145, 140));
    assert_eq!(viridis(f64::NAN), viridis(0.0));
    assert!(LEVELS.windows(2).all(|w| w[1] > w[0]));
}

/// Example figures to look at (`cargo test --release -p host-sim --lib
/// study::lateral::plots -- --ignored --nocapture`; the directory printed).
#[test]
#[ignore = "writes example figures to look at"]
fn write_example_figures() {
    let dir = std::env::temp_dir().join("lateral-plots-example");
    std::fs::create_dir_all(&dir).expect("dir");
    let mut a = series("scc1300", 1.0);
    a.rms_error[2] = f64::NAN;
    let grades = [
        a,
        series("mems-hi", 0.05),
        series("ge-2020", 3e-3),
        series("navigation", 1e-4),
    ];
    plot_error_along_md(&dir.join("along"), "azimuth error along MD", "deg", &grades)
        .expect("along");
    let (bias, arw, mut value) = grid();
    value[3][2] = f64::NAN;
    let g = vec![
        ("SCC1300".to_string(), 2.0, 0.9),
        ("navigation".to_string(), 0.003, 0.002),
    ];
    plot_sweep_contour(&dir.join("sweep"), &sweep(&bias, &arw, &value, &g)).expect("sweep");
    println!("{}", dir.display());
}
