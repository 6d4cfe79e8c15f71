//! One emulated EtherCAT SubDevice Controller (ESC): its register space and process RAM, the
//! AL state machine, SII EEPROM access, SyncManagers, FMMUs, the CoE mailbox and the DC
//! registers. Register map and behaviour: Beckhoff "EtherCAT Slave Controller, Section I –
//! Technology" and "Section II – Register Description"; what ethercrab 0.7.1 reads and writes
//! is digested in the project's EtherCAT + CiA 402 reference (sections 2 to 7).
//!
//! Pure: the caller passes the time (ns of the ESC's local clock) with every frame.

use core::fmt;

use crate::coe::serve_mailbox;
use crate::device::{
    AnalogIo, Cia402Drive, DeviceKind, DeviceOptions, DigitalIo, EncoderTerminal, Model,
};
use crate::sii::{Identity, SiiSpec, SmType};

/// Size of the emulated memory: registers 0x0000..0x1000 and 4 KiB of process RAM.
pub const MEMORY_SIZE: usize = 0x2000;
/// FMMUs an emulated ESC has (0x0004).
pub const FMMU_COUNT: usize = 8;
/// SyncManagers an emulated ESC has (0x0005).
pub const SM_COUNT: usize = 8;

/// ESC register addresses used by the emulation.
pub mod reg {
    /// ESC features supported (bit 2 DC, bit 3 64-bit DC, bit 8 enhanced DC sync).
    pub const FEATURES: u16 = 0x0008;
    /// Configured station address.
    pub const STATION_ADDRESS: u16 = 0x0010;
    /// DL status.
    pub const DL_STATUS: u16 = 0x0110;
    /// AL control.
    pub const AL_CONTROL: u16 = 0x0120;
    /// AL status.
    pub const AL_STATUS: u16 = 0x0130;
    /// AL status code.
    pub const AL_STATUS_CODE: u16 = 0x0134;
    /// SII control/status.
    pub const SII_CONTROL: u16 = 0x0502;
    /// SII address (word address).
    pub const SII_ADDRESS: u16 = 0x0504;
    /// SII data (8 bytes per read).
    pub const SII_DATA: u16 = 0x0508;
    /// FMMU 0 (16 bytes per FMMU).
    pub const FMMU0: u16 = 0x0600;
    /// SyncManager 0 (8 bytes per SyncManager).
    pub const SM0: u16 = 0x0800;
    /// Receive time port 0 (a write latches the receive times).
    pub const DC_RECEIVE_TIME_PORT0: u16 = 0x0900;
    /// System time.
    pub const DC_SYSTEM_TIME: u16 = 0x0910;
    /// Receive time of the ECAT processing unit (local time of the latch).
    pub const DC_RECEIVE_TIME: u16 = 0x0918;
    /// System time offset.
    pub const DC_SYSTEM_TIME_OFFSET: u16 = 0x0920;
    /// System time delay.
    pub const DC_SYSTEM_TIME_DELAY: u16 = 0x0928;
}

/// The AL state of a SubDevice (0x0130 bits 0..3).
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum AlState {
    /// INIT.
    Init = 1,
    /// PRE-OP: mailbox.
    PreOp = 2,
    /// BOOT (never reached: bootstrap is not supported).
    Boot = 3,
    /// SAFE-OP: inputs valid, outputs safe.
    SafeOp = 4,
    /// OP: inputs and outputs.
    Op = 8,
}

impl AlState {
    fn from_code(code: u16) -> Option<Self> {
        match code {
            1 => Some(Self::Init),
            2 => Some(Self::PreOp),
            3 => Some(Self::Boot),
            4 => Some(Self::SafeOp),
            8 => Some(Self::Op),
            _ => None,
        }
    }
}

/// An AL status code (0x0134).
#[doc(alias = "0x0134")]
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct AlStatusCode(pub u16);

impl AlStatusCode {
    /// No error.
    pub const NO_ERROR: Self = Self(0x0000);
    /// Invalid requested state change (e.g. INIT → OP).
    pub const INVALID_STATE_CHANGE: Self = Self(0x0011);
    /// Unknown requested state.
    pub const UNKNOWN_STATE: Self = Self(0x0012);
    /// Bootstrap not supported.
    pub const BOOTSTRAP_NOT_SUPPORTED: Self = Self(0x0013);
    /// Invalid mailbox configuration (PRE-OP).
    pub const INVALID_MAILBOX_CONFIG: Self = Self(0x0016);
    /// Invalid SyncManager configuration.
    pub const INVALID_SM_CONFIG: Self = Self(0x0017);
    /// Invalid output configuration.
    pub const INVALID_OUTPUT_CONFIG: Self = Self(0x001D);
    /// Invalid input configuration.
    pub const INVALID_INPUT_CONFIG: Self = Self(0x001E);
}

/// Why an ESC could not be built.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum EscError {
    /// The drive model refused its parameters (the cycle must be positive).
    DriveCycle {
        /// The cycle given (ns).
        cycle_ns: i64,
    },
}

impl fmt::Display for EscError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::DriveCycle { cycle_ns } => {
                write!(f, "the drive model refuses a cycle of {cycle_ns} ns")
            }
        }
    }
}

impl std::error::Error for EscError {}

/// How a datagram accesses ESC memory.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Access {
    /// Read: the datagram data becomes the memory contents (APRD, FPRD, ARMW/FRMW read).
    Read,
    /// Read OR-ed into the datagram data (BRD).
    ReadOr,
    /// Write (APWR, FPWR, BWR, ARMW/FRMW write).
    Write,
    /// Read and write: the data becomes the old contents (APRW, FPRW).
    ReadWrite,
    /// Read and write, the old contents OR-ed into the data (BRW).
    ReadWriteOr,
}

impl Access {
    const fn reads(self) -> bool {
        !matches!(self, Self::Write)
    }
    const fn writes(self) -> bool {
        matches!(self, Self::Write | Self::ReadWrite | Self::ReadWriteOr)
    }
    const fn or(self) -> bool {
        matches!(self, Self::ReadOr | Self::ReadWriteOr)
    }
}

/// Which process data a logical command moves.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Logical {
    /// LRD: read FMMUs only.
    Read,
    /// LWR: write FMMUs only.
    Write,
    /// LRW: both.
    ReadWrite,
}

/// One emulated ESC with its device model.
#[derive(Clone, Debug)]
pub struct Esc {
    mem: Vec<u8>,
    sii: SiiSpec,
    eeprom: Vec<u16>,
    model: Model,
    state: AlState,
    error: bool,
    code: AlStatusCode,
    dc: bool,
    read_mailbox_full: bool,
    mailbox_counter: u8,
    now_ns: u64,
}

impl Esc {
    /// A SubDevice of the given kind in INIT, with `serial` as its serial number. It reports
    /// a link on port 0 only until [`Esc::set_downstream`] says a neighbour follows.
    pub fn new(kind: DeviceKind, serial: u32, options: DeviceOptions) -> Result<Self, EscError> {
        let (sii, model, dc) = match kind {
            DeviceKind::DigitalIo => (
                DigitalIo::sii(serial),
                Model::DigitalIo(DigitalIo {
                    loopback: options.dio_loopback,
                    ..DigitalIo::default()
                }),
                false,
            ),
            DeviceKind::AnalogIo => (
                AnalogIo::sii(serial),
                Model::AnalogIo(AnalogIo {
                    loopback: options.aio_loopback,
                    inputs: options.analog_in,
                    ..AnalogIo::default()
                }),
                false,
            ),
            DeviceKind::Encoder => (
                EncoderTerminal::sii(serial),
                Model::Encoder(EncoderTerminal::new(options.encoder_velocity)),
                false,
            ),
            DeviceKind::Cia402Drive => {
                let sii = Cia402Drive::sii(serial);
                let drive = Cia402Drive::new(sii.identity, options.cycle_ns).ok_or(
                    EscError::DriveCycle {
                        cycle_ns: options.cycle_ns,
                    },
                )?;
                (sii, Model::Drive(Box::new(drive)), true)
            }
        };
        let mut esc = Self {
            mem: vec![0; MEMORY_SIZE],
            eeprom: sii.image(),
            sii,
            model,
            state: AlState::Init,
            error: false,
            code: AlStatusCode::NO_ERROR,
            dc,
            read_mailbox_full: false,
            mailbox_counter: 0,
            now_ns: 0,
        };
        // Type (IP core), revision, build; FMMUs, SMs, RAM (KiB), ports 0 and 1 E-bus.
        esc.put(0x0000, &[0x04, 0x01, 0x01, 0x00]);
        esc.put(0x0004, &[FMMU_COUNT as u8, SM_COUNT as u8, 4, 0x0A]);
        // 64-bit DC with enhanced SYNC activation for the drive; none for the terminal.
        let features: u16 = if dc { 0x010C } else { 0x0000 };
        esc.put(reg::FEATURES, &features.to_le_bytes());
        esc.put(0x0930, &0x1000u16.to_le_bytes());
        esc.put(reg::SII_CONTROL, &0x0040u16.to_le_bytes());
        esc.set_downstream(false);
        esc.sync_al();
        Ok(esc)
    }

    /// Sets the DL status 0x0110: port 0 linked, and port 1 too if a neighbour follows (the
    /// values a real middle and last device report).
    pub fn set_downstream(&mut self, downstream: bool) {
        let dl: u16 = if downstream { 0x5A33 } else { 0x5613 };
        self.put(reg::DL_STATUS, &dl.to_le_bytes());
    }

    /// The configured station address 0x0010.
    pub fn station_address(&self) -> u16 {
        self.u16_at(reg::STATION_ADDRESS)
    }

    /// The AL state.
    pub const fn al_state(&self) -> AlState {
        self.state
    }

    /// Whether the AL status error indication (0x0130 bit 4) is set.
    pub const fn al_error(&self) -> bool {
        self.error
    }

    /// The AL status code 0x0134.
    pub const fn al_status_code(&self) -> AlStatusCode {
        self.code
    }

    /// The identity.
    pub const fn identity(&self) -> Identity {
        self.sii.identity
    }

    /// The SII description.
    pub const fn sii(&self) -> &SiiSpec {
        &self.sii
    }

    /// The EEPROM image (words).
    pub fn eeprom(&self) -> &[u16] {
        &self.eeprom
    }

    /// The device model.
    pub const fn model(&self) -> &Model {
        &self.model
    }

    /// The device model, to inject inputs or faults.
    pub fn model_mut(&mut self) -> &mut Model {
        &mut self.model
    }

    /// Whether this ESC supports distributed clocks.
    pub const fn has_dc(&self) -> bool {
        self.dc
    }

    /// The local time (ns) of the frame being processed.
    pub fn set_time(&mut self, now_ns: u64) {
        self.now_ns = now_ns;
    }

    /// The memory (registers and process RAM), for inspection.
    pub fn memory(&self) -> &[u8] {
        &self.mem
    }

    fn put(&mut self, addr: u16, data: &[u8]) {
        let a = usize::from(addr);
        if let Some(dst) = self.mem.get_mut(a..a + data.len()) {
            dst.copy_from_slice(data);
        }
    }

    fn bytes<const N: usize>(&self, addr: u16) -> [u8; N] {
        let a = usize::from(addr);
        let mut out = [0u8; N];
        if let Some(src) = self.mem.get(a..a + N) {
            out.copy_from_slice(src);
        }
        out
    }

    fn u16_at(&self, addr: u16) -> u16 {
        u16::from_le_bytes(self.bytes(addr))
    }

    /// Whether a register byte exists (a real ESC does not count a datagram touching only
    /// registers it lacks): FMMUs and SMs beyond the supported count and the DC block of a
    /// device without DC are absent.
    fn present(&self, a: usize) -> bool {
        let fmmu_end = usize::from(reg::FMMU0) + 16 * FMMU_COUNT;
        let sm_end = usize::from(reg::SM0) + 8 * SM_COUNT;
        a < MEMORY_SIZE
            && !(fmmu_end..0x0800).contains(&a)
            && !(sm_end..0x0900).contains(&a)
            && (self.dc || !(0x0900..0x0A00).contains(&a))
    }

    /// Whether the MainDevice may write a byte: identification, DL status, AL status, SII
    /// data, SyncManager status and the DC time registers are read-only from the ECAT side.
    fn writable(a: usize) -> bool {
        let read_only = [
            0x0000..0x0010,
            0x0110..0x0112,
            0x0130..0x0136,
            0x0508..0x0510,
            0x0900..0x0920,
        ];
        let sm_status = (0x0800..0x0800 + 8 * SM_COUNT).contains(&a) && a % 8 == 5;
        !sm_status && !read_only.iter().any(|r| r.contains(&a))
    }

    /// A physical access by a datagram at `addr` (data in place). Returns the working
    /// counter increment: read +1, write +1, read and write +3, 0 if no byte exists.
    pub fn access(&mut self, addr: u16, data: &mut [u8], access: Access) -> u16 {
        let base = usize::from(addr);
        if access.reads() {
            self.refresh(base, data.len());
        }
        let mut any = false;
        for (k, d) in data.iter_mut().enumerate() {
            let a = base + k;
            if !self.present(a) {
                continue;
            }
            any = true;
            let Some(old) = self.mem.get(a).copied() else {
                continue;
            };
            if access.writes() && Self::writable(a) {
                if let Some(m) = self.mem.get_mut(a) {
                    *m = *d;
                }
            }
            if access.reads() {
                *d = if access.or() { *d | old } else { old };
            }
        }
        if !any {
            return 0;
        }
        if access.reads() {
            self.after_read(base, data.len());
        }
        if access.writes() {
            self.after_write(base, data);
        }
        match (access.reads(), access.writes()) {
            (true, true) => 3,
            _ => 1,
        }
    }

    /// Registers whose value is computed when read: the DC system time.
    fn refresh(&mut self, base: usize, len: usize) {
        let st = usize::from(reg::DC_SYSTEM_TIME);
        if self.dc && base < st + 8 && st < base + len {
            let offset = i64::from_le_bytes(self.bytes(reg::DC_SYSTEM_TIME_OFFSET));
            let system = self.now_ns.wrapping_add_signed(offset);
            self.put(reg::DC_SYSTEM_TIME, &system.to_le_bytes());
        }
    }

    /// The SyncManager `n` as configured in the registers: (start, length, control, enabled).
    fn sm(&self, n: usize) -> (u16, u16, u8, bool) {
        let at = reg::SM0 + 8 * n as u16;
        let b: [u8; 8] = self.bytes(at);
        (
            u16::from_le_bytes([b[0], b[1]]),
            u16::from_le_bytes([b[2], b[3]]),
            b[4],
            b[6] & 0x01 != 0,
        )
    }

    fn after_read(&mut self, base: usize, len: usize) {
        // The MainDevice has read the last byte of the read mailbox: it is empty again.
        if let Some((n, _)) = self.sii.sync_manager(SmType::MailboxIn) {
            let (start, length, _, enabled) = self.sm(n);
            let last = usize::from(start) + usize::from(length).saturating_sub(1);
            if enabled && length > 0 && (base..base + len).contains(&last) {
                self.read_mailbox_full = false;
                self.sync_sm_status();
            }
        }
    }

    fn after_write(&mut self, base: usize, data: &[u8]) {
        let hit = |addr: u16, len: usize| {
            let a = usize::from(addr);
            base < a + len && a < base + data.len()
        };
        if hit(reg::AL_CONTROL, 2) {
            let control = self.u16_at(reg::AL_CONTROL);
            self.al_control(control);
        }
        if hit(reg::SII_CONTROL, 2) {
            self.sii_command();
        }
        if self.dc && hit(reg::DC_RECEIVE_TIME_PORT0, 4) {
            // Latch: the receive time of every port and of the processing unit is now
            // (inferred: no propagation delay between emulated devices).
            let t = self.now_ns;
            for port in 0..4u16 {
                self.put(
                    reg::DC_RECEIVE_TIME_PORT0 + 4 * port,
                    &(t as u32).to_le_bytes(),
                );
            }
            self.put(reg::DC_RECEIVE_TIME, &t.to_le_bytes());
        }
        if hit(reg::SM0, 8 * SM_COUNT) {
            self.sync_sm_status();
        }
        if let Some((n, _)) = self.sii.sync_manager(SmType::MailboxOut) {
            let (start, length, _, enabled) = self.sm(n);
            let last = start.wrapping_add(length.saturating_sub(1));
            if enabled && length > 0 && hit(last, 1) && self.state >= AlState::PreOp {
                self.mailbox_request();
            }
        }
    }

    /// The SyncManager status bytes: the read mailbox's "mailbox full" (bit 3, with the
    /// write event bit 0, as a real device reports 0x09).
    fn sync_sm_status(&mut self) {
        if let Some((n, _)) = self.sii.sync_manager(SmType::MailboxIn) {
            let status = if self.read_mailbox_full { 0x09 } else { 0x00 };
            self.put(reg::SM0 + 8 * n as u16 + 5, &[status]);
        }
    }

    /// The write mailbox is complete: answer it into the read mailbox at once.
    fn mailbox_request(&mut self) {
        let (Some((out, _)), Some((inn, _))) = (
            self.sii.sync_manager(SmType::MailboxOut),
            self.sii.sync_manager(SmType::MailboxIn),
        ) else {
            return;
        };
        let (req_start, req_len, _, _) = self.sm(out);
        let (resp_start, resp_len, _, resp_enabled) = self.sm(inn);
        let mut request = [0u8; 1024];
        let n = usize::from(req_len).min(request.len());
        let r = usize::from(req_start);
        let (Some(dst), Some(src)) = (request.get_mut(..n), self.mem.get(r..r + n)) else {
            return;
        };
        dst.copy_from_slice(src);
        let pre_op = self.state == AlState::PreOp;
        self.mailbox_counter = self.mailbox_counter % 7 + 1;
        let counter = self.mailbox_counter;
        let s = usize::from(resp_start);
        let e = s + usize::from(resp_len);
        let (Some(od), Some(response)) = (self.model.od_mut(), self.mem.get_mut(s..e)) else {
            return;
        };
        if !resp_enabled {
            return;
        }
        if serve_mailbox(od, pre_op, dst, response, counter).is_some() {
            self.read_mailbox_full = true;
            self.sync_sm_status();
        }
    }

    /// An SII command written to 0x0502: a read fills 0x0508..0x0510 with four words from
    /// the word address in 0x0504 (at once: never busy, no error bits).
    fn sii_command(&mut self) {
        let control = self.u16_at(reg::SII_CONTROL);
        if control & 0x0100 != 0 {
            let word = u32::from_le_bytes(self.bytes(reg::SII_ADDRESS)) as usize;
            let mut data = [0u8; 8];
            for (k, chunk) in data.chunks_exact_mut(2).enumerate() {
                let w = self.eeprom.get(word + k).copied().unwrap_or(0xFFFF);
                chunk.copy_from_slice(&w.to_le_bytes());
            }
            self.put(reg::SII_DATA, &data);
        }
        // 8-byte reads supported; not busy; no error.
        self.put(reg::SII_CONTROL, &0x0040u16.to_le_bytes());
    }

    fn sync_al(&mut self) {
        let status = self.state as u16 | if self.error { 0x10 } else { 0 };
        self.put(reg::AL_STATUS, &status.to_le_bytes());
        self.put(reg::AL_STATUS_CODE, &self.code.0.to_le_bytes());
    }

    fn refuse(&mut self, code: AlStatusCode) {
        self.error = true;
        self.code = code;
    }

    /// A write to AL control 0x0120: the state machine of the ESC Section I "AL state
    /// machine" with the checks of a SubDevice stack (reference section 4.2).
    fn al_control(&mut self, control: u16) {
        let ack = control & 0x10 != 0;
        if ack {
            self.error = false;
            self.code = AlStatusCode::NO_ERROR;
        }
        let requested = AlState::from_code(control & 0x0F);
        match requested {
            None => self.refuse(AlStatusCode::UNKNOWN_STATE),
            Some(AlState::Boot) => self.refuse(AlStatusCode::BOOTSTRAP_NOT_SUPPORTED),
            Some(target) if target <= self.state => self.go_down(target),
            // Inferred (SubDevice stack behaviour): with the error indication set and not
            // acknowledged, a request for a higher state is ignored.
            Some(_) if self.error => {}
            Some(target) => self.go_up(target),
        }
        self.sync_al();
    }

    fn go_down(&mut self, target: AlState) {
        if target < AlState::PreOp {
            self.read_mailbox_full = false;
            self.sync_sm_status();
        }
        self.state = target;
    }

    fn go_up(&mut self, target: AlState) {
        let check = match (self.state, target) {
            (AlState::Init, AlState::PreOp) => self.check_mailbox(),
            (AlState::PreOp, AlState::SafeOp) => self.check_process_data(),
            (AlState::SafeOp, AlState::Op) => Ok(()),
            _ => Err(AlStatusCode::INVALID_STATE_CHANGE),
        };
        match check {
            Ok(()) => {
                if target == AlState::SafeOp {
                    self.model.prepare();
                }
                self.state = target;
            }
            Err(code) => self.refuse(code),
        }
    }

    /// INIT → PRE-OP: the mailbox SyncManagers as the SII describes them: enabled, mailbox
    /// mode and direction, in process RAM, not overlapping.
    fn check_mailbox(&self) -> Result<(), AlStatusCode> {
        let bad = Err(AlStatusCode::INVALID_MAILBOX_CONFIG);
        let mut areas = [(0usize, 0usize); 2];
        for (slot, kind) in [SmType::MailboxOut, SmType::MailboxIn].iter().enumerate() {
            let Some((n, spec)) = self.sii.sync_manager(*kind) else {
                return Ok(());
            };
            let (start, length, control, enabled) = self.sm(n);
            let end = usize::from(start) + usize::from(length);
            if !enabled
                || control & 0x0F != spec.control & 0x0F
                || start < 0x1000
                || length < 16
                || end > MEMORY_SIZE
            {
                return bad;
            }
            if let Some(a) = areas.get_mut(slot) {
                *a = (usize::from(start), end);
            }
        }
        let [a, b] = areas;
        if a.0 < b.1 && b.0 < a.1 {
            return bad;
        }
        Ok(())
    }

    /// PRE-OP → SAFE-OP: the process data SyncManagers match the PDO image (length, buffered
    /// mode, direction, enabled when not empty, the three buffers inside process RAM).
    fn check_process_data(&self) -> Result<(), AlStatusCode> {
        let (out_bytes, in_bytes) = self.model.image_sizes();
        for (kind, bytes, direction, code) in [
            (
                SmType::Outputs,
                out_bytes,
                0x04,
                AlStatusCode::INVALID_OUTPUT_CONFIG,
            ),
            (
                SmType::Inputs,
                in_bytes,
                0x00,
                AlStatusCode::INVALID_INPUT_CONFIG,
            ),
        ] {
            let Some((n, _)) = self.sii.sync_manager(kind) else {
                continue;
            };
            let (start, length, control, enabled) = self.sm(n);
            if usize::from(length) != bytes {
                return Err(code);
            }
            if bytes == 0 {
                continue;
            }
            if !enabled || control & 0x03 != 0 || control & 0x0C != direction {
                return Err(code);
            }
            if usize::from(start) + 3 * usize::from(length) > MEMORY_SIZE {
                return Err(AlStatusCode::INVALID_SM_CONFIG);
            }
        }
        Ok(())
    }

    /// A logical datagram at logical address `addr`: every enabled FMMU overlapping it moves
    /// bytes (write FMMUs from the incoming data, then read FMMUs into it). Returns the working
    /// counter increment: +1 if a read FMMU matched, +2 if a write FMMU did (once per ESC).
    /// In SAFE-OP and OP the device then exchanges its process data.
    pub fn logical(&mut self, command: Logical, addr: u32, data: &mut [u8]) -> u16 {
        let reads = command != Logical::Write;
        let writes = command != Logical::Read;
        let (mut read, mut wrote) = (false, false);
        // Writes first, so they see the incoming data; then reads.
        for pass_write in [true, false] {
            for n in 0..FMMU_COUNT {
                let f: [u8; 16] = self.bytes(reg::FMMU0 + 16 * n as u16);
                let logical = u32::from_le_bytes([f[0], f[1], f[2], f[3]]);
                let length = u32::from(u16::from_le_bytes([f[4], f[5]]));
                let physical = usize::from(u16::from_le_bytes([f[8], f[9]]));
                let (is_read, is_write, enabled) = (f[11] & 1 != 0, f[11] & 2 != 0, f[12] & 1 != 0);
                let moves = if pass_write {
                    is_write && writes
                } else {
                    is_read && reads
                };
                if !enabled || !moves {
                    continue;
                }
                let lo = logical.max(addr);
                let hi = logical
                    .saturating_add(length)
                    .min(addr.saturating_add(data.len() as u32));
                if lo >= hi {
                    continue;
                }
                let d = (lo - addr) as usize;
                let p = physical + (lo - logical) as usize;
                let n = (hi - lo) as usize;
                let (Some(dg), Some(mem)) = (data.get_mut(d..d + n), self.mem.get_mut(p..p + n))
                else {
                    continue;
                };
                if pass_write {
                    mem.copy_from_slice(dg);
                    wrote = true;
                } else {
                    dg.copy_from_slice(mem);
                    read = true;
                }
            }
        }
        if (read || wrote) && self.state >= AlState::SafeOp {
            self.exchange_process_data();
        }
        u16::from(read) + 2 * u16::from(wrote)
    }

    /// Runs the device model on the process data SyncManagers' buffers.
    fn exchange_process_data(&mut self) {
        let area = |esc: &Self, kind| {
            esc.sii.sync_manager(kind).map_or((0, 0), |(n, _)| {
                let (start, length, _, enabled) = esc.sm(n);
                (
                    usize::from(start),
                    if enabled { usize::from(length) } else { 0 },
                )
            })
        };
        let (os, ol) = area(self, SmType::Outputs);
        let (is, il) = area(self, SmType::Inputs);
        let mut outputs = [0u8; 256];
        let ol = ol.min(outputs.len());
        if let (Some(dst), Some(src)) = (outputs.get_mut(..ol), self.mem.get(os..os + ol)) {
            dst.copy_from_slice(src);
        }
        let op = self.state == AlState::Op;
        let now = self.now_ns;
        if let Some(inputs) = self.mem.get_mut(is..is + il) {
            self.model
                .cycle(outputs.get(..ol).unwrap_or(&[]), inputs, op, now);
        }
    }
}
