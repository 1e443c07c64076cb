//! The replay's rows as CSV (`host-sim replay --csv`): the header, and the
//! rows a file replay writes at once or a live one as they settle.

use std::io::{self, Write};

use mwd_core::conventions::{DrillingAngles, Euler};
use mwd_core::protocol::NavSolution;

use crate::formats::display;
use crate::replay::rows::ReplayRow;

/// CSV columns of [`write_csv`]: SI inside, degrees at this edge. Azimuth
/// and toolface in [0, 360); the azimuth is empty unless determined
/// (`azimuth_status`: determined, undetermined, lost, n/a: `display::AzimuthStatus`); NaN is a placeholder
/// (no estimate yet). `matches_probe`: yes, no, unchecked (the replay was
/// out of step), empty (no probe solution).
pub const CSV_HEADER: &str = "sample,time_s,mode,flags,roll_deg,pitch_deg,\
inclination_deg,azimuth_deg,azimuth_status,toolface_deg,\
vn_m_s,ve_m_s,vd_m_s,lat_deg,lon_deg,height_m,roll_std_deg,pitch_std_deg,azimuth_std_deg,\
matches_probe";

/// Writes the replayed solutions as CSV, one row per raw frame.
pub fn write_csv(rows: &[ReplayRow], mut out: impl Write) -> io::Result<()> {
    writeln!(out, "{CSV_HEADER}")?;
    write_csv_rows(rows, &mut out)?;
    out.flush()
}

/// Writes rows without the header (a live replay writes them as they
/// settle).
pub fn write_csv_rows(rows: &[ReplayRow], mut out: impl Write) -> io::Result<()> {
    for row in rows {
        let s = &row.solution;
        let deg = |a: f32| f64::from(a).to_degrees();
        let [roll, pitch, heading] = s.attitude.map(f64::from);
        let [roll_std, pitch_std, heading_std] = s.attitude_std.map(deg);
        let drilling = DrillingAngles::from_euler(&Euler::new(roll, pitch, heading));
        let (azimuth, status) = azimuth_cells(s);
        let [vn, ve, vd] = s.velocity_ned;
        let matches = match (row.in_step, row.matches_probe) {
            (false, _) => "unchecked",
            (true, Some(true)) => "yes",
            (true, Some(false)) => "no",
            (true, None) => "",
        };
        writeln!(
            out,
            "{},{:.6},{},{},{:.6},{:.6},{:.6},{azimuth},{status},{:.6},{vn},{ve},{vd},{:.9},{:.9},{},\
             {roll_std:.6},{pitch_std:.6},{heading_std:.6},{matches}",
            s.sample_counter,
            s.time_us as f64 * 1e-6,
            s.mode,
            s.flags,
            roll.to_degrees(),
            pitch.to_degrees(),
            drilling.inclination.to_degrees(),
            angle_0_360(roll),
            s.latitude.to_degrees(),
            s.longitude.to_degrees(),
            s.height,
        )?;
    }
    Ok(())
}

/// Toolface (or any angle) in [0, 360) deg, NaN kept as the placeholder.
fn angle_0_360(angle_rad: f64) -> f64 {
    if angle_rad.is_finite() {
        display::deg_0_360(angle_rad)
    } else {
        f64::NAN
    }
}

/// The azimuth cell (empty unless determined, deg) and its status
/// ([`display::AzimuthStatus`]).
pub fn azimuth_cells(s: &NavSolution) -> (String, &'static str) {
    match display::AzimuthStatus::of_nav(s) {
        display::AzimuthStatus::Determined => (
            format!("{:.6}", display::deg_0_360(f64::from(s.attitude[2]))),
            "determined",
        ),
        status => (String::new(), status.word()),
    }
}
