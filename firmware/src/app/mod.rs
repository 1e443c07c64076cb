//! The probe's application core, independent of the board: what happens in
//! each 20 Hz cycle, how frames wait for the UART, and how the driver's
//! readings and faults become frames. Pure code (no registers, no interrupts, no heap), so
//! the host tests it and every board binary runs the same logic; a board
//! only supplies the timer interrupt, the UART and the sensors' SPI.

pub mod cycle;
pub mod frame_queue;
pub mod probe;
pub mod sample_inbox;
pub mod sensor_wire;
pub mod start_up;

pub use cycle::{AcquisitionCycle, CycleReport};
pub use frame_queue::{FrameQueue, TX_QUEUE_LEN};
pub use probe::{ProbeState, Recovery, Sensors};
pub use sample_inbox::{SampleInbox, NAV_INBOX_LEN};
pub use sensor_wire::{fault_code, raw_part, reset_event_code, sensor_fault_event};
pub use start_up::{start_parts, START_ATTEMPTS};
