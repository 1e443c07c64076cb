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
        self.displaced_with_trig(ned, &LatitudeTrig::new(self.lat))
    }

    /// [`displaced`](Self::displaced) with the sine and cosine of this
    /// position's latitude already at hand (one square root, no
    /// trigonometry).
    pub fn displaced_with_trig(&self, ned: &Vector3<f64>, trig: &LatitudeTrig) -> Self {
        let r = radii_from_trig(trig);
        Self {
            lat: self.lat + ned.x / (r.meridian + self.height),
            lon: self.lon + ned.y / ((r.transverse + self.height) * trig.cos),
            height: self.height - ned.z,
        }
    }

    /// North-east-down offset in metres of this position from `origin`, to
    /// first order (good to millimetres over the kilometres of a well).
    pub fn ned_from(&self, origin: &Position) -> Vector3<f64> {
        let r = radii(origin.lat);
        Vector3::new(
            (self.lat - origin.lat) * (r.meridian + origin.height),
            (self.lon - origin.lon) * (r.transverse + origin.height) * libm::cos(origin.lat),
            origin.height - self.height,
        )
    }
}

/// Sine and cosine of a geodetic latitude. The latitude-dependent terms
/// below (radii, normal gravity, earth and transport rate) all derive from
/// them: a caller that needs several terms at one latitude computes this
/// once (one `libm::sincos`) and passes it to the `*_from_trig` functions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LatitudeTrig {
    pub sin: f64,
    pub cos: f64,
}

impl LatitudeTrig {
    pub fn new(lat: f64) -> Self {
        let (sin, cos) = libm::sincos(lat);
        Self { sin, cos }
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

/// [`radii`] from the sine and cosine of the latitude.
pub fn radii_from_trig(trig: &LatitudeTrig) -> Radii {
    radii_from_sin(trig.sin)
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

/// [`normal_gravity`] from the sine and cosine of the latitude.
pub fn normal_gravity_from_trig(trig: &LatitudeTrig, height: f64) -> f64 {
    normal_gravity_from_sin(trig.sin, height)
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

/// Gravity vector in NED (m/s^2): normal gravity along the ellipsoid normal
/// (the deflection of the vertical is below the probe's accuracy).
pub fn gravity_n(pos: &Position) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, normal_gravity(pos.lat, pos.height))
}

/// [`gravity_n`] from the sine and cosine of the position's latitude.
pub fn gravity_n_from_trig(trig: &LatitudeTrig, height: f64) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, normal_gravity_from_trig(trig, height))
}

/// Earth rate in NED, omega_ie^n = Omega (cos L, 0, -sin L).
pub fn earth_rate_n(lat: f64) -> Vector3<f64> {
    earth_rate_n_from_trig(&LatitudeTrig::new(lat))
}

/// [`earth_rate_n`] from the sine and cosine of the latitude.
pub fn earth_rate_n_from_trig(trig: &LatitudeTrig) -> Vector3<f64> {
    Vector3::new(EARTH_RATE * trig.cos, 0.0, -EARTH_RATE * trig.sin)
}

/// Transport rate omega_en^n: the turning of the NED frame as the probe moves
/// over the curved earth.
pub fn transport_rate_n(pos: &Position, vel_n: &Vector3<f64>) -> Vector3<f64> {
    let trig = LatitudeTrig::new(pos.lat);
    transport_rate_n_from_trig(&trig, &radii_from_trig(&trig), pos.height, vel_n)
}

/// [`transport_rate_n`] from the sine and cosine of the latitude and the
/// radii there (tan L = sin L / cos L).
pub fn transport_rate_n_from_trig(
    trig: &LatitudeTrig,
    radii: &Radii,
    height: f64,
    vel_n: &Vector3<f64>,
) -> Vector3<f64> {
    let rn = radii.transverse + height;
    let rm = radii.meridian + height;
    let east_over_rn = vel_n.y / rn;
    Vector3::new(
        east_over_rn,
        -vel_n.x / rm,
        -east_over_rn * (trig.sin / trig.cos),
    )
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
    fn terms_from_precomputed_trig_match_the_latitude_forms() {
        let vel = Vector3::new(3.0, -2.0, 0.5);
        for lat in [-1.3, -0.4, 0.0, 0.798_968, 1.5] {
            let trig = LatitudeTrig::new(lat);
            assert_eq!((trig.sin, trig.cos), (libm::sin(lat), libm::cos(lat)));
            assert_eq!(radii_from_trig(&trig), radii(lat));
            assert_eq!(
                normal_gravity_from_trig(&trig, 123.0),
                normal_gravity(lat, 123.0)
            );
            let pos = Position::new(lat, 0.3, 123.0);
            assert_eq!(gravity_n_from_trig(&trig, 123.0), gravity_n(&pos));
            assert_eq!(earth_rate_n_from_trig(&trig), earth_rate_n(lat));
            let w = transport_rate_n_from_trig(&trig, &radii(lat), 123.0, &vel);
            assert_eq!(w, transport_rate_n(&pos, &vel));
            // tan L as sin L / cos L: libm's tangent to rounding.
            let r = radii(lat);
            let with_tan = -vel.y * libm::tan(lat) / (r.transverse + 123.0);
            assert!((w.z - with_tan).abs() <= 1e-15 * with_tan.abs().max(1e-300));
        }
    }

    #[test]
    fn displacement_round_trips() {
        let origin = Position::paper_site();
        let offset = Vector3::new(123.4, -56.7, 8.9);
        let moved = origin.displaced(&offset);
        assert!((moved.ned_from(&origin) - offset).norm() < 1e-9);
    }
}
