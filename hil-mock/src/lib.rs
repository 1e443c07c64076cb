//! A register-level model of the Murata SCC1300-D04 (gyro and accelerometer
//! slaves) behind the embedded-hal 1.0 `SpiDevice` trait, with fault
//! injection, for host tests and the QEMU firmware.
//!
//! One [`Scc1300`] is one part. Put it in a `RefCell` and give its two
//! chip selects to the driver as [`GyroSpi`] and [`AccelSpi`]. The part
//! walks its start-up with the time of a [`TimeSource`] ([`SimClock`] on the
//! host, advanced by the driver's waits through [`SimDelay`]), reads the
//! physics from a [`SampleSource`], and answers every frame as TN92 frames
//! it: odd parity on every word, in-frame answers, the accelerometer's FRME
//! one frame late and its dPAR over the frame [`DparScope`] names, the
//! accelerometer's 10 ms settling after CTRL = 0. [`Faults`] injects errors
//! on either side.
//!
//! ```
//! use core::cell::RefCell;
//! use hil_mock::{AccelSpi, Constant, GyroSpi, Scc1300, SimClock};
//! let clock = SimClock::new();
//! let part = RefCell::new(Scc1300::new(&clock, Constant::default(), 1));
//! let (gyro_spi, accel_spi) = (GyroSpi::new(&part), AccelSpi::new(&part));
//! # let _ = (gyro_spi, accel_spi);
//! ```
//!
//! RAM: one part with the built-in generator is about 230 bytes (measured by
//! `firmware/tests/driver_vs_mock.rs`, `ram_footprint_fits_the_probe`); no
//! heap, no unsafe.
#![no_std]
#![forbid(unsafe_code)]

mod accel;
pub mod clock;
pub mod faults;
mod gyro;
pub mod part;
pub mod source;
pub mod spi;
pub mod still;
pub mod stream;

pub use accel::ACCEL_SETTLE_NS;
pub use clock::{SimClock, SimDelay, TimeSource, SAMPLE_PERIOD_NS};
pub use faults::{Chance, DeadLevel, Faults, LinkFaults, TemperatureExcursion, Window};
pub use part::{DparScope, MockStats, Scc1300, DEFAULT_DPAR_SCOPE, START_UP_NS};
pub use source::{
    BodySample, BodySource, Constant, Generator, MountedSource, PhysicalSample, SampleSource,
    SliceSource,
};
pub use spi::{AccelSpi, GyroSpi, MockBusError};
pub use still::StillProbe;
pub use stream::{StreamError, StreamHeader, StreamPlayer, StreamRead, StreamRecord, StreamSource};
