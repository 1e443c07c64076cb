//! A register-level model of the Murata SCC1300-D04 (gyro and accelerometer
//! slaves) behind the embedded-hal 1.0 `SpiDevice` trait, with fault
//! injection, for host tests and the QEMU firmware.
//!
//! Filled by the SPI driver issue; this crate is the place for it.
#![no_std]
#![forbid(unsafe_code)]
