//! Navigation core of the gyro MWD probe: no_std, no heap, no unsafe.
#![no_std]
#![forbid(unsafe_code)]
