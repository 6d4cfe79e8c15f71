//! A segment: a line of emulated ESCs that processes whole EtherCAT frames in passing, every
//! datagram by every ESC in bus order, with the addressing, auto-increment and working
//! counter rules of the Beckhoff "EtherCAT Slave Controller, Section I – Technology"
//! (frame processing and the command table; the project's EtherCAT + CiA 402 reference,
//! sections 1.3, 1.4 and 7.3).

use core::fmt;

use crate::device::{DeviceKind, DeviceOptions};
use crate::esc::{Access, Esc, EscError, Logical};

/// EtherType of EtherCAT.
pub const ETHERTYPE_ETHERCAT: u16 = 0x88A4;
/// Length of the Ethernet header (no VLAN tag).
pub const ETHERNET_HEADER: usize = 14;
/// Length of a datagram header.
const DATAGRAM_HEADER: usize = 10;

/// Datagram command codes.
pub mod cmd {
    /// No operation.
    pub const NOP: u8 = 0x00;
    /// Auto-increment physical read.
    pub const APRD: u8 = 0x01;
    /// Auto-increment physical write.
    pub const APWR: u8 = 0x02;
    /// Auto-increment physical read-write.
    pub const APRW: u8 = 0x03;
    /// Configured address physical read.
    pub const FPRD: u8 = 0x04;
    /// Configured address physical write.
    pub const FPWR: u8 = 0x05;
    /// Configured address physical read-write.
    pub const FPRW: u8 = 0x06;
    /// Broadcast read (OR-combined).
    pub const BRD: u8 = 0x07;
    /// Broadcast write.
    pub const BWR: u8 = 0x08;
    /// Broadcast read-write.
    pub const BRW: u8 = 0x09;
    /// Logical read.
    pub const LRD: u8 = 0x0A;
    /// Logical write.
    pub const LWR: u8 = 0x0B;
    /// Logical read-write.
    pub const LRW: u8 = 0x0C;
    /// Auto-increment read, multiple write.
    pub const ARMW: u8 = 0x0D;
    /// Configured address read, multiple write.
    pub const FRMW: u8 = 0x0E;
}

/// Why a frame could not be processed; the frame is then not answered.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum FrameError {
    /// Shorter than the Ethernet and EtherCAT headers.
    TooShort {
        /// Its length.
        len: usize,
    },
    /// Not EtherType 0x88A4.
    NotEtherCat {
        /// Its EtherType.
        ethertype: u16,
    },
    /// The EtherCAT header's type is not 1 (DL PDUs).
    NotDatagrams {
        /// The type found.
        kind: u8,
    },
    /// A datagram runs past the end of the frame or the header's length.
    Truncated {
        /// Offset of the datagram in the EtherCAT payload.
        offset: usize,
    },
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooShort { len } => write!(f, "frame of {len} bytes is too short"),
            Self::NotEtherCat { ethertype } => {
                write!(f, "EtherType {ethertype:#06x} is not EtherCAT")
            }
            Self::NotDatagrams { kind } => {
                write!(f, "EtherCAT header type {kind} is not 1 (datagrams)")
            }
            Self::Truncated { offset } => write!(f, "datagram at offset {offset} is truncated"),
        }
    }
}

impl std::error::Error for FrameError {}

/// Walks the datagram chain without processing it: a frame is processed whole or not at all.
fn check_datagrams(body: &[u8]) -> Result<(), FrameError> {
    let mut offset = 0;
    loop {
        let h = body
            .get(offset..offset + DATAGRAM_HEADER)
            .ok_or(FrameError::Truncated { offset: offset + 2 })?;
        let flags = u16::from_le_bytes([h[6], h[7]]);
        let end = offset + DATAGRAM_HEADER + usize::from(flags & 0x07FF) + 2;
        if end > body.len() {
            return Err(FrameError::Truncated { offset: offset + 2 });
        }
        if flags & 0x8000 == 0 {
            return Ok(());
        }
        offset = end;
    }
}

/// A line of emulated SubDevices, position 0 first.
#[derive(Clone, Debug)]
pub struct Segment {
    escs: Vec<Esc>,
}

impl Segment {
    /// A segment of the given devices in bus order; serial numbers count from 1.
    pub fn new(kinds: &[DeviceKind], options: DeviceOptions) -> Result<Self, EscError> {
        let mut escs = kinds
            .iter()
            .enumerate()
            .map(|(k, kind)| Esc::new(*kind, k as u32 + 1, options))
            .collect::<Result<Vec<_>, _>>()?;
        let n = escs.len();
        for (k, esc) in escs.iter_mut().enumerate() {
            esc.set_downstream(k + 1 < n);
        }
        Ok(Self { escs })
    }

    /// The ESCs in bus order.
    pub fn escs(&self) -> &[Esc] {
        &self.escs
    }

    /// The ESC at `position`.
    pub fn esc_mut(&mut self, position: usize) -> Option<&mut Esc> {
        self.escs.get_mut(position)
    }

    /// Processes a whole Ethernet frame in place at local time `now_ns`, and marks it as
    /// passed by setting the locally administered bit of the source MAC.
    pub fn process_frame(&mut self, frame: &mut [u8], now_ns: u64) -> Result<(), FrameError> {
        let len = frame.len();
        let ethertype = match frame.get(12..14) {
            Some(b) if len >= ETHERNET_HEADER + 2 => u16::from_be_bytes([b[0], b[1]]),
            _ => return Err(FrameError::TooShort { len }),
        };
        if ethertype != ETHERTYPE_ETHERCAT {
            return Err(FrameError::NotEtherCat { ethertype });
        }
        let payload = frame
            .get_mut(ETHERNET_HEADER..)
            .ok_or(FrameError::TooShort { len })?;
        self.process_ethercat(payload, now_ns)?;
        if let Some(b) = frame.get_mut(6) {
            *b |= 0x02;
        }
        Ok(())
    }

    /// Processes an EtherCAT payload (EtherCAT header and datagrams) in place.
    pub fn process_ethercat(&mut self, payload: &mut [u8], now_ns: u64) -> Result<(), FrameError> {
        let header = match payload.get(0..2) {
            Some(b) => u16::from_le_bytes([b[0], b[1]]),
            None => return Err(FrameError::TooShort { len: payload.len() }),
        };
        let kind = (header >> 12) as u8;
        if kind != 1 {
            return Err(FrameError::NotDatagrams { kind });
        }
        let length = usize::from(header & 0x07FF);
        let end = 2 + length;
        let body = payload
            .get_mut(2..end)
            .ok_or(FrameError::Truncated { offset: 2 })?;
        check_datagrams(body)?;
        for esc in &mut self.escs {
            esc.set_time(now_ns);
        }
        let mut offset = 0;
        // The chain is checked: every header, data and working counter is inside `body`.
        while let Some(h) = body.get(offset..offset + DATAGRAM_HEADER) {
            let command = h[0];
            let mut adp = u16::from_le_bytes([h[2], h[3]]);
            let ado = u16::from_le_bytes([h[4], h[5]]);
            let flags = u16::from_le_bytes([h[6], h[7]]);
            let data_at = offset + DATAGRAM_HEADER;
            let wkc_at = data_at + usize::from(flags & 0x07FF);
            let Some(&[lo, hi]) = body.get(wkc_at..wkc_at + 2) else {
                break;
            };
            let mut wkc = u16::from_le_bytes([lo, hi]);
            if let Some(data) = body.get_mut(data_at..wkc_at) {
                wkc = wkc.wrapping_add(self.datagram(command, &mut adp, ado, data));
            }
            if let Some(b) = body.get_mut(offset + 2..offset + 4) {
                b.copy_from_slice(&adp.to_le_bytes());
            }
            if let Some(b) = body.get_mut(wkc_at..wkc_at + 2) {
                b.copy_from_slice(&wkc.to_le_bytes());
            }
            offset = wkc_at + 2;
            if flags & 0x8000 == 0 {
                break;
            }
        }
        Ok(())
    }

    /// One datagram through every ESC; returns the working counter increment. `adp` is
    /// incremented by every ESC for the position-addressed and broadcast commands.
    pub fn datagram(&mut self, command: u8, adp: &mut u16, ado: u16, data: &mut [u8]) -> u16 {
        let mut wkc = 0u16;
        let logical_addr = u32::from(*adp) | (u32::from(ado) << 16);
        for esc in &mut self.escs {
            let inc = match command {
                cmd::APRD | cmd::APWR | cmd::APRW | cmd::ARMW => {
                    let here = *adp == 0;
                    *adp = adp.wrapping_add(1);
                    let access = match command {
                        cmd::APRD => Access::Read,
                        cmd::APWR => Access::Write,
                        cmd::APRW => Access::ReadWrite,
                        // ARMW: read where addressed, write everywhere else.
                        _ if here => Access::Read,
                        _ => Access::Write,
                    };
                    if here || command == cmd::ARMW {
                        esc.access(ado, data, access)
                    } else {
                        0
                    }
                }
                cmd::FPRD | cmd::FPWR | cmd::FPRW | cmd::FRMW => {
                    let here = *adp == esc.station_address();
                    let access = match command {
                        cmd::FPRD => Access::Read,
                        cmd::FPWR => Access::Write,
                        cmd::FPRW => Access::ReadWrite,
                        // FRMW: read at the addressed SubDevice, write at all others.
                        _ if here => Access::Read,
                        _ => Access::Write,
                    };
                    if here || command == cmd::FRMW {
                        esc.access(ado, data, access)
                    } else {
                        0
                    }
                }
                cmd::BRD | cmd::BWR | cmd::BRW => {
                    *adp = adp.wrapping_add(1);
                    let access = match command {
                        cmd::BRD => Access::ReadOr,
                        cmd::BWR => Access::Write,
                        _ => Access::ReadWriteOr,
                    };
                    esc.access(ado, data, access)
                }
                cmd::LRD => esc.logical(Logical::Read, logical_addr, data),
                cmd::LWR => esc.logical(Logical::Write, logical_addr, data),
                cmd::LRW => esc.logical(Logical::ReadWrite, logical_addr, data),
                _ => 0,
            };
            wkc = wkc.wrapping_add(inc);
        }
        wkc
    }
}
