//! What the shared glue needs of a board's UART: the one piece that differs
//! between boards in how frames leave the probe. A board implements
//! [`Transmitter`] for its UART, or, when its transmitter holds one byte,
//! gives [`OneByteTransmitter`] its data register ([`TxDataRegister`]);
//! [`SharedProbe`](super::SharedProbe) calls it whenever frames were
//! queued and from the UART's interrupt.

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

/// The data register of a UART whose transmitter holds one byte and
/// interrupts when it has sent it (QEMU's CMSDK UART0; the host tests'
/// wire), as [`OneByteTransmitter`] drives it.
pub trait TxDataRegister {
    /// The register can take a byte. Normally so whenever the interrupt
    /// said it emptied; a register that can be full unexpectedly says so
    /// here, and the next push or timer tick tries again.
    fn has_room(&self) -> bool {
        true
    }

    /// Puts the byte into the register (it leaves on the line).
    fn write(&mut self, byte: u8);
}

/// A [`Transmitter`] over a one-byte transmit register: one byte in the
/// UART at a time, the next sent when its interrupt says it left.
pub struct OneByteTransmitter<R> {
    register: R,
    /// A byte is in the UART and its interrupt will ask for the next.
    busy: bool,
}

impl<R> OneByteTransmitter<R> {
    pub const fn new(register: R) -> Self {
        Self {
            register,
            busy: false,
        }
    }

    /// The register (the host tests read their wire from it).
    pub fn register_mut(&mut self) -> &mut R {
        &mut self.register
    }
}

impl<R: TxDataRegister> Transmitter for OneByteTransmitter<R> {
    /// Sends the next byte if the UART is idle.
    fn kick(&mut self, queue: &mut FrameQueue<TX_QUEUE_LEN>) {
        if self.busy || !self.register.has_room() {
            return;
        }
        if let Some(byte) = queue.pop() {
            self.register.write(byte);
            self.busy = true;
        }
    }

    fn ready(&mut self, queue: &mut FrameQueue<TX_QUEUE_LEN>) {
        self.busy = false;
        self.kick(queue);
    }

    fn is_idle(&self) -> bool {
        !self.busy
    }
}
