//! The last few sequence numbers up to the newest received, each received
//! (with its frame's CRC) or counted lost: what tells a frame received
//! again (a duplicate) and a late one (reordered) from a restart.
//! 36 bytes, no allocation.

/// Sequence numbers kept, the newest included: a frame at most this many
/// minus one behind the newest is looked up. A link that duplicates or
/// swaps frames does so with neighbours; a frame further behind is taken
/// as the sequence going backwards (a restart), as before.
pub(super) const WINDOW: u16 = 8;

/// What a frame behind the newest is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Behind {
    /// Received already, the same bytes (same number and CRC).
    Duplicate,
    /// Counted lost when the sequence skipped it: it came late.
    Reordered,
}

/// Bit `i` of a mask stands for the frame numbered `newest - i`.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct RecentFrames {
    received: u8,
    lost: u8,
    /// The CRC-32C of the frame numbered `n` at `n % WINDOW`, where
    /// received.
    crcs: [u32; WINDOW as usize],
}

impl RecentFrames {
    pub(super) const fn new() -> Self {
        Self {
            received: 0,
            lost: 0,
            crcs: [0; WINDOW as usize],
        }
    }

    /// The frame numbered `seq` is the new newest, `skipped` numbers after
    /// the last newest (counted lost); nothing before it is known when the
    /// window was `reset` (a restart, or no frame yet).
    pub(super) fn advance(&mut self, seq: u16, crc: u32, skipped: u16, reset: bool) {
        if reset {
            self.received = 0;
            self.lost = 0;
        }
        let shift = u32::from(skipped) + 1;
        let kept_lost = u32::from(skipped.min(WINDOW - 1));
        let newly_lost = ((1u32 << kept_lost) - 1) << 1;
        self.received = self.received.checked_shl(shift).unwrap_or(0) | 1;
        self.lost = self.lost.checked_shl(shift).unwrap_or(0) | newly_lost as u8;
        self.set_crc(seq, crc);
    }

    /// Frames counted lost so far are no longer counted (a restart found
    /// late, by the sample counter): one arriving late is not reordered.
    pub(super) fn forget_lost(&mut self) {
        self.lost = 0;
    }

    /// The frame numbered `seq` with CRC `crc`, when `newest` is the newest:
    /// a duplicate, a reordered frame (then taken as received), or neither
    /// (ahead of the newest, too far behind, or another frame with a
    /// number just received: a restart).
    pub(super) fn behind(&mut self, newest: u16, seq: u16, crc: u32) -> Option<Behind> {
        let distance = newest.wrapping_sub(seq);
        if distance >= WINDOW {
            return None;
        }
        let bit = 1u8 << distance;
        let slot = usize::from(seq % WINDOW);
        if self.received & bit != 0 {
            return (self.crcs.get(slot) == Some(&crc)).then_some(Behind::Duplicate);
        }
        if self.lost & bit != 0 {
            self.lost &= !bit;
            self.received |= bit;
            self.set_crc(seq, crc);
            return Some(Behind::Reordered);
        }
        None
    }

    fn set_crc(&mut self, seq: u16, crc: u32) {
        if let Some(slot) = self.crcs.get_mut(usize::from(seq % WINDOW)) {
            *slot = crc;
        }
    }
}
