//! ISCWSA wellbore position-uncertainty model (SPE 67616, Williamson 2000)
//! on the host: error sources as data (a term table read from CSV), the
//! weighting functions of the ISCWSA MWD Rev 5 model, and the propagation
//! of each source's error vectors to the NEV covariance at every station.
//!
//! Conventions (as in the ISCWSA example workbooks and SPE 67616):
//! * stations are (MD, inclination, true azimuth, TVD), MD/TVD in metres,
//!   angles in radians; the first station is the tie-on;
//! * the position change over the leg k-1 -> k is taken, for the
//!   derivatives, as the balanced-tangential
//!   `dr_k = (D_k - D_{k-1})/2 * (t_{k-1} + t_k)` with `t` the unit tangent;
//! * a source's error at station k is `e_k = sigma * (d dr_k/dp_k +
//!   d dr_{k+1}/dp_k) * w_k` with `w = (dD, dI, dA)/d eps` the weighting
//!   function; at the station of interest K only the leg before it counts;
//! * the tie-on's own inclination/azimuth error is carried by station 1
//!   (its leg-before weight covers the whole first course length), its depth
//!   error is not counted — this is what the published Rev 5 diagnostics
//!   show (e.g. the random XYM3E of well #1 at 1200 m); the Rev 4
//!   diagnostics take the tie-on as exact instead ([`TieOn`]);
//! * random sources: sum over stations of `e e^T`; systematic, per-well and
//!   global sources: the outer product of the summed vector (the same
//!   thing on a single well);
//! * at a station closer to vertical than the model's limit, a source
//!   whose azimuth weighting is singular uses its tabulated NEV
//!   "singularity" vector in place of `dr/dp * w`;
//! * the long-course-length terms XCLA/XCLH (SPE 187249) use the
//!   tangential form instead (see `weighting::xcl_vector`).
//!
//! Where the workbook's documentation formulas and its published numbers
//! disagree, the numbers win (each case checked against the diagnostic
//! block of the three test wells, `host-sim/tests/iscwsa_error_model.rs`):
//! XYM3E's azimuth weight is `-|cos I| sin A / sin I` (the 5.10 Model sheet
//! prints it without the minus sign), and an azimuth change out of a
//! vertical station does not count in XCLA.
//!
//! Weighting functions are looked up by the table's `Wt.Fn.` name; a name
//! not implemented here is reported in [`ModelResult::missing`], never
//! treated as zero. Implemented: DREF, DSF, DST, ABXY-TI1/2, ABZ,
//! ASXY-TI1/2/3, ASZ, MBXY-TI1/2, MBZ, MSXY-TI1/2/3, MSZ, AZ, DBH, AMIL,
//! SAGE, XYM1, XYM2, XYM3L/XYM3E, XYM4L/XYM4E, XCLA, XCLH (the Rev 5.10
//! MWD set; XCLA in both its pre-5.10 and 5.10 forms, [`XclAzimuth`]), and
//! SAG, XYM3, XYM4 (Rev 4), and the OWSG GYRO-MWD / GYRO-NS gyro and
//! accelerometer functions AXYZ-MIS/SF/ZB, GXY-B1/B2/G1/G4/RN (no
//! published covariances to check them against: tested only by closed
//! forms; the OWSG models are stated for inclinations up to 89 deg, and
//! GXY-B1/G4/RN grow without bound towards 90 deg); and this probe's own
//! PRB-GXB/GZB/GN ([`probe_weighting`]), valid through 90 deg. Not
//! implemented: the Rev 5.04 single `XCL` function.
//!
//! Files: `term_table` (the term table read from CSV), `stations` (the
//! survey, the site and their check), `weighting` (the weighting
//! functions), `propagation` (the error vectors and their sums, [`run`]);
//! the probe's own model in [`probe_model`], [`probe_weighting`] and
//! [`probe_station`].

mod link_chain;
pub mod probe_model;
pub mod probe_station;
pub mod probe_weighting;
mod propagation;
mod stations;
mod term_table;
#[cfg(test)]
mod tests;
mod weighting;

pub use link_chain::through_superseded;
pub use propagation::{cov_matrix, run, run_with, Cov6, ModelResult, Options, Propagator, TieOn};
pub use stations::{check_stations, Site, Station, EARTH_RATE};
pub use term_table::{load_term_table, parse_term_table, DataError, ErrorTerm, Propagation};
pub use weighting::{XclAzimuth, XCL_TORTUOSITY};
