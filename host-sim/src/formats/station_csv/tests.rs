//! The station file reader's tests: spellings, separators, units, ranges
//! and refusals, and the files the tool writes read back.

use super::*;

fn read(text: &str) -> Result<StationFile> {
    read_stations(text.as_bytes())
}

fn refused(text: &str, needle: &str) {
    let e = format!("{:#}", read(text).unwrap_err());
    assert!(e.contains(needle), "`{e}` lacks `{needle}`");
}

/// MD, inclination and azimuth of every station.
fn angles(f: &StationFile) -> Vec<[f64; 3]> {
    f.stations
        .iter()
        .map(|s| [s.md, s.inc_deg, s.azi_deg])
        .collect()
}

const ROWS: &str = "0,0,0\n30,1.5,10\n";

fn expect_rows(f: &StationFile) {
    assert_eq!(angles(f), [[0.0, 0.0, 0.0], [30.0, 1.5, 10.0]]);
}

#[test]
fn md_spellings_and_their_units() {
    for (md, unit) in [
        ("md_m", LengthUnit::Metre),
        ("MD (m)", LengthUnit::Metre),
        (" Depth[m] ", LengthUnit::Metre),
        ("measured depth m", LengthUnit::Metre),
        ("Measured_Depth_M", LengthUnit::Metre),
        ("md_ft", LengthUnit::Foot),
        ("MD [ft]", LengthUnit::Foot),
        ("Depth(ft)", LengthUnit::Foot),
        ("depth feet", LengthUnit::Foot),
        ("MD (usft)", LengthUnit::Foot),
    ] {
        let f = read(&format!("{md},inc_deg,azi_deg\n{ROWS}")).unwrap();
        assert_eq!(f.unit, unit, "{md}");
        expect_rows(&f);
    }
}

#[test]
fn angle_spellings() {
    for inc in [
        "inc",
        "INCL",
        "Inclination",
        "inc_deg",
        "Inc (deg)",
        "incl [deg]",
    ] {
        for azi in [
            "azi",
            "Az",
            "AZIMUTH",
            "azi_deg",
            "Azimuth (deg)",
            "azi_true_deg",
        ] {
            let f = read(&format!("md_m,{inc},{azi}\n{ROWS}")).unwrap();
            expect_rows(&f);
        }
    }
}

#[test]
fn toolface_and_time_spellings() {
    for tf in ["toolface_deg", "toolface", "TF", "Toolface (deg)"] {
        for time in ["time_s", "Time (s)", "TIME [s]"] {
            let f = read(&format!(
                "md_m,inc,azi,{tf},{time}\n0,0,0,5,1\n30,1,10,,2\n"
            ))
            .unwrap();
            assert_eq!(f.stations[0].toolface_deg, Some(5.0), "{tf}");
            assert_eq!(f.stations[1].toolface_deg, None);
            assert_eq!(f.stations[1].time_s, Some(2.0), "{time}");
        }
    }
    // a time without a unit (maybe a clock time) is not read
    let f = read("md_m,inc,azi,time\n0,0,0,12:00\n30,1,10,12:05\n").unwrap();
    assert_eq!(f.stations[0].time_s, None);
}

#[test]
fn separators_and_other_columns() {
    for text in [
        "MD (m);Inc (deg);TVD (m);Azi (deg)\n0;0;0;0\n30;1.5;30;10\n",
        "MD (m)\tInc (deg)\tTVD (m)\tAzi (deg)\n0\t0\t0\t0\n30\t1.5\t30\t10\n",
        "md_m inc_deg tvd_m azi_deg\n0 0 0 0\n30 1.5 30 10\n",
        "MD [m],Inc,Azi,TVD [m],N [m],E [m],DLS [deg/30m]\n0,0,0,0,0,0,0\n30,1.5,10,30,0,0,1.5\n",
    ] {
        expect_rows(&read(text).unwrap());
    }
}

#[test]
fn values_outside_their_ranges_are_refused_by_line() {
    for (row, needle) in [
        ("100,10,400", "line 3: azimuth 400 deg outside 0..360"),
        ("100,10,-30", "line 3: azimuth -30 deg outside 0..360"),
        ("100,10,1e300", "line 3: azimuth 1e300 deg outside 0..360"),
        ("1e300,10,30", "line 3: MD 1e300 m outside 0..20000"),
        ("100,190,30", "line 3: inclination 190 deg outside 0..180"),
        (
            "100,10,30,720",
            "line 3: toolface 720 deg outside -360..360",
        ),
    ] {
        refused(&format!("md_m,inc,azi,tf\n0,0,0,\n{row}\n"), needle);
    }
    refused("md_m,inc,azi\n-5,0,0\n", "line 2: MD -5 m outside 0..20000");
    refused(
        "md_m,inc,azi\n0,0,0\n30,90,\n",
        "line 3: no azi (an empty cell: undetermined at this station)",
    );
    // the limit in the file's unit: 20,000 m is 65,616 ft
    refused("md_ft,inc,azi\n65700,0,0\n", "MD 65700 ft outside 0..65616");
    assert!(read("md_ft,inc,azi\n65000,0,360\n").is_ok());
}

#[test]
fn refusals() {
    refused(
        "MD,inc,azi\n0,0,0\n",
        "line 1: the MD column `MD` has no unit: name it with one, e.g. \"MD (m)\" or \"md_ft\"",
    );
    refused(
        "# made by X\nDepth,inc,azi\n0,0,0\n",
        "line 2: the MD column `Depth` has no unit",
    );
    refused(
        "MD (km),inc,azi\n0,0,0\n",
        "the MD column `MD (km)` is in `km`",
    );
    refused(
        "md_m,Inc (rad),azi\n0,0,0\n",
        "column `Inc (rad)`: the inclination is in `rad`, not degrees",
    );
    refused(
        "md_m,inc,azi_grad\n0,0,0\n",
        "column `azi_grad`: the azimuth is in `grad`",
    );
    refused(
        "md_m,inc,azi,tf (rad)\n0,0,0,0\n",
        "column `tf (rad)`: the toolface",
    );
    refused(
        "md_m,Depth (m),inc,azi\n0,0,0,0\n",
        "columns `md_m` and `Depth (m)` both give the MD",
    );
    refused(
        "md_m,inc,incl,azi\n0,0,0,0\n",
        "columns `inc` and `incl` both give the inclination",
    );
    refused(
        "md_m,inc,az,azimuth\n0,0,0,0\n",
        "columns `az` and `azimuth` both give the azimuth",
    );
    refused(
        "MD (ft),inc,azi,TVD (m)\n0,0,0,0\n",
        "mixes feet and metres (TVD (m) and MD (ft))",
    );
    refused("md_m,inc,azi_grid_deg\n0,0,0\n", "no column azi_deg");
    refused(
        "depth_m,inc,azi\n0,x,0\n",
        "line 2: inc `x` is not a number",
    );
}

/// The stations CSV of a capture survey (`stations_csv`): its `bit`
/// row is skipped.
#[test]
fn capture_stations_csv_and_its_bit_row() {
    let text = "station,time_s,md_m,inc_deg,sigma_inc_deg,azi_deg,sigma_azi_deg,toolface_deg,\
        sigma_toolface_deg,corr_inc_azi,tvd_m,north_m,east_m,sigma_north_m,sigma_east_m,\
        sigma_vert_m,ellipse_semi_major_m,ellipse_semi_minor_m,ellipse_azimuth_deg,confidence\n\
        1,10,0,0,0.1,0,0.5,20,1,0.1,0,0,0,0,0,0,0,0,0,0.95\n\
        2,80,30,1.5,0.1,10,0.5,,1,0.1,30,0,0,0,0,0,0,0,0,0.95\n\
        bit,,42,1.5,0.1,10,0.5,,,0.1,42,0,0,0,0,0,0,0,0,0.95\n";
    let f = read(text).unwrap();
    expect_rows(&f);
    assert_eq!(f.stations[0].toolface_deg, Some(20.0));
    assert_eq!(f.stations[1].time_s, Some(80.0));
}

/// Every station-like file of tests/data/iscwsa is read, in its unit.
#[test]
fn iscwsa_station_files() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/iscwsa");
    for (name, unit) in [
        ("well1_stations.csv", LengthUnit::Metre),
        ("well1_survey.csv", LengthUnit::Metre),
        ("well2_survey.csv", LengthUnit::Foot),
        ("well3_survey.csv", LengthUnit::Metre),
    ] {
        let text = std::fs::read_to_string(dir.join(name)).unwrap();
        let f = read(&text).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        assert_eq!(f.unit, unit, "{name}");
        let rows = text.lines().filter(|l| !l.trim().is_empty()).count() - 1;
        assert_eq!(f.stations.len(), rows, "{name}");
    }
}

#[test]
fn lengths_variances_and_dogleg_severity_convert_to_feet() {
    let ft = LengthUnit::Foot;
    assert!((ft.from_m(30.48) - 100.0).abs() < 1e-12);
    assert!((ft.from_m2(0.3048 * 0.3048 * 4.0) - 4.0).abs() < 1e-12);
    // 3 deg over 30 m is 3.048 deg over 100 ft (30.48 m)
    assert!((ft.dls_from_per_30m(3.0) - 3.048).abs() < 1e-12);
    assert_eq!(LengthUnit::Metre.dls_from_per_30m(3.0), 3.0);
    assert_eq!((ft.symbol(), ft.dls_course().1), ("ft", "100ft"));
}

#[test]
fn an_md_column_without_a_unit_takes_the_declared_one() {
    let text = "MD;Inc;Azi\n0;0;0\n100;3;10\n";
    let f = read_stations_in(
        text.as_bytes(),
        StationReading::in_unit(Some(LengthUnit::Foot)),
    )
    .unwrap();
    assert_eq!(f.unit, LengthUnit::Foot);
    // the header's own unit stands
    let f = read_stations_in(
        "md_m,inc,azi\n0,0,0\n".as_bytes(),
        StationReading::in_unit(Some(LengthUnit::Foot)),
    );
    assert_eq!(f.unwrap().unit, LengthUnit::Metre);
    let e = read_stations_in(
        "MD,Inc,Azi,TVD (m)\n0,0,0,0\n".as_bytes(),
        StationReading::in_unit(Some(LengthUnit::Foot)),
    )
    .unwrap_err();
    assert!(format!("{e:#}").contains("other unit"), "{e:#}");
    refused(text, "--units");
}

#[test]
fn wrap_azimuth_wraps_within_one_turn_and_refuses_the_rest() {
    let wrapping = StationReading {
        wrap_azimuth: true,
        ..StationReading::default()
    };
    let text = "md_m,inc,azi\n0,0,0\n100,10,400\n200,20,-30\n300,30,719.5\n";
    let f = read_stations_in(text.as_bytes(), wrapping).unwrap();
    let azimuths: Vec<f64> = f.stations.iter().map(|s| s.azi_deg).collect();
    assert_eq!(azimuths, [0.0, 40.0, 330.0, 359.5]);
    // Without the option the same file is refused, naming the option.
    let e = format!("{:#}", read(text).unwrap_err());
    assert!(
        e.contains("line 3: azimuth 400") && e.contains("--wrap-azimuth"),
        "{e}"
    );
    // Far outside a turn, or not a number: refused even when wrapping.
    for bad in ["1e300", "720", "-361", "NaN"] {
        let text = format!("md_m,inc,azi\n0,0,0\n100,10,{bad}\n");
        assert!(
            read_stations_in(text.as_bytes(), wrapping).is_err(),
            "{bad}"
        );
    }
}
