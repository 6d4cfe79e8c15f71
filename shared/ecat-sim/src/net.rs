//! The segment on a network interface: an AF_PACKET raw socket bound to the interface and
//! EtherType 0x88A4; every EtherCAT frame received from the MainDevice goes through the
//! [`Segment`] and is sent back with the locally administered bit of its source MAC set, as
//! a real segment returns it (Beckhoff ESC Section I, frame processing). Frames the socket
//! sees going out (its own replies) are skipped.
//!
//! The only unsafe code of this crate: the socket calls of `libc`, each block saying why it
//! is sound.
#![allow(unsafe_code)]

use core::fmt;
use std::ffi::CString;
use std::io;

use crate::device::{DeviceKind, DeviceOptions};
use crate::esc::AlState;
use crate::segment::{Segment, ETHERTYPE_ETHERCAT};

/// Why the emulator stopped or could not start.
#[derive(Debug)]
pub enum RunError {
    /// A command-line argument is wrong.
    Usage(UsageError),
    /// The interface does not exist.
    NoInterface,
    /// A socket call failed.
    Socket {
        /// Which call.
        call: &'static str,
        /// The OS error.
        source: io::Error,
    },
    /// The segment could not be built.
    Segment(crate::esc::EscError),
}

/// What is wrong with the command line.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum UsageError {
    /// `--interface` is missing.
    NoInterface,
    /// An option needs a value.
    MissingValue {
        /// The option.
        option: &'static str,
    },
    /// An option is not known.
    UnknownOption,
    /// A device kind in `--devices` is not `drive`, `dio`, `aio` or `enc`.
    UnknownDevice,
    /// `--encoder-velocity` is not an integer.
    BadEncoderVelocity,
    /// `--analog-in` is not `CH=VOLTS` with channel 1 or 2 and volts within ±10.
    BadAnalogIn,
    /// `--cycle-us` is not a positive integer.
    BadCycle,
    /// `--drop` is not a share between 0 and 1.
    BadDrop,
    /// `--seed` is not an unsigned integer.
    BadSeed,
}

impl fmt::Display for UsageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoInterface => f.write_str("--interface <name> is required"),
            Self::MissingValue { option } => write!(f, "{option} needs a value"),
            Self::UnknownOption => f.write_str("unknown option"),
            Self::UnknownDevice => f.write_str(
                "--devices takes a comma-separated list of `drive`, `dio`, `aio`, `enc`",
            ),
            Self::BadEncoderVelocity => {
                f.write_str("--encoder-velocity takes increments per second (an integer)")
            }
            Self::BadAnalogIn => {
                f.write_str("--analog-in takes CH=VOLTS: channel 1 or 2, a voltage from -10 to 10")
            }
            Self::BadCycle => f.write_str("--cycle-us takes a positive integer"),
            Self::BadDrop => f.write_str("--drop takes a share of frames from 0 to 1 (0.01: 1 %)"),
            Self::BadSeed => f.write_str("--seed takes an unsigned 64-bit integer"),
        }
    }
}

impl std::error::Error for UsageError {}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Usage(e) => write!(f, "{e}\n{USAGE}"),
            Self::NoInterface => f.write_str("no such network interface"),
            Self::Socket { call, source } => write!(f, "{call}: {source}"),
            Self::Segment(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for RunError {}

/// The command line.
pub const USAGE: &str = "usage: tandem-ecat-sim --interface <name> [--devices drive,dio,aio,enc,...] [--cycle-us <n>] [--loopback] [--analog-in CH=VOLTS]... [--encoder-velocity <inc/s>] [--drop <share> [--seed <n>] [--drop-log <file>]]";

/// What the emulator runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// The network interface.
    pub interface: String,
    /// The devices in bus order.
    pub devices: Vec<DeviceKind>,
    /// Device behaviour.
    pub device: DeviceOptions,
    /// The share of frames dropped once every SubDevice is in OP (`--drop`), and the seed of
    /// the choice (`--seed`, default 1).
    pub drop: Option<FrameDrop>,
    /// A file that gets one line per dropped frame (`--drop-log`).
    pub drop_log: Option<String>,
}

/// A reproducible choice of the frames a faulty segment drops: a given share of them, chosen
/// by SplitMix64 from a fixed seed (the same seed drops the same frames of the same sequence).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FrameDrop {
    /// The share of frames dropped, 0 to 1.
    pub share: f64,
    /// The generator's seed.
    pub seed: u64,
    state: u64,
}

impl FrameDrop {
    /// Drops `share` (0 to 1) of the frames, chosen from `seed`.
    pub fn new(share: f64, seed: u64) -> Result<Self, UsageError> {
        if !(0.0..=1.0).contains(&share) {
            return Err(UsageError::BadDrop);
        }
        Ok(Self {
            share,
            seed,
            state: seed,
        })
    }

    /// Whether the next frame is dropped.
    pub fn next_dropped(&mut self) -> bool {
        // SplitMix64 (Steele, Lea, Flood: "Fast splittable pseudorandom number generators").
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        // The top 53 bits as a uniform value in [0, 1).
        ((z >> 11) as f64) * (1.0 / (1u64 << 53) as f64) < self.share
    }
}

impl Options {
    /// Parses `--interface`, `--devices` (default `drive,dio`), `--cycle-us` (default 1000),
    /// `--loopback` (digital and analog outputs read back on the inputs), `--analog-in
    /// CH=VOLTS` (an analog input's reading, repeatable), `--drop <share>` with `--seed
    /// <n>` (default 1) and `--drop-log <file>`.
    pub fn parse(args: &[String]) -> Result<Self, UsageError> {
        let mut interface = None;
        let mut devices = vec![DeviceKind::Cia402Drive, DeviceKind::DigitalIo];
        let mut device = DeviceOptions::default();
        let (mut share, mut seed, mut drop_log) = (None, 1u64, None);
        let mut it = args.iter();
        while let Some(arg) = it.next() {
            let mut value = |option| it.next().ok_or(UsageError::MissingValue { option });
            match arg.as_str() {
                "--interface" => interface = Some(value("--interface")?.clone()),
                "--devices" => {
                    devices = value("--devices")?
                        .split(',')
                        .map(|d| d.trim().parse().map_err(|_| UsageError::UnknownDevice))
                        .collect::<Result<_, _>>()?;
                }
                "--cycle-us" => {
                    let us: i64 = value("--cycle-us")?
                        .parse()
                        .map_err(|_| UsageError::BadCycle)?;
                    if us <= 0 {
                        return Err(UsageError::BadCycle);
                    }
                    device.cycle_ns = us.saturating_mul(1000);
                }
                "--loopback" => {
                    device.dio_loopback = true;
                    device.aio_loopback = true;
                }
                "--encoder-velocity" => {
                    device.encoder_velocity = value("--encoder-velocity")?
                        .parse()
                        .map_err(|_| UsageError::BadEncoderVelocity)?;
                }
                "--analog-in" => {
                    let (c, code) = analog_in(value("--analog-in")?)?;
                    device.analog_in[c] = code;
                }
                "--drop" => {
                    let v: f64 = value("--drop")?.parse().map_err(|_| UsageError::BadDrop)?;
                    share = Some(v);
                }
                "--seed" => seed = value("--seed")?.parse().map_err(|_| UsageError::BadSeed)?,
                "--drop-log" => drop_log = Some(value("--drop-log")?.clone()),
                _ => return Err(UsageError::UnknownOption),
            }
        }
        Ok(Self {
            interface: interface.ok_or(UsageError::NoInterface)?,
            devices,
            device,
            drop: share.map(|s| FrameDrop::new(s, seed)).transpose()?,
            drop_log,
        })
    }
}

/// `CH=VOLTS` of `--analog-in`: the channel's index (0 or 1) and the 16-bit code of the
/// voltage (0x7FFF = +10 V).
fn analog_in(arg: &str) -> Result<(usize, i16), UsageError> {
    let (ch, volts) = arg.split_once('=').ok_or(UsageError::BadAnalogIn)?;
    let c = match ch.trim() {
        "1" => 0,
        "2" => 1,
        _ => return Err(UsageError::BadAnalogIn),
    };
    let v: f64 = volts.trim().parse().map_err(|_| UsageError::BadAnalogIn)?;
    if !(v.is_finite() && v.abs() <= crate::device::AIO_FULL_SCALE) {
        return Err(UsageError::BadAnalogIn);
    }
    Ok((c, crate::device::AnalogIo::code(v)))
}

/// CLOCK_MONOTONIC in ns: the ESCs' local clock (the same clock ethercrab's `ethercat_now`
/// reads, so DC offsets stay small).
pub fn monotonic_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_MONOTONIC always exists on Linux.
    unsafe {
        libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts);
    }
    (ts.tv_sec as u64)
        .wrapping_mul(1_000_000_000)
        .wrapping_add(ts.tv_nsec as u64)
}

/// An AF_PACKET raw socket bound to one interface and EtherType 0x88A4.
#[derive(Debug)]
pub struct RawSocket {
    fd: libc::c_int,
}

impl RawSocket {
    /// Opens and binds the socket (needs CAP_NET_RAW).
    pub fn open(interface: &str) -> Result<Self, RunError> {
        let name = CString::new(interface).map_err(|_| RunError::NoInterface)?;
        // SAFETY: `name` is a valid NUL-terminated string that outlives the call.
        let index = unsafe { libc::if_nametoindex(name.as_ptr()) };
        if index == 0 {
            return Err(RunError::NoInterface);
        }
        let protocol = ETHERTYPE_ETHERCAT.to_be();
        // SAFETY: plain socket(2) call with constant arguments; the result is checked.
        let fd =
            unsafe { libc::socket(libc::AF_PACKET, libc::SOCK_RAW, libc::c_int::from(protocol)) };
        if fd < 0 {
            return Err(os_error("socket"));
        }
        let socket = Self { fd };
        // SAFETY: sockaddr_ll is plain old data; all-zero is a valid value.
        let mut addr: libc::sockaddr_ll = unsafe { core::mem::zeroed() };
        addr.sll_family = libc::AF_PACKET as u16;
        addr.sll_protocol = protocol;
        addr.sll_ifindex = index as i32;
        // SAFETY: `addr` is a valid sockaddr_ll and the length passed is its size.
        let rc = unsafe {
            libc::bind(
                socket.fd,
                (&addr as *const libc::sockaddr_ll).cast(),
                core::mem::size_of::<libc::sockaddr_ll>() as libc::socklen_t,
            )
        };
        if rc < 0 {
            return Err(os_error("bind"));
        }
        Ok(socket)
    }

    /// Receives one frame into `buf`; returns its length and whether the socket saw it going
    /// out (its own transmission).
    pub fn recv(&self, buf: &mut [u8]) -> Result<(usize, bool), RunError> {
        // SAFETY: sockaddr_ll is plain old data; all-zero is a valid value.
        let mut from: libc::sockaddr_ll = unsafe { core::mem::zeroed() };
        let mut len = core::mem::size_of::<libc::sockaddr_ll>() as libc::socklen_t;
        // SAFETY: `buf` is valid for writes of `buf.len()` bytes, `from`/`len` describe a
        // writable sockaddr_ll; the kernel writes at most those sizes.
        let n = unsafe {
            libc::recvfrom(
                self.fd,
                buf.as_mut_ptr().cast(),
                buf.len(),
                0,
                (&mut from as *mut libc::sockaddr_ll).cast(),
                &mut len,
            )
        };
        if n < 0 {
            return Err(os_error("recvfrom"));
        }
        Ok((n as usize, from.sll_pkttype == libc::PACKET_OUTGOING))
    }

    /// Sends one frame on the bound interface.
    pub fn send(&self, frame: &[u8]) -> Result<(), RunError> {
        // SAFETY: `frame` is valid for reads of `frame.len()` bytes.
        let n = unsafe { libc::send(self.fd, frame.as_ptr().cast(), frame.len(), 0) };
        if n < 0 {
            return Err(os_error("send"));
        }
        Ok(())
    }
}

impl Drop for RawSocket {
    fn drop(&mut self) {
        // SAFETY: `fd` is a socket this value owns and nothing uses it after the drop.
        unsafe {
            libc::close(self.fd);
        }
    }
}

fn os_error(call: &'static str) -> RunError {
    RunError::Socket {
        call,
        source: io::Error::last_os_error(),
    }
}

/// Runs the emulator until a socket error: parse the arguments (without the program name),
/// build the segment, answer every EtherCAT frame.
pub fn run(args: &[String]) -> Result<(), RunError> {
    let options = Options::parse(args).map_err(RunError::Usage)?;
    let mut segment = Segment::new(&options.devices, options.device).map_err(RunError::Segment)?;
    let socket = RawSocket::open(&options.interface)?;
    eprintln!(
        "tandem-ecat-sim: {} SubDevice(s) on {}",
        segment.escs().len(),
        options.interface
    );
    let mut buf = vec![0u8; 9216];
    let mut drop = options.drop;
    let mut drop_log = match &options.drop_log {
        Some(path) => Some(
            std::fs::File::create(path).map_err(|source| RunError::Socket {
                call: "create the --drop-log file",
                source,
            })?,
        ),
        None => None,
    };
    let mut dropped = 0u64;
    loop {
        let (n, outgoing) = socket.recv(&mut buf)?;
        // Our own replies (the socket sees its transmissions) and frames already passed by
        // a segment (locally administered bit set) are not for us.
        if outgoing || buf.get(6).is_some_and(|b| b & 0x02 != 0) {
            continue;
        }
        let Some(frame) = buf.get_mut(..n) else {
            continue;
        };
        // Frames are dropped once every SubDevice is in OP: the start-up, whose frames
        // ethercrab does not repeat, completes (inferred: a test of a running segment).
        let in_op = segment.escs().iter().all(|e| e.al_state() == AlState::Op);
        if in_op && drop.as_mut().is_some_and(FrameDrop::next_dropped) {
            dropped += 1;
            if let Some(f) = drop_log.as_mut() {
                use std::io::Write;
                writeln!(f, "dropped frame {dropped}").map_err(|source| RunError::Socket {
                    call: "write the --drop-log file",
                    source,
                })?;
            }
            continue;
        }
        if segment.process_frame(frame, monotonic_ns()).is_ok() {
            socket.send(frame)?;
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;

    fn args(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    #[test]
    fn drop_and_seed_are_parsed_and_refused_out_of_range() {
        let o = Options::parse(&args("--interface ecs --drop 0.01 --seed 7")).unwrap();
        assert_eq!(o.drop, Some(FrameDrop::new(0.01, 7).unwrap()));
        let o = Options::parse(&args("--interface ecs --drop 0.5")).unwrap();
        assert_eq!(o.drop.unwrap().seed, 1);
        assert_eq!(Options::parse(&args("--interface ecs")).unwrap().drop, None);
        for bad in ["--drop 1.5", "--drop -0.1", "--drop x", "--drop NaN"] {
            assert_eq!(
                Options::parse(&args(&format!("--interface ecs {bad}"))),
                Err(UsageError::BadDrop),
                "{bad}"
            );
        }
        assert_eq!(
            Options::parse(&args("--interface ecs --drop 0.1 --seed -1")),
            Err(UsageError::BadSeed)
        );
    }

    #[test]
    fn the_same_seed_drops_the_same_frames_at_the_given_share() {
        let run = |share, seed| {
            let mut d = FrameDrop::new(share, seed).unwrap();
            (0..100_000).map(|_| d.next_dropped()).collect::<Vec<_>>()
        };
        let a = run(0.01, 42);
        assert_eq!(a, run(0.01, 42));
        assert_ne!(a, run(0.01, 43));
        let n = a.iter().filter(|d| **d).count();
        // Binomial(100 000, 0.01): mean 1000, standard deviation 31.5; 4 sigma either side.
        assert!((874..=1126).contains(&n), "{n}");
        assert!(run(0.0, 1).iter().all(|d| !d));
        assert!(run(1.0, 1).iter().all(|d| *d));
    }
}
