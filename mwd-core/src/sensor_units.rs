//! Sensor unit facts of the SCC1300-D04, in one place for the driver
//! (firmware), the simulated part (hil-mock) and the host tools: output
//! word formats, sensitivities, count <-> SI conversions, and how each of the
//! probe's two parts is mounted in the body frame.
//!
//! Sources: `docs/scc1300.md`, "the spec" (Murata TN92 and the D04 datasheet
//! front page). Values the spec marks as unverified carry `UNVERIFIED` in their
//! doc comment; correct them here and every crate follows.

/// Standard gravity, the "g" of the datasheet's LSB/g sensitivity (the
/// conventional value of ISO 80000-3, not the local gravity of the earth
/// model, which the navigation core owns).
pub const STANDARD_GRAVITY: f64 = 9.806_65;
/// [`STANDARD_GRAVITY`] in the probe's single precision.
pub const STANDARD_GRAVITY_M_S2: f32 = STANDARD_GRAVITY as f32;

/// Both slaves deliver 14-bit two's complement values, left-aligned in a
/// 16-bit word: `(word as i16) >> 2` \[TN92\]. Smallest count.
pub const COUNT_MIN: i16 = -8192;
/// Largest 14-bit count.
pub const COUNT_MAX: i16 = 8191;

/// Gyro sensitivity of the D04 variant: 18 LSB per deg/s [TN92, datasheet
/// front page].
pub const GYRO_LSB_PER_DEG_S: f32 = 18.0;
/// Specified gyro range, +-300 deg/s [datasheet front page]. The 14-bit word
/// could carry +-455 deg/s; beyond the range the output is not specified.
pub const GYRO_RANGE_DEG_S: f32 = 300.0;
/// The specified gyro range in counts: +-300 deg/s at 18 LSB per deg/s =
/// +-5400 counts. The 14-bit word could carry +-8191 counts (+-455 deg/s),
/// but beyond the range the output is not specified.
pub const GYRO_RANGE_COUNTS: i16 = (GYRO_RANGE_DEG_S * GYRO_LSB_PER_DEG_S) as i16;

/// Whether a gyro rate count is saturated: beyond the specified range
/// (+-[`GYRO_RANGE_COUNTS`]), the 14-bit limits included (the output is not
/// specified there, and at the limits the true rate may be beyond them).
/// The one rule the driver applies and the simulator's captures follow.
pub const fn gyro_count_is_saturated(count: i16) -> bool {
    count > GYRO_RANGE_COUNTS || count < -GYRO_RANGE_COUNTS
}

/// Accelerometer sensitivity of the D04 variant: 650 LSB/g \[TN92\].
pub const ACCEL_LSB_PER_G: f32 = 650.0;
/// Specified accelerometer range, 6 g [datasheet front page]; the part flags
/// SAT beyond it (behaviour taken from the SCA3100 family, see the spec).
pub const ACCEL_RANGE_G: f32 = 6.0;

/// A linear temperature output: `T[degC] = (count + offset_counts) / counts_per_degc`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TemperatureScale {
    pub offset_counts: f32,
    pub counts_per_degc: f32,
}

/// Gyro TEMP register (0x0A), 14-bit count. UNVERIFIED: the formula
/// `((raw >> 2) + 3250) / 65` comes from a third-party driver, not from the
/// datasheet (spec, "Gyro part").
pub const GYRO_TEMPERATURE: TemperatureScale = TemperatureScale {
    offset_counts: 3250.0,
    counts_per_degc: 65.0,
};

/// Accelerometer TEMP_MSB/LSB (0x13/0x12), read as a 14-bit count like the
/// axes. UNVERIFIED placeholder: no public source gives this formula; the
/// gyro's is reused so that host, mock and driver agree until the datasheet
/// is found.
pub const ACCEL_TEMPERATURE: TemperatureScale = GYRO_TEMPERATURE;

/// The part's operating temperature range, -40..+125 degC (datasheet
/// front page, the MGWD paper's Table 1; docs/scc1300.md). Readings outside
/// it are flagged (`raw_flags::TEMPERATURE_OUT_OF_RANGE`).
pub const OPERATING_TEMPERATURE_DEGC: (f32, f32) = (-40.0, 125.0);

/// Converts a left-aligned 16-bit output word into its 14-bit count
/// (arithmetic shift keeps the sign) \[TN92\].
pub const fn word_to_count(word: u16) -> i16 {
    (word as i16) >> 2
}

/// Left-aligns a 14-bit count into an output word; bits 1..0 are zero.
pub const fn count_to_word(count: i16) -> u16 {
    (clamp_count(count as i32) << 2) as u16
}

const fn clamp_count(value: i32) -> i16 {
    if value < COUNT_MIN as i32 {
        COUNT_MIN
    } else if value > COUNT_MAX as i32 {
        COUNT_MAX
    } else {
        value as i16
    }
}

/// Rounds to the nearest count and saturates at the 14-bit limits, as the
/// part's output does. NaN maps to 0 (the float-to-int cast's rule).
fn quantise(value_in_counts: f32) -> i16 {
    let rounded = libm::roundf(value_in_counts);
    // `as i32` saturates for out-of-range floats and maps NaN to 0.
    clamp_count(rounded as i32)
}

/// One degree in radians, single precision (the bits of f32 pi / 180).
const RAD_PER_DEG: f32 = crate::conventions::DEG as f32;

/// Gyro count -> rate in rad/s.
pub fn gyro_count_to_rad_s(count: i16) -> f32 {
    f32::from(count) / GYRO_LSB_PER_DEG_S * RAD_PER_DEG
}

/// Rate in rad/s -> gyro count (rounded, saturated at the 14-bit limits).
pub fn rad_s_to_gyro_count(rate_rad_s: f32) -> i16 {
    quantise(rate_rad_s / RAD_PER_DEG * GYRO_LSB_PER_DEG_S)
}

/// Accelerometer count -> specific force in m/s^2.
pub fn accel_count_to_m_s2(count: i16) -> f32 {
    f32::from(count) / ACCEL_LSB_PER_G * STANDARD_GRAVITY_M_S2
}

/// Specific force in m/s^2 -> accelerometer count (rounded, saturated).
pub fn m_s2_to_accel_count(accel_m_s2: f32) -> i16 {
    quantise(accel_m_s2 / STANDARD_GRAVITY_M_S2 * ACCEL_LSB_PER_G)
}

impl TemperatureScale {
    /// Count -> temperature in degrees Celsius.
    pub fn count_to_degc(&self, count: i16) -> f32 {
        (f32::from(count) + self.offset_counts) / self.counts_per_degc
    }

    /// Temperature in degrees Celsius -> count (rounded, saturated).
    pub fn degc_to_count(&self, degc: f32) -> i16 {
        quantise(degc * self.counts_per_degc - self.offset_counts)
    }
}

/// A body-frame axis (x right, y forward along the tool, z up).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyAxis {
    X = 0,
    Y = 1,
    Z = 2,
}

/// A body axis with a sign: what one sensor axis senses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SignedAxis {
    pub axis: BodyAxis,
    pub negative: bool,
}

const fn pos(axis: BodyAxis) -> SignedAxis {
    SignedAxis {
        axis,
        negative: false,
    }
}

const fn neg(axis: BodyAxis) -> SignedAxis {
    SignedAxis {
        axis,
        negative: true,
    }
}

impl SignedAxis {
    /// The component of a body-frame vector along this signed axis.
    pub fn pick(&self, body: [f32; 3]) -> f32 {
        let value = match self.axis {
            BodyAxis::X => body[0],
            BodyAxis::Y => body[1],
            BodyAxis::Z => body[2],
        };
        if self.negative {
            -value
        } else {
            value
        }
    }
}

/// How one SCC1300 sits in the body frame: the body axis that each of the
/// part's own axes X, Y, Z senses. The gyro senses the part's X axis
/// (datasheet: "angular rate measurement around X axis"), so its body axis is
/// `sensor_axes[0]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mounting {
    pub sensor_axes: [SignedAxis; 3],
}

impl Mounting {
    /// The body axis the part's gyro senses.
    pub const fn gyro_axis(&self) -> SignedAxis {
        self.sensor_axes[0]
    }

    /// A vector in the part's axes -> the same vector in body axes.
    pub fn sensor_to_body(&self, sensor: [f32; 3]) -> [f32; 3] {
        let mut body = [0.0; 3];
        for (value, axis) in sensor.iter().zip(self.sensor_axes.iter()) {
            let signed = if axis.negative { -value } else { *value };
            if let Some(slot) = body.get_mut(axis.axis as usize) {
                *slot = signed;
            }
        }
        body
    }

    /// A body-frame vector -> its components along the part's axes.
    pub fn body_to_sensor(&self, body: [f32; 3]) -> [f32; 3] {
        self.sensor_axes.map(|axis| axis.pick(body))
    }

    /// The gyro's reading (rad/s, about the part's X axis) for a body rate.
    pub fn gyro_rate_from_body(&self, body_rate: [f32; 3]) -> f32 {
        self.gyro_axis().pick(body_rate)
    }
}

/// The probe's two parts, in the order of the raw-sample frame.
pub const PART_COUNT: usize = 2;

/// Mounting of the two parts (project decision, `docs/scc1300.md`): part 1 ("azimuth
/// gyro board") has its X, Y, Z along body x, y, z, so its gyro senses +x;
/// part 2 ("pitch gyro board") is turned so that its X, Y, Z sense body
/// z, y, -x, so its gyro senses +z. Correct a mounting here, nowhere else.
pub const PART_MOUNTINGS: [Mounting; PART_COUNT] = [
    Mounting {
        sensor_axes: [pos(BodyAxis::X), pos(BodyAxis::Y), pos(BodyAxis::Z)],
    },
    Mounting {
        sensor_axes: [pos(BodyAxis::Z), pos(BodyAxis::Y), neg(BodyAxis::X)],
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_precision_degree_is_f32_pi_over_180() {
        assert_eq!(RAD_PER_DEG, core::f32::consts::PI / 180.0);
    }

    #[test]
    fn single_precision_gravity_is_the_literal() {
        assert_eq!(STANDARD_GRAVITY_M_S2, 9.806_65_f32);
    }

    fn matrix(m: &Mounting) -> [[f32; 3]; 3] {
        // Column j = body image of sensor unit vector j.
        let mut out = [[0.0; 3]; 3];
        for j in 0..3 {
            let mut unit = [0.0; 3];
            unit[j] = 1.0;
            let col = m.sensor_to_body(unit);
            for i in 0..3 {
                out[i][j] = col[i];
            }
        }
        out
    }

    #[test]
    fn mountings_are_proper_rotations() {
        for m in &PART_MOUNTINGS {
            let a = matrix(m);
            let det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
            assert_eq!(det, 1.0, "a mounting must not mirror the part");
        }
    }

    #[test]
    fn project_mounting_decision() {
        assert_eq!(PART_MOUNTINGS[0].gyro_axis(), pos(BodyAxis::X));
        assert_eq!(PART_MOUNTINGS[1].gyro_axis(), pos(BodyAxis::Z));
        // Part 2: sensor (1, 2, 3) lands on body z = 1, y = 2, x = -3.
        assert_eq!(
            PART_MOUNTINGS[1].sensor_to_body([1.0, 2.0, 3.0]),
            [-3.0, 2.0, 1.0]
        );
        assert_eq!(
            PART_MOUNTINGS[1].body_to_sensor([-3.0, 2.0, 1.0]),
            [1.0, 2.0, 3.0]
        );
        assert_eq!(PART_MOUNTINGS[1].gyro_rate_from_body([0.1, 0.2, 0.3]), 0.3);
    }

    #[test]
    fn words_and_counts() {
        assert_eq!(word_to_count(0xFFFC), -1);
        assert_eq!(word_to_count(0x7FFC), COUNT_MAX);
        assert_eq!(word_to_count(0x8000), COUNT_MIN);
        assert_eq!(count_to_word(-1), 0xFFFC);
        assert_eq!(count_to_word(i16::MAX), 0x7FFC);
        for c in [COUNT_MIN, -1, 0, 1, 1234, COUNT_MAX] {
            assert_eq!(word_to_count(count_to_word(c)), c);
        }
    }

    #[test]
    fn sensitivities() {
        // 18 counts = 1 deg/s; 650 counts = 1 g.
        let one_deg = 1.0f32.to_radians();
        assert!((gyro_count_to_rad_s(18) - one_deg).abs() < 1e-7);
        assert_eq!(rad_s_to_gyro_count(one_deg), 18);
        assert_eq!(rad_s_to_gyro_count(-10.0 * one_deg), -180);
        assert!((accel_count_to_m_s2(650) - STANDARD_GRAVITY_M_S2).abs() < 1e-5);
        assert_eq!(m_s2_to_accel_count(-STANDARD_GRAVITY_M_S2), -650);
    }

    #[test]
    fn conversions_saturate_and_survive_nan() {
        assert_eq!(rad_s_to_gyro_count(1.0e9), COUNT_MAX);
        assert_eq!(m_s2_to_accel_count(-1.0e9), COUNT_MIN);
        assert_eq!(m_s2_to_accel_count(f32::NAN), 0);
        assert_eq!(GYRO_TEMPERATURE.degc_to_count(f32::INFINITY), COUNT_MAX);
    }

    #[test]
    fn temperature_formula() {
        // ((raw >> 2) + 3250) / 65: count -3250 is 0 degC, count 0 is 50 degC.
        assert_eq!(GYRO_TEMPERATURE.count_to_degc(-3250), 0.0);
        assert_eq!(GYRO_TEMPERATURE.count_to_degc(0), 50.0);
        assert_eq!(GYRO_TEMPERATURE.degc_to_count(25.0), -1625);
    }

    proptest::proptest! {
        #[test]
        fn quantisation_is_within_half_a_count(rate in -5.0f32..5.0, acc in -50.0f32..50.0) {
            proptest::prop_assert!(gyro_round_trip_error(rate) <= half_a_count(gyro_count_to_rad_s(1), rate));
            proptest::prop_assert!(accel_round_trip_error(acc) <= half_a_count(accel_count_to_m_s2(1), acc));
        }
    }

    fn gyro_round_trip_error(rate: f32) -> f32 {
        (gyro_count_to_rad_s(rad_s_to_gyro_count(rate)) - rate).abs()
    }

    fn accel_round_trip_error(acc: f32) -> f32 {
        (accel_count_to_m_s2(m_s2_to_accel_count(acc)) - acc).abs()
    }

    /// Half a count, plus the f32 rounding of the two conversions (a few
    /// ulps of the value): near a count boundary at ~5,000 counts the
    /// latter is ~6e-4 of a count, more than a fixed 0.1 % slack.
    fn half_a_count(lsb: f32, value: f32) -> f32 {
        0.5 * lsb + 4.0 * f32::EPSILON * value.abs()
    }

    /// The case proptest found (rate 4.970794 rad/s, 5,126.5 counts: on a
    /// rounding boundary) stays within the bound.
    #[test]
    fn a_rate_on_a_count_boundary_rounds_within_half_a_count() {
        let rate = 4.970794f32;
        assert!(gyro_round_trip_error(rate) <= half_a_count(gyro_count_to_rad_s(1), rate));
        assert!(gyro_round_trip_error(rate) > 0.49 * gyro_count_to_rad_s(1));
    }
}
