//! The toolface while drilling from the accelerometers' block mean
//! (derivation section 4g; not in the paper).
//!
//! While drilling the probe holds its roll (`ToolAxisSource::AtRest`): one
//! sample's accelerometer roll carries the vibration (~7 m/s^2 of lateral
//! force per sample at the simulator's moderate level, 40 deg of roll), and
//! the roll-derived tool-axis rate would put it into the attitude. But the
//! driller turns the toolface on bottom too (a slide's orientation, a new
//! section's toolface: 100 deg at 10 deg/s in the simulated lateral), and a
//! held roll 100 deg off maps the gyros' earth rate onto the wrong axes:
//! about 12 deg/h of heading drift until the next station, which no sigma
//! covered. The mean of a block of samples sees gravity through the
//! vibration: its roll atan2(-f_x, f_z) (`attitude::level`) has variance
//! (f_z^2 var(f_x) + f_x^2 var(f_z)) / (f_x^2 + f_z^2)^2, the force
//! variances being the block's own scatter over its length (the vibration
//! taken as white at the sample rate) plus the accelerometer-bias budget,
//! which no averaging removes. One scalar update per block: z = computed
//! toolface - block toolface (wrapped), h = the toolface row of the
//! drilling-angle Jacobian (`conventions::angles_and_jacobian`).

use super::attitude_angle::attitude_angle_scalar;
use crate::attitude::level;
use crate::conventions::{angles_and_jacobian, dcm_from_quat, wrap_pi};
use crate::kalman::{FilterScalar, Measurement, ScalarMeasurement};
use crate::mechanization::NavState;
use nalgebra::Vector3;

/// Samples per block: 2 s at 20 Hz, about 6 deg of toolface sigma per
/// block at the moderate vibration.
pub const TOOLFACE_BLOCK_SAMPLES: u32 = 40;

/// Sums of one block of drilling samples' specific force (body axes).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ForceBlock {
    sum: Vector3<f64>,
    /// Sums of f_x^2 and f_z^2.
    sum_squares: [f64; 2],
    samples: u32,
}

impl ForceBlock {
    pub fn add(&mut self, force: &Vector3<f64>) {
        self.sum += force;
        self.sum_squares[0] += force.x * force.x;
        self.sum_squares[1] += force.z * force.z;
        self.samples += 1;
    }

    pub fn samples(&self) -> u32 {
        self.samples
    }

    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// The mean force and the variances of the mean's x and z (the
    /// scatter over the block divided by its length); `None` for fewer
    /// than two samples.
    fn mean_and_variances(&self) -> Option<(Vector3<f64>, [f64; 2])> {
        if self.samples < 2 {
            return None;
        }
        let n = f64::from(self.samples);
        let mean = self.sum / n;
        let scatter = |sum_sq: f64, m: f64| ((sum_sq - n * m * m) / (n - 1.0)).max(0.0) / n;
        Some((
            mean,
            [
                scatter(self.sum_squares[0], mean.x),
                scatter(self.sum_squares[1], mean.z),
            ],
        ))
    }
}

/// One block's toolface against the filter's attitude: one scalar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrillingToolface<T> {
    /// Computed minus block toolface (rad, wrapped).
    pub toolface_residual: T,
    /// d(toolface) / d(phi).
    pub attitude_row: [T; 3],
    /// The block toolface's variance (rad^2).
    pub variance: T,
    /// The block's toolface (rad): what a gross re-levelling sets.
    pub block_toolface: f64,
}

impl<T: FilterScalar> DrillingToolface<T> {
    /// The update at `state` from `block`, with the accelerometer bias
    /// variance `bias_variance` ((m/s^2)^2, per axis); `None` when the
    /// block is too short or the tool axis too near vertical for a roll
    /// (`attitude::level`).
    pub fn at(state: &NavState, block: &ForceBlock, bias_variance: f64) -> Option<Self> {
        let (mean, var) = block.mean_and_variances()?;
        let levelling = level(&mean);
        if !levelling.roll_valid {
            return None;
        }
        let cross2 = mean.x * mean.x + mean.z * mean.z;
        let variance = (mean.z * mean.z * (var[0] + bias_variance)
            + mean.x * mean.x * (var[1] + bias_variance))
            / (cross2 * cross2);
        let (angles, jacobian) = angles_and_jacobian(&dcm_from_quat(&state.attitude));
        let row: [f64; 3] = core::array::from_fn(|k| jacobian[(2, k)]);
        let valid = variance > 0.0 && variance.is_finite() && row.iter().all(|v| v.is_finite());
        valid.then(|| Self {
            toolface_residual: T::of(wrap_pi(angles.toolface - levelling.roll)),
            attitude_row: row.map(T::of),
            variance: T::of(variance),
            block_toolface: levelling.roll,
        })
    }
}

impl<T: FilterScalar> Measurement<T> for DrillingToolface<T> {
    fn len(&self) -> usize {
        1
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        if k != 0 {
            return None;
        }
        Some(attitude_angle_scalar(
            self.toolface_residual,
            &self.attitude_row,
            self.variance,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conventions::{quat_from_euler, specific_force_at_rest, Euler, DEG};
    use crate::earth::Position;

    fn state(roll: f64) -> NavState {
        let e = Euler {
            roll,
            pitch: 2.0 * DEG,
            heading: 120.0 * DEG,
        };
        NavState::at_rest(quat_from_euler(&e), Position::paper_site())
    }

    /// A block of a tool rolled 30 deg more than the filter thinks: the
    /// residual is the computed minus the block's toolface, and its
    /// variance the scatter's, shrinking with the block's length.
    #[test]
    fn a_block_measures_the_roll_the_filter_holds_wrongly() {
        let truth = Euler {
            roll: 40.0 * DEG,
            pitch: 2.0 * DEG,
            heading: 120.0 * DEG,
        };
        let g = specific_force_at_rest(&truth, 9.80665);
        let mut block = ForceBlock::default();
        for k in 0..40 {
            // +-1 m/s^2 of alternating lateral force: mean exact, scatter 1
            let s = if k % 2 == 0 { 1.0 } else { -1.0 };
            block.add(&(g + Vector3::new(s, 0.0, -s)));
        }
        let m = DrillingToolface::<f64>::at(&state(10.0 * DEG), &block, 0.0).unwrap();
        assert!((m.toolface_residual - (-30.0 * DEG)).abs() < 1e-9, "{m:?}");
        assert!((m.block_toolface - 40.0 * DEG).abs() < 1e-9);
        // var(f) = 40/39 per axis, /40 for the mean, / g_cross^2
        let g_cross2 = g.x * g.x + g.z * g.z;
        let want = (40.0 / 39.0) / 40.0 / g_cross2;
        assert!(
            (m.variance / want - 1.0).abs() < 1e-9,
            "{} {want}",
            m.variance
        );
        // the row turns the attitude about the tool axis
        let row = Vector3::from(m.attitude_row);
        assert!(row.norm() > 0.99 && row.norm() < 1.01, "{row:?}");
    }

    #[test]
    fn a_vertical_tool_or_a_short_block_gives_no_toolface() {
        let mut block = ForceBlock::default();
        block.add(&Vector3::new(0.0, -9.8, 0.0));
        assert!(DrillingToolface::<f64>::at(&state(0.0), &block, 0.0).is_none());
        block.add(&Vector3::new(0.0, -9.8, 0.0));
        assert!(DrillingToolface::<f64>::at(&state(0.0), &block, 0.0).is_none());
    }
}
