//! The site of a run, as every command that needs one takes it: `--lat`,
//! `--lon`, `--height`, by default the MGWD paper's test site.
use mwd_core::earth::Position;

/// Where the probe is (degrees and metres on the command line).
#[derive(clap::Args, Debug, Clone, Copy, PartialEq)]
pub struct SiteArgs {
    /// Latitude of the site, degrees (defaults: the MGWD paper's site).
    #[arg(long, alias = "latitude", default_value_t = paper_site_degrees()[0], allow_hyphen_values = true)]
    pub lat: f64,
    /// Longitude of the site, degrees.
    #[arg(long, default_value_t = paper_site_degrees()[1], allow_hyphen_values = true)]
    pub lon: f64,
    /// Height of the site above the ellipsoid, metres.
    #[arg(long, default_value_t = paper_site_degrees()[2], allow_hyphen_values = true)]
    pub height: f64,
}

impl SiteArgs {
    /// The site as the core takes it (radians).
    pub fn position(&self) -> Position {
        Position::from_degrees(self.lat, self.lon, self.height)
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
}
