//! The drilling parameters of a plan (the file's `drilling` object, each
//! field with a default): rate of penetration, stands and connections, the
//! orienter's toolface changes, the vibration and shocks while drilling,
//! the errors of the surface depth log and the hole's tortuosity; with the
//! checks of their ranges.
use anyhow::{ensure, Result};
use mwd_core::conventions::DEG;
use serde::{Deserialize, Serialize};

/// The random vibration and shocks while drilling (on bottom). Levels are
/// the environment's (before the sensor), flat over [band_low_hz,
/// band_high_hz]; what the 20 Hz samples see follows from the sensor's
/// low-pass (see `docs/drilling-simulation.md`, "Vibration").
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Vibration {
    /// Across the tool (body x and z), each axis, g RMS over the band.
    pub lateral_rms_g: f64,
    /// Along the tool (body y), g RMS over the band.
    pub axial_rms_g: f64,
    pub band_low_hz: f64,
    pub band_high_hz: f64,
    /// The sensor's internal low-pass, taken as first order, -3 dB here
    /// (Hz). The datasheet available to the project does not give it.
    pub sensor_lowpass_hz: f64,
    /// Angular vibration about body x and z, each, deg/s RMS over the band.
    pub angular_rms_deg_s: f64,
    /// Shocks while drilling: mean rate (per hour), half-sine peak (g) and
    /// duration (ms), lateral direction at random.
    pub shocks_per_hour: f64,
    pub shock_peak_g: f64,
    pub shock_duration_ms: f64,
}

impl Vibration {
    /// The default: a moderate sliding environment, 2 g RMS lateral and
    /// 1 g axial over 5-500 Hz, 1 deg/s angular, 6 shocks of 30 g per hour.
    pub const MODERATE: Self = Self {
        lateral_rms_g: 2.0,
        axial_rms_g: 1.0,
        band_low_hz: 5.0,
        band_high_hz: 500.0,
        sensor_lowpass_hz: 50.0,
        angular_rms_deg_s: 1.0,
        shocks_per_hour: 6.0,
        shock_peak_g: 30.0,
        shock_duration_ms: 1.0,
    };
    /// The paper's environment: 15 g RMS over 5-500 Hz on every axis,
    /// 30 deg/s angular, 60 shocks of 100 g per hour.
    pub const HARSH: Self = Self {
        lateral_rms_g: 15.0,
        axial_rms_g: 15.0,
        band_low_hz: 5.0,
        band_high_hz: 500.0,
        sensor_lowpass_hz: 50.0,
        angular_rms_deg_s: 30.0,
        shocks_per_hour: 60.0,
        shock_peak_g: 100.0,
        shock_duration_ms: 1.0,
    };
    /// No vibration.
    pub const NONE: Self = Self {
        lateral_rms_g: 0.0,
        axial_rms_g: 0.0,
        band_low_hz: 5.0,
        band_high_hz: 500.0,
        sensor_lowpass_hz: 50.0,
        angular_rms_deg_s: 0.0,
        shocks_per_hour: 0.0,
        shock_peak_g: 0.0,
        shock_duration_ms: 1.0,
    };

    /// The fraction of a flat band's power a first-order low-pass at fc
    /// lets through: (1 / (hi - lo)) int_lo^hi df / (1 + (f/fc)^2)
    /// = fc (atan(hi/fc) - atan(lo/fc)) / (hi - lo).
    pub fn passed_power_fraction(&self) -> f64 {
        let (lo, hi, fc) = (self.band_low_hz, self.band_high_hz, self.sensor_lowpass_hz);
        fc * (libm::atan(hi / fc) - libm::atan(lo / fc)) / (hi - lo)
    }

    fn check(&self) -> Result<()> {
        let nonneg = [
            ("lateral_rms_g", self.lateral_rms_g),
            ("axial_rms_g", self.axial_rms_g),
            ("angular_rms_deg_s", self.angular_rms_deg_s),
            ("shocks_per_hour", self.shocks_per_hour),
            ("shock_peak_g", self.shock_peak_g),
        ];
        for (name, v) in nonneg {
            ensure!(
                v.is_finite() && (0.0..=1000.0).contains(&v),
                "drilling.vibration.{name} must be a number from 0 to 1000 (got {v})"
            );
        }
        ensure!(
            self.band_low_hz.is_finite()
                && self.band_low_hz >= 0.0
                && self.band_high_hz.is_finite()
                && self.band_high_hz > self.band_low_hz
                && self.band_high_hz <= 100_000.0,
            "drilling.vibration: the band must satisfy 0 <= band_low_hz < band_high_hz <= 100000 Hz"
        );
        ensure!(
            self.sensor_lowpass_hz.is_finite()
                && self.sensor_lowpass_hz > 0.0
                && self.sensor_lowpass_hz <= 100_000.0,
            "drilling.vibration.sensor_lowpass_hz must be a number of Hz above 0, at most 100000"
        );
        ensure!(
            self.shock_duration_ms.is_finite()
                && self.shock_duration_ms > 0.0
                && self.shock_duration_ms <= 50.0,
            "drilling.vibration.shock_duration_ms must be above 0 and at most 50 ms"
        );
        Ok(())
    }
}

impl Default for Vibration {
    fn default() -> Self {
        Self::MODERATE
    }
}

/// 1 deg / 100 ft in deg / 30 m.
const ONE_DEG_PER_100_FT: f64 = 30.0 / 30.48;

/// The tortuosity of the drilled hole (the plan file's
/// `drilling.tortuosity`), each field with a default; the hole is drawn
/// from it by [`super::tortuosity`].
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct Tortuosity {
    /// RMS of each component (build, walk) of the curvature's deviation
    /// from the plan's, deg/30 m; 0: the plan drilled exactly.
    pub rms_deg_per_30m: f64,
    /// Its correlation length along MD (m).
    pub correlation_length_m: f64,
    /// The length over which the driller steers a direction deviation
    /// back to the plan (m).
    pub steering_length_m: f64,
}

impl Default for Tortuosity {
    /// The amplitude is the tortuosity the ISCWSA model assumes for its
    /// long-course-length terms: 1 deg/100 ft (0.98 deg/30 m), the
    /// `XCLTortuosity` of the MWD Rev 5 and OWSG tool models (SPE 187249;
    /// `host-sim/data/mwd_rev5_model_terms.csv`, XCLA and XCLH: 0.0328084
    /// deg/m), taken here per component. The correlation length puts it
    /// below the survey interval, where Bang et al. (SPE 173103, 2016)
    /// place the tortuosity surveys at 30 m (100 ft) do not see ("small-
    /// scale tortuosity"): 10 m, a third of a stand, is a choice within
    /// that range, not a published figure. The steering length (60 m, two
    /// stands: a deviation seen at one connection's survey corrected over
    /// the next stands) is a choice too.
    fn default() -> Self {
        Self {
            rms_deg_per_30m: ONE_DEG_PER_100_FT,
            correlation_length_m: 10.0,
            steering_length_m: 60.0,
        }
    }
}

impl Tortuosity {
    /// The plan drilled exactly.
    pub const NONE: Self = Self {
        rms_deg_per_30m: 0.0,
        correlation_length_m: 10.0,
        steering_length_m: 60.0,
    };

    /// This tortuosity with the amplitude and correlation length a command
    /// line gives instead (each optional; checked when the plan is built).
    pub fn overridden(
        self,
        rms_deg_per_30m: Option<f64>,
        correlation_length_m: Option<f64>,
    ) -> Self {
        Self {
            rms_deg_per_30m: rms_deg_per_30m.unwrap_or(self.rms_deg_per_30m),
            correlation_length_m: correlation_length_m.unwrap_or(self.correlation_length_m),
            ..self
        }
    }

    /// The curvature deviation's RMS per component (rad/m).
    pub fn sigma_rad_per_m(&self) -> f64 {
        self.rms_deg_per_30m * DEG / 30.0
    }

    /// The MD step the hole is drawn at (m): fine enough for the
    /// correlation length.
    pub fn step_m(&self) -> f64 {
        (self.correlation_length_m / 4.0).min(1.0)
    }

    pub(super) fn check(&self) -> Result<()> {
        let ranges = [
            ("rms_deg_per_30m", self.rms_deg_per_30m, 0.0, 10.0),
            (
                "correlation_length_m",
                self.correlation_length_m,
                1.0,
                1000.0,
            ),
            ("steering_length_m", self.steering_length_m, 10.0, 10_000.0),
        ];
        for (name, v, lo, hi) in ranges {
            ensure!(
                v.is_finite() && (lo..=hi).contains(&v),
                "drilling.tortuosity.{name} must be a number from {lo} to {hi} (got {v})"
            );
        }
        Ok(())
    }
}

/// Errors of the surface depth measurement (the ISCWSA depth terms):
/// md_log = md (1 + scale) + stretch md TVD.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DepthErrors {
    /// Scale-factor error, ppm of MD (ISCWSA DSF, 1 sigma 560 ppm in MWD Rev 5).
    pub scale_ppm: f64,
    /// Stretch, 1/m: error = stretch x MD x TVD (ISCWSA DST, 2.5e-7 /m).
    pub stretch_per_m: f64,
}

impl Default for DepthErrors {
    fn default() -> Self {
        Self {
            scale_ppm: 560.0,
            stretch_per_m: 2.5e-7,
        }
    }
}

/// The most dwells a connection's still time is split into
/// ([`DrillingParams::connection_dwells`]).
pub const MAX_CONNECTION_DWELLS: u32 = 8;

/// One dwell: no indexing (left out of a plan's output).
pub fn is_single_dwell(dwells: &u32) -> bool {
    *dwells == 1
}

/// Drilling parameters, each with a default.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct DrillingParams {
    /// Rate of penetration while drilling (m/h).
    pub rop_m_per_h: f64,
    /// Time to reach ROP from rest and to stop again (s): linear ramps.
    pub rop_ramp_s: f64,
    /// MD drilled between connections (m).
    pub stand_length_m: f64,
    /// Still time at each connection (s): pumps off, the probe at rest.
    pub connection_still_s: f64,
    /// The connection's still time in this many equal dwells, the orienter
    /// turning the toolface by 360 deg / dwells between them and on to a
    /// whole turn after the last (toolface indexing: the cross-axis gyro
    /// biases turn against the earth rate; docs/toolface-indexing.md).
    /// 1: one still period, no indexing.
    #[serde(skip_serializing_if = "is_single_dwell")]
    pub connection_dwells: u32,
    /// Still time at the tie-on before drilling starts (s): alignment.
    pub initial_still_s: f64,
    /// Toolface change at each connection (deg; back towards the section's
    /// toolface, or either way at random from it).
    pub toolface_change_per_connection_deg: f64,
    /// Rate of the orienter's toolface turns (deg/s).
    pub toolface_turn_rate_deg_s: f64,
    /// Toolface steps while sliding (reactive torque, driller's
    /// corrections): mean rate (per hour of drilling) and size (deg,
    /// directed as the connection steps).
    pub sliding_toolface_steps_per_hour: f64,
    pub sliding_toolface_step_deg: f64,
    pub vibration: Vibration,
    pub depth_errors: DepthErrors,
    /// Interval of the surface depth log (s).
    pub depth_log_interval_s: f64,
    /// How the drilled hole wanders around the plan
    /// ([`super::tortuosity`]).
    pub tortuosity: Tortuosity,
}

impl Default for DrillingParams {
    fn default() -> Self {
        Self {
            rop_m_per_h: 30.0,
            rop_ramp_s: 10.0,
            stand_length_m: 28.0,
            connection_still_s: 300.0,
            connection_dwells: 1,
            initial_still_s: 600.0,
            toolface_change_per_connection_deg: 30.0,
            toolface_turn_rate_deg_s: 10.0,
            sliding_toolface_steps_per_hour: 1.0,
            sliding_toolface_step_deg: 10.0,
            vibration: Vibration::default(),
            depth_errors: DepthErrors::default(),
            depth_log_interval_s: 1.0,
            tortuosity: Tortuosity::default(),
        }
    }
}

impl DrillingParams {
    pub(super) fn check(&self) -> Result<()> {
        let ranges = [
            ("rop_m_per_h", self.rop_m_per_h, 0.1, 500.0),
            ("rop_ramp_s", self.rop_ramp_s, 0.0, 600.0),
            ("stand_length_m", self.stand_length_m, 1.0, 1000.0),
            ("connection_still_s", self.connection_still_s, 0.0, 86_400.0),
            ("initial_still_s", self.initial_still_s, 0.0, 86_400.0),
            (
                "toolface_change_per_connection_deg",
                self.toolface_change_per_connection_deg,
                0.0,
                360.0,
            ),
            (
                "toolface_turn_rate_deg_s",
                self.toolface_turn_rate_deg_s,
                0.1,
                300.0,
            ),
            (
                "sliding_toolface_steps_per_hour",
                self.sliding_toolface_steps_per_hour,
                0.0,
                3600.0,
            ),
            (
                "sliding_toolface_step_deg",
                self.sliding_toolface_step_deg,
                0.0,
                360.0,
            ),
            (
                "depth_log_interval_s",
                self.depth_log_interval_s,
                0.05,
                3600.0,
            ),
        ];
        for (name, v, lo, hi) in ranges {
            ensure!(
                v.is_finite() && (lo..=hi).contains(&v),
                "drilling.{name} must be a number from {lo} to {hi} (got {v})"
            );
        }
        ensure!(
            (1..=MAX_CONNECTION_DWELLS).contains(&self.connection_dwells),
            "drilling.connection_dwells must be a whole number from 1 to {MAX_CONNECTION_DWELLS} \
             (got {})",
            self.connection_dwells
        );
        self.vibration.check()?;
        self.tortuosity.check()?;
        let d = &self.depth_errors;
        ensure!(
            d.scale_ppm.is_finite() && d.scale_ppm.abs() <= 10_000.0,
            "drilling.depth_errors.scale_ppm must be a number from -10000 to 10000 ppm"
        );
        ensure!(
            d.stretch_per_m.is_finite() && d.stretch_per_m.abs() <= 1e-5,
            "drilling.depth_errors.stretch_per_m must be a number from -1e-5 to 1e-5 per m"
        );
        Ok(())
    }
}
