//! The one earth model: WGS-84 ellipsoid, normal gravity, earth rate and
//! transport rate, in the NED navigation frame.
//!
//! Constants from NIMA TR8350.2 (WGS-84, 3rd ed.), tables 3.1-3.4 and
//! eq. 4-1 (Somigliana) and 4-3 (normal gravity above the ellipsoid).
use nalgebra::Vector3;

/// Semi-major axis a (m).
pub const SEMI_MAJOR_AXIS: f64 = 6_378_137.0;
/// Flattening f.
pub const FLATTENING: f64 = 1.0 / 298.257_223_563;
/// First eccentricity squared e^2 = f (2 - f).
pub const ECCENTRICITY_SQUARED: f64 = FLATTENING * (2.0 - FLATTENING);
/// Semi-minor axis b = a (1 - f) (m).
pub const SEMI_MINOR_AXIS: f64 = SEMI_MAJOR_AXIS * (1.0 - FLATTENING);
/// Earth's angular rate Omega (rad/s).
pub const EARTH_RATE: f64 = 7.292_115e-5;
/// Earth's gravitational constant GM (m^3/s^2).
pub const GM: f64 = 3.986_004_418e14;
/// Normal gravity at the equator (m/s^2).
pub const GRAVITY_EQUATOR: f64 = 9.780_325_335_9;
/// Somigliana's constant k = (b g_p) / (a g_e) - 1.
pub const SOMIGLIANA_K: f64 = 0.001_931_852_652_41;
/// m = Omega^2 a^2 b / GM, used by the height correction.
const GRAVITY_RATIO_M: f64 =
    EARTH_RATE * EARTH_RATE * SEMI_MAJOR_AXIS * SEMI_MAJOR_AXIS * SEMI_MINOR_AXIS / GM;

/// Geodetic position. Latitude and longitude stay in f64 on the probe too:
/// one metre is about 1.6e-7 rad, below f32's resolution at these values.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Position {
    /// Geodetic latitude (rad).
    pub lat: f64,
    /// Longitude (rad).
    pub lon: f64,
    /// Height above the ellipsoid (m).
    pub height: f64,
}

impl Position {
    pub const fn new(lat: f64, lon: f64, height: f64) -> Self {
        Self { lat, lon, height }
    }

    /// Position from degrees and metres (the form used at the edges).
    pub fn from_degrees(lat_deg: f64, lon_deg: f64, height: f64) -> Self {
        Self::new(lat_deg.to_radians(), lon_deg.to_radians(), height)
    }

    /// The test site of the MGWD paper (section 4): 45.77755 N,
    /// 126.687898 E, 124 m.
    pub fn paper_site() -> Self {
        Self::from_degrees(45.777_55, 126.687_898, 124.0)
    }

    /// This position moved by a small north-east-down offset in metres.
    pub fn displaced(&self, ned: &Vector3<f64>) -> Self {
        LocalEarth::at(self).displaced(ned)
    }

    /// North-east-down offset in metres of this position from `origin`, to
    /// first order (good to millimetres over the kilometres of a well).
    pub fn ned_from(&self, origin: &Position) -> Vector3<f64> {
        LocalEarth::at(origin).offset_to(self)
    }
}

/// The earth around one position: everything the navigation needs of the
/// ellipsoid there, from one sine and cosine of the latitude. The
/// mechanization builds one per step; the filter keeps one while the
/// solution stays near it ([`is_near`](Self::is_near)), since on the probe
/// the geodetic terms cost ~15 000 instructions of software f64 and change
/// by parts per million over a kilometre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalEarth {
    pub position: Position,
    pub sin_lat: f64,
    pub cos_lat: f64,
    /// Meridian radius of curvature plus height, R_M + h (m).
    pub meridian: f64,
    /// Transverse radius of curvature plus height, R_N + h (m).
    pub transverse: f64,
    /// Normal gravity (m/s^2).
    pub gravity: f64,
    /// Free-air gravity gradient dg/dh = -2 g / R, R the Gaussian mean
    /// radius sqrt((R_M + h)(R_N + h)) (s^-2).
    pub gravity_gradient: f64,
}

impl LocalEarth {
    pub fn at(position: &Position) -> Self {
        let (sin_lat, cos_lat) = libm::sincos(position.lat);
        Self::with_latitude_trig(position, sin_lat, cos_lat)
    }

    /// The same with the sine and cosine of `position.lat` already at hand
    /// (the mechanization carries them across a step by series).
    pub fn with_latitude_trig(position: &Position, sin_lat: f64, cos_lat: f64) -> Self {
        let r = radii_from_sin(sin_lat);
        let meridian = r.meridian + position.height;
        let transverse = r.transverse + position.height;
        let gravity = normal_gravity_from_sin(sin_lat, position.height);
        Self {
            position: *position,
            sin_lat,
            cos_lat,
            meridian,
            transverse,
            gravity,
            gravity_gradient: -2.0 * gravity / libm::sqrt(meridian * transverse),
        }
    }

    /// Earth rate in NED, omega_ie^n = Omega (cos L, 0, -sin L).
    pub fn earth_rate_n(&self) -> Vector3<f64> {
        earth_rate_from_trig(self.sin_lat, self.cos_lat)
    }

    /// Transport rate omega_en^n: the turning of the NED frame as the probe
    /// moves at `velocity_n` over the curved earth (tan L = sin L / cos L).
    pub fn transport_rate_n(&self, velocity_n: &Vector3<f64>) -> Vector3<f64> {
        let east_over_rn = velocity_n.y / self.transverse;
        Vector3::new(
            east_over_rn,
            -velocity_n.x / self.meridian,
            -east_over_rn * (self.sin_lat / self.cos_lat),
        )
    }

    /// Gravity in NED: normal gravity along the ellipsoid normal (the
    /// deflection of the vertical is below the probe's accuracy).
    pub fn gravity_n(&self) -> Vector3<f64> {
        Vector3::new(0.0, 0.0, self.gravity)
    }

    /// This position moved by a small north-east-down offset (m).
    pub fn displaced(&self, ned: &Vector3<f64>) -> Position {
        displace(
            &self.position,
            self.meridian,
            self.transverse,
            self.cos_lat,
            ned,
        )
    }

    /// North-east-down offset (m) of `other` from this position, to first
    /// order.
    pub fn offset_to(&self, other: &Position) -> Vector3<f64> {
        let p = &self.position;
        Vector3::new(
            (other.lat - p.lat) * self.meridian,
            (other.lon - p.lon) * self.transverse * self.cos_lat,
            p.height - other.height,
        )
    }

    /// True while `position` is within about 10 m of this one (cheap
    /// comparisons, no trigonometry).
    pub fn is_near(&self, position: &Position) -> bool {
        const ANGLE: f64 = 1.5e-6; // rad, ~10 m of latitude
        (position.lat - self.position.lat).abs() < ANGLE
            && (position.lon - self.position.lon).abs() * self.cos_lat < ANGLE
            && (position.height - self.position.height).abs() < 10.0
    }
}

/// Principal radii of curvature of the ellipsoid at a latitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Radii {
    /// Meridian (north-south) radius R_M (m).
    pub meridian: f64,
    /// Transverse (prime vertical, east-west) radius R_N (m).
    pub transverse: f64,
}

pub fn radii(lat: f64) -> Radii {
    radii_from_sin(libm::sin(lat))
}

fn radii_from_sin(s: f64) -> Radii {
    let w2 = 1.0 - ECCENTRICITY_SQUARED * s * s;
    let w = libm::sqrt(w2);
    Radii {
        meridian: SEMI_MAJOR_AXIS * (1.0 - ECCENTRICITY_SQUARED) / (w2 * w),
        transverse: SEMI_MAJOR_AXIS / w,
    }
}

/// Normal gravity magnitude (m/s^2) at a latitude and height: Somigliana's
/// closed formula on the ellipsoid (TR8350.2 eq. 4-1) with the second-order
/// height correction (eq. 4-3).
pub fn normal_gravity(lat: f64, height: f64) -> f64 {
    normal_gravity_from_sin(libm::sin(lat), height)
}

fn normal_gravity_from_sin(s: f64, height: f64) -> f64 {
    let s2 = s * s;
    let on_ellipsoid =
        GRAVITY_EQUATOR * (1.0 + SOMIGLIANA_K * s2) / libm::sqrt(1.0 - ECCENTRICITY_SQUARED * s2);
    let a = SEMI_MAJOR_AXIS;
    on_ellipsoid
        * (1.0 - 2.0 / a * (1.0 + FLATTENING + GRAVITY_RATIO_M - 2.0 * FLATTENING * s2) * height
            + 3.0 * height * height / (a * a))
}

/// `position` moved by a small north-east-down offset (m), the sine and
/// cosine of its latitude at hand: [`LocalEarth::displaced`] with the radii
/// only (the same bits), for the mechanization's feedback every cycle, which
/// has no use for the local gravity (software f64 on the probe).
pub fn displaced_with_trig(
    position: &Position,
    sin_lat: f64,
    cos_lat: f64,
    ned: &Vector3<f64>,
) -> Position {
    let r = radii_from_sin(sin_lat);
    let meridian = r.meridian + position.height;
    let transverse = r.transverse + position.height;
    displace(position, meridian, transverse, cos_lat, ned)
}

/// `position` moved by `ned` (m) with the radii of curvature plus height
/// `meridian` and `transverse` (m) and the latitude's cosine there.
fn displace(
    position: &Position,
    meridian: f64,
    transverse: f64,
    cos_lat: f64,
    ned: &Vector3<f64>,
) -> Position {
    Position {
        lat: position.lat + ned.x / meridian,
        lon: position.lon + ned.y / (transverse * cos_lat),
        height: position.height - ned.z,
    }
}

/// Gravity vector in NED at a position ([`LocalEarth::gravity_n`] without
/// the rest of the local terms).
pub fn gravity_n(pos: &Position) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, normal_gravity(pos.lat, pos.height))
}

/// Earth rate in NED at a latitude ([`LocalEarth::earth_rate_n`]).
pub fn earth_rate_n(lat: f64) -> Vector3<f64> {
    let (sin, cos) = libm::sincos(lat);
    earth_rate_from_trig(sin, cos)
}

fn earth_rate_from_trig(sin_lat: f64, cos_lat: f64) -> Vector3<f64> {
    Vector3::new(EARTH_RATE * cos_lat, 0.0, -EARTH_RATE * sin_lat)
}

/// Transport rate in NED at a position and velocity
/// ([`LocalEarth::transport_rate_n`]).
pub fn transport_rate_n(pos: &Position, vel_n: &Vector3<f64>) -> Vector3<f64> {
    LocalEarth::at(pos).transport_rate_n(vel_n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_gravity_matches_published_values() {
        // TR8350.2 table 3.4: g_e = 9.7803253359, g_p = 9.8321849378 m/s^2.
        assert!((normal_gravity(0.0, 0.0) - 9.780_325_335_9).abs() < 1e-9);
        let pole = normal_gravity(core::f64::consts::FRAC_PI_2, 0.0);
        assert!((pole - 9.832_184_937_8).abs() < 1e-8, "{pole}");
        // Free-air gradient about -3.086e-6 s^-2 near the surface.
        let gradient = (normal_gravity(0.8, 100.0) - normal_gravity(0.8, 0.0)) / 100.0;
        assert!((gradient + 3.086e-6).abs() < 0.01e-6, "{gradient}");
    }

    #[test]
    fn radii_at_equator_and_pole() {
        let eq = radii(0.0);
        assert!((eq.transverse - SEMI_MAJOR_AXIS).abs() < 1e-6);
        assert!((eq.meridian - SEMI_MAJOR_AXIS * (1.0 - ECCENTRICITY_SQUARED)).abs() < 1e-6);
        let pole = radii(core::f64::consts::FRAC_PI_2);
        // At the pole both radii equal a^2 / b.
        let c = SEMI_MAJOR_AXIS * SEMI_MAJOR_AXIS / SEMI_MINOR_AXIS;
        assert!((pole.meridian - c).abs() < 1e-6 && (pole.transverse - c).abs() < 1e-6);
    }

    #[test]
    fn earth_rate_has_the_right_size_and_direction() {
        let lat = Position::paper_site().lat;
        let w = earth_rate_n(lat);
        assert!((w.norm() - EARTH_RATE).abs() < 1e-18);
        // Northern hemisphere: the rotation axis points north and up (-down).
        assert!(w.x > 0.0 && w.z < 0.0 && w.y == 0.0);
    }

    #[test]
    fn transport_rate_of_a_northbound_probe_turns_about_west() {
        let pos = Position::paper_site();
        let w = transport_rate_n(&pos, &Vector3::new(10.0, 0.0, 0.0));
        assert!(w.y < 0.0 && w.x == 0.0 && w.z == 0.0);
        assert!((w.y + 10.0 / (radii(pos.lat).meridian + pos.height)).abs() < 1e-18);
    }

    #[test]
    fn local_terms_match_the_latitude_forms() {
        let vel = Vector3::new(3.0, -2.0, 0.5);
        for lat in [-1.3, -0.4, 0.0, 0.798_968, 1.5] {
            let pos = Position::new(lat, 0.3, 123.0);
            let earth = LocalEarth::at(&pos);
            // One sincos gives the bits of libm's sine and cosine.
            assert_eq!(
                (earth.sin_lat, earth.cos_lat),
                (libm::sin(lat), libm::cos(lat))
            );
            let r = radii(lat);
            assert_eq!(earth.meridian, r.meridian + 123.0);
            assert_eq!(earth.transverse, r.transverse + 123.0);
            assert_eq!(earth.gravity_n(), gravity_n(&pos));
            assert_eq!(earth.earth_rate_n(), earth_rate_n(lat));
            let w = earth.transport_rate_n(&vel);
            assert_eq!(w, transport_rate_n(&pos, &vel));
            // tan L as sin L / cos L: libm's tangent to rounding.
            let with_tan = -vel.y * libm::tan(lat) / (r.transverse + 123.0);
            assert!((w.z - with_tan).abs() <= 1e-15 * with_tan.abs().max(1e-300));
        }
    }

    #[test]
    fn gravity_gradient_is_the_free_air_gradient() {
        let pos = Position::paper_site();
        let earth = LocalEarth::at(&pos);
        let numeric = (normal_gravity(pos.lat, pos.height + 1.0)
            - normal_gravity(pos.lat, pos.height - 1.0))
            / 2.0;
        assert!((earth.gravity_gradient - numeric).abs() < 0.005 * numeric.abs());
    }

    #[test]
    fn nearness_is_about_ten_metres() {
        let reference = Position::paper_site();
        let earth = LocalEarth::at(&reference);
        assert!(earth.is_near(&reference.displaced(&Vector3::new(5.0, -4.0, 2.0))));
        assert!(!earth.is_near(&reference.displaced(&Vector3::new(50.0, 0.0, 0.0))));
        assert!(!earth.is_near(&reference.displaced(&Vector3::new(0.0, 20.0, 0.0))));
        assert!(!earth.is_near(&reference.displaced(&Vector3::new(0.0, 0.0, 11.0))));
    }

    #[test]
    fn displacement_round_trips() {
        let origin = Position::paper_site();
        let offset = Vector3::new(123.4, -56.7, 8.9);
        let moved = origin.displaced(&offset);
        assert!((moved.ned_from(&origin) - offset).norm() < 1e-9);
    }
}
