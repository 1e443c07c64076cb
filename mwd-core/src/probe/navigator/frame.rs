//! What a cycle's frame reports (docs/protocol.md, Kind 2;
//! docs/filter-derivation.md section 5b): the solution, its sigmas once
//! the covariance is healthy, and the flags that say how far to trust it.

use super::heading::AZIMUTH_SIGMA_LIMIT_RAD;
use super::readout::AttitudeReadout;
use super::state::{Navigator, Phase};
use crate::error_model::{POS, TILT_SIGMA_LIMIT_RAD, VEL};
use crate::kalman::FilterScalar;
use crate::protocol::frame::{nav_flags, nav_mode};
use crate::protocol::NavSolution;

/// The covariance health check's bound on every variance, in the states'
/// own units squared (rad^2, (m/s)^2, m^2, and the sensor-error states'):
/// 1e16 is a position sigma of 1e8 m (100,000 km), far past any meaning.
/// The f32 covariance also holds variances down to ~1e-11 (the gyro-bias
/// states); with a spread of much more than 1e21 its Phi P Phi^T would
/// lose the small entries to the rounding of the large ones (f32: 24-bit
/// mantissa; docs/filter-derivation.md section 5b), so
/// the check stops it before that rather than report what the roundings
/// made. An f64 filter is held to the same bound, so it stops where the
/// probe would.
pub const VARIANCE_LIMIT: f32 = 1e16;

impl<T: FilterScalar> Navigator<T> {
    /// The readout of the filter's attitude now (`readout`): the cycle's,
    /// when nothing has changed since it was made.
    pub(super) fn readout(&mut self) -> AttitudeReadout {
        if let Some(readout) = self.readout.filter(|r| r.is_of(&self.filter)) {
            return readout;
        }
        let readout = AttitudeReadout::of(&self.filter);
        self.readout = Some(readout);
        readout
    }

    /// The attitude's readout once there is a solution (after the coarse
    /// alignment): made once per cycle, for the frame and the heading-loss
    /// check (and the station's survey before them).
    pub(super) fn solution_readout(&mut self) -> Option<AttitudeReadout> {
        let has_solution = !matches!(self.phase, Phase::Coarse(_));
        has_solution.then(|| self.readout())
    }

    /// The cycle's frame; `readout` from [`solution_readout`](Self::solution_readout).
    pub(super) fn solution(
        &self,
        time_us: u64,
        sample_counter: u32,
        readout: Option<AttitudeReadout>,
    ) -> NavSolution {
        let mut solution = NavSolution {
            time_us,
            sample_counter,
            mode: nav_mode::COARSE_ALIGNMENT,
            flags: self.flags,
            // Placeholders while there is no solution: NaN, never a
            // number that could be read (docs/protocol.md, Kind 2).
            attitude: [f32::NAN; 3],
            velocity_ned: [f32::NAN; 3],
            latitude: self.position.lat,
            longitude: self.position.lon,
            height: self.position.height as f32,
            attitude_std: self.coarse_std,
            // No filter yet: velocity and position uncertainty unknown.
            velocity_std: [f32::NAN; 3],
            position_std_ned: [f32::NAN; 3],
        };
        solution.mode = match self.phase {
            Phase::Coarse(_) => nav_mode::COARSE_ALIGNMENT,
            Phase::Fine { .. } => nav_mode::FINE_ALIGNMENT,
            Phase::Navigating => nav_mode::NAVIGATING,
        };
        let Some(readout) = readout else {
            // No solution yet (the coarse alignment has no readout): the
            // NaN placeholders come with the bit that says not to use them.
            solution.flags |= nav_flags::SOLUTION_INVALID;
            return solution;
        };
        let filter = &self.filter;
        let state = filter.state();
        let e = readout.euler;
        solution.attitude = [e.roll, e.pitch, e.heading].map(|a| a as f32);
        let v = state.velocity;
        solution.velocity_ned = [v.x, v.y, v.z].map(|v| v as f32);
        solution.latitude = state.position.lat;
        solution.longitude = state.position.lon;
        solution.height = state.position.height as f32;
        if self.coasting {
            solution.flags |= nav_flags::COASTING;
        }
        if self.heading_lost {
            solution.flags |= nav_flags::HEADING_LOST;
        }
        let std = readout.euler_std();
        if self.covariance_invalid {
            solution.flags |= nav_flags::COVARIANCE_INVALID | nav_flags::SOLUTION_INVALID;
            solution.attitude_std = [f32::NAN; 3];
            return solution;
        }
        // The azimuth's sigma: infinite while the heading is undetermined
        // (coarse alignment, or lost in navigation) or rests on one gyro
        // (single part).
        let heading_std = if self.coarse_std[2].is_finite()
            && solution.flags & nav_flags::SINGLE_PART == 0
            && std.z <= AZIMUTH_SIGMA_LIMIT_RAD
        {
            std.z as f32
        } else {
            f32::INFINITY
        };
        solution.attitude_std = [std.x as f32, std.y as f32, heading_std];
        // Beyond the tilt limit (or with a tilt sigma that is not even a
        // number) the small-angle error model no longer holds.
        let tilt_valid = std.x <= TILT_SIGMA_LIMIT_RAD && std.y <= TILT_SIGMA_LIMIT_RAD;
        if !tilt_valid {
            solution.flags |= nav_flags::SOLUTION_INVALID;
        }
        let kalman = filter.filter();
        // The frames' sigmas are f32 whatever the filter's scalar (the wire
        // protocol's type).
        let std_dev = |i: usize| kalman.std_dev(i).as_f64() as f32;
        solution.velocity_std = core::array::from_fn(|i| std_dev(VEL + i));
        solution.position_std_ned = core::array::from_fn(|i| std_dev(POS + i));
        solution
    }
}
