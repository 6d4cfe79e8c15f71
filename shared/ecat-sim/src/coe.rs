//! CANopen over EtherCAT: the object dictionary of an emulated SubDevice and its SDO server
//! (expedited and normal upload and download, abort), behind the mailbox header. Layouts from
//! the Beckhoff "EtherCAT Slave Controller, Section I – Technology" (mailbox) and CiA 301 as
//! ethercrab 0.7.1 speaks it (its `mailbox/coe` module): mailbox header 6 bytes, CoE header
//! 2 bytes, SDO command byte, index, subindex, 4 data bytes.

use core::fmt;

use crate::sii::PdoEntry;

/// Mailbox type CoE (mailbox header byte 5, bits 0..3).
pub const MAILBOX_TYPE_COE: u8 = 3;
/// CoE service: SDO request.
const SERVICE_SDO_REQUEST: u16 = 2;
/// CoE service: SDO response.
const SERVICE_SDO_RESPONSE: u16 = 3;
/// Length of mailbox header + CoE header + SDO header (command, index, subindex, 4 bytes).
const SDO_FRAME: usize = 16;

/// An SDO abort code (CiA 301).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct AbortCode(pub u32);

impl AbortCode {
    /// Client/server command specifier not valid or unknown.
    pub const INVALID_COMMAND: Self = Self(0x0504_0001);
    /// Unsupported access to an object.
    pub const UNSUPPORTED_ACCESS: Self = Self(0x0601_0000);
    /// Attempt to write a read-only object.
    pub const READ_ONLY: Self = Self(0x0601_0002);
    /// Subindex cannot be written, subindex 0 must be 0 for write access.
    pub const SUBINDEX_0_NOT_0: Self = Self(0x0601_0003);
    /// Complete access not supported.
    pub const COMPLETE_ACCESS: Self = Self(0x0601_0004);
    /// Object does not exist in the object dictionary.
    pub const NO_OBJECT: Self = Self(0x0602_0000);
    /// Object cannot be mapped to the PDO.
    pub const NOT_MAPPABLE: Self = Self(0x0604_0041);
    /// Data type does not match, length of service parameter does not match.
    pub const LENGTH_MISMATCH: Self = Self(0x0607_0010);
    /// Subindex does not exist.
    pub const NO_SUBINDEX: Self = Self(0x0609_0011);
    /// Value range of parameter exceeded.
    pub const VALUE_RANGE: Self = Self(0x0609_0030);
    /// Value of parameter written too high.
    pub const VALUE_TOO_HIGH: Self = Self(0x0609_0031);
    /// Data cannot be transferred because of the present device state.
    pub const DEVICE_STATE: Self = Self(0x0800_0022);
}

impl fmt::Display for AbortCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "SDO abort {:#010x}", self.0)
    }
}

impl std::error::Error for AbortCode {}

/// Who may write an object.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Access {
    /// Read only.
    ReadOnly,
    /// Read and write in any state.
    ReadWrite,
    /// Read always, write in PRE-OP only (PDO assignment and mapping).
    ReadWritePreOp,
}

/// Whether and in which direction an object can be mapped into a PDO.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Mappable {
    /// Not mappable.
    No,
    /// Into an RxPDO (outputs).
    Rx,
    /// Into a TxPDO (inputs).
    Tx,
}

/// One subindex of the object dictionary.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    /// Object index.
    pub index: u16,
    /// Subindex.
    pub subindex: u8,
    /// Size in bytes (1, 2 or 4); 0 for a visible string.
    pub size: u8,
    /// The value (the low `size` bytes, little-endian on the wire).
    pub raw: u32,
    /// The value of a visible string.
    pub text: &'static str,
    /// Access.
    pub access: Access,
    /// PDO mapping.
    pub mappable: Mappable,
}

impl Entry {
    /// A numeric entry.
    pub const fn number(index: u16, subindex: u8, size: u8, raw: u32, access: Access) -> Self {
        Self {
            index,
            subindex,
            size,
            raw,
            text: "",
            access,
            mappable: Mappable::No,
        }
    }

    /// A read-only visible string.
    pub const fn string(index: u16, subindex: u8, text: &'static str) -> Self {
        Self {
            index,
            subindex,
            size: 0,
            raw: 0,
            text,
            access: Access::ReadOnly,
            mappable: Mappable::No,
        }
    }

    /// The same entry, mappable in the given direction.
    pub const fn mappable(self, mappable: Mappable) -> Self {
        Self { mappable, ..self }
    }
}

/// The object dictionary: entries sorted by index and subindex.
#[derive(Clone, Debug)]
pub struct ObjectDictionary {
    entries: Vec<Entry>,
}

impl ObjectDictionary {
    /// A dictionary of the given entries.
    pub fn new(mut entries: Vec<Entry>) -> Self {
        entries.sort_by_key(|e| (e.index, e.subindex));
        Self { entries }
    }

    fn position(&self, index: u16, subindex: u8) -> Result<usize, AbortCode> {
        match self
            .entries
            .binary_search_by_key(&(index, subindex), |e| (e.index, e.subindex))
        {
            Ok(k) => Ok(k),
            Err(_) if self.entries.iter().any(|e| e.index == index) => Err(AbortCode::NO_SUBINDEX),
            Err(_) => Err(AbortCode::NO_OBJECT),
        }
    }

    /// The entry at `index:subindex`.
    pub fn entry(&self, index: u16, subindex: u8) -> Result<&Entry, AbortCode> {
        let k = self.position(index, subindex)?;
        self.entries.get(k).ok_or(AbortCode::NO_OBJECT)
    }

    /// The numeric value at `index:subindex` (0 if absent).
    pub fn value(&self, index: u16, subindex: u8) -> u32 {
        self.entry(index, subindex).map_or(0, |e| e.raw)
    }

    /// Sets a value from the device side (no access check); absent entries are ignored.
    pub fn set_value(&mut self, index: u16, subindex: u8, raw: u32) {
        if let Ok(k) = self.position(index, subindex) {
            if let Some(e) = self.entries.get_mut(k) {
                e.raw = raw;
            }
        }
    }

    /// An SDO download (a write from the MainDevice) of `data` to `index:subindex` in the
    /// given AL state, with the checks of the PDO assignment (0x1C12/0x1C13) and mapping
    /// (0x1600.., 0x1A00..) objects. A refused write changes nothing.
    pub fn download(
        &mut self,
        index: u16,
        subindex: u8,
        data: &[u8],
        pre_op: bool,
    ) -> Result<(), AbortCode> {
        let entry = *self.entry(index, subindex)?;
        match entry.access {
            Access::ReadOnly => return Err(AbortCode::READ_ONLY),
            Access::ReadWritePreOp if !pre_op => return Err(AbortCode::DEVICE_STATE),
            _ => {}
        }
        if data.len() != usize::from(entry.size) {
            return Err(AbortCode::LENGTH_MISMATCH);
        }
        let mut le = [0u8; 4];
        le.get_mut(..data.len())
            .ok_or(AbortCode::LENGTH_MISMATCH)?
            .copy_from_slice(data);
        let raw = u32::from_le_bytes(le);
        self.check_pdo_write(index, subindex, raw)?;
        self.set_value(index, subindex, raw);
        Ok(())
    }

    /// The rules of CiA 301 for PDO mapping and assignment objects: entries change only while
    /// subindex 0 is 0; subindex 0 may only count valid entries.
    fn check_pdo_write(&self, index: u16, subindex: u8, raw: u32) -> Result<(), AbortCode> {
        let direction = pdo_direction(index);
        let is_assign = index == 0x1C12 || index == 0x1C13;
        if direction.is_none() && !is_assign {
            return Ok(());
        }
        if subindex != 0 {
            if self.value(index, 0) != 0 {
                return Err(AbortCode::SUBINDEX_0_NOT_0);
            }
            if is_assign {
                let want = if index == 0x1C12 {
                    Mappable::Rx
                } else {
                    Mappable::Tx
                };
                return match pdo_direction(raw as u16) {
                    Some(d) if d == want && self.entry(raw as u16, 0).is_ok() => Ok(()),
                    _ => Err(AbortCode::VALUE_RANGE),
                };
            }
            let e = PdoEntry {
                index: (raw >> 16) as u16,
                subindex: (raw >> 8) as u8,
                bits: raw as u8,
            };
            let target = self.entry(e.index, e.subindex).ok();
            return match target {
                Some(t)
                    if Some(t.mappable) == direction
                        && u32::from(t.size) * 8 == u32::from(e.bits) =>
                {
                    Ok(())
                }
                _ => Err(AbortCode::NOT_MAPPABLE),
            };
        }
        // Subindex 0: the number of entries, each of which must exist and be set.
        let capacity = self
            .entries
            .iter()
            .filter(|e| e.index == index && e.subindex > 0)
            .count();
        if raw as usize > capacity {
            return Err(AbortCode::VALUE_TOO_HIGH);
        }
        for k in 1..=raw {
            let sub = u8::try_from(k).map_err(|_| AbortCode::VALUE_TOO_HIGH)?;
            match self.entry(index, sub) {
                Ok(e) if e.raw != 0 => {}
                Ok(_) => return Err(AbortCode::VALUE_RANGE),
                Err(_) => return Err(AbortCode::VALUE_TOO_HIGH),
            }
        }
        Ok(())
    }

    /// The entries of the PDOs assigned by `assign` (0x1C12 or 0x1C13), in order.
    pub fn assigned_entries(&self, assign: u16) -> Vec<PdoEntry> {
        let mut out = Vec::new();
        for k in 1..=self.value(assign, 0).min(255) {
            let pdo = self.value(assign, k as u8) as u16;
            for j in 1..=self.value(pdo, 0).min(255) {
                let raw = self.value(pdo, j as u8);
                out.push(PdoEntry {
                    index: (raw >> 16) as u16,
                    subindex: (raw >> 8) as u8,
                    bits: raw as u8,
                });
            }
        }
        out
    }
}

/// The direction of a PDO mapping object: 0x1600..0x17FF RxPDO, 0x1A00..0x1BFF TxPDO.
fn pdo_direction(index: u16) -> Option<Mappable> {
    match index {
        0x1600..=0x17FF => Some(Mappable::Rx),
        0x1A00..=0x1BFF => Some(Mappable::Tx),
        _ => None,
    }
}

/// Answers one mailbox request (`request` = the whole write mailbox) into `response` (the
/// whole read mailbox). Returns `None` when there is nothing to answer (not CoE, not an SDO
/// request, or a zero-length mailbox).
pub fn serve_mailbox(
    od: &mut ObjectDictionary,
    pre_op: bool,
    request: &[u8],
    response: &mut [u8],
    counter: u8,
) -> Option<()> {
    let length = usize::from(u16::from_le_bytes([*request.first()?, *request.get(1)?]));
    let kind = request.get(5)? & 0x0F;
    let coe = u16::from_le_bytes([*request.get(6)?, *request.get(7)?]);
    if length < 2 || kind != MAILBOX_TYPE_COE || coe >> 12 != SERVICE_SDO_REQUEST {
        return None;
    }
    let body = request.get(8..6 + length.min(request.len().saturating_sub(6)))?;
    let command = *body.first()?;
    let index = u16::from_le_bytes([*body.get(1)?, *body.get(2)?]);
    let subindex = *body.get(3)?;
    response.fill(0);
    let result = if command & 0x10 != 0 {
        Err(AbortCode::COMPLETE_ACCESS)
    } else {
        match command >> 5 {
            // Initiate download request.
            1 => download(od, pre_op, command, index, subindex, body)
                .and_then(|n| set(response, 8, &[0x60]).map(|()| n)),
            // Initiate upload request.
            2 => upload(od, index, subindex, response),
            _ => Err(AbortCode::INVALID_COMMAND),
        }
    };
    let length = match result {
        Ok(length) => length,
        Err(abort) => {
            *response.get_mut(8)? = 0x80;
            response
                .get_mut(12..16)?
                .copy_from_slice(&abort.0.to_le_bytes());
            10
        }
    };
    response
        .get_mut(0..2)?
        .copy_from_slice(&(length as u16).to_le_bytes());
    *response.get_mut(5)? = MAILBOX_TYPE_COE | ((counter & 0x07) << 4);
    response
        .get_mut(6..8)?
        .copy_from_slice(&(SERVICE_SDO_RESPONSE << 12).to_le_bytes());
    response
        .get_mut(9..11)?
        .copy_from_slice(&index.to_le_bytes());
    *response.get_mut(11)? = subindex;
    Some(())
}

/// Download (expedited or normal); returns the response's mailbox length.
fn download(
    od: &mut ObjectDictionary,
    pre_op: bool,
    command: u8,
    index: u16,
    subindex: u8,
    body: &[u8],
) -> Result<usize, AbortCode> {
    let expedited = command & 0x02 != 0;
    let data = if expedited {
        let size = if command & 0x01 != 0 {
            4 - usize::from((command >> 2) & 0x03)
        } else {
            4
        };
        body.get(4..4 + size)
    } else {
        let size = body
            .get(4..8)
            .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
        body.get(8..8 + size)
    };
    let data = data.ok_or(AbortCode::LENGTH_MISMATCH)?;
    od.download(index, subindex, data, pre_op)?;
    Ok(10)
}

/// Upload: expedited up to 4 bytes, normal beyond; returns the response's mailbox length.
fn upload(
    od: &ObjectDictionary,
    index: u16,
    subindex: u8,
    response: &mut [u8],
) -> Result<usize, AbortCode> {
    let entry = od.entry(index, subindex)?;
    if entry.size == 0 {
        let text = entry.text.as_bytes();
        let room = response.len().saturating_sub(SDO_FRAME);
        if text.len() > room {
            return Err(AbortCode::UNSUPPORTED_ACCESS);
        }
        set(response, 8, &[0x41])?;
        set(response, 12, &(text.len() as u32).to_le_bytes())?;
        set(response, SDO_FRAME, text)?;
        return Ok(10 + text.len());
    }
    let unused = 4 - entry.size.min(4);
    set(response, 8, &[0x43 | (unused << 2)])?;
    set(response, 12, &entry.raw.to_le_bytes())?;
    if unused > 0 {
        // Only the object's own bytes; the rest of the 4-byte field stays 0.
        let keep = 12 + usize::from(entry.size);
        response
            .get_mut(keep..16)
            .ok_or(AbortCode::UNSUPPORTED_ACCESS)?
            .fill(0);
    }
    Ok(10)
}

fn set(buf: &mut [u8], at: usize, data: &[u8]) -> Result<(), AbortCode> {
    buf.get_mut(at..at + data.len())
        .ok_or(AbortCode::UNSUPPORTED_ACCESS)?
        .copy_from_slice(data);
    Ok(())
}
