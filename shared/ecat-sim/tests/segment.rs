//! Known answers of the pure emulator: every datagram command with its working counter and
//! auto-increment (Beckhoff ESC Section I command table; the project's EtherCAT reference,
//! sections 1.3, 1.4, 7.2, 7.3), the AL state machine with refused transitions and their
//! AL status codes (section 4), SII reads (section 3), CoE SDO upload/download (section 5) and
//! LRW through FMMUs.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_ecat_sim::segment::cmd;
use tandem_ecat_sim::{AlState, AlStatusCode, DeviceKind, DeviceOptions, Segment};

const DRIVE: u16 = 0x1000;
const DIO: u16 = 0x1001;

/// A drive at position 0 and a terminal at position 1, station addresses 0x1000, 0x1001.
fn segment() -> Segment {
    let mut s = Segment::new(
        &[DeviceKind::Cia402Drive, DeviceKind::DigitalIo],
        DeviceOptions {
            dio_loopback: true,
            ..DeviceOptions::default()
        },
    )
    .unwrap();
    for p in 0..2u16 {
        let (_, _, wkc) = dg(
            &mut s,
            cmd::APWR,
            0u16.wrapping_sub(p),
            0x0010,
            &(0x1000 + p).to_le_bytes(),
        );
        assert_eq!(wkc, 1);
    }
    s
}

/// One datagram: (ADP after, data after, working counter).
fn dg(s: &mut Segment, command: u8, adp: u16, ado: u16, data: &[u8]) -> (u16, Vec<u8>, u16) {
    let mut adp = adp;
    let mut d = data.to_vec();
    let wkc = s.datagram(command, &mut adp, ado, &mut d);
    (adp, d, wkc)
}

fn fprd(s: &mut Segment, station: u16, ado: u16, len: usize) -> Vec<u8> {
    let (_, d, wkc) = dg(s, cmd::FPRD, station, ado, &vec![0; len]);
    assert_eq!(wkc, 1, "FPRD {station:#x}:{ado:#x}");
    d
}

fn fpwr(s: &mut Segment, station: u16, ado: u16, data: &[u8]) {
    let (_, _, wkc) = dg(s, cmd::FPWR, station, ado, data);
    assert_eq!(wkc, 1, "FPWR {station:#x}:{ado:#x}");
}

fn al(s: &mut Segment, station: u16) -> (u16, u16) {
    let st = fprd(s, station, 0x0130, 2);
    let code = fprd(s, station, 0x0134, 2);
    (
        u16::from_le_bytes([st[0], st[1]]),
        u16::from_le_bytes([code[0], code[1]]),
    )
}

fn sm(start: u16, len: u16, control: u8, enable: bool) -> [u8; 8] {
    let [a, b] = start.to_le_bytes();
    let [c, d] = len.to_le_bytes();
    [a, b, c, d, control, 0, u8::from(enable), 0]
}

fn fmmu(logical: u32, len: u16, physical: u16, kind: u8) -> [u8; 16] {
    let mut f = [0u8; 16];
    f[0..4].copy_from_slice(&logical.to_le_bytes());
    f[4..6].copy_from_slice(&len.to_le_bytes());
    f[7] = 7;
    f[8..10].copy_from_slice(&physical.to_le_bytes());
    f[11] = kind;
    f[12] = 1;
    f
}

#[test]
fn position_and_broadcast_commands_count_and_increment() {
    let mut s = segment();
    // BRD of the type register: both answer, ADP incremented twice, data OR-ed.
    assert_eq!(dg(&mut s, cmd::BRD, 0, 0x0000, &[0]), (2, vec![0x04], 2));
    // BRD of ESC features: 0x010C (drive) OR 0x0000 (terminal).
    assert_eq!(
        dg(&mut s, cmd::BRD, 0, 0x0008, &[0, 0]),
        (2, vec![0x0C, 0x01], 2)
    );
    // APRD position 1 reads the terminal's station address; ADP 0xFFFF + 2 = 1.
    assert_eq!(
        dg(&mut s, cmd::APRD, 0xFFFF, 0x0010, &[0, 0]),
        (1, vec![0x01, 0x10], 1)
    );
    // APRD of a position that does not exist: nobody answers.
    assert_eq!(dg(&mut s, cmd::APRD, 0xFFFD, 0x0010, &[0, 0]).2, 0);
    // APRW: read the old value, write the new: +3.
    assert_eq!(
        dg(&mut s, cmd::APRW, 0, 0x0012, &[0x34, 0x12]),
        (2, vec![0, 0], 3)
    );
    assert_eq!(fprd(&mut s, DRIVE, 0x0012, 2), vec![0x34, 0x12]);
    // FPRW on the terminal: +3, old value back.
    assert_eq!(
        dg(&mut s, cmd::FPRW, DIO, 0x0012, &[0x78, 0x56]),
        (DIO, vec![0, 0], 3)
    );
    assert_eq!(fprd(&mut s, DIO, 0x0012, 2), vec![0x78, 0x56]);
    // BWR: both written, +1 each. BRW: +3 each; each ESC writes the data as it arrives and
    // ORs its old contents into it, so the second one writes what the first passed on.
    assert_eq!(dg(&mut s, cmd::BWR, 0, 0x0012, &[0x01, 0x00]).2, 2);
    assert_eq!(
        dg(&mut s, cmd::BRW, 0, 0x0012, &[0x02, 0x00]),
        (2, vec![0x03, 0x00], 6)
    );
    assert_eq!(fprd(&mut s, DRIVE, 0x0012, 2), vec![0x02, 0x00]);
    assert_eq!(fprd(&mut s, DIO, 0x0012, 2), vec![0x03, 0x00]);
    // FPWR to an unknown station: nobody.
    assert_eq!(dg(&mut s, cmd::FPWR, 0x2000, 0x0012, &[9, 9]).2, 0);
    // Registers the ESC lacks (FMMU 8.., SM 8..) do not count: blank FMMU writes to 0..15.
    assert_eq!(dg(&mut s, cmd::BWR, 0, 0x0600 + 16 * 7, &[0; 16]).2, 2);
    assert_eq!(dg(&mut s, cmd::BWR, 0, 0x0600 + 16 * 8, &[0; 16]).2, 0);
    // DC registers exist only on the drive: the latch counts the DC SubDevices only.
    assert_eq!(dg(&mut s, cmd::BWR, 0, 0x0900, &[0; 4]).2, 1);
    // A NOP is processed by nobody.
    assert_eq!(dg(&mut s, cmd::NOP, 0, 0x0000, &[0]), (0, vec![0], 0));
}

#[test]
fn read_modify_write_commands_distribute_the_reference_time() {
    let mut s = segment();
    fpwr(&mut s, DRIVE, 0x0920, &1_000i64.to_le_bytes());
    s.esc_mut(0).unwrap().set_time(5_000);
    s.esc_mut(1).unwrap().set_time(5_000);
    // FRMW at the drive: it reads its system time (local 5000 + offset 1000); the terminal
    // has no DC registers, so only the read counts.
    let (adp, d, wkc) = dg(&mut s, cmd::FRMW, DRIVE, 0x0910, &[0; 8]);
    assert_eq!(
        (adp, u64::from_le_bytes(d.try_into().unwrap()), wkc),
        (DRIVE, 6_000, 1)
    );
    // ARMW at position 0: read the drive, write the others (the terminal's alias).
    fpwr(&mut s, DRIVE, 0x0012, &[0xEF, 0xBE]);
    let (adp, d, wkc) = dg(&mut s, cmd::ARMW, 0, 0x0012, &[0, 0]);
    assert_eq!((adp, d, wkc), (2, vec![0xEF, 0xBE], 2));
    assert_eq!(fprd(&mut s, DIO, 0x0012, 2), vec![0xEF, 0xBE]);
}

#[test]
fn a_frame_is_processed_in_passing_with_the_source_mac_marked() {
    let mut s = segment();
    // BRD 0x0000 (1 byte), more follows; FPRD 0x0130 at the drive (2 bytes).
    let mut datagrams = vec![cmd::BRD, 0x11, 0, 0, 0, 0, 1, 0x80, 0, 0, 0, 0, 0];
    datagrams.extend_from_slice(&[
        cmd::FPRD,
        0x12,
        0x00,
        0x10,
        0x30,
        0x01,
        2,
        0,
        0,
        0,
        0,
        0,
        0,
        0,
    ]);
    let mut frame = vec![0xFF; 6];
    frame.extend_from_slice(&[0x10; 6]);
    frame.extend_from_slice(&[0x88, 0xA4]);
    frame.extend_from_slice(&(0x1000u16 | datagrams.len() as u16).to_le_bytes());
    frame.extend_from_slice(&datagrams);
    s.process_frame(&mut frame, 0).unwrap();
    assert_eq!(frame[6], 0x12);
    let d = &frame[16..];
    // BRD: idx kept, ADP 2, data 0x04, WKC 2.
    assert_eq!(
        &d[0..13],
        &[cmd::BRD, 0x11, 2, 0, 0, 0, 1, 0x80, 0, 0, 0x04, 2, 0]
    );
    // FPRD: AL status INIT, WKC 1.
    assert_eq!(
        &d[13..],
        &[
            cmd::FPRD,
            0x12,
            0x00,
            0x10,
            0x30,
            0x01,
            2,
            0,
            0,
            0,
            1,
            0,
            1,
            0
        ]
    );
    // Not EtherCAT, or not datagrams: refused.
    let mut bad = frame.clone();
    bad[12] = 0x08;
    assert!(s.process_frame(&mut bad, 0).is_err());
    let mut bad = frame.clone();
    bad[15] = 0x20;
    assert!(s.process_frame(&mut bad, 0).is_err());
}

/// Reads `n` words of the SII through 0x0502/0x0504/0x0508 as ethercrab does.
fn sii_read(s: &mut Segment, station: u16, word: u16, n: usize) -> Vec<u16> {
    let mut out = Vec::new();
    let mut w = word;
    while out.len() < n {
        let [lo, hi] = w.to_le_bytes();
        fpwr(s, station, 0x0502, &[0x00, 0x01, lo, hi, 0, 0]);
        let status = fprd(s, station, 0x0502, 2);
        assert_eq!(status, vec![0x40, 0x00], "not busy, no error, 8-byte reads");
        let d = fprd(s, station, 0x0508, 8);
        out.extend(d.chunks(2).map(|c| u16::from_le_bytes([c[0], c[1]])));
        w += 4;
    }
    out.truncate(n);
    out
}

#[test]
fn sii_holds_the_identity_and_the_categories() {
    let mut s = segment();
    let words = sii_read(&mut s, DIO, 0x08, 8);
    let id: Vec<u32> = words
        .chunks(2)
        .map(|c| u32::from(c[0]) | (u32::from(c[1]) << 16))
        .collect();
    assert_eq!(id, vec![0x0000_0002, 0x0743_3052, 0x0010_0000, 2]);
    let words = sii_read(&mut s, DRIVE, 0x08, 8);
    let id: Vec<u32> = words
        .chunks(2)
        .map(|c| u32::from(c[0]) | (u32::from(c[1]) << 16))
        .collect();
    assert_eq!(id, vec![0x0054_444D, 0x0000_0402, 0x0001_0000, 1]);
    // Mailbox words 0x18..0x1C: 0x1000/128, 0x1080/128, CoE.
    assert_eq!(
        sii_read(&mut s, DRIVE, 0x18, 5),
        vec![0x1000, 128, 0x1080, 128, 0x0004]
    );
    // The header checksum (CRC-8 over bytes 0..14) is right.
    let header = sii_read(&mut s, DRIVE, 0, 8);
    let bytes: Vec<u8> = header.iter().flat_map(|w| w.to_le_bytes()).collect();
    assert_eq!(bytes[14], tandem_ecat_sim::sii::crc8(&bytes[..14]));
    // Walk the categories: STRINGS first, with the order code as string 1.
    let eeprom = s.escs()[1].eeprom().to_vec();
    let mut at = 0x40usize;
    let mut kinds = Vec::new();
    while eeprom[at] != 0xFFFF {
        kinds.push(eeprom[at]);
        at += 2 + usize::from(eeprom[at + 1]);
    }
    assert_eq!(kinds, vec![10, 30, 40, 41, 50, 51]);
    let strings: Vec<u8> = eeprom[0x42..0x42 + 4]
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .collect();
    assert_eq!(&strings[..8], &[2, 6, b'E', b'L', b'1', b'8', b'5', b'9']);
}

/// The drive's mailbox SyncManagers as its SII describes them.
fn configure_mailbox(s: &mut Segment) {
    fpwr(s, DRIVE, 0x0800, &sm(0x1000, 128, 0x26, true));
    fpwr(s, DRIVE, 0x0808, &sm(0x1080, 128, 0x22, true));
}

fn request_state(s: &mut Segment, station: u16, control: u16) -> (u16, u16) {
    fpwr(s, station, 0x0120, &control.to_le_bytes());
    al(s, station)
}

#[test]
fn al_state_machine_accepts_and_refuses_with_status_codes() {
    let mut s = segment();
    // INIT → OP and INIT → SAFE-OP are invalid: stay INIT, error, 0x0011.
    assert_eq!(request_state(&mut s, DRIVE, 0x08), (0x11, 0x0011));
    // With the error set and not acknowledged, a higher state is ignored.
    assert_eq!(request_state(&mut s, DRIVE, 0x02), (0x11, 0x0011));
    // INIT → PRE-OP without mailbox SyncManagers: 0x0016.
    assert_eq!(request_state(&mut s, DRIVE, 0x12), (0x11, 0x0016));
    // A write mailbox in the wrong direction is refused too.
    fpwr(&mut s, DRIVE, 0x0800, &sm(0x1000, 128, 0x22, true));
    fpwr(&mut s, DRIVE, 0x0808, &sm(0x1080, 128, 0x22, true));
    assert_eq!(request_state(&mut s, DRIVE, 0x12), (0x11, 0x0016));
    // Overlapping mailboxes too.
    fpwr(&mut s, DRIVE, 0x0800, &sm(0x1000, 128, 0x26, true));
    fpwr(&mut s, DRIVE, 0x0808, &sm(0x1040, 128, 0x22, true));
    assert_eq!(request_state(&mut s, DRIVE, 0x12), (0x11, 0x0016));
    configure_mailbox(&mut s);
    assert_eq!(request_state(&mut s, DRIVE, 0x12), (0x02, 0));
    // Unknown state and BOOT.
    assert_eq!(request_state(&mut s, DRIVE, 0x05), (0x12, 0x0012));
    assert_eq!(request_state(&mut s, DRIVE, 0x13), (0x12, 0x0013));
    // PRE-OP → OP is invalid.
    assert_eq!(request_state(&mut s, DRIVE, 0x18), (0x12, 0x0011));
    // PRE-OP → SAFE-OP without process data SyncManagers: output configuration first.
    assert_eq!(request_state(&mut s, DRIVE, 0x14), (0x12, 0x001D));
    fpwr(&mut s, DRIVE, 0x0810, &sm(0x1100, 9, 0x64, true));
    assert_eq!(request_state(&mut s, DRIVE, 0x14), (0x12, 0x001E));
    // Inputs one byte short of the 21-byte TxPDO: still refused.
    fpwr(&mut s, DRIVE, 0x0818, &sm(0x1180, 20, 0x20, true));
    assert_eq!(request_state(&mut s, DRIVE, 0x14), (0x12, 0x001E));
    fpwr(&mut s, DRIVE, 0x0818, &sm(0x1180, 21, 0x20, true));
    assert_eq!(request_state(&mut s, DRIVE, 0x14), (0x04, 0));
    assert_eq!(request_state(&mut s, DRIVE, 0x08), (0x08, 0));
    assert_eq!(s.escs()[0].al_state(), AlState::Op);
    // Any downward transition is valid.
    assert_eq!(request_state(&mut s, DRIVE, 0x02), (0x02, 0));
    assert_eq!(request_state(&mut s, DRIVE, 0x01), (0x01, 0));
    // The terminal has no mailbox: INIT → PRE-OP needs nothing; SAFE-OP needs its SMs.
    assert_eq!(request_state(&mut s, DIO, 0x02), (0x02, 0));
    fpwr(&mut s, DIO, 0x0800, &sm(0x0F00, 1, 0x44, true));
    assert_eq!(request_state(&mut s, DIO, 0x04), (0x12, 0x001E));
    assert_eq!(
        s.escs()[1].al_status_code(),
        AlStatusCode::INVALID_INPUT_CONFIG
    );
    fpwr(&mut s, DIO, 0x0808, &sm(0x1000, 1, 0x00, true));
    assert_eq!(request_state(&mut s, DIO, 0x14), (0x04, 0));
}

/// One SDO exchange through the drive's mailbox; returns the response mailbox (128 bytes).
fn sdo(s: &mut Segment, body: &[u8]) -> Vec<u8> {
    let status = fprd(s, DRIVE, 0x080D, 1);
    assert_eq!(status[0] & 0x08, 0, "read mailbox empty before the request");
    let mut request = vec![0u8; 128];
    request[0..2].copy_from_slice(&(2 + body.len() as u16).to_le_bytes());
    request[5] = 0x13;
    request[6..8].copy_from_slice(&0x2000u16.to_le_bytes());
    request[8..8 + body.len()].copy_from_slice(body);
    fpwr(s, DRIVE, 0x1000, &request);
    assert_eq!(fprd(s, DRIVE, 0x080D, 1), vec![0x09], "response ready");
    let response = fprd(s, DRIVE, 0x1080, 128);
    assert_eq!(
        fprd(s, DRIVE, 0x080D, 1),
        vec![0x00],
        "read mailbox empty again"
    );
    assert_eq!(response[5] & 0x0F, 3, "CoE");
    assert_eq!(
        u16::from_le_bytes([response[6], response[7]]) >> 12,
        3,
        "SDO response"
    );
    response
}

fn pre_op(s: &mut Segment) {
    configure_mailbox(s);
    assert_eq!(request_state(s, DRIVE, 0x02), (0x02, 0));
}

#[test]
fn sdo_upload_and_download_round_trip() {
    let mut s = segment();
    pre_op(&mut s);
    // Expedited upload of 0x1018:02 (u32): 0x43.
    let r = sdo(&mut s, &[0x40, 0x18, 0x10, 0x02, 0, 0, 0, 0]);
    assert_eq!(&r[0..2], &[10, 0]);
    assert_eq!(&r[8..16], &[0x43, 0x18, 0x10, 0x02, 0x02, 0x04, 0x00, 0x00]);
    // 0x1C12:00 (u8): 0x4F, one byte.
    let r = sdo(&mut s, &[0x40, 0x12, 0x1C, 0x00, 0, 0, 0, 0]);
    assert_eq!(&r[8..16], &[0x4F, 0x12, 0x1C, 0x00, 0x01, 0, 0, 0]);
    // Normal upload of the device name 0x1008: 0x41, size, data.
    let r = sdo(&mut s, &[0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(&r[0..2], &[17, 0]);
    assert_eq!(&r[8..16], &[0x41, 0x08, 0x10, 0x00, 7, 0, 0, 0]);
    assert_eq!(&r[16..23], b"TSD-402");
    // Expedited download of 0x6060 = 8 (1 byte: 0x2F), response 0x60, read back.
    let r = sdo(&mut s, &[0x2F, 0x60, 0x60, 0x00, 8, 0, 0, 0]);
    assert_eq!(&r[8..12], &[0x60, 0x60, 0x60, 0x00]);
    let r = sdo(&mut s, &[0x40, 0x60, 0x60, 0x00, 0, 0, 0, 0]);
    assert_eq!(&r[8..13], &[0x4F, 0x60, 0x60, 0x00, 8]);
    // Normal download of 0x607A (4 bytes: 0x21 + size) and read back.
    let r = sdo(
        &mut s,
        &[0x21, 0x7A, 0x60, 0x00, 4, 0, 0, 0, 0x78, 0x56, 0x34, 0x12],
    );
    assert_eq!(r[8], 0x60);
    let r = sdo(&mut s, &[0x40, 0x7A, 0x60, 0x00, 0, 0, 0, 0]);
    assert_eq!(&r[8..16], &[0x43, 0x7A, 0x60, 0x00, 0x78, 0x56, 0x34, 0x12]);
    // Aborts: no object, no subindex, read-only, wrong length, complete access.
    let abort = |r: &[u8]| (r[8], u32::from_le_bytes([r[12], r[13], r[14], r[15]]));
    assert_eq!(
        abort(&sdo(&mut s, &[0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0])),
        (0x80, 0x0602_0000)
    );
    assert_eq!(
        abort(&sdo(&mut s, &[0x40, 0x18, 0x10, 0x09, 0, 0, 0, 0])),
        (0x80, 0x0609_0011)
    );
    assert_eq!(
        abort(&sdo(&mut s, &[0x2B, 0x41, 0x60, 0x00, 1, 0, 0, 0])),
        (0x80, 0x0601_0002)
    );
    assert_eq!(
        abort(&sdo(&mut s, &[0x2B, 0x60, 0x60, 0x00, 1, 0, 0, 0])),
        (0x80, 0x0607_0010)
    );
    assert_eq!(
        abort(&sdo(&mut s, &[0x50, 0x18, 0x10, 0x00, 0, 0, 0, 0])),
        (0x80, 0x0601_0004)
    );
}

#[test]
fn pdo_mapping_and_assignment_are_writable_in_pre_op_only() {
    let mut s = segment();
    pre_op(&mut s);
    let abort = |r: &[u8]| u32::from_le_bytes([r[12], r[13], r[14], r[15]]);
    // Entries change only while subindex 0 is 0.
    let r = sdo(&mut s, &[0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60]);
    assert_eq!((r[8], abort(&r)), (0x80, 0x0601_0003));
    // Remap 0x1A00 to statusword + position actual (6 bytes).
    for (sub, value) in [(0u8, 0u32), (1, 0x6041_0010), (2, 0x6064_0020)] {
        let mut body = vec![if sub == 0 { 0x2F } else { 0x23 }, 0x00, 0x1A, sub];
        body.extend_from_slice(&value.to_le_bytes());
        assert_eq!(sdo(&mut s, &body)[8], 0x60, "0x1A00:{sub}");
    }
    // An output object cannot be mapped into a TxPDO; a wrong bit length neither.
    let r = sdo(&mut s, &[0x23, 0x00, 0x1A, 0x03, 0x10, 0x00, 0x40, 0x60]);
    assert_eq!(abort(&r), 0x0604_0041);
    let r = sdo(&mut s, &[0x23, 0x00, 0x1A, 0x03, 0x08, 0x00, 0x41, 0x60]);
    assert_eq!(abort(&r), 0x0604_0041);
    // Subindex 0 may only count existing (8) and set entries (3..7 are still set from the
    // default mapping, 8 is empty).
    let r = sdo(&mut s, &[0x2F, 0x00, 0x1A, 0x00, 9, 0, 0, 0]);
    assert_eq!(abort(&r), 0x0609_0031);
    let r = sdo(&mut s, &[0x2F, 0x00, 0x1A, 0x00, 8, 0, 0, 0]);
    assert_eq!(abort(&r), 0x0609_0030);
    assert_eq!(sdo(&mut s, &[0x2F, 0x00, 0x1A, 0x00, 2, 0, 0, 0])[8], 0x60);
    // Assignment entries change only while 0x1C13:00 is 0, and name a TxPDO only.
    let r = sdo(&mut s, &[0x2B, 0x13, 0x1C, 0x01, 0x00, 0x1A, 0, 0]);
    assert_eq!(abort(&r), 0x0601_0003);
    assert_eq!(sdo(&mut s, &[0x2F, 0x13, 0x1C, 0x00, 0, 0, 0, 0])[8], 0x60);
    let r = sdo(&mut s, &[0x2B, 0x13, 0x1C, 0x01, 0x00, 0x16, 0, 0]);
    assert_eq!(abort(&r), 0x0609_0030);
    assert_eq!(
        sdo(&mut s, &[0x2B, 0x13, 0x1C, 0x01, 0x00, 0x1A, 0, 0])[8],
        0x60
    );
    assert_eq!(sdo(&mut s, &[0x2F, 0x13, 0x1C, 0x00, 1, 0, 0, 0])[8], 0x60);
    // The new image is 6 bytes of inputs: SAFE-OP accepts SM3 with 6 bytes only.
    fpwr(&mut s, DRIVE, 0x0810, &sm(0x1100, 9, 0x64, true));
    fpwr(&mut s, DRIVE, 0x0818, &sm(0x1180, 21, 0x20, true));
    assert_eq!(request_state(&mut s, DRIVE, 0x04), (0x12, 0x001E));
    fpwr(&mut s, DRIVE, 0x0818, &sm(0x1180, 6, 0x20, true));
    assert_eq!(request_state(&mut s, DRIVE, 0x14), (0x04, 0));
    // In SAFE-OP the mapping is locked.
    let r = sdo(&mut s, &[0x2F, 0x00, 0x1A, 0x00, 0, 0, 0, 0]);
    assert_eq!(abort(&r), 0x0800_0022);
}

/// Both devices configured as ethercrab does it: inputs first (drive 21 bytes at logical 0,
/// terminal 1 byte at 21), then outputs (drive 9 bytes at 22, terminal 1 byte at 31).
fn to_op(s: &mut Segment) {
    pre_op(s);
    fpwr(s, DRIVE, 0x0810, &sm(0x1100, 9, 0x64, true));
    fpwr(s, DRIVE, 0x0818, &sm(0x1180, 21, 0x20, true));
    fpwr(s, DRIVE, 0x0600, &fmmu(22, 9, 0x1100, 2));
    fpwr(s, DRIVE, 0x0610, &fmmu(0, 21, 0x1180, 1));
    fpwr(s, DIO, 0x0800, &sm(0x0F00, 1, 0x44, true));
    fpwr(s, DIO, 0x0808, &sm(0x1000, 1, 0x00, true));
    fpwr(s, DIO, 0x0600, &fmmu(31, 1, 0x0F00, 2));
    fpwr(s, DIO, 0x0610, &fmmu(21, 1, 0x1000, 1));
    for station in [DRIVE, DIO] {
        assert_eq!(request_state(s, station, 0x02).0, 0x02);
        assert_eq!(request_state(s, station, 0x04), (0x04, 0));
        assert_eq!(request_state(s, station, 0x08), (0x08, 0));
    }
}

#[test]
fn lrw_moves_process_data_through_two_fmmus_per_subdevice() {
    let mut s = segment();
    to_op(&mut s);
    let mut pdi = vec![0u8; 32];
    pdi[22..24].copy_from_slice(&0x0006u16.to_le_bytes());
    pdi[24] = 8;
    pdi[31] = 0xA5;
    // LRW: each SubDevice +3 (inputs and outputs).
    let (_, d, wkc) = dg(&mut s, cmd::LRW, 0, 0, &pdi);
    assert_eq!(wkc, 6);
    // Outputs are written into the SM buffers, the data of the output part unchanged.
    assert_eq!(&d[22..32], &pdi[22..32]);
    assert_eq!(s.escs()[1].memory()[0x0F00], 0xA5);
    assert_eq!(&s.escs()[0].memory()[0x1100..0x1103], &[0x06, 0x00, 0x08]);
    // The looped terminal shows its outputs on the next exchange.
    let (_, d, _) = dg(&mut s, cmd::LRW, 0, 0, &pdi);
    assert_eq!(d[21], 0xA5);
    // The drive (one CiA 402 transition per exchange, inputs one exchange behind): not ready
    // to switch on (transition 0), switch on disabled (1), ready to switch on (2, shutdown
    // 0x06), always with remote (bit 9), mode display 8 (CSP) from its first exchange.
    let sw = |d: &[u8]| u16::from_le_bytes([d[0], d[1]]);
    assert_eq!(sw(&d), 0x0200);
    assert_eq!(d[2], 8);
    let (_, d, _) = dg(&mut s, cmd::LRW, 0, 0, &pdi);
    assert_eq!(sw(&d) & 0x6F, 0x40);
    let (_, d, _) = dg(&mut s, cmd::LRW, 0, 0, &pdi);
    assert_eq!(sw(&d) & 0x6F, 0x21);
    // LRD reads only (+1 each), LWR writes only (+2 each).
    assert_eq!(dg(&mut s, cmd::LRD, 0, 0, &pdi).2, 2);
    assert_eq!(dg(&mut s, cmd::LWR, 0, 0, &pdi).2, 4);
    // A window touching only the terminal's input byte: +1 from it alone.
    let mut adp = 21u16;
    let mut one = [0u8];
    assert_eq!(s.datagram(cmd::LRD, &mut adp, 0, &mut one), 1);
    // A window beyond every FMMU: nobody.
    let mut adp = 100u16;
    assert_eq!(s.datagram(cmd::LRW, &mut adp, 0, &mut one), 0);
    // Logical addresses use ADO as the high word: 0x0001_0000 is beyond every FMMU.
    let mut adp = 0u16;
    assert_eq!(s.datagram(cmd::LRW, &mut adp, 1, &mut pdi.clone()), 0);
}

#[test]
fn outputs_are_ignored_in_safe_op() {
    let mut s = segment();
    to_op(&mut s);
    assert_eq!(request_state(&mut s, DIO, 0x04), (0x04, 0));
    let mut pdi = vec![0u8; 32];
    pdi[31] = 0xFF;
    dg(&mut s, cmd::LRW, 0, 0, &pdi);
    let (_, d, wkc) = dg(&mut s, cmd::LRW, 0, 0, &pdi);
    assert_eq!(wkc, 6);
    assert_eq!(d[21], 0x00, "SAFE-OP: the terminal's outputs stay off");
}
