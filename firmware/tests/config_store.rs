//! The configuration's two flash slots against an in-memory NOR flash that
//! behaves as the real one (erase to 0xFF, writes only clear bits) and can
//! lose power part way through any erase or write.

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use firmware::app::config_store::{ConfigStore, LoadSource, SlotState, StoreError};
use mwd_core::config::record::{RecordError, RECORD_LEN};
use mwd_core::config::ProbeConfig;
use mwd_core::earth::Position;
use mwd_core::protocol::uplink::Command;

const ERASE: usize = 1024;

/// NOR flash in memory. `budget`: bytes the next operations may still
/// erase or program before the power fails (then the operation stops
/// where it was and every later one fails until `power_on`).
struct MemFlash {
    data: Vec<u8>,
    budget: Option<usize>,
    powered: bool,
}

#[derive(Debug, PartialEq)]
struct PowerCut;

impl NorFlashError for PowerCut {
    fn kind(&self) -> NorFlashErrorKind {
        NorFlashErrorKind::Other
    }
}

impl MemFlash {
    fn new(len: usize) -> Self {
        Self {
            data: vec![0xFF; len],
            budget: None,
            powered: true,
        }
    }

    fn power_on(&mut self) {
        self.powered = true;
        self.budget = None;
    }

    /// Spends one byte of the budget; false when the power is gone.
    fn spend(&mut self) -> bool {
        match &mut self.budget {
            Some(0) => {
                self.powered = false;
                false
            }
            Some(n) => {
                *n -= 1;
                true
            }
            None => self.powered,
        }
    }
}

impl ErrorType for MemFlash {
    type Error = PowerCut;
}

impl ReadNorFlash for MemFlash {
    const READ_SIZE: usize = 1;
    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), PowerCut> {
        let at = offset as usize;
        bytes.copy_from_slice(&self.data[at..at + bytes.len()]);
        Ok(())
    }
    fn capacity(&self) -> usize {
        self.data.len()
    }
}

impl NorFlash for MemFlash {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = ERASE;
    fn erase(&mut self, from: u32, to: u32) -> Result<(), PowerCut> {
        assert_eq!((from as usize % ERASE, to as usize % ERASE), (0, 0));
        for at in from as usize..to as usize {
            if !self.spend() {
                return Err(PowerCut);
            }
            self.data[at] = 0xFF;
        }
        Ok(())
    }
    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), PowerCut> {
        assert_eq!((offset as usize % 4, bytes.len() % 4), (0, 0));
        for (i, b) in bytes.iter().enumerate() {
            if !self.spend() {
                return Err(PowerCut);
            }
            // NOR programming only clears bits.
            self.data[offset as usize + i] &= *b;
        }
        Ok(())
    }
}

fn changed(config: &mut ProbeConfig, height: f64) {
    let site = Position::from_degrees(30.0, 50.0, height);
    config.apply(&Command::SetSite(site)).unwrap();
}

#[test]
fn a_blank_flash_loads_the_defaults_and_says_so() {
    let mut store = ConfigStore::new(MemFlash::new(4 * ERASE), 0).unwrap();
    let loaded = store.load();
    assert_eq!(loaded.source, LoadSource::Defaults);
    assert_eq!(loaded.config, ProbeConfig::default());
    let erased = SlotState::Invalid(RecordError::Erased);
    assert_eq!(loaded.slots, [erased, erased]);
}

#[test]
fn saves_alternate_slots_and_the_newest_is_loaded() {
    let mut store = ConfigStore::new(MemFlash::new(4 * ERASE), ERASE as u32).unwrap();
    let mut config = ProbeConfig::default();
    for (n, expected_slot) in [(1u32, 0u8), (2, 1), (3, 0), (4, 1)] {
        changed(&mut config, f64::from(n));
        assert_eq!(config.version, n);
        assert_eq!(store.save(&config), Ok(expected_slot));
        let loaded = store.load();
        assert_eq!(
            loaded.source,
            LoadSource::Slot {
                index: expected_slot,
                version: n
            }
        );
        assert_eq!(loaded.config, config);
    }
    // The previous one is still in the other slot.
    assert_eq!(
        store.load().slots,
        [SlotState::Valid(3), SlotState::Valid(4)]
    );
    // An older or equal version is refused, not stored.
    let stale = ProbeConfig {
        version: 4,
        ..config
    };
    assert_eq!(
        store.save(&stale),
        Err(StoreError::NotNewer {
            stored: 4,
            config: 4
        })
    );
    // The slots lie at `base`: the first erase unit is untouched.
    assert!(store.into_inner().data[..ERASE].iter().all(|b| *b == 0xFF));
}

/// A power cut after every possible number of bytes of a save (its erase
/// and its write): the previous configuration loads, or the new one once
/// its record's last byte (its CRC) is in, never anything else.
#[test]
fn a_power_cut_anywhere_in_a_save_leaves_the_previous_configuration() {
    let mut base = ConfigStore::new(MemFlash::new(2 * ERASE), 0).unwrap();
    let mut previous = ProbeConfig::default();
    changed(&mut previous, 1.0);
    base.save(&previous).unwrap();
    changed(&mut previous, 2.0);
    base.save(&previous).unwrap(); // slots: v1 in 0, v2 in 1
    let image = base.into_inner().data;
    let mut next = previous;
    changed(&mut next, 3.0); // goes to slot 0, over v1
    let committed = ERASE + RECORD_LEN; // the erase, then the record
    let written = ERASE + RECORD_LEN.div_ceil(4) * 4;
    for cut in 0..=written + 1 {
        let mut flash = MemFlash::new(0);
        flash.data = image.clone();
        flash.budget = Some(cut);
        let mut store = ConfigStore::new(flash, 0).unwrap();
        let saved = store.save(&next);
        assert_eq!(saved.is_ok(), cut >= written, "cut {cut}: {saved:?}");
        let mut flash = store.into_inner();
        flash.power_on();
        let loaded = ConfigStore::new(flash, 0).unwrap().load();
        if cut >= committed {
            assert_eq!(loaded.config, next, "cut {cut}");
        } else {
            assert_eq!(loaded.config, previous, "cut {cut}");
            let source = LoadSource::Slot {
                index: 1,
                version: 2,
            };
            assert_eq!(loaded.source, source, "cut {cut}");
        }
    }
}

#[test]
fn a_region_that_does_not_fit_is_refused() {
    assert!(matches!(
        ConfigStore::new(MemFlash::new(ERASE), 0),
        Err(StoreError::Geometry)
    ));
    assert!(matches!(
        ConfigStore::new(MemFlash::new(4 * ERASE), 100),
        Err(StoreError::Geometry)
    ));
}

/// The whole probe side without the board: command bytes through the
/// receive queue and the receiver, applied and stored before their ACK;
/// after a reboot (a new store on the same flash) the configuration is
/// back, and the loader says it came from a slot.
#[test]
fn configured_over_the_uplink_then_rebooted_the_configuration_persists() {
    use firmware::app::uplink_rx::{apply, UplinkInbox, UplinkReceiver};
    use mwd_core::protocol::uplink::{encode_command, ReplyStatus, MAX_COMMAND_WIRE_LEN};
    let mut store = ConfigStore::new(MemFlash::new(2 * ERASE), 0).unwrap();
    let mut config = store.load().config;
    let mut inbox = UplinkInbox::new();
    let (mut isr, mut main_loop) = inbox.split();
    let mut rx = UplinkReceiver::new();
    let site = Position::from_degrees(-33.9, 18.4, 40.0);
    let commands = [Command::SetSite(site), Command::ClearTieIn, Command::Reboot];
    let mut replies = Vec::new();
    for (seq, command) in commands.iter().enumerate() {
        let mut wire = [0u8; MAX_COMMAND_WIRE_LEN];
        let n = encode_command(seq as u16, command, &mut wire).unwrap();
        wire[..n].iter().for_each(|b| isr.push(*b));
        let decoded = rx.poll(&mut main_loop, 512).expect("a command");
        let outcome = apply(&decoded, &mut config, 0, true, |c| {
            store.save(c).map(|_| ())
        });
        replies.push(outcome.expect("answered"));
    }
    assert!(replies.iter().all(|o| o.reply.status == ReplyStatus::Ack));
    assert_eq!(replies[0].reply.config_version, 1);
    assert_eq!(
        replies[2].action,
        Some(firmware::app::uplink_rx::Action::Reboot)
    );
    let flash = store.into_inner();
    let loaded = ConfigStore::new(flash, 0).unwrap().load();
    assert_eq!(
        loaded.source,
        LoadSource::Slot {
            index: 0,
            version: 1
        }
    );
    assert_eq!(loaded.config.site, site);
    assert_eq!(loaded.config, config);
}
