//! The SII EEPROM image of an emulated SubDevice: the fixed header (identity, mailbox
//! configuration) and the categories STRINGS, GENERAL, FMMU, SYNCM, TXPDO and RXPDO, as the
//! Beckhoff "EtherCAT Slave Controller, Section I – Technology" describes them (SII EEPROM
//! chapter) and as ethercrab 0.7.1 parses them (its `SiiCoding` and category walk).

/// Word address of the vendor ID in the SII header.
pub const WORD_VENDOR: u16 = 0x08;
/// Word address of the standard receive mailbox (MainDevice → SubDevice) offset.
pub const WORD_RX_MAILBOX: u16 = 0x18;
/// Word address of the first category header.
pub const WORD_FIRST_CATEGORY: u16 = 0x40;

/// Category type STRINGS.
pub const CAT_STRINGS: u16 = 10;
/// Category type GENERAL.
pub const CAT_GENERAL: u16 = 30;
/// Category type FMMU.
pub const CAT_FMMU: u16 = 40;
/// Category type SYNCM.
pub const CAT_SYNCM: u16 = 41;
/// Category type TXPDO (inputs).
pub const CAT_TXPDO: u16 = 50;
/// Category type RXPDO (outputs).
pub const CAT_RXPDO: u16 = 51;
/// End of the category list.
pub const CAT_END: u16 = 0xFFFF;

/// The identity of a SubDevice: SII words 0x08..0x0F and CoE object 0x1018.
#[doc(alias = "0x1018")]
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Identity {
    /// Vendor ID (0x1018:01).
    pub vendor: u32,
    /// Product code (0x1018:02).
    pub product: u32,
    /// Revision number (0x1018:03).
    pub revision: u32,
    /// Serial number (0x1018:04).
    pub serial: u32,
}

/// What an FMMU of the SII FMMU category is used for.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum FmmuUsage {
    /// Process data outputs (MainDevice → SubDevice).
    Outputs = 1,
    /// Process data inputs (SubDevice → MainDevice).
    Inputs = 2,
    /// Mailbox status (SyncManager status bits).
    SyncManagerStatus = 3,
}

/// The type of a SyncManager in the SII SYNCM category.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SmType {
    /// Mailbox out (write mailbox, MainDevice → SubDevice).
    MailboxOut = 1,
    /// Mailbox in (read mailbox, SubDevice → MainDevice).
    MailboxIn = 2,
    /// Process data outputs.
    Outputs = 3,
    /// Process data inputs.
    Inputs = 4,
}

/// A SyncManager as the SII describes it (its default configuration).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct SmSpec {
    /// Physical start address.
    pub start: u16,
    /// Length (bytes); for process data the default PDO image size.
    pub length: u16,
    /// Control byte (mode and direction, ESC register 0x0804 + 8·n).
    pub control: u8,
    /// Type.
    pub kind: SmType,
}

/// One entry of a PDO: the mapped object and its bit length.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct PdoEntry {
    /// Object index.
    pub index: u16,
    /// Object subindex.
    pub subindex: u8,
    /// Bit length.
    pub bits: u8,
}

/// A PDO of the SII TXPDO/RXPDO categories.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PdoSpec {
    /// PDO index (0x16xx outputs, 0x1Axx inputs).
    pub index: u16,
    /// The SyncManager it is assigned to.
    pub sync_manager: u8,
    /// Its entries.
    pub entries: Vec<PdoEntry>,
}

/// Everything the SII image of a SubDevice holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SiiSpec {
    /// Identity.
    pub identity: Identity,
    /// Order code (the GENERAL order index string, ethercrab's `name()`).
    pub order: &'static str,
    /// Device name (the GENERAL name index string, ethercrab's `description()`).
    pub name: &'static str,
    /// Mailbox protocols (SII word 0x1C: 0x04 = CoE); 0 without a mailbox.
    pub mailbox_protocols: u16,
    /// CoE details byte of GENERAL (bit 0 SDO, bit 2 PDO assign, bit 3 PDO configuration).
    pub coe_details: u8,
    /// FMMU usages in FMMU order.
    pub fmmus: Vec<FmmuUsage>,
    /// SyncManagers in SM order.
    pub sync_managers: Vec<SmSpec>,
    /// TxPDOs (inputs).
    pub tx_pdos: Vec<PdoSpec>,
    /// RxPDOs (outputs).
    pub rx_pdos: Vec<PdoSpec>,
}

impl SiiSpec {
    /// The SyncManager of the given type, with its index.
    pub fn sync_manager(&self, kind: SmType) -> Option<(usize, SmSpec)> {
        self.sync_managers
            .iter()
            .copied()
            .enumerate()
            .find(|(_, sm)| sm.kind == kind)
    }

    /// The EEPROM image in words (2 KiB, unused words 0xFFFF).
    pub fn image(&self) -> Vec<u16> {
        let mut bytes = vec![0u8; usize::from(WORD_FIRST_CATEGORY) * 2];
        let id = self.identity;
        for (word, value) in [
            (WORD_VENDOR, id.vendor),
            (0x0A, id.product),
            (0x0C, id.revision),
            (0x0E, id.serial),
        ] {
            put(&mut bytes, usize::from(word) * 2, &value.to_le_bytes());
        }
        let out = self.sync_manager(SmType::MailboxOut).map(|(_, sm)| sm);
        let inn = self.sync_manager(SmType::MailboxIn).map(|(_, sm)| sm);
        let mbx = [
            out.map_or(0, |sm| sm.start),
            out.map_or(0, |sm| sm.length),
            inn.map_or(0, |sm| sm.start),
            inn.map_or(0, |sm| sm.length),
            self.mailbox_protocols,
        ];
        for (k, value) in mbx.iter().enumerate() {
            put(
                &mut bytes,
                (usize::from(WORD_RX_MAILBOX) + k) * 2,
                &value.to_le_bytes(),
            );
        }
        // Size: (15 + 1) kbit = 2 KiB; version 1.
        put(&mut bytes, 0x3E * 2, &15u16.to_le_bytes());
        put(&mut bytes, 0x3F * 2, &1u16.to_le_bytes());
        bytes[14] = crc8(&bytes[..14]);

        category(&mut bytes, CAT_STRINGS, &self.strings());
        category(&mut bytes, CAT_GENERAL, &self.general());
        let mut fmmus: Vec<u8> = self.fmmus.iter().map(|f| *f as u8).collect();
        if fmmus.len() % 2 == 1 {
            fmmus.push(0xFF);
        }
        category(&mut bytes, CAT_FMMU, &fmmus);
        let mut syncm = Vec::new();
        for sm in &self.sync_managers {
            syncm.extend_from_slice(&sm.start.to_le_bytes());
            syncm.extend_from_slice(&sm.length.to_le_bytes());
            // Control, status (unused), enable (bit 0), type.
            syncm.extend_from_slice(&[sm.control, 0, 1, sm.kind as u8]);
        }
        category(&mut bytes, CAT_SYNCM, &syncm);
        category(&mut bytes, CAT_TXPDO, &pdos(&self.tx_pdos));
        category(&mut bytes, CAT_RXPDO, &pdos(&self.rx_pdos));
        bytes.extend_from_slice(&CAT_END.to_le_bytes());
        bytes.resize(2048, 0xFF);
        bytes
            .chunks_exact(2)
            .map(|w| u16::from_le_bytes([w[0], w[1]]))
            .collect()
    }

    /// STRINGS: 1 = order code, 2 = name.
    fn strings(&self) -> Vec<u8> {
        let mut out = vec![2u8];
        for s in [self.order, self.name] {
            let b = s.as_bytes();
            out.push(b.len().min(255) as u8);
            out.extend_from_slice(b.get(..b.len().min(255)).unwrap_or(b));
        }
        out
    }

    /// GENERAL, 32 bytes (ETG.2010 size): group 1, image 0, order 1, name 2, CoE details,
    /// flags 0, E-bus current 0.
    fn general(&self) -> Vec<u8> {
        let mut g = vec![0u8; 32];
        g[0] = 1;
        g[2] = 1;
        g[3] = 2;
        g[5] = self.coe_details;
        g
    }
}

/// Writes `data` at `offset`, growing the buffer as needed.
fn put(bytes: &mut Vec<u8>, offset: usize, data: &[u8]) {
    if bytes.len() < offset + data.len() {
        bytes.resize(offset + data.len(), 0);
    }
    if let Some(dst) = bytes.get_mut(offset..offset + data.len()) {
        dst.copy_from_slice(data);
    }
}

/// Appends a category: type, length in words, data padded to whole words.
fn category(bytes: &mut Vec<u8>, kind: u16, data: &[u8]) {
    let words = data.len().div_ceil(2);
    bytes.extend_from_slice(&kind.to_le_bytes());
    bytes.extend_from_slice(&(words as u16).to_le_bytes());
    bytes.extend_from_slice(data);
    if data.len() % 2 == 1 {
        bytes.push(0);
    }
}

/// The TXPDO/RXPDO category body.
fn pdos(list: &[PdoSpec]) -> Vec<u8> {
    let mut out = Vec::new();
    for pdo in list {
        out.extend_from_slice(&pdo.index.to_le_bytes());
        // Entries, SM, DC sync, name index, flags.
        out.extend_from_slice(&[pdo.entries.len() as u8, pdo.sync_manager, 0, 0, 0, 0]);
        for e in &pdo.entries {
            out.extend_from_slice(&e.index.to_le_bytes());
            // Subindex, name index, data type (0: not given), bit length, flags.
            out.extend_from_slice(&[e.subindex, 0, 0, e.bits, 0, 0]);
        }
    }
    out
}

/// The SII header checksum: CRC-8, polynomial 0x07, initial value 0xFF, over bytes 0..14.
pub fn crc8(data: &[u8]) -> u8 {
    let mut crc = 0xFFu8;
    for &b in data {
        crc ^= b;
        for _ in 0..8 {
            crc = if crc & 0x80 != 0 {
                (crc << 1) ^ 0x07
            } else {
                crc << 1
            };
        }
    }
    crc
}
