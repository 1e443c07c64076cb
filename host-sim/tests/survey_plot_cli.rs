//! `host-sim survey --plot DIR` through the binary: the four figures of
//! ISCWSA test well #1 with ISCWSA MWD Rev5 (SVG well-formed with one
//! ellipse per station that has a covariance, PNG decodable, sized and
//! drawn on), stations beyond a model's validity without ellipse, and a
//! file in the way of DIR refused.

mod common;

use common::{s, well1, Run, WELL1_SITE};
use host_sim::survey::listing::plot::{ELLIPSE_COLOUR, SIZE};
use std::path::{Path, PathBuf};

fn host_sim(args: &[&str]) -> Run {
    common::run(&[&["survey"], args].concat())
}

fn scratch(name: &str) -> PathBuf {
    common::scratch("survey-plot", name)
}

/// Runs well #1 with `model` and `--plot`, and returns the plot directory
/// and the number of stations the JSON export gives a covariance.
fn plotted(name: &str, model: &str) -> (PathBuf, usize, usize) {
    let dir = scratch(name);
    let plots = dir.join("figures"); // not there yet: created by the tool
    let json = dir.join("survey.json");
    let well = well1();
    let mut args = vec![s(&well)];
    args.extend_from_slice(&WELL1_SITE);
    args.extend_from_slice(&[
        "--error-model",
        model,
        "--json",
        s(&json),
        "--plot",
        s(&plots),
    ]);
    let run = host_sim(&args);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let stations = doc["stations"].as_array().unwrap();
    let with_cov = stations
        .iter()
        .filter(|st| st["nev_covariance_m2"].is_array())
        .count();
    (plots, with_cov, stations.len())
}

/// The number of `<polyline>`s stroked in the ellipse colour, after checking
/// the SVG parses as XML.
fn ellipses_in(svg: &Path) -> usize {
    let text = std::fs::read_to_string(svg).unwrap();
    let doc = roxmltree::Document::parse(&text)
        .unwrap_or_else(|e| panic!("{} is not well-formed XML: {e}", svg.display()));
    let colour = format!(
        "#{:02X}{:02X}{:02X}",
        ELLIPSE_COLOUR.0, ELLIPSE_COLOUR.1, ELLIPSE_COLOUR.2
    );
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    doc.descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .filter(|n| {
            n.attribute("stroke")
                .is_some_and(|c| c.eq_ignore_ascii_case(&colour))
        })
        .count()
}

fn svg_text(svg: &Path) -> String {
    let text = std::fs::read_to_string(svg).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    doc.descendants()
        .filter_map(|n| n.text())
        .collect::<Vec<_>>()
        .join("\n")
}

/// Decodes a PNG; returns (width, height, pixels differing from the
/// top-left corner's colour, the background).
fn png_stats(path: &Path) -> (u32, u32, usize) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let bytes = &buf[..info.buffer_size()];
    let channels = info.color_type.samples();
    let background = &bytes[..channels];
    let drawn = bytes
        .chunks_exact(channels)
        .filter(|px| *px != background)
        .count();
    (info.width, info.height, drawn)
}

#[test]
fn well1_mwd_rev5_figures() {
    let (dir, with_cov, n) = plotted("rev5", "ISCWSA MWD Rev5");
    // Rev5 is stated for every inclination: every station has one
    assert_eq!(with_cov, n);
    for stem in ["plan", "section"] {
        let svg = dir.join(format!("{stem}.svg"));
        assert_eq!(ellipses_in(&svg), with_cov, "{}", svg.display());
        let text = svg_text(&svg);
        assert!(text.contains("ISCWSA MWD Rev5"), "{text}");
        assert!(text.contains("2-sigma"), "{text}");
        assert!(text.contains("(m,"), "unit missing: {text}");
        let (w, h, drawn) = png_stats(&dir.join(format!("{stem}.png")));
        assert_eq!((w, h), SIZE);
        // path, ellipses, axes and text: far more than a few pixels
        assert!(drawn > 5_000, "{stem}.png: only {drawn} pixels drawn");
    }
    assert!(svg_text(&dir.join("plan.svg")).contains("north"));
    assert!(svg_text(&dir.join("section.svg")).contains("TVD"));
}

#[test]
fn stations_beyond_the_model_get_no_ellipse() {
    // GYRO-MWD is stated up to 89 deg; well #1 reaches 90 deg
    let (dir, with_cov, n) = plotted("gyro", "GYRO-MWD");
    assert!(with_cov > 0 && with_cov < n, "{with_cov} of {n}");
    for stem in ["plan", "section"] {
        let svg = dir.join(format!("{stem}.svg"));
        assert_eq!(ellipses_in(&svg), with_cov);
        assert!(svg_text(&svg).contains("no ellipse from MD"));
    }
}

#[test]
fn without_model_path_only() {
    let dir = scratch("none");
    let plots = dir.join("figures");
    let run = host_sim(&[s(&well1()), "--plot", s(&plots)]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    for stem in ["plan", "section"] {
        let svg = plots.join(format!("{stem}.svg"));
        assert_eq!(ellipses_in(&svg), 0);
        assert!(svg_text(&svg).contains("no error model"));
        let (w, h, drawn) = png_stats(&plots.join(format!("{stem}.png")));
        assert_eq!((w, h), SIZE);
        assert!(drawn > 1_000);
    }
}

#[test]
fn plot_onto_a_file_is_refused() {
    let dir = scratch("file");
    let file = dir.join("not-a-dir");
    std::fs::write(&file, "x").unwrap();
    let run = host_sim(&[s(&well1()), "--plot", s(&file)]);
    assert!(matches!(run.code, Some(1)), "exit {:?}", run.code);
    assert!(
        run.stderr.contains("is not a directory"),
        "stderr: {}",
        run.stderr
    );
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
    // the file is left alone
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
}

#[test]
fn offset_well_is_drawn_without_ellipses() {
    let dir = scratch("offset");
    let plots = dir.join("figures");
    let json = dir.join("survey.json");
    let well = well1();
    let mut args = vec![s(&well)];
    args.extend_from_slice(&WELL1_SITE);
    args.extend_from_slice(&[
        "--error-model",
        "ISCWSA MWD Rev5",
        "--offset",
        s(&well),
        "--offset-tie-on-north",
        "30",
        "--hole-radius-m",
        "0.1",
        "--offset-hole-radius-m",
        "0.1",
        "--json",
        s(&json),
        "--plot",
        s(&plots),
    ]);
    let run = host_sim(&args);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let n = doc["stations"].as_array().unwrap().len();
    for stem in ["plan", "section"] {
        let svg = plots.join(format!("{stem}.svg"));
        // the reference well's ellipses only
        assert_eq!(ellipses_in(&svg), n);
        assert!(svg_text(&svg).contains("offset well well1_stations.csv"));
    }
}

#[test]
fn feet_file_plotted_in_feet() {
    let dir = scratch("feet");
    let path = dir.join("ft.csv");
    std::fs::write(
        &path,
        "md_ft,inc_deg,azi_deg\n0,0,0\n1000,10,45\n2000,20,45\n3000,30,45\n",
    )
    .unwrap();
    let plots = dir.join("figures");
    let run = host_sim(&[s(&path), "--plot", s(&plots)]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    for stem in ["plan", "section"] {
        let text = svg_text(&plots.join(format!("{stem}.svg")));
        assert!(text.contains("(ft"), "{text}");
        assert!(!text.contains("(m,") && !text.contains("(m)"), "{text}");
    }
    // TVD axis labels in feet: the well reaches ~2850 ft TVD, ~870 m
    let section = svg_text(&plots.join("section.svg"));
    assert!(section.lines().any(|l| l.trim() == "2500"), "{section}");
}
