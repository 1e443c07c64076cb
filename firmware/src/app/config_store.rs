//! The configuration in flash, in two slots, so that a power cut while
//! writing leaves the previous configuration readable: generic over the
//! `embedded-storage` `NorFlash` trait (the STM32F4 HAL's flash, or an
//! emulated region in QEMU and the tests).
//!
//! Each slot is whole erase units (one sector on the STM32F411). A save
//! goes to the slot that does not hold the newest valid record: erase,
//! write the record (`mwd_core::config::record`: its CRC-32C is the
//! commit, a cut write fails it), read it back. Loading reads both slots
//! and takes the valid record with the highest version; with none valid
//! the defaults, and the caller learns which case it was ([`LoadSource`]).
//! At any instant at most one slot is being changed and the other holds
//! the last configuration saved before it, so after a cut the probe loads
//! the previous configuration, or the new one if the cut came after the
//! record's last byte (then committed, though never acknowledged): never
//! neither, and never a mix.

use embedded_storage::nor_flash::NorFlash;
use mwd_core::config::record::{decode_record, encode_record, RecordError, RECORD_LEN};
use mwd_core::config::ProbeConfig;

/// The record padded with 0xFF (erased flash) to a multiple of the
/// flash's write and read sizes; any power of two up to 64 divides it.
const PADDED_LEN: usize = RECORD_LEN.div_ceil(64) * 64;

/// What a slot holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlotState {
    /// A valid record of this version.
    Valid(u32),
    /// No usable record, and why (erased, cut write, other format...).
    Invalid(RecordError),
    /// The flash read failed.
    ReadFailed,
}

/// Where the loaded configuration came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoadSource {
    /// The newest valid record, in slot `index`.
    Slot { index: u8, version: u32 },
    /// No slot held a valid record: the defaults.
    Defaults,
}

/// A loaded configuration, where it came from, and what each slot held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Loaded {
    pub config: ProbeConfig,
    pub source: LoadSource,
    pub slots: [SlotState; 2],
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StoreError<E> {
    /// The flash driver failed (the previous configuration is intact in
    /// the other slot).
    Flash(E),
    /// The region does not fit two slots, or `base` is not on an erase
    /// unit, or the write or read size does not divide the padded record.
    Geometry,
    /// The configuration is not newer than the stored one: storing it
    /// would make loading ambiguous.
    NotNewer { stored: u32, config: u32 },
    /// The record read back is not the one written.
    VerifyFailed,
}

/// Two configuration slots at `base` in `flash`.
#[derive(Debug)]
pub struct ConfigStore<F> {
    flash: F,
    base: u32,
}

impl<F: NorFlash> ConfigStore<F> {
    /// Bytes of one slot: the record rounded up to whole erase units.
    pub const SLOT_LEN: usize = PADDED_LEN.div_ceil(F::ERASE_SIZE) * F::ERASE_SIZE;

    pub fn new(flash: F, base: u32) -> Result<Self, StoreError<F::Error>> {
        let aligned = (base as usize) % F::ERASE_SIZE == 0;
        let divides = PADDED_LEN % F::WRITE_SIZE == 0 && PADDED_LEN % F::READ_SIZE == 0;
        let end = (base as usize).checked_add(2 * Self::SLOT_LEN);
        let fits = end.is_some_and(|end| end <= flash.capacity());
        if aligned && divides && fits {
            Ok(Self { flash, base })
        } else {
            Err(StoreError::Geometry)
        }
    }

    pub fn into_inner(self) -> F {
        self.flash
    }

    fn offset(&self, slot: usize) -> u32 {
        // `new` checked that both slots lie within the flash (a u32).
        self.base + (slot * Self::SLOT_LEN) as u32
    }

    fn read_slot(&mut self, slot: usize) -> (SlotState, Option<ProbeConfig>) {
        let mut buf = [0u8; PADDED_LEN];
        if self.flash.read(self.offset(slot), &mut buf).is_err() {
            return (SlotState::ReadFailed, None);
        }
        match decode_record(&buf) {
            Ok(config) => (SlotState::Valid(config.version), Some(config)),
            Err(e) => (SlotState::Invalid(e), None),
        }
    }

    /// The newest valid configuration, or the defaults, and why.
    pub fn load(&mut self) -> Loaded {
        let (s0, c0) = self.read_slot(0);
        let (s1, c1) = self.read_slot(1);
        let newest = match (c0, c1) {
            (Some(a), Some(b)) if b.version > a.version => Some((1, b)),
            (Some(a), _) => Some((0, a)),
            (None, Some(b)) => Some((1, b)),
            (None, None) => None,
        };
        let (config, source) = match newest {
            Some((index, config)) => (
                config,
                LoadSource::Slot {
                    index,
                    version: config.version,
                },
            ),
            None => (ProbeConfig::default(), LoadSource::Defaults),
        };
        Loaded {
            config,
            source,
            slots: [s0, s1],
        }
    }

    /// Stores `config` (its version above the stored one's) in the slot
    /// not holding the newest record; returns that slot.
    pub fn save(&mut self, config: &ProbeConfig) -> Result<u8, StoreError<F::Error>> {
        let target = match self.load().source {
            LoadSource::Slot { version, .. } if config.version <= version => {
                return Err(StoreError::NotNewer {
                    stored: version,
                    config: config.version,
                })
            }
            LoadSource::Slot { index, .. } => 1 - index,
            LoadSource::Defaults => 0,
        };
        let slot = usize::from(target);
        let from = self.offset(slot);
        let to = from + Self::SLOT_LEN as u32;
        self.flash.erase(from, to).map_err(StoreError::Flash)?;
        let mut buf = [0xFFu8; PADDED_LEN];
        if let Some(head) = buf.get_mut(..RECORD_LEN) {
            head.copy_from_slice(&encode_record(config));
        }
        let written = RECORD_LEN.div_ceil(F::WRITE_SIZE) * F::WRITE_SIZE;
        let padded = buf.get(..written).ok_or(StoreError::Geometry)?;
        self.flash.write(from, padded).map_err(StoreError::Flash)?;
        match self.read_slot(slot) {
            (_, Some(read)) if read == *config => Ok(target),
            _ => Err(StoreError::VerifyFailed),
        }
    }
}
