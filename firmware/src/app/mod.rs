//! The probe's application core, independent of the board: what happens in
//! each 20 Hz cycle, how frames wait for the UART, how the driver's readings
//! and faults become frames, and the glue between the board's contexts;
//! [`budget`] derives the worst recovery, the inbox's size and the
//! watchdog's worst unfed stretch from the driver's waits, [`watchdog`]
//! the watchdog's timeout from them; [`config_store`] keeps the
//! configuration in two flash slots ([`ram_flash`]: a flash emulated in
//! RAM for QEMU; [`power_cut`]: a write cut on purpose, for QEMU's
//! power-cut test), [`uplink_rx`] receives the host's commands and
//! [`uplink_service`] answers them from the main loop; [`boot`] packs the
//! boot event's reset cause and configuration source; [`main_loop`] is
//! the probe's main loop, the same on every board, [`board_basics`] what
//! it uses alike of every board.
//! Pure code (no registers, no heap), so the host tests it and every board
//! binary runs the same logic; a board only supplies the timer interrupt,
//! its UART ([`Transmitter`]), the sensors' SPI, the watchdog and the
//! rest of what the main loop needs of it ([`Board`]).

pub mod board_basics;
pub mod boot;
pub mod budget;
pub mod config_store;
pub mod cycle;
pub mod frame_queue;
pub mod main_loop;
pub mod power_cut;
pub mod probe;
pub mod ram_flash;
pub mod sample_inbox;
pub mod sensor_wire;
pub mod shared;
pub mod start_up;
#[cfg(test)]
mod test_support;
pub mod transmitter;
pub mod uplink_rx;
pub mod uplink_service;
pub mod watchdog;

pub use board_basics::{BoardBasics, SamplePeriods};
pub use cycle::{AcquisitionCycle, CycleReport};
pub use frame_queue::{FrameQueue, TX_QUEUE_LEN};
pub use main_loop::{Board, Pass};
pub use probe::{ProbeState, RecoveryJob, Sensors};
pub use sample_inbox::{SampleInbox, NAV_INBOX_LEN};
pub use sensor_wire::{fault_code, raw_part, reset_event_code, sensor_fault_event};
pub use shared::{Shared, SharedProbe, FIRMWARE_VERSION};
pub use start_up::{start_parts, START_ATTEMPTS};
pub use transmitter::{OneByteTransmitter, Transmitter, TxDataRegister};
pub use watchdog::{Watchdog, WATCHDOG_TIMEOUT_MS};
