//! The probe's application core, independent of the board: what happens in
//! each 20 Hz cycle, how frames wait for the UART, and how sensor faults
//! become event frames. Pure code (no registers, no interrupts, no heap), so
//! the host tests it and every board binary runs the same logic; a board
//! only supplies the timer interrupt, the UART and the sensors' SPI.

pub mod cycle;
pub mod frame_queue;
pub mod probe;
pub mod sample_inbox;
pub mod start_up;

pub use cycle::{AcquisitionCycle, CycleReport};
pub use frame_queue::{FrameQueue, TX_QUEUE_LEN};
pub use probe::{ProbeState, Recovery, Sensors};
pub use sample_inbox::{SampleInbox, NAV_INBOX_LEN};
pub use start_up::{reset_event_code, start_parts, START_ATTEMPTS};
