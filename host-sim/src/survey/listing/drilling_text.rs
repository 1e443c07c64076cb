//! The drilling survey's listing (terminal) and CSV files: every angle and
//! position with its sigma; an undetermined azimuth, and every position
//! from the first one on, shown as undetermined, never as a number.

use super::drilling::{
    BitProjection, DrillingRow, DrillingSurvey, DEPTH_GAP_FLAG, UNCALIBRATED_FLAG,
    UNCALIBRATED_NOTE,
};
use super::ellipse::scale_2d;
use super::station_gaps::lost_line;
use super::trajectory::TrajectoryPoint;
use super::LengthUnit;
use mwd_core::probe::navigator::AZIMUTH_SIGMA_LIMIT_RAD;
use mwd_core::protocol::frame::station_flags;
use std::fmt::Write as _;

/// Angle and its 1-sigma, deg: "91.082+-0.064".
fn angle(value_deg: f64, sigma_rad: f64) -> String {
    format!("{value_deg:.3}+-{:.3}", sigma_rad.to_degrees())
}

/// The listing: [`top_note`], one line per station, then the skipped
/// stations ([`stations_listing`]).
pub fn listing(s: &DrillingSurvey, confidence: f64) -> String {
    top_note(s) + &stations_listing(s, confidence)
}

/// What a reader must see before anything else: for a probe that ran
/// without a calibration, [`UNCALIBRATED_NOTE`] (a line); else nothing.
pub fn top_note(s: &DrillingSurvey) -> String {
    if s.uncalibrated {
        format!("{UNCALIBRATED_NOTE}\n")
    } else {
        String::new()
    }
}

/// The listing's stations: one line per station, then the skipped
/// stations; each station's flags at the end of its line (for a probe that
/// ran without a calibration, every station and the bit).
pub fn stations_listing(s: &DrillingSurvey, confidence: f64) -> String {
    let mut out = String::new();
    let flag = station_flag(s);
    let row_flags = |r: &DrillingRow| {
        r.flags(s.uncalibrated)
            .iter()
            .map(|f| format!("  {f}"))
            .collect::<String>()
    };
    let _ = writeln!(
        out,
        "{} stations from the probe's station surveys; MD from the depth log{}; N/E along true north, m",
        s.rows.len(),
        if s.md_offset_m == 0.0 {
            String::new()
        } else {
            format!(" shifted by {:+.3} m to the tie-on MD", s.md_offset_m)
        }
    );
    let _ = writeln!(
        out,
        "uncertainty: the probe's station sigmas (azimuth carried from station to station as the \
         probe re-finds it, inclination re-levelled per station), the depth log's scale and stretch \
         (DSFS, DSTG) and the minimum-curvature method's long course lengths (XCLA, XCLH); angles \
         1-sigma; ellipse at {:.1} % (k = {:.4})",
        100.0 * confidence,
        scale_2d(confidence)
    );
    let _ = writeln!(
        out,
        "{}",
        super::tie_on_note(s.tie_on_cov_m2.as_ref(), LengthUnit::Metre)
    );
    let _ =
        writeln!(
        out,
        "{:>3} {:>9} {:>15} {:>16} {:>16} {:>9} {:>9} {:>9} {:>6} {:>6} {:>6} {:>7} {:>7} {:>5}",
        "st", "MD m", "inc deg", "azi deg", "tf deg", "TVD m", "N m", "E m", "sN m", "sE m", "sV m",
        "major m", "minor m", "az"
    );
    // A lost station's line where it would have been.
    let mut lost = s.lost.iter().peekable();
    for r in &s.rows {
        while let Some((first, last)) = lost.next_if(|(first, _)| *first < r.survey.station) {
            let _ = writeln!(out, "{}", lost_line(*first, *last));
        }
        let _ = writeln!(out, "{}{}", line(r, confidence), row_flags(r));
    }
    for (first, last) in lost {
        let _ = writeln!(out, "{}", lost_line(*first, *last));
    }
    if let (Some(bit), Some(last)) = (&s.bit, s.rows.last()) {
        let _ = writeln!(out, "{}{flag}", bit_line(bit, last, confidence));
        let _ = writeln!(
            out,
            "bit: at the depth log's end plus {:.2} m from the sensors to the bit, projected \
             {:.2} m straight ahead of station {} (its inclination and azimuth; their errors act \
             over the projection too)",
            bit.sensor_to_bit_m, bit.projected_m, last.survey.station
        );
    }
    let gaps: Vec<String> = s
        .rows
        .iter()
        .filter_map(|r| {
            r.depth_gap_s
                .map(|g| format!("{} ({g:.0} s)", r.survey.station))
        })
        .collect();
    if !gaps.is_empty() {
        let _ = writeln!(
            out,
            "{DEPTH_GAP_FLAG}: station {}: the depth log has no row for longer than {:.0} s              around the station's time, and its MD there is a straight line between the rows              each side; check the surface depth record for the interval",
            gaps.join(", "),
            s.depth_gap_limit_s
        );
    }
    if let Some(u) = s.rows.iter().find(|r| !r.position_determined) {
        let _ = writeln!(
            out,
            "note: azimuth undetermined from station {} (MD {:.2} m) on: no position from there on",
            u.survey.station, u.row.md_m
        );
    }
    let lost = |r: &&DrillingRow| r.survey.flags & station_flags::HEADING_LOST != 0;
    if let Some(l) = s.rows.iter().find(lost) {
        let _ = writeln!(
            out,
            "note: the probe lost its heading at station {} (MD {:.2} m): its azimuth sigma \
             passed {:.0} deg; no azimuth until the probe is tied in again",
            l.survey.station,
            l.row.md_m,
            AZIMUTH_SIGMA_LIMIT_RAD.to_degrees()
        );
    }
    for k in &s.skipped {
        let _ = writeln!(out, "skipped station {}: {}", k.survey.station, k.reason);
    }
    out + &qc_text(s)
}

/// The stations' quality checks: what they were checked against, one line
/// a station, and the count out of tolerance.
fn qc_text(s: &DrillingSurvey) -> String {
    let Some(reference) = &s.qc_reference else {
        return String::new();
    };
    let t = &reference.tolerances;
    let mut out = format!(
        "station QC: total gravity against the site's {:.4} m/s^2 (tolerance +-{:.4} m/s^2, 3 sigma \
         of the tool model's accelerometer terms); the cross-axis gyros' rates against the earth \
         rate the station's attitude predicts (tolerance 3.44 sigma of the gyro terms, {:.1} deg/h \
         an axis, and of the azimuth sigma)\n",
        reference.gravity_m_s2,
        t.gravity_m_s2,
        t.gyro_sigma_deg_h()
    );
    let mut out_of_tolerance = Vec::new();
    for r in &s.rows {
        let Some(q) = &r.qc else {
            let _ = writeln!(
                out,
                "  station {:>3}: not checked (its samples are not all in the capture)",
                r.survey.station
            );
            continue;
        };
        let rate = match (q.earth_rate_deg_h(), q.earth_rate_ok()) {
            (Some((res, tol)), Some(ok)) => format!(
                "earth-rate residual {res:.1} deg/h (tolerance {tol:.1}) {}",
                if ok { "ok" } else { "OUT" }
            ),
            _ => "earth rate not checked (azimuth undetermined)".into(),
        };
        let _ = writeln!(
            out,
            "  station {:>3}: gravity {:.4} m/s^2 ({:+.2} mg) {}; {rate}",
            r.survey.station,
            q.gravity_m_s2,
            q.gravity_error_mg(),
            if q.gravity_ok() { "ok" } else { "OUT" }
        );
        if !q.ok() {
            out_of_tolerance.push(r.survey.station.to_string());
        }
    }
    let checked = s.rows.iter().filter(|r| r.qc.is_some()).count();
    let _ = writeln!(
        out,
        "station QC: {} of {checked} stations checked out of tolerance{}",
        out_of_tolerance.len(),
        if out_of_tolerance.is_empty() {
            String::new()
        } else {
            format!(
                " (stations {}): their sensors disagree with the earth at the site; check the \
                 calibration and whether the probe was still",
                out_of_tolerance.join(", ")
            )
        }
    );
    out
}

/// What ends each station's line: "  uncalibrated" for a probe that ran
/// without a calibration, else nothing.
fn station_flag(s: &DrillingSurvey) -> String {
    if s.uncalibrated {
        format!("  {UNCALIBRATED_FLAG}")
    } else {
        String::new()
    }
}

fn line(r: &DrillingRow, confidence: f64) -> String {
    let sd = r.survey.angles_std.map(f64::from);
    let azi = if r.azimuth_determined {
        angle(r.row.azi_deg, sd[1])
    } else {
        "undetermined".into()
    };
    let tf = match r.row.input.toolface_deg {
        Some(tf) if sd[2].is_finite() => angle(tf, sd[2]),
        _ => "n/a".into(),
    };
    let text = format!(
        "{:>3} {:>9.2} {:>15} {:>16} {:>16}",
        r.survey.station,
        r.row.md_m,
        angle(r.row.inc_deg, sd[0]),
        azi,
        tf
    );
    text + &position_text(&r.row, r.position_determined, confidence)
}

/// The listing's position columns, or "position undetermined".
fn position_text(row: &super::Row, determined: bool, confidence: f64) -> String {
    match position_numbers(row, determined, confidence) {
        Some([tvd, n, e, sn, se, sv, a, b, az]) => format!(
            " {tvd:>9.2} {n:>9.2} {e:>9.2} {sn:>6.2} {se:>6.2} {sv:>6.2} {a:>7.2} {b:>7.2} {az:>5.1}"
        ),
        None => "  position undetermined".into(),
    }
}

/// TVD, north, east, their sigmas (north, east, vertical), the ellipse's
/// semi-axes at `confidence` and its azimuth; `None` where undetermined.
fn position_numbers(row: &super::Row, determined: bool, confidence: f64) -> Option<[f64; 9]> {
    let (c, e) = (row.cov.filter(|_| determined)?, row.ellipse()?);
    let (a, b) = e.scaled(confidence);
    Some([
        row.tvd_m,
        row.north_m,
        row.east_m,
        c[0].max(0.0).sqrt(),
        c[1].max(0.0).sqrt(),
        e.sigma_vert,
        a,
        b,
        e.azimuth_deg,
    ])
}

/// The bit's line: the last station's angles (and sigmas) held straight
/// ahead, "projected" where the toolface would be.
fn bit_line(bit: &BitProjection, last: &DrillingRow, confidence: f64) -> String {
    let sd = last.survey.angles_std.map(f64::from);
    let azi = if last.azimuth_determined {
        angle(bit.row.azi_deg, sd[1])
    } else {
        "undetermined".into()
    };
    let text = format!(
        "{:>3} {:>9.2} {:>15} {:>16} {:>16}",
        "bit",
        bit.row.md_m,
        angle(bit.row.inc_deg, sd[0]),
        azi,
        "projected"
    );
    text + &position_text(&bit.row, bit.row.cov.is_some(), confidence)
}

fn opt(v: Option<f64>) -> String {
    v.map_or_else(String::new, |v| v.to_string())
}

/// Position columns, empty where undetermined.
fn position_cells(row: &super::Row, determined: bool, confidence: f64) -> String {
    match position_numbers(row, determined, confidence) {
        Some(v) => v.map(|x| x.to_string()).join(","),
        None => ",,,,,,,,".into(),
    }
}

const POSITION_HEADER: &str = "tvd_m,north_m,east_m,sigma_north_m,sigma_east_m,sigma_vert_m,\
ellipse_semi_major_m,ellipse_semi_minor_m,ellipse_azimuth_deg";

/// The stations as CSV (angles in deg, sigmas 1-sigma; empty cells:
/// undetermined). Where a station has a flag: one more column, `flag`,
/// each row's flags separated by "; " ("uncalibrated" on every row of a
/// probe that ran without a calibration).
pub fn stations_csv(s: &DrillingSurvey, confidence: f64) -> String {
    let any_flag = s.uncalibrated || s.rows.iter().any(|r| !r.flags(false).is_empty());
    let flag_header = if any_flag { ",flag" } else { "" };
    let row_flag = |r: &DrillingRow| {
        if any_flag {
            format!(",{}", r.flags(s.uncalibrated).join("; "))
        } else {
            String::new()
        }
    };
    let flag = if s.uncalibrated {
        format!(",{UNCALIBRATED_FLAG}")
    } else if any_flag {
        ",".to_string()
    } else {
        String::new()
    };
    let mut out = format!(
        "station,time_s,md_m,inc_deg,sigma_inc_deg,azi_deg,sigma_azi_deg,toolface_deg,sigma_toolface_deg,\
         corr_inc_azi,{POSITION_HEADER},confidence,qc,gravity_m_s2,gravity_error_m_s2,\
         earth_rate_residual_deg_h,earth_rate_tolerance_deg_h{flag_header}\n"
    );
    for r in &s.rows {
        let sd = r.survey.angles_std.map(f64::from);
        let (azi, s_azi, corr) = if r.azimuth_determined {
            (
                Some(r.row.azi_deg),
                Some(sd[1].to_degrees()),
                Some(f64::from(r.survey.correlations[0])),
            )
        } else {
            (None, None, None)
        };
        let qc = r.qc.as_ref();
        let rate = qc.and_then(|q| q.earth_rate_deg_h());
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{confidence},{},{},{},{},{}{}",
            r.survey.station,
            r.time_s,
            r.row.md_m,
            r.row.inc_deg,
            sd[0].to_degrees(),
            opt(azi),
            opt(s_azi),
            opt(r.row.input.toolface_deg),
            sd[2].to_degrees(),
            opt(corr.filter(|c| c.is_finite())),
            position_cells(&r.row, r.position_determined, confidence),
            qc.map_or("not checked", |q| q.word()),
            opt(qc.map(|q| q.gravity_m_s2)),
            opt(qc.map(|q| q.gravity_error_m_s2)),
            opt(rate.map(|r| r.0)),
            opt(rate.map(|r| r.1)),
            row_flag(r)
        );
    }
    if let (Some(bit), Some(last)) = (&s.bit, s.rows.last()) {
        // the bit: "bit" for the station number, no time, the last
        // station's angles and sigmas, no toolface
        let sd = last.survey.angles_std.map(f64::from);
        let determined = last.azimuth_determined;
        let _ = writeln!(
            out,
            "bit,,{},{},{},{},{},,,{},{},{confidence},,,,,{flag}",
            bit.row.md_m,
            bit.row.inc_deg,
            sd[0].to_degrees(),
            opt(determined.then_some(bit.row.azi_deg)),
            opt(determined.then_some(sd[1].to_degrees())),
            opt(determined
                .then_some(f64::from(last.survey.correlations[0]))
                .filter(|c| c.is_finite())),
            position_cells(&bit.row, bit.row.cov.is_some(), confidence)
        );
    }
    out
}

/// The continuous trajectory as CSV.
pub fn trajectory_csv(points: &[TrajectoryPoint], confidence: f64) -> String {
    let mut out = format!(
        "md_m,time_s,inc_deg,sigma_inc_deg,azi_deg,sigma_azi_deg,{POSITION_HEADER},confidence\n"
    );
    for p in points {
        let (azi, s_azi) = if p.azimuth_determined {
            (Some(p.row.azi_deg), Some(p.sigma_azi.to_degrees()))
        } else {
            (None, None)
        };
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{confidence}",
            p.row.md_m,
            p.time_s,
            p.row.inc_deg,
            p.sigma_inc.to_degrees(),
            opt(azi),
            opt(s_azi),
            position_cells(&p.row, p.position_determined, confidence)
        );
    }
    out
}
