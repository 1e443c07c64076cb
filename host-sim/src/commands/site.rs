//! The site of a run, as every command that needs one takes it: `--lat`,
//! `--lon`, `--height`, by default the MGWD paper's test site. Each is
//! checked when parsed: latitude -90..90 deg, longitude -180..360 deg,
//! height -15,000..10,000 m (below the deepest well, above the highest
//! ground).
use super::limits::number_in;
use host_sim::paper::mgwd::PUBLISHED;
use mwd_core::conventions::{Euler, DEG};
use mwd_core::earth::Position;

/// Latitude range, degrees.
pub const LATITUDE_DEG: (f64, f64) = (-90.0, 90.0);
/// Longitude range, degrees (east of Greenwich as -180..180 or 0..360).
pub const LONGITUDE_DEG: (f64, f64) = (-180.0, 360.0);
/// Height range above the ellipsoid, metres.
pub const HEIGHT_M: (f64, f64) = (-15_000.0, 10_000.0);

/// `--lat`: degrees in [`LATITUDE_DEG`].
pub fn latitude_deg(text: &str) -> Result<f64, String> {
    number_in(text, "the latitude", LATITUDE_DEG, "deg")
}

/// `--lon`: degrees in [`LONGITUDE_DEG`].
pub fn longitude_deg(text: &str) -> Result<f64, String> {
    number_in(text, "the longitude", LONGITUDE_DEG, "deg")
}

/// `--height`: metres in [`HEIGHT_M`].
pub fn height_m(text: &str) -> Result<f64, String> {
    number_in(text, "the height", HEIGHT_M, "m")
}

/// A site given as three numbers (degrees, degrees, metres), checked
/// against the same ranges as `--lat`, `--lon`, `--height`.
pub fn checked_position(lat: f64, lon: f64, height: f64) -> anyhow::Result<Position> {
    let check = |parse: fn(&str) -> Result<f64, String>, v: f64| {
        parse(&v.to_string()).map_err(|e| anyhow::anyhow!("--site: {e}"))
    };
    Ok(Position::from_degrees(
        check(latitude_deg, lat)?,
        check(longitude_deg, lon)?,
        check(height_m, height)?,
    ))
}

/// Where the probe is (degrees and metres on the command line).
#[derive(clap::Args, Debug, Clone, Copy, PartialEq)]
pub struct SiteArgs {
    /// Latitude of the site, degrees (defaults: the MGWD paper's site).
    #[arg(long, alias = "latitude", default_value_t = paper_site_degrees()[0], allow_hyphen_values = true,
          value_parser = latitude_deg)]
    pub lat: f64,
    /// Longitude of the site, degrees.
    #[arg(long, default_value_t = paper_site_degrees()[1], allow_hyphen_values = true,
          value_parser = longitude_deg)]
    pub lon: f64,
    /// Height of the site above the ellipsoid, metres.
    #[arg(long, default_value_t = paper_site_degrees()[2], allow_hyphen_values = true,
          value_parser = height_m)]
    pub height: f64,
}

impl SiteArgs {
    /// The site as the core takes it (radians).
    pub fn position(&self) -> Position {
        Position::from_degrees(self.lat, self.lon, self.height)
    }
}

/// How the probe sits at the start (degrees on the command line; by
/// default the MGWD paper's coarse alignment). A command whose start means
/// something narrower says so in its own help (`mut_arg`).
#[derive(clap::Args, Debug, Clone, Copy, PartialEq)]
pub struct AttitudeArgs {
    /// Roll (gravity toolface) at the start, degrees.
    #[arg(long, default_value_t = PUBLISHED.coarse_deg[0], allow_hyphen_values = true)]
    pub roll: f64,
    /// Pitch (tool axis above horizontal), degrees.
    #[arg(long, default_value_t = PUBLISHED.coarse_deg[1], allow_hyphen_values = true)]
    pub pitch: f64,
    /// Heading (azimuth of the tool axis), degrees.
    #[arg(long, default_value_t = PUBLISHED.coarse_deg[2], allow_hyphen_values = true)]
    pub heading: f64,
}

impl AttitudeArgs {
    /// The attitude as the core takes it (radians).
    pub fn euler(&self) -> Euler {
        Euler::new(self.roll * DEG, self.pitch * DEG, self.heading * DEG)
    }
}

/// [`Position::paper_site`] in degrees, as the defaults show it: converted
/// back and rounded to the micro-degree the paper gives its site in, so
/// that the help prints 126.687898, not 126.68789800000002, and the
/// default position is the paper's to the bit.
fn paper_site_degrees() -> [f64; 3] {
    let site = Position::paper_site();
    let micro_degrees = |rad: f64| (rad.to_degrees() * 1e6).round() / 1e6;
    [
        micro_degrees(site.lat),
        micro_degrees(site.lon),
        site.height,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        site: SiteArgs,
    }

    #[test]
    fn the_default_site_is_the_papers_to_the_bit() {
        let site = Cli::parse_from(["host-sim"]).site;
        assert_eq!(site.position(), Position::paper_site());
        assert_eq!(
            format!("{} {} {}", site.lat, site.lon, site.height),
            "45.77755 126.687898 124"
        );
    }

    #[test]
    fn the_site_takes_negative_numbers_and_the_old_latitude_flag() {
        let args = ["host-sim", "--latitude", "-33.9", "--lon", "-18.4"];
        let site = Cli::parse_from(args).site;
        assert_eq!((site.lat, site.lon), (-33.9, -18.4));
        assert_eq!(site.position(), Position::from_degrees(-33.9, -18.4, 124.0));
    }

    #[test]
    fn sites_off_the_earth_are_refused() {
        for bad in [
            &["host-sim", "--lat", "95"][..],
            &["host-sim", "--lat", "nan"],
            &["host-sim", "--lon", "inf"],
            &["host-sim", "--height", "1e7"],
        ] {
            let e = Cli::try_parse_from(bad).err().map(|e| e.to_string());
            assert!(
                e.as_deref()
                    .is_some_and(|e| e.contains("finite number from")),
                "{bad:?}: {e:?}"
            );
        }
        assert!(checked_position(f64::NAN, 0.0, 0.0).is_err());
        assert!(checked_position(45.0, 126.0, 124.0).is_ok());
    }
}
