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
    /// A device kind in `--devices` is not `drive` or `dio`.
    UnknownDevice,
    /// `--cycle-us` is not a positive integer.
    BadCycle,
}

impl fmt::Display for UsageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoInterface => f.write_str("--interface <name> is required"),
            Self::MissingValue { option } => write!(f, "{option} needs a value"),
            Self::UnknownOption => f.write_str("unknown option"),
            Self::UnknownDevice => {
                f.write_str("--devices takes a comma-separated list of `drive`, `dio`")
            }
            Self::BadCycle => f.write_str("--cycle-us takes a positive integer"),
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
pub const USAGE: &str = "usage: tandem-ecat-sim --interface <name> [--devices drive,dio,...] [--cycle-us <n>] [--loopback]";

/// What the emulator runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// The network interface.
    pub interface: String,
    /// The devices in bus order.
    pub devices: Vec<DeviceKind>,
    /// Device behaviour.
    pub device: DeviceOptions,
}

impl Options {
    /// Parses `--interface`, `--devices` (default `drive,dio`), `--cycle-us` (default 1000)
    /// and `--loopback` (digital outputs read back on the inputs).
    pub fn parse(args: &[String]) -> Result<Self, UsageError> {
        let mut interface = None;
        let mut devices = vec![DeviceKind::Cia402Drive, DeviceKind::DigitalIo];
        let mut device = DeviceOptions::default();
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
                "--loopback" => device.dio_loopback = true,
                _ => return Err(UsageError::UnknownOption),
            }
        }
        Ok(Self {
            interface: interface.ok_or(UsageError::NoInterface)?,
            devices,
            device,
        })
    }
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
        if segment.process_frame(frame, monotonic_ns()).is_ok() {
            socket.send(frame)?;
        }
    }
}
