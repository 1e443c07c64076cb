//! Driver for the Murata SCC1300-D04 (X-axis gyro + three-axis
//! accelerometer), generic over embedded-hal 1.0 `SpiDevice`: one device per
//! chip select, so a part is a gyro device and an accelerometer device, and
//! the probe's two parts are four devices.
//!
//! - [`frame`]: command words and odd parity, both ways [TN92].
//! - [`gyro`], [`accel`]: the two slaves, readings in counts.
//! - [`part`]: start-up (800 ms, STATUS clearing, INT_STATUS + CTRL), the
//!   non-blocking 20 Hz sample and the recovery after a flagged one.
//! - [`error`]: what went wrong, told apart and in a sentence.
//! - [`datasheet`]: registers, timings and the unverified values.
//!
//! No heap, no panics on data: every word the part sends is checked and
//! every failure comes back as an [`Error`]. The driver knows nothing of the
//! probe's wire protocol: its readings and errors are its own types, which
//! the application (`crate::app::sensor_wire`) turns into frames.
//!
//! ```text
//! let mut part = Part::new(gyro_spi, accel_spi);
//! part.start(&mut delay)?;            // once, 800 ms
//! let reading = part.sample();        // every 50 ms, in the timer task
//! if reading.needs_recovery() {       // in a lower-priority task
//!     part.recover(&mut delay, &reading)?;
//! }
//! ```

pub mod accel;
pub mod datasheet;
pub mod error;
pub mod frame;
pub mod gyro;
pub mod part;

pub use accel::{Accel, AccelCounts};
pub use error::{Error, Slave, Word};
pub use gyro::{Gyro, GyroCounts, GyroRecovery, GyroStatus};
pub use part::{Part, PartReading, RecoveryReport};
