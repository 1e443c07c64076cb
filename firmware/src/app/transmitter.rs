//! What the shared glue needs of a board's UART: the one piece that differs
//! between boards in how frames leave the probe. A board implements
//! [`Transmitter`] for its UART; [`SharedProbe`](super::SharedProbe) calls
//! it whenever frames were queued and from the UART's interrupt.

use super::frame_queue::{FrameQueue, TX_QUEUE_LEN};

/// A UART that sends the transmit queue one byte at a time, driven by its
/// interrupt. Both methods run inside the probe's critical section: neither
/// may wait.
pub trait Transmitter {
    /// Frames were queued: if the transmitter is idle, get it going (send
    /// the first byte, or enable the interrupt that asks for it).
    fn kick(&mut self, queue: &mut FrameQueue<TX_QUEUE_LEN>);

    /// The UART's interrupt: it can take the next byte, if one waits.
    fn ready(&mut self, queue: &mut FrameQueue<TX_QUEUE_LEN>);

    /// No byte waits in the transmitter itself (its buffer is empty). A
    /// transmitter that cannot tell says so (the default) and its board
    /// waits for the line itself where it matters
    /// ([`Board::reboot`](super::main_loop::Board::reboot)).
    fn is_idle(&self) -> bool {
        true
    }
}
