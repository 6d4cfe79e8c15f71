//! The node's EtherCAT segment (`[[ethercat]]`, docs/ethercat.md): an adapter at the edge
//! between unmodified `ethercrab` 0.7.1 and the executive's external drives.
//!
//! At start, [`open`] runs the MainDevice on a thread of its own ("ethercat", with ethercrab's
//! TX/RX loop on "ethercat-io"): it finds the SubDevices, compares them position by position
//! with the cell file (the first mismatch refuses the start), reads each CiA 402 drive's
//! assigned PDO mapping over CoE (0x1C12/0x1C13, then 0x16xx/0x1Axx), brings the segment to
//! OP and waits for exchanges.
//!
//! Each cycle at `t`, before the step, the cyclic thread calls [`Link::exchange`]: it takes
//! the process image back from the exchange it handed over at `t - cycle`, puts each drive's
//! TxPDO into the executive, writes the RxPDO the step at `t - cycle` computed and hands the
//! image to the "ethercat" thread, which runs one LRW (`SubDeviceGroup::tx_rx`) at once. The
//! image moves between the two threads through two bounded channels (no lock, no allocation,
//! no wait on the cyclic thread).
//!
//! The "ethercat" thread gives each exchange it attempted a [`Verdict`]: complete, or a miss
//! (the frame went out and no answer came within [`answer_budget_ns`] of it, nothing being left
//! unread in the socket; a short working counter; ethercrab failing the exchange). Frames go
//! out and come in on "ethercat-io" ([`Io`]), which notes when each frame went out. A cycle
//! whose image is not back yet is `ecat_late`: our own threads were late, not the segment, and
//! it never counts as a miss. After [`MISSES_TO_ALARM`] misses in a row each drive on the
//! segment shows a fault with error code [`LOST_CODE`], which its axis takes as alarm 421 with
//! the reaction the drive fault has; the node's other axes carry on. Drives' positions are
//! extrapolated over misses and late cycles until then; a stall of [`LATE_TO_ALARM_NS`] is the
//! same alarm.

use async_io::Async;
use ethercrab::subdevice_group::{self, DcConfiguration};
use ethercrab::{
    DcSync, MainDevice, MainDeviceConfig, PduRx, PduStorage, PduTx, RegisterAddress,
    SubDeviceGroup, SubDeviceRef, Timeouts,
};
use socket::RawSocket;
use std::fmt;
use std::future::Future;
use std::io::Write;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, AtomicI64, AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError, SyncSender, TrySendError};
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::{Duration, Instant};
use tandem_config::{Cell, EthercatIdentity, EthercatRole};
use tandem_motion::plant::cia402::{controlword, DriveCommand, DriveFeedback};
use tandem_runtime::exec::{Executive, Secs};
use tracing::{info, warn};

/// Misses in a row after which the drives on the segment show [`LOST_CODE`]: 3, the bound the
/// EtherCAT issue sets for a lost SubDevice's alarm (inferred: one or two unanswered frames
/// are noise, three in a row a lost segment). Only the "ethercat" thread's verdicts on frames
/// that went out count (see [`Verdict`]); a cycle in which our own threads were late is
/// `ecat_late`, never a miss, so a loaded host cannot raise this alarm on a healthy segment.
pub const MISSES_TO_ALARM: u32 = 3;

/// Late cycles in a row (in ns of the node's time) after which the segment is in alarm all
/// the same: the "ethercat" thread stalled or gone, the drives unsupervised (inferred: twice
/// ethercrab's PDU timeout, after which a frame that never went out fails the exchange).
pub const LATE_TO_ALARM_NS: i64 = 200_000_000;

/// The time a frame's answer has, from the frame going out, before the exchange is a miss:
/// three quarters of the node's cycle, so that the verdict of an exchange handed over at a
/// boundary is back before the next one (inferred: the most a segment can take while its
/// exchange still fits in the cycle; the emulator's round trip on a veth pair is 0.1 to
/// 0.3 ms, a 64-SubDevice line of real ESCs well below 0.1 ms).
fn answer_budget_ns(cycle_ns: u64) -> i64 {
    i64::try_from(cycle_ns / 4 * 3).unwrap_or(i64::MAX)
}

/// The error code 0x603F a drive on a segment that stopped exchanging shows: 0x8130, "life
/// guard error or heartbeat error" of CiA 301's emergency error codes (inferred: the code of a
/// lost cyclic communication closest to a lost EtherCAT exchange).
#[doc(alias = "0x603F")]
pub const LOST_CODE: u16 = 0x8130;

/// Statusword 0x6041 of *fault* (IEC 61800-7-201 (CiA 402) drive profile, 0x6041: xxxx xxxx
/// x0xx 1000).
const FAULT_STATUSWORD: u16 = 0x0008;

/// ethercrab's PDU timeout. Not below the cycle: in ethercrab 0.7.1 a reply arriving after its
/// PDU timed out ends the receive task (and with it the segment), and on a loaded host a reply
/// can take tens of ms (docs/ethercat.md, the emulator's measurements). The cyclic thread never
/// waits for it: an exchange not back by the next cycle is a miss.
const PDU_TIMEOUT: Duration = Duration::from_millis(100);

/// The RxPDO mapping the node writes into a drive's assigned RxPDO (CiA 301 entries: index,
/// subindex, bit length): controlword 0x6040, modes of operation 0x6060, target position
/// 0x607A, velocity offset 0x60B1, touch probe function 0x60B8.
const CSP_RXPDO: [u32; 5] = [
    0x6040_0010,
    0x6060_0008,
    0x607A_0020,
    0x60B1_0020,
    0x60B8_0010,
];

/// Time allowed from opening the interface to OP.
const START_TIMEOUT: Duration = Duration::from_secs(60);

/// The most SubDevices and bytes of process image the node drives on one segment.
const MAX_SUBDEVICES: usize = 64;
const MAX_PDI: usize = 4096;
/// Frames in flight and their size.
const MAX_FRAMES: usize = 16;
static PDU_STORAGE: PduStorage<MAX_FRAMES, { PduStorage::element_size(1100) }> = PduStorage::new();

/// Why the segment could not be started.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum EthercatError {
    /// The interface could not be opened, a thread not started, or ethercrab failed.
    Start {
        /// The interface.
        interface: String,
        /// What failed.
        reason: String,
    },
    /// The bus does not match the cell file at `position`.
    Mismatch {
        /// The interface.
        interface: String,
        /// Bus position (0: the first SubDevice after the MainDevice).
        position: usize,
        /// The SubDevice the cell file expects there (name, identity), if any.
        expected: Option<(String, EthercatIdentity)>,
        /// What the bus has there (its SII name, identity), if anything.
        found: Option<(String, EthercatIdentity)>,
    },
    /// A drive's PDO mapping lacks an object the drive connection needs.
    Mapping {
        /// The SubDevice.
        name: String,
        /// The missing object.
        object: u16,
    },
}

impl fmt::Display for EthercatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Start { interface, reason } => {
                write!(f, "EtherCAT segment on `{interface}`: {reason}")
            }
            Self::Mismatch {
                interface,
                position,
                expected,
                found,
            } => {
                write!(
                    f,
                    "EtherCAT segment on `{interface}` does not match the cell file at position {position}: expected "
                )?;
                match expected {
                    Some((n, id)) => write!(f, "`{n}` ({id})")?,
                    None => f.write_str("no SubDevice")?,
                }
                f.write_str(", found ")?;
                match found {
                    Some((n, id)) => write!(f, "`{n}` ({id})"),
                    None => f.write_str("no SubDevice"),
                }
            }
            Self::Mapping { name, object } => write!(
                f,
                "EtherCAT SubDevice `{name}`: its PDO mapping has no object 0x{object:04X}, which a CiA 402 drive connection needs"
            ),
        }
    }
}

impl std::error::Error for EthercatError {}

/// One mapped object of a PDO: index, byte offset in the SubDevice's image, length in bytes.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
struct Mapped {
    index: u16,
    offset: usize,
    len: usize,
}

/// A PDO mapping entry (CiA 301: index << 16 | subindex << 8 | bit length) as [`Mapped`] at
/// `bit` bits into the image; `None` for an entry that is not whole bytes.
fn mapped(entry: u32, bit: usize) -> Option<Mapped> {
    let bits = (entry & 0xFF) as usize;
    (bits % 8 == 0 && bit % 8 == 0).then_some(Mapped {
        index: (entry >> 16) as u16,
        offset: bit / 8,
        len: bits / 8,
    })
}

/// The PDO mapping of a CiA 402 drive, as read from the drive.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
struct DriveMap {
    rx: Vec<Mapped>,
    tx: Vec<Mapped>,
}

/// The little-endian bytes of `v`'s `len` low bytes into `buf` at `at` (as far as they fit).
fn put(buf: &mut [u8], at: usize, len: usize, v: i64) {
    for (i, b) in v.to_le_bytes().iter().take(len).enumerate() {
        if let Some(x) = buf.get_mut(at + i) {
            *x = *b;
        }
    }
}

/// `len` little-endian bytes of `buf` at `at`, sign-extended when `signed`.
fn get(buf: &[u8], at: usize, len: usize, signed: bool) -> i64 {
    let mut b = [0u8; 8];
    for (i, x) in b.iter_mut().take(len.min(8)).enumerate() {
        *x = buf.get(at + i).copied().unwrap_or(0);
    }
    let v = i64::from_le_bytes(b);
    let shift = 64 - 8 * len.clamp(1, 8) as u32;
    if signed {
        (v << shift) >> shift
    } else {
        v
    }
}

/// The RxPDO of `c` into the drive's output image by its mapping (objects it does not map
/// are not sent; objects it maps that tandem does not write stay 0).
fn encode(map: &DriveMap, c: &DriveCommand, out: &mut [u8]) {
    for m in &map.rx {
        let v = match m.index {
            0x6040 => i64::from(c.controlword),
            0x6060 => i64::from(c.mode),
            0x607A => i64::from(c.target_position),
            0x60FF => i64::from(c.target_velocity),
            0x6071 => i64::from(c.target_torque),
            0x60B1 => i64::from(c.velocity_offset),
            0x60B2 => i64::from(c.torque_offset),
            0x6072 => i64::from(c.max_torque),
            0x60E0 => i64::from(c.positive_torque_limit),
            0x60E1 => i64::from(c.negative_torque_limit),
            0x60B8 => i64::from(c.touch_probe_function),
            _ => 0,
        };
        put(out, m.offset, m.len, v);
    }
}

/// The TxPDO from the drive's input image by its mapping (objects it does not map read 0).
fn decode(map: &DriveMap, input: &[u8]) -> DriveFeedback {
    let mut f = DriveFeedback::default();
    for m in &map.tx {
        let u = get(input, m.offset, m.len, false);
        let s = get(input, m.offset, m.len, true);
        // Truncation to the object's own width is the PDO's encoding.
        match m.index {
            0x6041 => f.statusword = u as u16,
            0x6061 => f.mode_display = s as i8,
            0x6064 => f.position_actual = s as i32,
            0x606C => f.velocity_actual = s as i32,
            0x6077 => f.torque_actual = s as i16,
            0x60F4 => f.following_error = s as i32,
            0x603F => f.error_code = u as u16,
            0x60FD => f.digital_inputs = u as u32,
            0x60B9 => f.touch_probe_status = u as u16,
            0x60BA => f.touch_probe_1_positive = s as i32,
            0x60BB => f.touch_probe_1_negative = s as i32,
            0x60BC => f.touch_probe_2_positive = s as i32,
            0x60BD => f.touch_probe_2_negative = s as i32,
            _ => {}
        }
    }
    f
}

/// What the "ethercat-io" thread saw, for the "ethercat" thread's verdicts and the stop line.
#[derive(Debug, Default)]
struct IoWatch {
    /// Frames sent.
    sent: AtomicU64,
    /// When the last frame went out (cell clock, ns).
    sent_at_ns: AtomicI64,
    /// A frame is being read or handed to ethercrab.
    busy: AtomicBool,
    /// Answers that came after their exchange's verdict (no exchange waits for them).
    stray: AtomicU64,
    /// Frames the socket refused to send.
    send_errors: AtomicU64,
}

/// The raw socket of the segment: AF_PACKET bound to the interface and EtherType 0x88A4. The
/// only unsafe code of the node's EtherCAT adapter: the socket calls of `libc`, each block
/// saying why it is sound.
#[allow(unsafe_code)]
mod socket {

    use std::ffi::CString;
    use std::io;
    use std::os::fd::{AsFd, AsRawFd, BorrowedFd, FromRawFd, OwnedFd};

    /// The EtherCAT EtherType, in network byte order.
    const ETHERTYPE_BE: u16 = 0x88A4u16.to_be();

    /// An AF_PACKET raw socket on one interface, non-blocking.
    #[derive(Debug)]
    pub(super) struct RawSocket {
        fd: OwnedFd,
    }

    impl RawSocket {
        /// Opens the socket on `interface`.
        pub(super) fn open(interface: &str) -> io::Result<Self> {
            let name = CString::new(interface)
                .map_err(|_| io::Error::from(io::ErrorKind::InvalidInput))?;
            // SAFETY: `name` is a NUL-terminated string that lives across the call.
            let index = unsafe { libc::if_nametoindex(name.as_ptr()) };
            if index == 0 {
                return Err(io::Error::last_os_error());
            }
            // SAFETY: a plain system call with constant arguments.
            let fd = unsafe {
                libc::socket(
                    libc::AF_PACKET,
                    libc::SOCK_RAW | libc::SOCK_NONBLOCK | libc::SOCK_CLOEXEC,
                    libc::c_int::from(ETHERTYPE_BE),
                )
            };
            if fd < 0 {
                return Err(io::Error::last_os_error());
            }
            // SAFETY: `fd` is a fresh descriptor that nothing else owns.
            let fd = unsafe { OwnedFd::from_raw_fd(fd) };
            // SAFETY: all zeros is a valid `sockaddr_ll` (plain integers and bytes).
            let mut addr: libc::sockaddr_ll = unsafe { core::mem::zeroed() };
            addr.sll_family = libc::AF_PACKET as u16;
            addr.sll_protocol = ETHERTYPE_BE;
            addr.sll_ifindex = i32::try_from(index).unwrap_or(i32::MAX);
            // SAFETY: `addr` is a valid `sockaddr_ll` of the length passed, alive across the call.
            let rc = unsafe {
                libc::bind(
                    fd.as_raw_fd(),
                    core::ptr::from_ref(&addr).cast(),
                    core::mem::size_of::<libc::sockaddr_ll>() as libc::socklen_t,
                )
            };
            if rc != 0 {
                return Err(io::Error::last_os_error());
            }
            Ok(Self { fd })
        }

        /// Sends one Ethernet frame; the bytes sent.
        pub(super) fn send(&self, frame: &[u8]) -> io::Result<usize> {
            // SAFETY: `frame` is valid for reads of its length across the call.
            let n =
                unsafe { libc::send(self.fd.as_raw_fd(), frame.as_ptr().cast(), frame.len(), 0) };
            usize::try_from(n).map_err(|_| io::Error::last_os_error())
        }

        /// Receives one Ethernet frame into `buf`; its length.
        pub(super) fn recv(&self, buf: &mut [u8]) -> io::Result<usize> {
            // SAFETY: `buf` is valid for writes of its length across the call.
            let n =
                unsafe { libc::recv(self.fd.as_raw_fd(), buf.as_mut_ptr().cast(), buf.len(), 0) };
            usize::try_from(n).map_err(|_| io::Error::last_os_error())
        }

        /// Whether a frame waits in the socket, unread (FIONREAD: the length of the next one).
        pub(super) fn unread(&self) -> bool {
            let mut n: libc::c_int = 0;
            // SAFETY: FIONREAD writes one `c_int` through the pointer, which is valid.
            let rc = unsafe { libc::ioctl(self.fd.as_raw_fd(), libc::FIONREAD, &mut n) };
            // A socket that cannot say is taken as holding a frame: no verdict on a guess.
            rc != 0 || n > 0
        }
    }

    impl AsFd for RawSocket {
        fn as_fd(&self) -> BorrowedFd<'_> {
            self.fd.as_fd()
        }
    }
}

/// ethercrab's TX/RX on the "ethercat-io" thread, as its `std::tx_rx_task` but through the
/// public `PduTx`/`PduRx` of unmodified ethercrab (the transport its documentation leaves to
/// the application): it notes when each frame goes out (the "ethercat" thread's verdicts count
/// from there), and an answer no exchange waits for any more (its verdict given) is counted
/// and dropped, where ethercrab 0.7.1's own task would end, and the segment with it.
struct Io<'a> {
    socket: Async<Arc<RawSocket>>,
    tx: PduTx<'a>,
    rx: PduRx<'a>,
    watch: Arc<IoWatch>,
    buf: Vec<u8>,
}

impl Future for Io<'_> {
    type Output = ();

    fn poll(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<()> {
        let this = &mut *self;
        this.tx.replace_waker(cx.waker());
        if this.tx.should_exit() {
            return Poll::Ready(());
        }
        while let Some(frame) = this.tx.next_sendable_frame() {
            let socket = this.socket.get_ref();
            let sent = frame.send_blocking(|data| {
                socket
                    .send(data)
                    .map_err(|_| ethercrab::error::Error::SendFrame)
            });
            if sent.is_ok() {
                this.watch
                    .sent_at_ns
                    .store(tandem_rt::now_ns(), Ordering::Release);
                this.watch.sent.fetch_add(1, Ordering::AcqRel);
            } else {
                // The frame stays sendable; it goes at the next wake or its exchange fails.
                this.watch.send_errors.fetch_add(1, Ordering::Relaxed);
                break;
            }
        }
        loop {
            match this.socket.poll_readable(cx) {
                Poll::Pending => return Poll::Pending,
                Poll::Ready(Err(e)) => {
                    warn!("EtherCAT socket: {e}");
                    return Poll::Pending;
                }
                Poll::Ready(Ok(())) => {}
            }
            this.watch.busy.store(true, Ordering::Release);
            match this.socket.get_ref().recv(&mut this.buf) {
                Ok(n) => {
                    let frame = this.buf.get(..n).unwrap_or_default();
                    if this.rx.receive_frame(frame).is_err() {
                        this.watch.stray.fetch_add(1, Ordering::Relaxed);
                    }
                }
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
                Err(e) => warn!("EtherCAT socket: {e}"),
            }
            this.watch.busy.store(false, Ordering::Release);
        }
    }
}

/// One exchange of `group` with its verdict (see [`Verdict`]) and round trip (ns): the
/// frame's answer has `budget_ns` from the frame going out, and the verdict "no answer" is
/// only given when nothing is left unread in the socket, so that a thread of ours not
/// scheduled in time makes the verdict late, never a miss. The exchange's future is dropped
/// at the verdict (ethercrab releases its frame; a later answer is a stray, see [`Io`]).
async fn attempt<DC>(
    md: &MainDevice<'_>,
    group: &OpGroup<DC>,
    io: (&IoWatch, &RawSocket),
    budget_ns: i64,
    expected_wkc: u16,
) -> (Verdict, u64) {
    let (watch, socket) = io;
    let before = watch.sent.load(Ordering::Acquire);
    let started = tandem_rt::now_ns();
    let mut exchange = std::pin::pin!(group.tx_rx(md));
    let mut check_at = started.saturating_add(budget_ns);
    let result = loop {
        let wait = u64::try_from(check_at.saturating_sub(tandem_rt::now_ns())).unwrap_or(0);
        let mut timer = async_io::Timer::after(Duration::from_nanos(wait));
        let done = std::future::poll_fn(|cx| {
            if let Poll::Ready(r) = exchange.as_mut().poll(cx) {
                return Poll::Ready(Some(r));
            }
            Pin::new(&mut timer).poll(cx).map(|_| None)
        })
        .await;
        if let Some(r) = done {
            break Some(r);
        }
        let now = tandem_rt::now_ns();
        // Read before the exchange is polled once more: an answer handed over in between is
        // then seen by that poll.
        let quiet = !watch.busy.load(Ordering::Acquire) && !socket.unread();
        let out = watch.sent.load(Ordering::Acquire) != before;
        let due = watch
            .sent_at_ns
            .load(Ordering::Acquire)
            .saturating_add(budget_ns);
        if let Poll::Ready(r) = futures_poll_once(exchange.as_mut()).await {
            break Some(r);
        }
        if out && now >= due && quiet {
            break None;
        }
        // Not out yet, not due yet, or an answer waits to be read: look again shortly.
        check_at = if out && now < due {
            due
        } else {
            now.saturating_add(budget_ns / 16)
        };
    };
    let round_trip = u64::try_from(tandem_rt::now_ns().saturating_sub(started)).unwrap_or(0);
    let verdict = match result {
        None => Verdict::NoAnswer,
        Some(Ok(r)) if r.working_counter >= expected_wkc => Verdict::Complete,
        Some(Ok(r)) => Verdict::WorkingCounter {
            got: r.working_counter,
            want: expected_wkc,
        },
        Some(Err(_)) => Verdict::Failed,
    };
    (verdict, round_trip)
}

/// Polls `f` once: its output if ready.
async fn futures_poll_once<F: Future + Unpin>(mut f: F) -> Poll<F::Output> {
    std::future::poll_fn(|cx| Poll::Ready(Pin::new(&mut f).poll(cx))).await
}

/// The volts of an `aio` terminal's 16-bit word: `w · 10 / 32767` (0x7FFF = +10 V, the
/// EL31xx/EL41xx presentation; `tandem_config::ETHERCAT_AIO_CHANNELS`).
fn aio_volts(w: i16) -> f64 {
    let p = tandem_config::ETHERCAT_AIO_CHANNELS;
    f64::from(w) * p.range / f64::from(p.full_scale_code())
}

/// The 16-bit word of `volts` on an `aio` terminal's output: the channel's quantization
/// (`AnalogChannelParams::quantize`), full scale at ±10 V.
fn aio_word(volts: f64) -> i16 {
    let (code, _) = tandem_config::ETHERCAT_AIO_CHANNELS.quantize(volts);
    code.clamp(-32767, 32767) as i16
}

/// One SubDevice's part of the process image the two threads hand over.
#[derive(Debug)]
struct Part {
    /// Its device (index in the cell).
    device: usize,
    /// What it is.
    role: EthercatRole,
    /// A drive's mapping; `None` for a digital or analog terminal.
    map: Option<DriveMap>,
    /// The command to send (drives).
    command: DriveCommand,
    /// The feedback received (drives).
    feedback: DriveFeedback,
    /// The outputs byte (digital terminals).
    outputs: u8,
    /// The output words (analog terminals: channel 1, channel 2; 0x7FFF = +10 V).
    words_out: [i16; 2],
    /// The input words received (analog terminals).
    words_in: [i16; 2],
    /// The counter value received (encoder terminals).
    count: u32,
    /// The inputs byte received (digital terminals).
    inputs: u8,
    /// The inputs byte last logged.
    inputs_logged: u8,
    /// The device of its inputs, if they are bound to input signals.
    inputs_device: Option<usize>,
    /// Its name in the cell (for the log).
    name: String,
}

/// The "ethercat" thread's verdict on one exchange it attempted.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Verdict {
    /// Not attempted yet (the image is on its way to the "ethercat" thread or held by the
    /// cyclic thread).
    Pending,
    /// Answered with the expected working counter.
    Complete,
    /// The frame went out and no answer came within [`answer_budget_ns`] of it, with nothing
    /// left unread in the socket: the segment did not answer.
    NoAnswer,
    /// Answered with a working counter below the expected one.
    WorkingCounter {
        /// The working counter that came back.
        got: u16,
        /// The one a complete exchange has.
        want: u16,
    },
    /// ethercrab refused or failed the exchange (e.g. its own PDU timeout, no frame free).
    Failed,
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Pending => f.write_str("not attempted"),
            Self::Complete => f.write_str("complete"),
            Self::NoAnswer => f.write_str("no answer"),
            Self::WorkingCounter { got, want } => write!(f, "working counter {got} of {want}"),
            Self::Failed => f.write_str("exchange failed"),
        }
    }
}

/// The process image between the cyclic thread and the "ethercat" thread.
#[derive(Debug)]
struct Image {
    parts: Vec<Part>,
    /// The "ethercat" thread's verdict on its exchange.
    verdict: Verdict,
    /// Its round trip (ns).
    round_trip_ns: u64,
    /// MC_Reset of a lost segment: the "ethercat" thread brings the segment up again (from
    /// INIT to OP) before this image's exchange.
    reinit: bool,
}

/// Counters of the segment, reported at the end.
#[derive(Debug, Clone, Copy)]
pub struct SegmentCounts {
    /// Exchanges that came back complete.
    pub exchanges: u64,
    /// Exchanges the segment did not answer completely: the frame went out and its answer
    /// did not come within [`answer_budget_ns`], came with a short working counter, or
    /// ethercrab failed the exchange.
    pub misses: u64,
    /// `ecat_late`: cycles without a verdict on the exchange handed over a cycle before, our
    /// own threads being late (not the segment's fault, never a miss).
    pub late: u64,
    /// Times the segment went into alarm.
    pub alarms: u64,
    /// The most misses in a row.
    pub most_in_a_row: u32,
    /// The most late cycles in a row.
    pub most_late_in_a_row: u32,
    /// Late cycles whose frame had not even gone out: the "ethercat" or "ethercat-io" thread
    /// had not run since the handover (the rest waited for an answer or the verdict).
    pub late_unsent: u64,
    /// Re-inits of the segment MC_Reset asked for, and those that brought it back to OP.
    pub reinits: (u32, u32),
    /// Round trips of the exchanges, in buckets of 10 µs (the last one: 10 ms and more).
    pub round_trip_10us: [u32; 1001],
}

impl Default for SegmentCounts {
    fn default() -> Self {
        Self {
            exchanges: 0,
            misses: 0,
            late: 0,
            alarms: 0,
            most_in_a_row: 0,
            most_late_in_a_row: 0,
            late_unsent: 0,
            reinits: (0, 0),
            round_trip_10us: [0; 1001],
        }
    }
}

impl SegmentCounts {
    /// The round trip (µs, the bucket's upper edge) below which `share` of the exchanges are.
    pub fn round_trip_quantile_us(&self, share: f64) -> u64 {
        let total: u64 = self.round_trip_10us.iter().map(|&c| u64::from(c)).sum();
        let want = (total as f64 * share).ceil() as u64;
        let mut seen = 0u64;
        for (i, c) in self.round_trip_10us.iter().enumerate() {
            seen += u64::from(*c);
            if seen >= want && seen > 0 {
                return (i as u64 + 1) * 10;
            }
        }
        0
    }
}

/// The cyclic thread's end of the segment.
#[derive(Debug)]
pub struct Link {
    interface: String,
    to_bus: SyncSender<Box<Image>>,
    from_bus: Receiver<Box<Image>>,
    /// The image while the cyclic thread holds it.
    image: Option<Box<Image>>,
    /// Misses in a row.
    in_a_row: u32,
    /// Late cycles in a row.
    late_in_a_row: u32,
    /// Late cycles since the last complete exchange.
    late_since_complete: u32,
    /// The boundary at which the last complete exchange was taken back.
    last_complete: i64,
    /// In alarm for a stall of the "ethercat" thread ([`LATE_TO_ALARM_NS`]).
    stalled: bool,
    /// A re-init (MC_Reset of the lost segment) was handed over and is not back yet.
    reinit_pending: bool,
    /// The drives on the segment: device and last feedback (extrapolated over misses).
    drives: Vec<(usize, DriveFeedback)>,
    /// The node's cycle (ns).
    cycle_ns: i64,
    /// The first exchange has been started.
    started: bool,
    /// What the "ethercat-io" thread saw.
    watch: Arc<IoWatch>,
    /// Frames sent by the "ethercat-io" thread when the last image was handed over.
    sent_at_handover: u64,
    /// The counters.
    pub counts: Box<SegmentCounts>,
}

impl Link {
    /// The exchange at boundary `t` (see the module): the previous exchange's inputs into
    /// `exec`, this cycle's outputs out. Never waits.
    pub fn exchange(&mut self, t: i64, exec: &mut Executive<'_>, log: &mut impl Write) {
        if !self.started {
            // The first boundary: nothing was exchanged before it; the first outputs go out.
            self.started = true;
            if let Some(image) = self.image.take() {
                self.send(t, image, exec, log);
            }
            return;
        }
        if let Ok(image) = self.from_bus.try_recv() {
            self.image = Some(image);
        }
        let Some(mut image) = self.image.take() else {
            // No verdict yet on the exchange handed over a cycle ago: our own thread is late.
            self.late(exec);
            return;
        };
        if image.verdict == Verdict::Pending {
            // Still here from a cycle in which the "ethercat" thread held the previous image:
            // the handover waited, which is lateness of our own, not a miss.
            self.late(exec);
            self.send(t, image, exec, log);
            return;
        }
        self.late_in_a_row = 0;
        if self.reinit_pending {
            self.reinit_pending = false;
            let back = image.verdict == Verdict::Complete;
            self.counts.reinits.1 += u32::from(back);
            // As the other log lines.
            let _ = writeln!(
                log,
                "t={} EtherCAT {}: {}",
                Secs(t),
                self.interface,
                if back {
                    "back in OP after MC_Reset"
                } else {
                    "not back in OP after MC_Reset (the node's log says why)"
                }
            );
        }
        if image.verdict == Verdict::Complete {
            self.complete(t, &mut image, exec, log);
        } else {
            self.miss(t, image.verdict, exec, log);
        }
        self.send(t, image, exec, log);
    }

    /// A complete exchange: its inputs into `exec`.
    fn complete(
        &mut self,
        t: i64,
        image: &mut Image,
        exec: &mut Executive<'_>,
        log: &mut impl Write,
    ) {
        self.in_a_row = 0;
        self.stalled = false;
        self.late_since_complete = 0;
        self.last_complete = t;
        self.counts.exchanges += 1;
        let bucket = usize::try_from(image.round_trip_ns / 10_000).unwrap_or(usize::MAX);
        if let Some(c) = self.counts.round_trip_10us.get_mut(bucket.min(1000)) {
            *c = c.saturating_add(1);
        }
        for p in &mut image.parts {
            if p.map.is_some() {
                exec.set_drive_feedback(p.device, &p.feedback);
                if let Some(d) = self.drives.iter_mut().find(|d| d.0 == p.device) {
                    d.1 = p.feedback;
                }
                continue;
            }
            if p.role == EthercatRole::Enc {
                // The counter value as the integer channel 1 of the terminal's own device.
                exec.set_input_value(p.device, 1, t, f64::from(p.count));
                continue;
            }
            if p.role == EthercatRole::Aio {
                if let Some(d) = p.inputs_device {
                    for (c, w) in (1u8..).zip(p.words_in) {
                        // The word as volts; the terminal's stage quantizes it back to `w`.
                        exec.set_input_value(d, c, t, aio_volts(w));
                    }
                }
                continue;
            }
            if let Some(d) = p.inputs_device {
                exec.set_input_levels(d, t, u32::from(p.inputs));
            }
            if p.inputs != p.inputs_logged {
                p.inputs_logged = p.inputs;
                // The log ring keeps what fits; a full ring counts its losses itself.
                let _ = writeln!(
                    log,
                    "t={} {} inputs 0x{:02X} (EtherCAT)",
                    Secs(t),
                    p.name,
                    p.inputs
                );
            }
        }
    }

    /// The RxPDO of the last step into `image`, handed to the "ethercat" thread (kept for the
    /// next cycle if it still holds the previous one).
    fn send(&mut self, t: i64, mut image: Box<Image>, exec: &Executive<'_>, log: &mut impl Write) {
        let mut fault_reset = false;
        for p in &mut image.parts {
            if p.map.is_some() {
                p.command = exec.drive_command(p.device).copied().unwrap_or_default();
                fault_reset |= p.command.controlword & controlword::FAULT_RESET != 0;
            } else if p.role == EthercatRole::Aio {
                // The values the last step left on its output channels, as 16-bit words.
                if let Some(v) = exec.value_device(p.device) {
                    for (w, x) in p.words_out.iter_mut().zip(v.values) {
                        *w = aio_word(x.as_f64());
                    }
                }
            } else {
                // The levels the last step left on its output channels (bit c - 1: channel c).
                p.outputs = exec
                    .output_device(p.device)
                    .map_or(0, |s| (s.levels & 0xFF) as u8);
            }
        }
        image.verdict = Verdict::Pending;
        self.sent_at_handover = self.watch.sent.load(Ordering::Acquire);
        // MC_Reset of an axis on the lost segment sends its drive a fault reset (0x6040 bit
        // 7): the segment is brought up again with it, on the "ethercat" thread.
        if fault_reset && self.in_alarm() && !self.reinit_pending {
            image.reinit = true;
            self.reinit_pending = true;
            self.counts.reinits.0 += 1;
            // As the other log lines.
            let _ = writeln!(
                log,
                "t={} EtherCAT {}: MC_Reset: bringing the segment up again",
                Secs(t),
                self.interface
            );
        }
        match self.to_bus.try_send(image) {
            Ok(()) => {}
            Err(TrySendError::Full(i) | TrySendError::Disconnected(i)) => self.image = Some(i),
        }
    }

    /// A cycle without a verdict on the exchange handed over (our own thread late, not the
    /// segment): counted as `ecat_late`, the drives' positions extrapolated; only a stall of
    /// [`LATE_TO_ALARM_NS`] in a row is an alarm.
    fn late(&mut self, exec: &mut Executive<'_>) {
        if self.reinit_pending {
            // The segment is being brought up again: still lost, and no lateness of ours.
            self.lost(exec);
            return;
        }
        self.counts.late += 1;
        if self.watch.sent.load(Ordering::Acquire) == self.sent_at_handover {
            self.counts.late_unsent += 1;
        }
        self.late_since_complete = self.late_since_complete.saturating_add(1);
        self.late_in_a_row = self.late_in_a_row.saturating_add(1);
        self.counts.most_late_in_a_row = self.counts.most_late_in_a_row.max(self.late_in_a_row);
        let stalled =
            i64::from(self.late_in_a_row).saturating_mul(self.cycle_ns) >= LATE_TO_ALARM_NS;
        if stalled && self.in_a_row < MISSES_TO_ALARM {
            if !self.stalled {
                self.stalled = true;
                self.counts.alarms += 1;
            }
            self.lost(exec);
        } else if self.in_a_row < MISSES_TO_ALARM {
            self.extrapolate(exec);
        } else {
            self.lost(exec);
        }
    }

    /// An exchange the segment did not answer (a verdict of the "ethercat" thread); the alarm
    /// at [`MISSES_TO_ALARM`] in a row.
    fn miss(&mut self, t: i64, verdict: Verdict, exec: &mut Executive<'_>, log: &mut impl Write) {
        self.counts.misses += 1;
        self.in_a_row = self.in_a_row.saturating_add(1);
        self.counts.most_in_a_row = self.counts.most_in_a_row.max(self.in_a_row);
        if self.in_a_row <= MISSES_TO_ALARM {
            // A few lines per lost segment; the log ring keeps what fits.
            let _ = writeln!(
                log,
                "t={} EtherCAT {}: miss {} in a row ({verdict}), last complete exchange at t={}, {} late cycle(s) since",
                Secs(t),
                self.interface,
                self.in_a_row,
                Secs(self.last_complete),
                self.late_since_complete,
            );
        }
        if self.in_a_row < MISSES_TO_ALARM && !self.stalled {
            self.extrapolate(exec);
            return;
        }
        if self.in_a_row == MISSES_TO_ALARM && !self.stalled {
            self.counts.alarms += 1;
        }
        self.lost(exec);
    }

    /// Until the alarm the drives' positions go on at their last velocity, so that a missed or
    /// late exchange makes no jump in the following error (inferred: a drive in CSP keeps
    /// following its last setpoints' motion; the real sample replaces this one).
    fn extrapolate(&mut self, exec: &mut Executive<'_>) {
        let dt = self.cycle_ns as f64 * 1e-9;
        for (device, last) in &mut self.drives {
            let step = (f64::from(last.velocity_actual) * dt).round() as i64;
            last.position_actual = last.position_actual.wrapping_add(step as i32);
            exec.set_drive_feedback(*device, last);
        }
    }

    /// The segment is in alarm (lost or stalled).
    fn in_alarm(&self) -> bool {
        self.in_a_row >= MISSES_TO_ALARM || self.stalled
    }

    /// Each drive on the segment shows a fault with [`LOST_CODE`].
    fn lost(&self, exec: &mut Executive<'_>) {
        let lost = DriveFeedback {
            statusword: FAULT_STATUSWORD,
            error_code: LOST_CODE,
            ..DriveFeedback::default()
        };
        for (device, _) in &self.drives {
            exec.set_drive_feedback(*device, &lost);
        }
    }

    /// The segment's counters, logged at the node's end (its stop line).
    pub fn report(&self) {
        let c = &self.counts;
        info!(
            interface = %self.interface,
            exchanges = c.exchanges,
            misses = c.misses,
            ecat_late = c.late,
            alarms = c.alarms,
            "EtherCAT segment: {} exchanges, {} missed exchanges (at most {} in a row), ecat_late {} cycles ({} before the frame went out, at most {} in a row), {} alarms; round trip p50 <= {} us, p99 <= {} us, max <= {} us; {} answers after their verdict; {} re-inits after MC_Reset, {} back in OP",
            c.exchanges,
            c.misses,
            c.most_in_a_row,
            c.late,
            c.late_unsent,
            c.most_late_in_a_row,
            c.alarms,
            c.round_trip_quantile_us(0.5),
            c.round_trip_quantile_us(0.99),
            c.round_trip_quantile_us(1.0),
            self.watch.stray.load(Ordering::Relaxed),
            c.reinits.0,
            c.reinits.1,
        );
    }
}

/// What the "ethercat" thread needs to start.
struct Plan {
    interface: String,
    /// The node's SCHED_FIFO priority, which the EtherCAT threads take too.
    priority: Option<u8>,
    /// The node's cycle (ns): SYNC0's period.
    cycle_ns: u64,
    /// Per expected SubDevice in bus order: name, identity, role, device, inputs device.
    expected: Vec<(String, EthercatIdentity, EthercatRole, usize, Option<usize>)>,
}

/// Opens node `n`'s segment if it has one: the bus checked against the cell file, the drives'
/// mappings read, OP reached (within [`START_TIMEOUT`]). `Ok(None)` for a node without
/// `[[ethercat]]`.
pub fn open(cell: &Cell, n: usize) -> Result<Option<Link>, EthercatError> {
    let Some(seg) = cell.ethercat.iter().find(|s| s.node == n) else {
        return Ok(None);
    };
    let plan = Plan {
        interface: seg.interface.clone(),
        priority: cell.nodes.get(n).and_then(|x| x.realtime.priority),
        cycle_ns: cell.nodes.get(n).map_or(1_000_000, |x| {
            u64::try_from(x.cycle_ns).unwrap_or(1_000_000)
        }),
        expected: seg
            .subdevices
            .iter()
            .map(|s| {
                (
                    s.name.clone(),
                    s.identity,
                    s.role,
                    s.device.0,
                    s.inputs.map(|d| d.0),
                )
            })
            .collect(),
    };
    let interface = seg.interface.clone();
    let start_error = |reason: String| EthercatError::Start {
        interface: interface.clone(),
        reason,
    };
    let (ready_tx, ready_rx) = sync_channel::<Result<Box<Image>, EthercatError>>(1);
    let (to_bus, bus_in) = sync_channel::<Box<Image>>(1);
    let (bus_out, from_bus) = sync_channel::<Box<Image>>(1);
    let watch = Arc::new(IoWatch::default());
    let io_watch = Arc::clone(&watch);
    std::thread::Builder::new()
        .name("ethercat".into())
        .stack_size(8 << 20)
        .spawn(move || bus_thread(&plan, &ready_tx, &bus_in, &bus_out, io_watch))
        .map_err(|e| start_error(format!("cannot start the ethercat thread: {e}")))?;
    let image = match ready_rx.recv_timeout(START_TIMEOUT) {
        Ok(r) => r?,
        Err(_) => {
            return Err(start_error(format!(
                "not in OP within {} s",
                START_TIMEOUT.as_secs()
            )))
        }
    };
    let drives = image
        .parts
        .iter()
        .filter(|p| p.map.is_some())
        .map(|p| (p.device, DriveFeedback::default()))
        .collect();
    info!(interface = %seg.interface, subdevices = seg.subdevices.len(), "EtherCAT segment in OP");
    Ok(Some(Link {
        interface: seg.interface.clone(),
        to_bus,
        from_bus,
        image: Some(image),
        in_a_row: 0,
        late_in_a_row: 0,
        late_since_complete: 0,
        last_complete: 0,
        stalled: false,
        reinit_pending: false,
        drives,
        cycle_ns: cell.nodes.get(n).map_or(1, |x| x.cycle_ns),
        started: false,
        watch,
        sent_at_handover: 0,
        counts: Box::default(),
    }))
}

/// The "ethercat" thread: starts the segment, reports it ready (or why not), then runs one
/// exchange per image handed over until the cyclic thread's end of the channel goes.
fn bus_thread(
    plan: &Plan,
    ready: &SyncSender<Result<Box<Image>, EthercatError>>,
    bus_in: &Receiver<Box<Image>>,
    bus_out: &SyncSender<Box<Image>>,
    watch: Arc<IoWatch>,
) {
    let fail = |reason: String| EthercatError::Start {
        interface: plan.interface.clone(),
        reason,
    };
    let Ok((tx, rx, pdu_loop)) = PDU_STORAGE.try_split() else {
        // The receiver waits with a timeout; if it gave up nobody needs the answer.
        let _ = ready.send(Err(fail("the PDU storage is in use already".into())));
        return;
    };
    let socket = match RawSocket::open(&plan.interface).and_then(|s| {
        let s = Arc::new(s);
        Async::new(Arc::clone(&s)).map(|a| (s, a))
    }) {
        Ok(s) => s,
        Err(e) => {
            // As above: a receiver that gave up needs no answer.
            let _ = ready.send(Err(fail(format!("cannot open the interface: {e}"))));
            return;
        }
    };
    let task = Io {
        socket: socket.1,
        tx,
        rx,
        watch: Arc::clone(&watch),
        buf: vec![0; 1 << 14],
    };
    let priority = plan.priority;
    realtime(priority);
    let io = std::thread::Builder::new()
        .name("ethercat-io".into())
        .spawn(move || {
            realtime(priority);
            async_io::block_on(task);
        });
    if let Err(e) = io {
        // As above.
        let _ = ready.send(Err(fail(format!(
            "cannot start the ethercat-io thread: {e}"
        ))));
        return;
    }
    let md = MainDevice::new(
        pdu_loop,
        Timeouts {
            pdu: PDU_TIMEOUT,
            ..Timeouts::default()
        },
        MainDeviceConfig {
            dc_static_sync_iterations: 1000,
            ..MainDeviceConfig::default()
        },
    );
    let ends = Ends {
        ready,
        bus_in,
        bus_out,
        watch,
        socket: socket.0,
    };
    async_io::block_on(run_bus(plan, &md, &ends));
}

/// SCHED_FIFO at the node's priority, if it has one (a refusal is a warning).
fn realtime(priority: Option<u8>) {
    tandem_rt::no_timer_slack();
    if let Some(p) = priority {
        if let Err(w) = tandem_rt::set_fifo(p) {
            warn!("{w}");
        }
    }
}

/// The DC epoch, 2000-01-01 00:00 UTC, on the cell clock (ns since the Unix epoch).
const DC_EPOCH_NS: i64 = 946_684_800 * 1_000_000_000;

/// The cell clock as DC system time (ns since 2000-01-01): the time base ethercrab sets the
/// SubDevices' clocks to (their offsets 0x0920), so that the DC system time is cell time and
/// SYNC0, at whole multiples of the node's cycle in DC time, falls on the node's grid (whose
/// epoch is a whole second: exactly when the cycle divides one second).
fn cell_dc_now() -> u64 {
    u64::try_from(tandem_rt::now_ns().saturating_sub(DC_EPOCH_NS)).unwrap_or(0)
}

/// The "ethercat" thread's ends of the channels, and what it watches of the "ethercat-io"
/// thread.
struct Ends<'a> {
    ready: &'a SyncSender<Result<Box<Image>, EthercatError>>,
    bus_in: &'a Receiver<Box<Image>>,
    bus_out: &'a SyncSender<Box<Image>>,
    watch: Arc<IoWatch>,
    socket: Arc<RawSocket>,
}

impl Ends<'_> {
    /// Reports why the start failed.
    fn refuse(&self, e: EthercatError) {
        // The receiver waits with a timeout; if it gave up nobody needs the answer.
        let _ = self.ready.send(Err(e));
    }
}

/// The node's group of SubDevices in OP, with or without DC.
type OpGroup<DC> =
    SubDeviceGroup<MAX_SUBDEVICES, MAX_PDI, ethercrab::DefaultLock, subdevice_group::Op, DC>;

/// How [`serve`] (and the bring-up before it) ended.
enum Served {
    /// The cyclic thread's end of the channel went.
    End,
    /// MC_Reset asked to bring the segment up again; the image to exchange once it is.
    Reinit(Box<Image>),
    /// The segment could not be brought to OP.
    Failed(EthercatError),
}

/// The MainDevice's work: start (see [`open`]), then the exchanges; after MC_Reset of a lost
/// segment it is brought up again from INIT (ethercrab's `init_single_group` on the same
/// MainDevice: it counts, resets and addresses the SubDevices anew), here on the "ethercat"
/// thread while the cyclic thread carries on, its drives shown lost until the image is back.
async fn run_bus(plan: &Plan, md: &MainDevice<'_>, ends: &Ends<'_>) {
    let mut held: Option<Box<Image>> = None;
    loop {
        let again = held.is_some();
        match bring_up(plan, md, ends, &mut held).await {
            Served::End => return,
            Served::Reinit(image) => held = Some(image),
            Served::Failed(e) if !again => return ends.refuse(e),
            Served::Failed(e) => {
                warn!(
                    "EtherCAT segment on `{}` not back in OP: {e}",
                    plan.interface
                );
                let Some(mut image) = held.take() else {
                    return;
                };
                image.verdict = Verdict::Failed;
                image.reinit = false;
                if ends.bus_out.send(image).is_err() {
                    return;
                }
                match wait_for_reinit(ends) {
                    Some(image) => held = Some(image),
                    None => return,
                }
            }
        }
    }
}

/// Without a segment in OP: every image handed over fails at once, until one asks for a
/// re-init (returned) or the cyclic thread's end goes (`None`).
fn wait_for_reinit(ends: &Ends<'_>) -> Option<Box<Image>> {
    loop {
        let mut image = match ends.bus_in.recv_timeout(Duration::from_secs(1)) {
            Ok(i) => i,
            Err(RecvTimeoutError::Timeout) => continue,
            Err(RecvTimeoutError::Disconnected) => return None,
        };
        if image.reinit {
            return Some(image);
        }
        image.verdict = Verdict::Failed;
        if ends.bus_out.send(image).is_err() {
            return None;
        }
    }
}

/// The segment from INIT to OP (the bus checked, the mappings read, SYNC0), then [`serve`];
/// `held` is the image of a re-init.
async fn bring_up(
    plan: &Plan,
    md: &MainDevice<'_>,
    ends: &Ends<'_>,
    held: &mut Option<Box<Image>>,
) -> Served {
    let fail = |what: &str, e: ethercrab::error::Error| EthercatError::Start {
        interface: plan.interface.clone(),
        reason: format!("{what}: {e}"),
    };
    let mut group = match md
        .init_single_group::<MAX_SUBDEVICES, MAX_PDI>(cell_dc_now)
        .await
    {
        Ok(g) => g,
        Err(e) => return Served::Failed(fail("no segment found", e)),
    };
    let parts = match check_and_map(plan, md, &group).await {
        Ok(p) => p,
        Err(e) => return Served::Failed(e),
    };
    // SYNC0 on every SubDevice with DC, every node cycle.
    let mut dc = 0usize;
    for mut sd in group.iter_mut(md) {
        if sd.dc_support().any() {
            sd.set_dc_sync(DcSync::Sync0);
            dc += 1;
        }
    }
    if dc == 0 {
        let group = match group.into_safe_op(md).await {
            Ok(g) => g,
            Err(e) => return Served::Failed(fail("SAFE-OP refused", e)),
        };
        return match group.request_into_op(md).await {
            Ok(g) => serve(plan, md, &g, parts, held, ends).await,
            Err(e) => Served::Failed(fail("OP refused", e)),
        };
    }
    let conf = DcConfiguration {
        // Inferred: time for the SubDevices to take the configuration before the first pulse.
        start_delay: Duration::from_millis(100),
        sync0_period: Duration::from_nanos(plan.cycle_ns),
        sync0_shift: Duration::ZERO,
    };
    let group = match group.into_pre_op_pdi(md).await {
        Ok(g) => g,
        Err(e) => return Served::Failed(fail("process data mapping", e)),
    };
    let group = match group.configure_dc_sync(md, conf).await {
        Ok(g) => g,
        Err(e) => return Served::Failed(fail("SYNC0 configuration", e)),
    };
    let group = match group.into_safe_op(md).await {
        Ok(g) => g,
        Err(e) => return Served::Failed(fail("SAFE-OP refused", e)),
    };
    match group.request_into_op(md).await {
        Ok(g) => {
            log_dc(plan, md, &g, dc).await;
            serve(plan, md, &g, parts, held, ends).await
        }
        Err(e) => Served::Failed(fail("OP refused", e)),
    }
}

/// Logs the SYNC0 configuration the first DC SubDevice holds and how far its DC system time
/// is from the cell clock.
async fn log_dc<DC>(plan: &Plan, md: &MainDevice<'_>, group: &OpGroup<DC>, dc: usize) {
    let Some(sd) = group.iter(md).find(|sd| sd.dc_support().any()) else {
        return;
    };
    let cycle = sd
        .register_read::<u32>(RegisterAddress::DcSync0CycleTime)
        .await;
    let start = sd
        .register_read::<u64>(RegisterAddress::DcSyncStartTime)
        .await;
    let system = sd.register_read::<u64>(RegisterAddress::DcSystemTime).await;
    let now = cell_dc_now();
    match (cycle, start, system) {
        (Ok(cycle), Ok(start), Ok(system)) => info!(
            interface = %plan.interface,
            sync0_ns = cycle,
            "EtherCAT SYNC0 every {cycle} ns on {dc} SubDevice(s), first pulse at DC time {start} ns \
             (on the node's grid: {} ns past a cycle boundary); DC system time {} us from the cell clock",
            (i128::from(start) + i128::from(DC_EPOCH_NS)).rem_euclid(i128::from(plan.cycle_ns.max(1))),
            (i128::from(system) - i128::from(now)) / 1000,
        ),
        _ => warn!(interface = %plan.interface, "EtherCAT SYNC0 registers not readable"),
    }
}

/// Compares the bus with the cell file position by position and reads each drive's mapping:
/// the parts of the process image in bus order.
async fn check_and_map<DC>(
    plan: &Plan,
    md: &MainDevice<'_>,
    group: &SubDeviceGroup<
        MAX_SUBDEVICES,
        MAX_PDI,
        ethercrab::DefaultLock,
        subdevice_group::PreOp,
        DC,
    >,
) -> Result<Vec<Part>, EthercatError> {
    let mut parts = Vec::new();
    let found: Vec<SubDeviceRef<'_, _>> = group.iter(md).collect();
    for position in 0..plan.expected.len().max(found.len()) {
        let expected = plan.expected.get(position);
        let sd = found.get(position);
        let id = sd.map(|sd| {
            let i = sd.identity();
            EthercatIdentity {
                vendor: i.vendor_id,
                product: i.product_id,
                revision: i.revision,
            }
        });
        let (Some((name, want, role, device, inputs_device)), Some(sd), Some(id)) =
            (expected, sd, id)
        else {
            return Err(mismatch(plan, position, expected, sd.zip(id)));
        };
        if *want != id {
            return Err(mismatch(plan, position, expected, Some((sd, id))));
        }
        let map = match role {
            EthercatRole::Cia402 => Some(read_mapping(name, sd, &plan.interface).await?),
            EthercatRole::Dio | EthercatRole::Aio | EthercatRole::Enc => None,
        };
        parts.push(Part {
            device: *device,
            role: *role,
            map,
            command: DriveCommand::default(),
            feedback: DriveFeedback::default(),
            outputs: 0,
            words_out: [0; 2],
            words_in: [0; 2],
            count: 0,
            inputs: 0,
            inputs_logged: 0,
            inputs_device: *inputs_device,
            name: name.to_string(),
        });
    }
    Ok(parts)
}

/// The mismatch at `position`: what the cell file expects there, what the bus has.
fn mismatch<S>(
    plan: &Plan,
    position: usize,
    expected: Option<&(String, EthercatIdentity, EthercatRole, usize, Option<usize>)>,
    found: Option<(&SubDeviceRef<'_, S>, EthercatIdentity)>,
) -> EthercatError
where
    S: core::ops::Deref<Target = ethercrab::SubDevice>,
{
    EthercatError::Mismatch {
        interface: plan.interface.clone(),
        position,
        expected: expected.map(|e| (e.0.clone(), e.1)),
        found: found.map(|(sd, id)| (sd.name().to_string(), id)),
    }
}

impl Part {
    /// Writes this SubDevice's part of the process image into its output bytes `out`: a
    /// drive's RxPDO, an analog terminal's output words, a digital terminal's output byte.
    fn put_outputs(&self, out: &mut [u8]) {
        match &self.map {
            Some(map) => encode(map, &self.command, out),
            None if self.role == EthercatRole::Aio => {
                for (c, w) in self.words_out.iter().enumerate() {
                    put(out, 2 * c, 2, i64::from(*w));
                }
            }
            None => put(out, 0, 1, i64::from(self.outputs)),
        }
    }

    /// Reads this SubDevice's input bytes `input` of a complete exchange into its part.
    fn take_inputs(&mut self, input: &[u8]) {
        match &self.map {
            Some(map) => self.feedback = decode(map, input),
            None if self.role == EthercatRole::Aio => {
                for (c, w) in self.words_in.iter_mut().enumerate() {
                    *w = get(input, 2 * c, 2, true) as i16;
                }
            }
            // The status word, then the counter value 0x6000:11 (UINT32).
            None if self.role == EthercatRole::Enc => self.count = get(input, 2, 4, false) as u32,
            None => self.inputs = input.first().copied().unwrap_or(0),
        }
    }
}

/// In OP: reports the segment ready (or, after a re-init, exchanges the `held` image with the
/// mappings read anew), then one exchange per image handed over until the cyclic thread's end
/// of the channel goes or an image asks for a re-init.
async fn serve<DC>(
    plan: &Plan,
    md: &MainDevice<'_>,
    group: &OpGroup<DC>,
    parts: Vec<Part>,
    held: &mut Option<Box<Image>>,
    ends: &Ends<'_>,
) -> Served {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        match group.tx_rx(md).await {
            Ok(r) if r.all_op() => break,
            // A frame lost on the way (a faulty segment) is tried again until the deadline.
            Ok(_) | Err(_) if Instant::now() < deadline => {}
            Ok(_) => {
                return Served::Failed(EthercatError::Start {
                    interface: plan.interface.clone(),
                    reason: "not all SubDevices in OP within 10 s".into(),
                })
            }
            Err(e) => {
                return Served::Failed(EthercatError::Start {
                    interface: plan.interface.clone(),
                    reason: format!("exchange on the way to OP: {e}"),
                })
            }
        }
        async_io::Timer::after(Duration::from_millis(1)).await;
    }
    // The working counter of a complete exchange: +1 per SubDevice with inputs, +2 per one
    // with outputs (an LRW through its read and its write FMMU).
    let expected_wkc: u16 = group
        .iter(md)
        .map(|sd| {
            let io = sd.io_raw();
            u16::from(!io.inputs().is_empty()) + 2 * u16::from(!io.outputs().is_empty())
        })
        .sum();
    let mut next = match held.take() {
        Some(mut image) => {
            // Back after MC_Reset: the same SubDevices (checked), their mappings read anew.
            for (p, n) in image.parts.iter_mut().zip(parts) {
                p.map = n.map;
            }
            image.reinit = false;
            info!(interface = %plan.interface, "EtherCAT segment back in OP");
            Some(image)
        }
        None => {
            let image = Box::new(Image {
                parts,
                verdict: Verdict::Pending,
                round_trip_ns: 0,
                reinit: false,
            });
            if ends.ready.send(Ok(image)).is_err() {
                return Served::End;
            }
            None
        }
    };
    loop {
        let mut image = match next.take() {
            Some(i) => i,
            None => match ends.bus_in.recv_timeout(Duration::from_secs(1)) {
                Ok(i) => i,
                Err(RecvTimeoutError::Timeout) => continue,
                Err(RecvTimeoutError::Disconnected) => return Served::End,
            },
        };
        if image.reinit {
            return Served::Reinit(image);
        }
        for (p, sd) in image.parts.iter().zip(group.iter(md)) {
            p.put_outputs(&mut sd.outputs_raw_mut());
        }
        let (verdict, round_trip) = attempt(
            md,
            group,
            (&ends.watch, &ends.socket),
            answer_budget_ns(plan.cycle_ns),
            expected_wkc,
        )
        .await;
        image.verdict = verdict;
        image.round_trip_ns = round_trip;
        if verdict == Verdict::Complete {
            for (p, sd) in image.parts.iter_mut().zip(group.iter(md)) {
                p.take_inputs(&sd.inputs_raw());
            }
        }
        if ends.bus_out.send(image).is_err() {
            return Served::End;
        }
    }
}

/// The assigned RxPDO and TxPDO mapping of drive `sd` over CoE (CiA 301: 0x1C12:01 and
/// 0x1C13:01 name the PDO, its subindex 0 counts the entries), checked for the objects the
/// CiA 402 drive connection needs.
async fn read_mapping<S>(
    name: &str,
    sd: &SubDeviceRef<'_, S>,
    interface: &str,
) -> Result<DriveMap, EthercatError>
where
    S: core::ops::Deref<Target = ethercrab::SubDevice>,
{
    let sdo = |e: ethercrab::error::Error| EthercatError::Start {
        interface: interface.to_string(),
        reason: format!("`{name}`: reading its PDO mapping over CoE: {e}"),
    };
    // The RxPDO tandem's CSP needs, with the velocity feedforward 0x60B1 (a drive's default
    // mapping often lacks it: without it the drive's own position loop lags by v / Kv).
    // Written into the assigned RxPDO in PRE-OP; a drive that refuses keeps its own mapping.
    let rx_pdo: u16 = sd.sdo_read(0x1C12, 1).await.map_err(sdo)?;
    if let Err(e) = sd.sdo_write_array(rx_pdo, &CSP_RXPDO).await {
        warn!(
            subdevice = name,
            "RxPDO 0x{rx_pdo:04X} not remapped ({e}): the drive's own mapping is used"
        );
    }
    let mut map = DriveMap::default();
    for (assign, rx) in [(0x1C12u16, true), (0x1C13u16, false)] {
        let pdo: u16 = sd.sdo_read(assign, 1).await.map_err(sdo)?;
        let n: u8 = sd.sdo_read(pdo, 0).await.map_err(sdo)?;
        let mut bit = 0usize;
        for sub in 1..=n {
            let entry: u32 = sd.sdo_read(pdo, sub).await.map_err(sdo)?;
            if let Some(m) = mapped(entry, bit) {
                if rx {
                    map.rx.push(m);
                } else {
                    map.tx.push(m);
                }
            }
            bit += (entry & 0xFF) as usize;
        }
    }
    for (list, object) in [
        (&map.rx, 0x6040u16),
        (&map.rx, 0x607A),
        (&map.tx, 0x6041),
        (&map.tx, 0x6064),
    ] {
        if !list.iter().any(|m| m.index == object) {
            return Err(EthercatError::Mapping {
                name: name.to_string(),
                object,
            });
        }
    }
    Ok(map)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;

    /// The emulated drive's mappings (docs/ethercat.md): RxPDO 0x1600 and TxPDO 0x1A00.
    fn emulated() -> DriveMap {
        let mut map = DriveMap::default();
        let mut bit = 0;
        for e in [0x6040_0010u32, 0x6060_0008, 0x607A_0020, 0x60B8_0010] {
            map.rx.push(mapped(e, bit).unwrap());
            bit += (e & 0xFF) as usize;
        }
        bit = 0;
        for e in [
            0x6041_0010u32,
            0x6061_0008,
            0x6064_0020,
            0x606C_0020,
            0x60B9_0010,
            0x60BA_0020,
            0x60BB_0020,
        ] {
            map.tx.push(mapped(e, bit).unwrap());
            bit += (e & 0xFF) as usize;
        }
        map
    }

    #[test]
    fn the_rxpdo_goes_out_at_the_mapped_offsets() {
        let c = DriveCommand {
            controlword: 0x000F,
            mode: 8,
            target_position: -2,
            touch_probe_function: 0x0013,
            target_velocity: 77,
            ..DriveCommand::default()
        };
        let mut out = [0xAAu8; 9];
        encode(&emulated(), &c, &mut out);
        assert_eq!(out, [0x0F, 0x00, 8, 0xFE, 0xFF, 0xFF, 0xFF, 0x13, 0x00]);
    }

    #[test]
    fn the_txpdo_comes_in_from_the_mapped_offsets() {
        let mut input = [0u8; 21];
        input[0..2].copy_from_slice(&0x1237u16.to_le_bytes());
        input[2] = 0xF7; // -9
        input[3..7].copy_from_slice(&(-123_456i32).to_le_bytes());
        input[7..11].copy_from_slice(&(1_000_000i32).to_le_bytes());
        input[11..13].copy_from_slice(&0x0202u16.to_le_bytes());
        input[13..17].copy_from_slice(&(i32::MIN).to_le_bytes());
        input[17..21].copy_from_slice(&(i32::MAX).to_le_bytes());
        let f = decode(&emulated(), &input);
        assert_eq!(
            f,
            DriveFeedback {
                statusword: 0x1237,
                mode_display: -9,
                position_actual: -123_456,
                velocity_actual: 1_000_000,
                touch_probe_status: 0x0202,
                touch_probe_1_positive: i32::MIN,
                touch_probe_1_negative: i32::MAX,
                ..DriveFeedback::default()
            }
        );
    }

    #[test]
    fn a_short_image_reads_zeros_and_writes_nothing_beyond_it() {
        let f = decode(&emulated(), &[0x27, 0x02]);
        assert_eq!(f.statusword, 0x0227);
        assert_eq!(f.position_actual, 0);
        let mut out = [0u8; 2];
        encode(
            &emulated(),
            &DriveCommand {
                controlword: 6,
                mode: 8,
                ..DriveCommand::default()
            },
            &mut out,
        );
        assert_eq!(out, [6, 0]);
    }

    /// Runs `f` with a link on `config/ethercat.toml`'s drive whose bus end is the test: the
    /// link, the node's executive, the images the link sends, the sender of the bus's answers,
    /// and the drive's device.
    fn with_link(
        f: impl FnOnce(
            &mut Link,
            &mut Executive<'_>,
            &Receiver<Box<Image>>,
            &SyncSender<Box<Image>>,
            usize,
        ),
    ) {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config/ethercat.toml");
        let cell = tandem_config::load(&path).unwrap();
        let drive = cell.ethercat[0].subdevices[0].device.0;
        let mut exec = Executive::new(&cell, Some(0)).unwrap();
        let (to_bus, bus_in) = sync_channel(1);
        let (bus_out, from_bus) = sync_channel(1);
        let part = Part {
            device: drive,
            role: EthercatRole::Cia402,
            map: Some(emulated()),
            command: DriveCommand::default(),
            feedback: DriveFeedback::default(),
            outputs: 0,
            words_out: [0; 2],
            words_in: [0; 2],
            count: 0,
            inputs: 0,
            inputs_logged: 0,
            inputs_device: None,
            name: "slide_servo".into(),
        };
        let mut link = Link {
            interface: "ecm".into(),
            to_bus,
            from_bus,
            image: Some(Box::new(Image {
                parts: vec![part],
                verdict: Verdict::Pending,
                round_trip_ns: 0,
                reinit: false,
            })),
            in_a_row: 0,
            late_in_a_row: 0,
            late_since_complete: 0,
            last_complete: 0,
            stalled: false,
            reinit_pending: false,
            drives: vec![(drive, DriveFeedback::default())],
            cycle_ns: 2_000_000,
            started: false,
            watch: Arc::default(),
            sent_at_handover: 0,
            counts: Box::default(),
        };
        f(&mut link, &mut exec, &bus_in, &bus_out, drive);
    }

    /// Cycle 0 and 1 of a link: the first image goes out, comes back complete with the drive
    /// at 1000 increments moving 500 000 increments/s, and goes out again (returned).
    fn first_exchange(
        link: &mut Link,
        exec: &mut Executive<'_>,
        bus_in: &Receiver<Box<Image>>,
        bus_out: &SyncSender<Box<Image>>,
        log: &mut Vec<u8>,
    ) -> Box<Image> {
        link.exchange(0, exec, log);
        let mut image = bus_in.try_recv().expect("sent at the first boundary");
        image.verdict = Verdict::Complete;
        image.round_trip_ns = 120_000;
        image.parts[0].feedback = DriveFeedback {
            statusword: 0x0237,
            position_actual: 1000,
            velocity_actual: 500_000,
            ..DriveFeedback::default()
        };
        bus_out.send(image).unwrap();
        link.exchange(2_000_000, exec, log);
        bus_in.try_recv().expect("sent again")
    }

    #[test]
    fn the_third_unanswered_exchange_in_a_row_is_the_alarm() {
        with_link(|link, exec, bus_in, bus_out, drive| {
            let mut log = Vec::new();
            let mut image = first_exchange(link, exec, bus_in, bus_out, &mut log);
            assert_eq!(exec.drive_feedback(drive).unwrap().position_actual, 1000);
            assert_eq!((link.counts.exchanges, link.counts.misses), (1, 0));
            assert_eq!(link.counts.round_trip_10us[12], 1);
            // The segment answers no more: two misses, the position goes on at the last
            // velocity (1000 increments per 2 ms), no alarm.
            for (k, want) in [(2i64, 2000), (3, 3000)] {
                image.verdict = Verdict::NoAnswer;
                bus_out.send(image).unwrap();
                link.exchange(k * 2_000_000, exec, &mut log);
                let f = exec.drive_feedback(drive).unwrap();
                assert_eq!((f.position_actual, f.statusword), (want, 0x0237));
                image = bus_in.try_recv().expect("the next command goes out");
            }
            assert_eq!(link.counts.alarms, 0);
            // The third miss in a row: fault with 0x8130.
            image.verdict = Verdict::NoAnswer;
            bus_out.send(image).unwrap();
            link.exchange(8_000_000, exec, &mut log);
            let f = exec.drive_feedback(drive).unwrap();
            assert_eq!((f.statusword, f.error_code), (FAULT_STATUSWORD, LOST_CODE));
            assert_eq!(
                (
                    link.counts.misses,
                    link.counts.alarms,
                    link.counts.most_in_a_row,
                    link.counts.late
                ),
                (3, 1, 3, 0)
            );
            // Further misses are the same alarm, not new ones.
            let mut image = bus_in.try_recv().unwrap();
            image.verdict = Verdict::NoAnswer;
            bus_out.send(image).unwrap();
            link.exchange(10_000_000, exec, &mut log);
            assert_eq!(link.counts.alarms, 1);
            let log = String::from_utf8(log).unwrap();
            assert!(
                log.contains(
                    "t=0.008000000 EtherCAT ecm: miss 3 in a row (no answer), last complete \
                     exchange at t=0.002000000, 0 late cycle(s) since"
                ),
                "{log}"
            );
        });
    }

    #[test]
    fn late_cycles_are_never_misses_and_the_third_miss_counts_only_misses() {
        with_link(|link, exec, bus_in, bus_out, drive| {
            let mut log = Vec::new();
            let mut image = first_exchange(link, exec, bus_in, bus_out, &mut log);
            // The "ethercat" thread holds the image for 20 cycles (not scheduled, 40 ms):
            // late cycles, the position extrapolated, no miss and no alarm.
            let mut k = 2i64;
            for n in 1..=20 {
                link.exchange(k * 2_000_000, exec, &mut log);
                k += 1;
                let f = exec.drive_feedback(drive).unwrap();
                assert_eq!((f.position_actual, f.statusword), (1000 + 1000 * n, 0x0237));
            }
            assert_eq!(
                (link.counts.late, link.counts.misses, link.counts.alarms),
                (20, 0, 0)
            );
            assert_eq!(link.counts.most_late_in_a_row, 20);
            // Two misses, a late cycle, a miss: the third miss in a row is the alarm, the late
            // cycle between does not count, as a miss or as a break of the row.
            for late_before in [false, false, true] {
                if late_before {
                    link.exchange(k * 2_000_000, exec, &mut log);
                    k += 1;
                    assert_eq!(link.counts.alarms, 0);
                }
                image.verdict = Verdict::NoAnswer;
                bus_out.send(image).unwrap();
                link.exchange(k * 2_000_000, exec, &mut log);
                k += 1;
                image = bus_in.try_recv().unwrap();
            }
            let f = exec.drive_feedback(drive).unwrap();
            assert_eq!((f.statusword, f.error_code), (FAULT_STATUSWORD, LOST_CODE));
            assert_eq!(
                (link.counts.misses, link.counts.alarms, link.counts.late),
                (3, 1, 21)
            );
            let log = String::from_utf8(log).unwrap();
            assert!(
                log.contains(
                    "t=0.050000000 EtherCAT ecm: miss 3 in a row (no answer), last complete \
                     exchange at t=0.002000000, 21 late cycle(s) since"
                ),
                "{log}"
            );
        });
    }

    #[test]
    fn a_stalled_ethercat_thread_is_an_alarm_after_200_ms() {
        with_link(|link, exec, bus_in, bus_out, drive| {
            let mut log = Vec::new();
            let _held = first_exchange(link, exec, bus_in, bus_out, &mut log);
            // 99 late cycles (198 ms): still extrapolated; the 100th (200 ms): the alarm.
            for k in 2..=100i64 {
                link.exchange(k * 2_000_000, exec, &mut log);
            }
            assert_eq!(exec.drive_feedback(drive).unwrap().statusword, 0x0237);
            link.exchange(101 * 2_000_000, exec, &mut log);
            let f = exec.drive_feedback(drive).unwrap();
            assert_eq!((f.statusword, f.error_code), (FAULT_STATUSWORD, LOST_CODE));
            assert_eq!((link.counts.alarms, link.counts.misses), (1, 0));
            link.exchange(102 * 2_000_000, exec, &mut log);
            assert_eq!(link.counts.alarms, 1);
        });
    }

    #[test]
    fn mc_reset_of_the_lost_segment_asks_the_ethercat_thread_to_bring_it_up_again() {
        use tandem_motion::objects::action::Action;
        use tandem_motion::objects::axis::{Command, StartMode, StopMode};
        with_link(|link, exec, bus_in, bus_out, _| {
            let mut log = Vec::new();
            let power = Action::Command(Command::Power {
                enable: true,
                start_mode: StartMode::PositionControlled,
                stop_mode: StopMode::Emergency,
            });
            let r = exec.apply(0, "slide", "MC_Power", power, &mut log).unwrap();
            assert!(r.is_ok(), "{r:?}");
            let mut image = first_exchange(link, exec, bus_in, bus_out, &mut log);
            exec.step(2_000_000, &mut log).unwrap();
            // A fault reset while the segment is fine is the drive's own business.
            assert!(!image.reinit);
            let mut k = 2i64;
            for _ in 0..3 {
                image.verdict = Verdict::NoAnswer;
                bus_out.send(image).unwrap();
                link.exchange(k * 2_000_000, exec, &mut log);
                exec.step(k * 2_000_000, &mut log).unwrap();
                k += 1;
                image = bus_in.try_recv().unwrap();
                assert!(!image.reinit);
            }
            assert_eq!(link.counts.alarms, 1);
            // MC_Reset: the axis' drive connection sends the fault reset (0x6040 bit 7), and
            // the image that carries it asks for the re-init.
            let t = k * 2_000_000;
            let r = exec
                .apply(
                    t,
                    "slide",
                    "MC_Reset",
                    Action::Command(Command::Reset { restart: false }),
                    &mut log,
                )
                .unwrap();
            assert!(r.is_ok(), "{r:?}");
            exec.step(t, &mut log).unwrap();
            // The drive connection sends the pulse within a cycle or two.
            let mut t = t;
            for _ in 0..3 {
                t += 2_000_000;
                image.verdict = Verdict::NoAnswer;
                bus_out.send(image).unwrap();
                link.exchange(t, exec, &mut log);
                image = bus_in.try_recv().unwrap();
                if image.reinit {
                    break;
                }
                exec.step(t, &mut log).unwrap();
            }
            assert!(image.reinit, "{}", String::from_utf8_lossy(&log));
            assert_eq!(link.counts.reinits, (1, 0));
            // While the segment is brought up, the cycles are not late and the drive shows
            // the loss; the image back complete is the segment back in OP.
            let late = link.counts.late;
            for n in 2..10 {
                link.exchange(t + n * 2_000_000, exec, &mut log);
                assert_eq!(
                    exec.drive_feedback(image.parts[0].device)
                        .unwrap()
                        .error_code,
                    LOST_CODE
                );
            }
            assert_eq!(link.counts.late, late);
            image.reinit = false;
            image.verdict = Verdict::Complete;
            bus_out.send(image).unwrap();
            link.exchange(t + 10 * 2_000_000, exec, &mut log);
            assert_eq!(link.counts.reinits, (1, 1));
            let log = String::from_utf8(log).unwrap();
            assert!(
                log.contains("EtherCAT ecm: MC_Reset: bringing the segment up again"),
                "{log}"
            );
            assert!(
                log.contains("EtherCAT ecm: back in OP after MC_Reset"),
                "{log}"
            );
        });
    }

    #[test]
    fn a_working_counter_error_is_a_miss_and_the_command_goes_out_anyway() {
        with_link(|link, exec, bus_in, bus_out, _| {
            let mut log = Vec::new();
            link.exchange(0, exec, &mut log);
            let mut image = bus_in.try_recv().unwrap();
            image.verdict = Verdict::WorkingCounter { got: 2, want: 3 };
            bus_out.send(image).unwrap();
            link.exchange(2_000_000, exec, &mut log);
            assert_eq!((link.counts.exchanges, link.counts.misses), (0, 1));
            let image = bus_in.try_recv().expect("the next command still goes out");
            assert_eq!(image.verdict, Verdict::Pending);
            assert!(image.parts[0].map.is_some());
            assert!(String::from_utf8(log)
                .unwrap()
                .contains("miss 1 in a row (working counter 2 of 3)"));
        });
    }

    #[test]
    fn an_aio_word_is_the_channel_quantization_of_plus_minus_10_v() {
        assert_eq!(aio_word(2.5), 8192);
        assert_eq!(aio_word(-10.0), -32767);
        assert_eq!(aio_word(12.0), 32767);
        assert_eq!(aio_volts(8192), 8192.0 * 10.0 / 32767.0);
        for w in [-32767i16, -1, 0, 1, 8192, 32767] {
            assert_eq!(aio_word(aio_volts(w)), w, "the word back from its volts");
        }
    }

    #[test]
    fn a_mismatch_names_position_and_both_identities() {
        let e = EthercatError::Mismatch {
            interface: "ecm".into(),
            position: 1,
            expected: Some((
                "io".into(),
                EthercatIdentity {
                    vendor: 2,
                    product: 0x0743_3052,
                    revision: 0x0010_0000,
                },
            )),
            found: Some((
                "EL1859".into(),
                EthercatIdentity {
                    vendor: 2,
                    product: 0x0743_3052,
                    revision: 0x0011_0000,
                },
            )),
        };
        assert_eq!(
            e.to_string(),
            "EtherCAT segment on `ecm` does not match the cell file at position 1: expected `io` \
             (vendor 0x00000002, product 0x07433052, revision 0x00100000), found `EL1859` \
             (vendor 0x00000002, product 0x07433052, revision 0x00110000)"
        );
    }
}
