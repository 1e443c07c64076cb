//! A capture's frames as CSV, one row a frame; the columns of the other
//! kinds stay empty.

use std::fmt;
use std::io::{self, Write};

use mwd_core::protocol::frame::{Payload, RawSample};
use mwd_core::protocol::Frame;
use mwd_core::sensor_units::{self, GYRO_TEMPERATURE};

use crate::formats::display::AzimuthStatus;

/// Columns of the CSV export: every frame is one row; the columns of the
/// other kinds stay empty. Raw counts come with their SI values (part axes).
pub const CSV_HEADER: &str = "seq,kind,time_us,sample_counter,\
p1_gyro_count,p1_gyro_temp_count,p1_ax_count,p1_ay_count,p1_az_count,p1_accel_temp_count,p1_flags,\
p2_gyro_count,p2_gyro_temp_count,p2_ax_count,p2_ay_count,p2_az_count,p2_accel_temp_count,p2_flags,\
p1_rate_rad_s,p1_ax_m_s2,p1_ay_m_s2,p1_az_m_s2,p1_gyro_temp_degc,\
p2_rate_rad_s,p2_ax_m_s2,p2_ay_m_s2,p2_az_m_s2,p2_gyro_temp_degc,\
nav_mode,nav_flags,roll_rad,pitch_rad,azimuth_rad,azimuth_status,vn_m_s,ve_m_s,vd_m_s,lat_rad,lon_rad,height_m,\
sd_roll_rad,sd_pitch_rad,sd_azimuth_rad,sd_vn_m_s,sd_ve_m_s,sd_vd_m_s,sd_pn_m,sd_pe_m,sd_pd_m,\
event,event_part,event_code,event_value,\
st_number,st_flags,st_start_sample,st_end_sample,st_inclination_rad,st_azimuth_rad,st_azimuth_status,\
st_toolface_rad,st_sd_inclination_rad,st_sd_azimuth_rad,st_sd_toolface_rad,\
st_corr_inc_azi,st_corr_inc_tf,st_corr_azi_tf,st_still_quality";

const RAW_COLS: usize = 24;
const NAV_COLS: usize = 21;
const EVENT_COLS: usize = 4;
const STATION_COLS: usize = 15;

fn empties(n: usize) -> String {
    ",".repeat(n)
}

fn join<T: fmt::Display>(values: impl IntoIterator<Item = T>) -> String {
    values
        .into_iter()
        .map(|v| format!(",{v}"))
        .collect::<String>()
}

/// Writes all frames as CSV (see [`CSV_HEADER`]).
pub fn write_csv(frames: &[Frame], mut out: impl Write) -> io::Result<()> {
    writeln!(out, "{CSV_HEADER}")?;
    for frame in frames {
        write_csv_row(frame, &mut out)?;
    }
    out.flush()
}

/// Writes one frame as a row of the CSV export (after [`CSV_HEADER`]).
pub fn write_csv_row(frame: &Frame, mut out: impl Write) -> io::Result<()> {
    let (kind, body) = match &frame.payload {
        Payload::Raw(r) => ("raw", raw_csv(r)),
        Payload::Nav(n) => {
            let mut cells = format!(",{},{}", n.time_us, n.sample_counter);
            cells += &empties(RAW_COLS);
            cells += &join([n.mode as u32, n.flags as u32]);
            cells += &join(&n.attitude[..2]);
            cells += &azimuth_cells(n);
            cells += &join(n.velocity_ned);
            cells += &join([n.latitude, n.longitude]);
            cells += &join(
                std::iter::once(&n.height)
                    .chain(&n.attitude_std)
                    .chain(&n.velocity_std)
                    .chain(&n.position_std_ned),
            );
            cells += &empties(EVENT_COLS + STATION_COLS);
            ("nav", cells)
        }
        Payload::Event(e) => {
            let mut cells = format!(",{},", e.time_us);
            cells += &empties(RAW_COLS + NAV_COLS);
            cells += &join([
                e.kind.to_byte() as u32,
                e.part as u32,
                e.code as u32,
                e.value,
            ]);
            cells += &empties(STATION_COLS);
            ("event", cells)
        }
        Payload::Station(st) => {
            // The end sample goes in the sample_counter column.
            let mut cells = format!(",{},{}", st.time_us, st.end_sample);
            cells += &empties(RAW_COLS + NAV_COLS + EVENT_COLS);
            cells += &join([
                u32::from(st.station),
                u32::from(st.flags),
                st.start_sample,
                st.end_sample,
            ]);
            cells += &join([st.angles[0]]);
            cells += &station_azimuth_cells(st);
            cells += &join(
                [st.angles[2]]
                    .iter()
                    .chain(&st.angles_std)
                    .chain(&st.correlations)
                    .chain([&st.still_quality]),
            );
            ("station", cells)
        }
    };
    writeln!(out, "{},{kind}{body}", frame.seq)
}

/// The azimuth and its status ([`AzimuthStatus`]): in [0, 2 pi) rad when
/// determined, empty when not.
fn azimuth_cells(n: &mwd_core::protocol::NavSolution) -> String {
    match AzimuthStatus::of_nav(n) {
        AzimuthStatus::Determined => {
            let wrapped = crate::formats::display::deg_0_360(f64::from(n.attitude[2])).to_radians();
            format!(",{},determined", wrapped as f32)
        }
        status => format!(",,{}", status.word()),
    }
}

/// The same for a station survey.
fn station_azimuth_cells(st: &mwd_core::protocol::StationSurvey) -> String {
    match AzimuthStatus::of_station(st) {
        AzimuthStatus::Determined => format!(",{},determined", st.angles[1]),
        status => format!(",,{}", status.word()),
    }
}

fn raw_csv(r: &RawSample) -> String {
    let mut cells = format!(",{},{}", r.time_us, r.sample_counter);
    for p in &r.parts {
        cells += &join(
            [p.gyro_rate, p.gyro_temp]
                .iter()
                .chain(&p.accel)
                .chain(&[p.accel_temp]),
        );
        cells += &format!(",{}", p.flags);
    }
    for p in &r.parts {
        let acc = p.accel.map(sensor_units::accel_count_to_m_s2);
        cells += &join(
            std::iter::once(sensor_units::gyro_count_to_rad_s(p.gyro_rate))
                .chain(acc)
                .chain([GYRO_TEMPERATURE.count_to_degc(p.gyro_temp)]),
        );
    }
    cells + &empties(NAV_COLS + EVENT_COLS + STATION_COLS)
}
