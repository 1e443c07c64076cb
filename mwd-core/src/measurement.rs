//! Measurements of the error-state filter (paper eq. 46-48).
//!
//! A measurement is a few scalars, each `z = h^T x + v` with a sparse row
//! `h` and noise variance `r`. Adding a measurement type (non-holonomic
//! constraint, measured depth, external heading) means one small type that
//! implements [`Measurement`]; the filter needs nothing else.
//!
//! The error states are computed - true, so a measurement's `z` is the
//! computed quantity minus its reference: for a zero-velocity update
//! `z = v_computed - 0 = dv` (eq. 47) and the row selects the velocity
//! error. Eq. 48 prints "H12, H13" as the unit blocks; the velocity and
//! position blocks are H12 and H23 (erratum 5).

use crate::earth::Position;
use crate::error_model::{EarthTerms, POS, VEL};
use crate::kalman::FilterScalar;
use nalgebra::Vector3;

/// Most non-zeros in one measurement row: enough for an attitude-and-
/// velocity constraint (3 + 3) with room to spare.
pub const MAX_ROW_NONZEROS: usize = 8;

/// A sparse measurement row: `h^T x = sum coef[k] * x[index[k]]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SparseRow<T> {
    index: [u8; MAX_ROW_NONZEROS],
    coef: [T; MAX_ROW_NONZEROS],
    len: u8,
}

impl<T: FilterScalar> SparseRow<T> {
    /// The unit row selecting state `i` (the selection matrices of eq. 48).
    pub fn select(i: usize) -> Self {
        let mut row = Self::empty();
        row.push(i, T::one());
        row
    }

    pub fn empty() -> Self {
        Self {
            index: [0; MAX_ROW_NONZEROS],
            coef: [T::zero(); MAX_ROW_NONZEROS],
            len: 0,
        }
    }

    /// Adds `coef * x[i]`; returns false (row unchanged) when full or `i`
    /// does not fit the index type.
    pub fn push(&mut self, i: usize, coef: T) -> bool {
        let n = self.len as usize;
        match u8::try_from(i) {
            Ok(i) if n < MAX_ROW_NONZEROS => {
                self.index[n] = i;
                self.coef[n] = coef;
                self.len += 1;
                true
            }
            _ => false,
        }
    }

    /// The (state index, coefficient) pairs.
    pub fn entries(&self) -> impl Iterator<Item = (usize, T)> + '_ {
        self.index
            .iter()
            .zip(self.coef.iter())
            .take(self.len as usize)
            .map(|(&i, &c)| (i as usize, c))
    }
}

/// One scalar measurement: value `z`, row `h`, noise variance `r`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScalarMeasurement<T> {
    pub z: T,
    pub h: SparseRow<T>,
    pub r: T,
}

/// A measurement made of `len()` scalars with uncorrelated noise.
pub trait Measurement<T: FilterScalar> {
    fn len(&self) -> usize;
    /// Scalar `k < len()`; `None` if `k` is out of range.
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>>;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Zero-velocity update (ZUPT): the probe is at rest, so the computed NED
/// velocity is the velocity error (eq. 47, first three rows).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZeroVelocity<T> {
    /// Computed velocity minus the reference (zero), NED, m/s.
    pub velocity_n: [T; 3],
    /// Noise variance of each component, (m/s)^2.
    pub variance: T,
}

impl<T: FilterScalar> ZeroVelocity<T> {
    pub fn new(computed_velocity_n: &Vector3<f64>, variance: T) -> Self {
        Self {
            velocity_n: core::array::from_fn(|i| T::of(computed_velocity_n[i])),
            variance,
        }
    }
}

impl<T: FilterScalar> Measurement<T> for ZeroVelocity<T> {
    fn len(&self) -> usize {
        3
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        Some(ScalarMeasurement {
            z: *self.velocity_n.get(k)?,
            h: SparseRow::select(VEL + k),
            r: self.variance,
        })
    }
}

/// Zero-position update: the probe has not moved from a known position,
/// so the computed position minus the reference is the position error, in
/// metres north, east, down (eq. 47, last three rows, in metres: erratum 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZeroPosition<T> {
    /// Computed position minus the reference, NED metres.
    pub position_error_ned_m: [T; 3],
    /// Noise variance of each component, m^2.
    pub variance: T,
}

impl<T: FilterScalar> ZeroPosition<T> {
    /// The difference is formed in f64 (geodetic angles need it) and only
    /// the small metric offset is converted to the filter's scalar.
    pub fn new(computed: &Position, reference: &Position, variance: T) -> Self {
        let d = computed.ned_from(reference);
        Self {
            position_error_ned_m: core::array::from_fn(|i| T::of(d[i])),
            variance,
        }
    }
}

impl<T: FilterScalar> ZeroPosition<T> {
    /// The same offset as [`ZeroPosition::new`] (first order, like
    /// `Position::ned_from`) with the radii and cos(lat) of the reference
    /// already at hand: no trigonometry in the 20 Hz cycle.
    pub fn with_earth_terms(computed: &Position, reference: &EarthTerms, variance: T) -> Self {
        let r = &reference.position;
        let d = [
            (computed.lat - r.lat) * reference.meridian,
            (computed.lon - r.lon) * reference.transverse * reference.cos_lat,
            r.height - computed.height,
        ];
        Self {
            position_error_ned_m: d.map(T::of),
            variance,
        }
    }
}

impl<T: FilterScalar> Measurement<T> for ZeroPosition<T> {
    fn len(&self) -> usize {
        3
    }
    fn scalar(&self, k: usize) -> Option<ScalarMeasurement<T>> {
        Some(ScalarMeasurement {
            z: *self.position_error_ned_m.get(k)?,
            h: SparseRow::select(POS + k),
            r: self.variance,
        })
    }
}
