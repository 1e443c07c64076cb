//! What the application's host tests share: the UART they send through,
//! its interrupts and its wire, and the checks of the frames it sent.

extern crate std;

use std::format;
use std::vec::Vec;

use mwd_core::earth::Position;
use mwd_core::probe::Navigator;
use mwd_core::protocol::{Decoder, Event, Frame, NavSolution, Payload, RawSample};

use super::shared::SharedProbe;
use super::transmitter::{OneByteTransmitter, Transmitter, TxDataRegister};

/// A UART that takes one byte per interrupt, as QEMU's does; what it sent
/// is on its wire (`register_mut`).
pub(crate) type TestUart = OneByteTransmitter<Wire>;

/// The tests' line: every byte the UART sent, in order.
#[derive(Default)]
pub(crate) struct Wire(pub(crate) Vec<u8>);

impl TxDataRegister for Wire {
    fn write(&mut self, byte: u8) {
        self.0.push(byte);
    }
}

impl Default for TestUart {
    fn default() -> Self {
        Self::new(Wire::default())
    }
}

/// The UART's interrupts until the queue is empty.
pub(crate) fn drain<G, A>(probe: &SharedProbe<G, A, TestUart>) {
    while probe.with(|shared| {
        shared.transmitter_ready();
        !shared.transmitter().is_idle()
    }) {}
}

/// What the UART has sent since the last call.
pub(crate) fn take_wire<G, A>(probe: &SharedProbe<G, A, TestUart>) -> Vec<u8> {
    probe.with(|shared| core::mem::take(&mut shared.transmitter_mut().register_mut().0))
}

/// The frames the UART has sent since the last call, none corrupt or lost.
pub(crate) fn sent_frames<G, A>(probe: &SharedProbe<G, A, TestUart>) -> Vec<Frame> {
    let mut decoder = Decoder::new();
    let mut frames = Vec::new();
    decoder.feed(&take_wire(probe), |f| frames.push(f));
    assert_eq!((decoder.stats().corrupt(), decoder.stats().lost), (0, 0));
    frames
}

/// The events among `frames`, in order.
pub(crate) fn events_of(frames: &[Frame]) -> Vec<Event> {
    frames
        .iter()
        .filter_map(|f| match f.payload {
            Payload::Event(e) => Some(e),
            _ => None,
        })
        .collect()
}

/// Every raw sample went out and was navigated, in order: `samples` raw
/// frames without a gap and as many navigation frames, those a fresh
/// navigator at the paper's site makes of the raw ones.
pub(crate) fn assert_navigated_in_order(frames: &[Frame], samples: usize) {
    let (mut raws, mut navs): (Vec<RawSample>, Vec<NavSolution>) = (Vec::new(), Vec::new());
    for frame in frames {
        match frame.payload {
            Payload::Raw(r) => raws.push(r),
            Payload::Nav(n) => navs.push(n),
            _ => {}
        }
    }
    assert_eq!(raws.len(), samples);
    assert_eq!(navs.len(), samples);
    let mut replay = Navigator::new(Position::paper_site());
    for (n, (raw, nav)) in raws.iter().zip(&navs).enumerate() {
        assert_eq!(raw.sample_counter as usize, n);
        // Debug text, so that NaN fields compare too.
        assert_eq!(format!("{:?}", replay.step(raw)), format!("{nav:?}"));
    }
}
