//! The emulated devices behind the ESCs: a digital input/output terminal, an analog
//! input/output terminal and a CiA 402 servo
//! drive (the project's simulated drive, [`SimServo`], behind a CoE object dictionary).

use core::fmt;
use core::str::FromStr;

use tandem_motion::plant::cia402::DriveCommand;
use tandem_motion::plant::servo::{ServoParams, SimServo};

use crate::coe::{Access, Entry, Mappable, ObjectDictionary};
use crate::sii::{FmmuUsage, Identity, PdoEntry, PdoSpec, SiiSpec, SmSpec, SmType};

/// Vendor ID of Beckhoff Automation (ETG-assigned), used by the terminal emulation.
pub const BECKHOFF_VENDOR_ID: u32 = 0x0000_0002;
/// Product code of the digital I/O terminal: an EL1859 (8 digital inputs + 8 digital outputs,
/// the combination of an EL1008 and an EL2008), (1859 << 16) | 0x3052.
pub const DIO_PRODUCT_CODE: u32 = 0x0743_3052;
/// Vendor ID of the emulated servo drive. Inferred: not an ETG-assigned vendor ID; chosen so
/// that it cannot be mistaken for a real product ("TDM").
pub const DRIVE_VENDOR_ID: u32 = 0x0054_444D;
/// Product code of the emulated servo drive.
pub const DRIVE_PRODUCT_CODE: u32 = 0x0000_0402;
/// Device type 0x1000 of the drive: CiA 402 profile (0x0192), servo drive (type 2 in the
/// high word).
#[doc(alias = "0x1000")]
pub const DRIVE_DEVICE_TYPE: u32 = 0x0002_0192;
/// Cycle the drive model is parameterised for when none is given (ns).
pub const DEFAULT_CYCLE_NS: i64 = 1_000_000;
/// Longest time step the drive model integrates at once (ns); a longer pause between two
/// process data exchanges is treated as this long (the model does not catch up seconds).
const MAX_STEP_NS: u64 = 100_000_000;

/// What kind of SubDevice an ESC emulates.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum DeviceKind {
    /// A CiA 402 servo drive with CoE (`drive`).
    Cia402Drive,
    /// An 8-channel digital input and output terminal without mailbox (`dio`).
    DigitalIo,
    /// A 2-channel ±10 V analog input and 2-channel ±10 V analog output terminal without
    /// mailbox (`aio`).
    AnalogIo,
    /// A 1-channel incremental encoder terminal with a 32-bit counter, without mailbox
    /// (`enc`).
    Encoder,
}

/// A device name that is not one of `drive`, `dio`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct UnknownDevice;

impl fmt::Display for UnknownDevice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("unknown device kind (expected `drive`, `dio`, `aio` or `enc`)")
    }
}

impl std::error::Error for UnknownDevice {}

impl FromStr for DeviceKind {
    type Err = UnknownDevice;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "drive" => Ok(Self::Cia402Drive),
            "dio" => Ok(Self::DigitalIo),
            "aio" => Ok(Self::AnalogIo),
            "enc" => Ok(Self::Encoder),
            _ => Err(UnknownDevice),
        }
    }
}

/// How the devices of a segment behave.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct DeviceOptions {
    /// The drive model's cycle (its interpolation period), ns.
    pub cycle_ns: i64,
    /// Digital I/O terminals read their own outputs on their inputs (a wired loop).
    pub dio_loopback: bool,
    /// Analog I/O terminals read their own outputs on their inputs (output channel c wired
    /// to input channel c).
    pub aio_loopback: bool,
    /// What the analog inputs of every analog I/O terminal read when not looped back: the
    /// 16-bit codes of channels 1 and 2.
    pub analog_in: [i16; 2],
    /// The velocity every encoder terminal counts at (increments per second).
    pub encoder_velocity: i64,
}

impl Default for DeviceOptions {
    fn default() -> Self {
        Self {
            cycle_ns: DEFAULT_CYCLE_NS,
            dio_loopback: false,
            aio_loopback: false,
            analog_in: [0; 2],
            encoder_velocity: 0,
        }
    }
}

/// The digital I/O terminal: 8 outputs (SM0 at 0x0F00) and 8 inputs (SM1 at 0x1000).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct DigitalIo {
    /// The outputs as the terminal drives them (all off outside OP).
    pub outputs: u8,
    /// The input levels (what the plant presents), unless looped back.
    pub inputs: u8,
    /// Inputs read the outputs.
    pub loopback: bool,
}

impl DigitalIo {
    /// The SII of the terminal.
    pub fn sii(serial: u32) -> SiiSpec {
        let bit = |index: u16| PdoEntry {
            index,
            subindex: 1,
            bits: 1,
        };
        SiiSpec {
            identity: Identity {
                vendor: BECKHOFF_VENDOR_ID,
                product: DIO_PRODUCT_CODE,
                revision: 0x0010_0000,
                serial,
            },
            order: "EL1859",
            name: "EL1859 8Ch. Dig. In/Out 24V (emulated)",
            mailbox_protocols: 0,
            coe_details: 0,
            fmmus: vec![FmmuUsage::Outputs, FmmuUsage::Inputs],
            sync_managers: vec![
                SmSpec {
                    start: 0x0F00,
                    length: 1,
                    control: 0x44,
                    kind: SmType::Outputs,
                },
                SmSpec {
                    start: 0x1000,
                    length: 1,
                    control: 0x00,
                    kind: SmType::Inputs,
                },
            ],
            tx_pdos: (0..8u16)
                .map(|ch| PdoSpec {
                    index: 0x1A00 + ch,
                    sync_manager: 1,
                    entries: vec![bit(0x6000 + 0x10 * ch)],
                })
                .collect(),
            rx_pdos: (0..8u16)
                .map(|ch| PdoSpec {
                    index: 0x1600 + ch,
                    sync_manager: 0,
                    entries: vec![bit(0x7000 + 0x10 * ch)],
                })
                .collect(),
        }
    }

    fn cycle(&mut self, outputs: &[u8], inputs: &mut [u8], op: bool) {
        // Outside OP the outputs are in their safe state (off).
        self.outputs = if op {
            outputs.first().copied().unwrap_or(0)
        } else {
            0
        };
        if let Some(b) = inputs.first_mut() {
            *b = if self.loopback {
                self.outputs
            } else {
                self.inputs
            };
        }
    }
}

/// Product code of the analog I/O terminal: that of an EL4374 (2 analog inputs and 2 analog
/// outputs, ±10 V among its ranges, 16 bit), (4374 << 16) | 0x3052. The emulation keeps only
/// the value words (see [`AnalogIo`]).
pub const AIO_PRODUCT_CODE: u32 = 0x1116_3052;

/// Full scale of the analog terminal's 16-bit words: 0x7FFF stands for +10 V (the signed
/// presentation of the EL31xx/EL41xx terminals).
pub const AIO_FULL_SCALE: f64 = 10.0;

/// The analog I/O terminal: 2 output words (SM0 at 0x1000, 4 bytes: channel 1, channel 2,
/// INT16 little-endian) and 2 input words (SM1 at 0x1100, 4 bytes). A word is the signed
/// 16-bit code, 0x7FFF = +10 V, 0x8001 = -10 V. No mailbox: the PDOs are those of the SII
/// (RxPDO 0x1600 → 0x7000:11, 0x1601 → 0x7010:11; TxPDO 0x1A00 → 0x6000:11, 0x1A01 →
/// 0x6010:11: the value entries of the EL3102/EL4132-like compact PDOs, without their status
/// words).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct AnalogIo {
    /// The output words as the terminal drives them (0 V outside OP).
    pub outputs: [i16; 2],
    /// The input words (what the plant presents), unless looped back.
    pub inputs: [i16; 2],
    /// Inputs read the outputs (output channel c on input channel c).
    pub loopback: bool,
}

impl AnalogIo {
    /// The code of `volts` on a ±10 V 16-bit word: `round(v · 32767 / 10)` clamped to ±32767.
    pub fn code(volts: f64) -> i16 {
        let full = f64::from(i16::MAX);
        (volts * full / AIO_FULL_SCALE).round().clamp(-full, full) as i16
    }

    /// The SII of the terminal.
    pub fn sii(serial: u32) -> SiiSpec {
        let word = |index: u16| PdoEntry {
            index,
            subindex: 0x11,
            bits: 16,
        };
        SiiSpec {
            identity: Identity {
                vendor: BECKHOFF_VENDOR_ID,
                product: AIO_PRODUCT_CODE,
                revision: 0x0010_0000,
                serial,
            },
            order: "EL4374",
            name: "EL4374 2Ch. Ana. In/Out +/-10V (emulated)",
            mailbox_protocols: 0,
            coe_details: 0,
            fmmus: vec![FmmuUsage::Outputs, FmmuUsage::Inputs],
            sync_managers: vec![
                SmSpec {
                    start: 0x1000,
                    length: 4,
                    control: 0x64,
                    kind: SmType::Outputs,
                },
                SmSpec {
                    start: 0x1100,
                    length: 4,
                    control: 0x20,
                    kind: SmType::Inputs,
                },
            ],
            tx_pdos: (0..2u16)
                .map(|ch| PdoSpec {
                    index: 0x1A00 + ch,
                    sync_manager: 1,
                    entries: vec![word(0x6000 + 0x10 * ch)],
                })
                .collect(),
            rx_pdos: (0..2u16)
                .map(|ch| PdoSpec {
                    index: 0x1600 + ch,
                    sync_manager: 0,
                    entries: vec![word(0x7000 + 0x10 * ch)],
                })
                .collect(),
        }
    }

    fn cycle(&mut self, outputs: &[u8], inputs: &mut [u8], op: bool) {
        for (c, out) in self.outputs.iter_mut().enumerate() {
            let w = outputs
                .get(2 * c..2 * c + 2)
                .map_or(0, |b| i16::from_le_bytes([b[0], b[1]]));
            // Outside OP the outputs are in their safe state (0 V).
            *out = if op { w } else { 0 };
        }
        let words = if self.loopback {
            self.outputs
        } else {
            self.inputs
        };
        for (c, w) in words.iter().enumerate() {
            if let Some(dst) = inputs.get_mut(2 * c..2 * c + 2) {
                dst.copy_from_slice(&w.to_le_bytes());
            }
        }
    }
}

/// Product code of the encoder terminal: that of an EL5101 (incremental encoder interface),
/// (5101 << 16) | 0x3052.
pub const ENC_PRODUCT_CODE: u32 = 0x13ED_3052;

/// The encoder terminal: 6 input bytes (SM0 at 0x1000): the status word 0x6000:01 (16 bit,
/// always 0 here) and the counter value 0x6000:11 (UINT32), little-endian, in one TxPDO
/// 0x1A00 (the EL5101's newer layout keeps the status as single bits 0x6000:01..10; the
/// emulation presents them as one word). No outputs (an EL5101's control word and set counter
/// value are not emulated). The counter counts `velocity` increments per second from the
/// first exchange, modulo 2^32.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct EncoderTerminal {
    /// Increments per second.
    pub velocity: i64,
    /// The counter value of the last exchange.
    pub count: u32,
    first_ns: Option<u64>,
}

impl EncoderTerminal {
    /// A terminal counting `velocity` increments per second from its first exchange.
    pub fn new(velocity: i64) -> Self {
        Self {
            velocity,
            ..Self::default()
        }
    }

    /// The SII of the terminal.
    pub fn sii(serial: u32) -> SiiSpec {
        SiiSpec {
            identity: Identity {
                vendor: BECKHOFF_VENDOR_ID,
                product: ENC_PRODUCT_CODE,
                revision: 0x0010_0000,
                serial,
            },
            order: "EL5101",
            name: "EL5101 1Ch. Enc. Interface (emulated)",
            mailbox_protocols: 0,
            coe_details: 0,
            fmmus: vec![FmmuUsage::Inputs],
            sync_managers: vec![SmSpec {
                start: 0x1000,
                length: 6,
                control: 0x20,
                kind: SmType::Inputs,
            }],
            tx_pdos: vec![PdoSpec {
                index: 0x1A00,
                sync_manager: 0,
                entries: vec![
                    PdoEntry {
                        index: 0x6000,
                        subindex: 0x01,
                        bits: 16,
                    },
                    PdoEntry {
                        index: 0x6000,
                        subindex: 0x11,
                        bits: 32,
                    },
                ],
            }],
            rx_pdos: Vec::new(),
        }
    }

    /// The count at `now_ns`: `velocity` · (time since the first exchange), modulo 2^32.
    fn cycle(&mut self, inputs: &mut [u8], now_ns: u64) {
        let first = *self.first_ns.get_or_insert(now_ns);
        let dt = i128::from(now_ns.saturating_sub(first));
        let counts = i128::from(self.velocity) * dt / 1_000_000_000;
        // Modulo 2^32: the register wraps.
        self.count = counts as u32;
        for (dst, src) in inputs
            .iter_mut()
            .zip([0u8, 0].into_iter().chain(self.count.to_le_bytes()))
        {
            *dst = src;
        }
    }
}

/// The CiA 402 servo drive: object dictionary, PDO image and the simulated drive behind it.
#[derive(Clone, Debug)]
pub struct Cia402Drive {
    /// The object dictionary (process objects carry the last exchanged values).
    pub od: ObjectDictionary,
    /// The simulated drive.
    pub servo: SimServo,
    rx_layout: Vec<PdoEntry>,
    tx_layout: Vec<PdoEntry>,
    last_ns: Option<u64>,
}

/// The drive's default RxPDO 0x1600 mapping (controlword, modes of operation, target
/// position, touch probe function: a CSP set as in the reference's typical mapping).
const RX_DEFAULT: [u32; 4] = [0x6040_0010, 0x6060_0008, 0x607A_0020, 0x60B8_0010];
/// The drive's default TxPDO 0x1A00 mapping.
const TX_DEFAULT: [u32; 7] = [
    0x6041_0010,
    0x6061_0008,
    0x6064_0020,
    0x606C_0020,
    0x60B9_0010,
    0x60BA_0020,
    0x60BB_0020,
];
/// Entries a PDO mapping object holds.
const MAPPING_CAPACITY: u8 = 8;

impl Cia402Drive {
    /// The SII of the drive: mailbox SM0 0x1000 / SM1 0x1080 (128 bytes each), outputs SM2
    /// 0x1100, inputs SM3 0x1180.
    pub fn sii(serial: u32) -> SiiSpec {
        let entries = |list: &[u32]| {
            list.iter()
                .map(|&raw| PdoEntry {
                    index: (raw >> 16) as u16,
                    subindex: (raw >> 8) as u8,
                    bits: raw as u8,
                })
                .collect::<Vec<_>>()
        };
        let bytes = |list: &[u32]| list.iter().map(|raw| u16::from(*raw as u8) / 8).sum();
        SiiSpec {
            identity: Identity {
                vendor: DRIVE_VENDOR_ID,
                product: DRIVE_PRODUCT_CODE,
                revision: 0x0001_0000,
                serial,
            },
            order: "TSD-402",
            name: "tandem CiA 402 servo drive (emulated)",
            mailbox_protocols: 0x04,
            coe_details: 0x0D,
            fmmus: vec![
                FmmuUsage::Outputs,
                FmmuUsage::Inputs,
                FmmuUsage::SyncManagerStatus,
            ],
            sync_managers: vec![
                SmSpec {
                    start: 0x1000,
                    length: 128,
                    control: 0x26,
                    kind: SmType::MailboxOut,
                },
                SmSpec {
                    start: 0x1080,
                    length: 128,
                    control: 0x22,
                    kind: SmType::MailboxIn,
                },
                SmSpec {
                    start: 0x1100,
                    length: bytes(&RX_DEFAULT),
                    control: 0x64,
                    kind: SmType::Outputs,
                },
                SmSpec {
                    start: 0x1180,
                    length: bytes(&TX_DEFAULT),
                    control: 0x20,
                    kind: SmType::Inputs,
                },
            ],
            tx_pdos: vec![PdoSpec {
                index: 0x1A00,
                sync_manager: 3,
                entries: entries(&TX_DEFAULT),
            }],
            rx_pdos: vec![PdoSpec {
                index: 0x1600,
                sync_manager: 2,
                entries: entries(&RX_DEFAULT),
            }],
        }
    }

    /// A drive with the given identity, its model parameterised for `cycle_ns`.
    pub fn new(identity: Identity, cycle_ns: i64) -> Option<Self> {
        let servo = SimServo::new(ServoParams::example(cycle_ns)).ok()?;
        Some(Self {
            od: ObjectDictionary::new(dictionary(identity)),
            servo,
            rx_layout: Vec::new(),
            tx_layout: Vec::new(),
            last_ns: None,
        })
    }

    /// The process image sizes (outputs, inputs) in bytes of the assigned PDOs.
    pub fn image_sizes(&self) -> (usize, usize) {
        let size = |assign| {
            let bits: usize = self
                .od
                .assigned_entries(assign)
                .iter()
                .map(|e| usize::from(e.bits))
                .sum();
            bits.div_ceil(8)
        };
        (size(0x1C12), size(0x1C13))
    }

    /// Takes over the PDO assignment (at PRE-OP → SAFE-OP).
    fn prepare(&mut self) {
        self.rx_layout = self.od.assigned_entries(0x1C12);
        self.tx_layout = self.od.assigned_entries(0x1C13);
        self.last_ns = None;
    }

    /// One process data exchange: outputs into the object dictionary (OP only), the drive
    /// model advanced to `now_ns` and stepped with the command, its feedback into the inputs.
    fn cycle(&mut self, outputs: &[u8], inputs: &mut [u8], op: bool, now_ns: u64) {
        if op {
            let mut offset = 0;
            for e in &self.rx_layout {
                let n = usize::from(e.bits / 8);
                let mut le = [0u8; 4];
                if let (Some(dst), Some(src)) = (le.get_mut(..n), outputs.get(offset..offset + n)) {
                    dst.copy_from_slice(src);
                }
                self.od
                    .set_value(e.index, e.subindex, u32::from_le_bytes(le));
                offset += n;
            }
        }
        let dt = self
            .last_ns
            .map_or(0, |last| now_ns.saturating_sub(last).min(MAX_STEP_NS));
        self.last_ns = Some(now_ns);
        self.servo.advance(dt as i64);
        let od = &self.od;
        let command = DriveCommand {
            // Outside OP the outputs are not valid: the drive sees "disable voltage".
            controlword: if op { od.value(0x6040, 0) as u16 } else { 0 },
            mode: od.value(0x6060, 0) as i8,
            target_position: od.value(0x607A, 0) as i32,
            target_velocity: od.value(0x60FF, 0) as i32,
            target_torque: od.value(0x6071, 0) as i16,
            velocity_offset: od.value(0x60B1, 0) as i32,
            torque_offset: od.value(0x60B2, 0) as i16,
            max_torque: od.value(0x6072, 0) as u16,
            positive_torque_limit: od.value(0x60E0, 0) as u16,
            negative_torque_limit: od.value(0x60E1, 0) as u16,
            touch_probe_function: od.value(0x60B8, 0) as u16,
        };
        self.servo.exchange(&command);
        let fb = self.servo.feedback();
        for (index, raw) in [
            (0x603F, u32::from(fb.error_code)),
            (0x6041, u32::from(fb.statusword)),
            (0x6061, fb.mode_display as u8 as u32),
            (0x6064, fb.position_actual as u32),
            (0x606C, fb.velocity_actual as u32),
            (0x6077, fb.torque_actual as u16 as u32),
            (0x60F4, fb.following_error as u32),
            (0x60FD, fb.digital_inputs),
            (0x60B9, u32::from(fb.touch_probe_status)),
            (0x60BA, fb.touch_probe_1_positive as u32),
            (0x60BB, fb.touch_probe_1_negative as u32),
            (0x60BC, fb.touch_probe_2_positive as u32),
            (0x60BD, fb.touch_probe_2_negative as u32),
        ] {
            self.od.set_value(index, 0, raw);
        }
        let mut offset = 0;
        for e in &self.tx_layout {
            let n = usize::from(e.bits / 8);
            let le = self.od.value(e.index, e.subindex).to_le_bytes();
            if let (Some(dst), Some(src)) = (inputs.get_mut(offset..offset + n), le.get(..n)) {
                dst.copy_from_slice(src);
            }
            offset += n;
        }
    }
}

/// The drive's object dictionary.
fn dictionary(id: Identity) -> Vec<Entry> {
    use Access::{ReadOnly as Ro, ReadWrite as Rw, ReadWritePreOp as Pre};
    let mut d = vec![
        Entry::number(0x1000, 0, 4, DRIVE_DEVICE_TYPE, Ro),
        Entry::string(0x1008, 0, "TSD-402"),
        Entry::string(0x100A, 0, "0.1.0"),
        Entry::number(0x1018, 0, 1, 4, Ro),
        Entry::number(0x1018, 1, 4, id.vendor, Ro),
        Entry::number(0x1018, 2, 4, id.product, Ro),
        Entry::number(0x1018, 3, 4, id.revision, Ro),
        Entry::number(0x1018, 4, 4, id.serial, Ro),
        Entry::number(0x1C12, 0, 1, 1, Pre),
        Entry::number(0x1C12, 1, 2, 0x1600, Pre),
        Entry::number(0x1C13, 0, 1, 1, Pre),
        Entry::number(0x1C13, 1, 2, 0x1A00, Pre),
        Entry::number(0x1600, 0, 1, RX_DEFAULT.len() as u32, Pre),
        Entry::number(0x1A00, 0, 1, TX_DEFAULT.len() as u32, Pre),
    ];
    for sub in 1..=MAPPING_CAPACITY {
        let k = usize::from(sub - 1);
        d.push(Entry::number(
            0x1600,
            sub,
            4,
            RX_DEFAULT.get(k).copied().unwrap_or(0),
            Pre,
        ));
        d.push(Entry::number(
            0x1A00,
            sub,
            4,
            TX_DEFAULT.get(k).copied().unwrap_or(0),
            Pre,
        ));
    }
    let rx = |index, size| Entry::number(index, 0, size, 0, Rw).mappable(Mappable::Rx);
    let tx = |index, size| Entry::number(index, 0, size, 0, Ro).mappable(Mappable::Tx);
    d.extend([
        tx(0x603F, 2),
        rx(0x6040, 2),
        tx(0x6041, 2),
        rx(0x6060, 1),
        tx(0x6061, 1),
        tx(0x6064, 4),
        tx(0x606C, 4),
        rx(0x6071, 2),
        rx(0x6072, 2),
        tx(0x6077, 2),
        rx(0x607A, 4),
        rx(0x60B1, 4),
        rx(0x60B2, 2),
        rx(0x60B8, 2),
        tx(0x60B9, 2),
        tx(0x60BA, 4),
        tx(0x60BB, 4),
        tx(0x60BC, 4),
        tx(0x60BD, 4),
        rx(0x60E0, 2),
        rx(0x60E1, 2),
        tx(0x60F4, 4),
        tx(0x60FD, 4),
        rx(0x60FF, 4),
    ]);
    d
}

/// The device model behind an ESC.
#[derive(Clone, Debug)]
pub enum Model {
    /// A digital I/O terminal.
    DigitalIo(DigitalIo),
    /// An analog I/O terminal.
    AnalogIo(AnalogIo),
    /// An encoder terminal.
    Encoder(EncoderTerminal),
    /// A CiA 402 drive.
    Drive(Box<Cia402Drive>),
}

impl Model {
    /// The object dictionary, for devices with CoE.
    pub fn od_mut(&mut self) -> Option<&mut ObjectDictionary> {
        match self {
            Self::DigitalIo(_) | Self::AnalogIo(_) | Self::Encoder(_) => None,
            Self::Drive(d) => Some(&mut d.od),
        }
    }

    /// The process image sizes (outputs, inputs) the device expects, bytes.
    pub fn image_sizes(&self) -> (usize, usize) {
        match self {
            Self::DigitalIo(_) => (1, 1),
            Self::AnalogIo(_) => (4, 4),
            Self::Encoder(_) => (0, 6),
            Self::Drive(d) => d.image_sizes(),
        }
    }

    /// PRE-OP → SAFE-OP accepted: take over the PDO configuration.
    pub(crate) fn prepare(&mut self) {
        if let Self::Drive(d) = self {
            d.prepare();
        }
    }

    /// One process data exchange.
    pub(crate) fn cycle(&mut self, outputs: &[u8], inputs: &mut [u8], op: bool, now_ns: u64) {
        match self {
            Self::DigitalIo(d) => d.cycle(outputs, inputs, op),
            Self::AnalogIo(d) => d.cycle(outputs, inputs, op),
            Self::Encoder(d) => d.cycle(inputs, now_ns),
            Self::Drive(d) => d.cycle(outputs, inputs, op, now_ns),
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn the_analog_words_are_the_signed_16_bit_codes_of_plus_minus_10_v() {
        assert_eq!(AnalogIo::code(2.5), 8192);
        assert_eq!(AnalogIo::code(1.0), 3277);
        assert_eq!(AnalogIo::code(10.0), 0x7FFF);
        assert_eq!(AnalogIo::code(-10.0), -0x7FFF);
        assert_eq!(AnalogIo::code(12.0), 0x7FFF, "clamped to full scale");
    }

    #[test]
    fn the_analog_terminal_loops_its_outputs_back_in_op_only() {
        let mut t = AnalogIo {
            loopback: true,
            ..AnalogIo::default()
        };
        let out = [0x00, 0x20, 0x01, 0x80];
        let mut inp = [0u8; 4];
        t.cycle(&out, &mut inp, false);
        assert_eq!(inp, [0; 4], "SAFE-OP: 0 V on the outputs");
        t.cycle(&out, &mut inp, true);
        assert_eq!(t.outputs, [8192, -32767]);
        assert_eq!(inp, out);
        let mut fixed = AnalogIo {
            inputs: [AnalogIo::code(-2.5), 5],
            ..AnalogIo::default()
        };
        fixed.cycle(&out, &mut inp, true);
        assert_eq!(inp, [0x00, 0xE0, 0x05, 0x00]);
    }

    #[test]
    fn the_encoder_terminal_counts_its_velocity_from_the_first_exchange_modulo_2_32() {
        let mut e = EncoderTerminal {
            velocity: 500_000,
            ..EncoderTerminal::default()
        };
        let mut inp = [0xFFu8; 6];
        e.cycle(&mut inp, 7_000_000_000);
        assert_eq!(inp, [0; 6]);
        e.cycle(&mut inp, 7_002_000_000);
        assert_eq!(e.count, 1000);
        assert_eq!(inp, [0, 0, 0xE8, 0x03, 0, 0]);
        let mut back = EncoderTerminal {
            velocity: -1000,
            ..EncoderTerminal::default()
        };
        back.cycle(&mut inp, 0);
        back.cycle(&mut inp, 1_000_000);
        assert_eq!(back.count, u32::MAX, "-1 wraps");
        let sii = EncoderTerminal::sii(1);
        assert_eq!(sii.identity.product, 0x13ED_3052);
        assert_eq!(sii.sync_manager(SmType::Inputs).unwrap().1.length, 6);
        assert!(sii.sync_manager(SmType::Outputs).is_none());
    }

    #[test]
    fn the_analog_terminal_describes_two_words_each_way_in_its_sii() {
        let sii = AnalogIo::sii(3);
        assert_eq!(sii.identity.vendor, BECKHOFF_VENDOR_ID);
        assert_eq!(sii.identity.product, 0x1116_3052);
        let bits = |p: &[PdoSpec]| -> u32 {
            p.iter()
                .flat_map(|p| p.entries.iter())
                .map(|e| u32::from(e.bits))
                .sum()
        };
        assert_eq!((bits(&sii.rx_pdos), bits(&sii.tx_pdos)), (32, 32));
        assert_eq!(sii.sync_manager(SmType::Outputs).unwrap().1.length, 4);
        assert_eq!(sii.sync_manager(SmType::Inputs).unwrap().1.length, 4);
    }
}
