//! Probe firmware library: the parts that bind the navigation core to the
//! sensors and the UART and that can be tested on the host. Board binaries
//! (real board, QEMU mps2-an386) build only for `thumbv7em-none-eabihf`.
#![no_std]
#![forbid(unsafe_code)]

pub use mwd_core;

pub mod app;
pub mod scc1300;
