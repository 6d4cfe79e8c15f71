//! The operating-system calls of the cyclic thread: the absolute-time sleep, real-time
//! scheduling, CPU affinity, memory locking and the termination signals. Each is one libc call;
//! this is the only module of tandem with `unsafe` code, and each block says why it is sound.
//! [`diag`] sets up the services' diagnostics output (`tracing`).
//!
//! ```no_run
//! use tandem_rt as rt;
//! // A 1 ms cycle on the cell clock, with an absolute sleep (no drift).
//! rt::install_termination_handler();
//! rt::no_timer_slack();
//! if let Err(e) = rt::set_fifo(80) {
//!     eprintln!("warning: {e}"); // e.g. not permitted without CAP_SYS_NICE
//! }
//! let mut next = rt::now_ns();
//! while !rt::termination_requested() {
//!     next += 1_000_000;
//!     rt::sleep_until(next);
//!     // ... one cycle ...
//! }
//! ```
#![allow(unsafe_code)]

pub mod diag;
pub mod retain;

use std::sync::atomic::{AtomicBool, Ordering};

/// The cell clock: CLOCK_REALTIME in ns (PTP-disciplined on a real cell; see deploy/README.md).
pub fn now_ns() -> i64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_REALTIME always exists.
    unsafe {
        libc::clock_gettime(libc::CLOCK_REALTIME, &mut ts);
    }
    // time_t and c_long are i64 on the 64-bit Linux targets tandem runs on.
    ts.tv_sec * 1_000_000_000 + ts.tv_nsec
}

/// The CPU time of `clock` (a CPU-time clock) in ns.
fn cpu_clock_ns(clock: libc::clockid_t) -> i64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the CPU-time clocks always exist on Linux.
    unsafe {
        libc::clock_gettime(clock, &mut ts);
    }
    ts.tv_sec * 1_000_000_000 + ts.tv_nsec
}

/// The CPU time (user + system) the whole process used so far, in ns.
pub fn process_cpu_ns() -> i64 {
    cpu_clock_ns(libc::CLOCK_PROCESS_CPUTIME_ID)
}

/// The CPU time (user + system) the calling thread used so far, in ns.
pub fn thread_cpu_ns() -> i64 {
    cpu_clock_ns(libc::CLOCK_THREAD_CPUTIME_ID)
}

/// Sleeps until the cell clock reads `t_ns` (absolute, so no drift accumulates). Returns early
/// on a signal; the caller checks the time and the termination flag.
pub fn sleep_until(t_ns: i64) {
    let ts = libc::timespec {
        tv_sec: t_ns.div_euclid(1_000_000_000) as libc::time_t,
        tv_nsec: t_ns.rem_euclid(1_000_000_000) as libc::c_long,
    };
    // SAFETY: `ts` is a valid timespec; the remaining-time pointer may be null with
    // TIMER_ABSTIME.
    unsafe {
        libc::clock_nanosleep(
            libc::CLOCK_REALTIME,
            libc::TIMER_ABSTIME,
            &ts,
            std::ptr::null_mut(),
        );
    }
}

/// The calling thread's `errno` after a failed call.
fn errno() -> i32 {
    std::io::Error::last_os_error().raw_os_error().unwrap_or(0)
}

/// An operating-system call that failed, with the OS error number (`errno`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RtError {
    /// SCHED_FIFO at `priority` was refused.
    Fifo {
        /// The priority asked for.
        priority: u8,
        /// The OS error.
        errno: i32,
    },
    /// The CPU is beyond what a CPU set can name.
    NoSuchCpu {
        /// The CPU asked for.
        cpu: usize,
    },
    /// Pinning to `cpu` was refused.
    Pin {
        /// The CPU asked for.
        cpu: usize,
        /// The OS error.
        errno: i32,
    },
    /// Locking the process' memory was refused.
    LockMemory {
        /// The OS error.
        errno: i32,
    },
    /// The process id does not fit the OS' type.
    NoSuchProcess {
        /// The process id.
        pid: u32,
    },
    /// Sending a signal to `pid` failed.
    Signal {
        /// The process id.
        pid: u32,
        /// The OS error.
        errno: i32,
    },
}

impl std::fmt::Display for RtError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let os = |e: i32| std::io::Error::from_raw_os_error(e);
        match *self {
            Self::Fifo { priority, errno } => write!(
                f,
                "SCHED_FIFO priority {priority} not permitted ({}); the node runs with normal \
                 scheduling (run as root, or grant CAP_SYS_NICE or an rtprio limit)",
                os(errno)
            ),
            Self::NoSuchCpu { cpu } => write!(f, "CPU {cpu} does not exist"),
            Self::Pin { cpu, errno } => write!(f, "cannot pin to CPU {cpu} ({})", os(errno)),
            Self::LockMemory { errno } => write!(
                f,
                "cannot lock memory ({}); page faults may delay cycles (raise the memlock limit)",
                os(errno)
            ),
            Self::NoSuchProcess { pid } => write!(f, "no process {pid}"),
            Self::Signal { pid, errno } => {
                write!(f, "cannot signal process {pid}: {}", os(errno))
            }
        }
    }
}

impl std::error::Error for RtError {}

/// Sets the calling thread's timer slack to 1 ns, so that an absolute sleep ends when asked
/// (normal threads get 50 µs of slack by default; SCHED_FIFO threads have none).
pub fn no_timer_slack() {
    // SAFETY: PR_SET_TIMERSLACK takes one integer argument; the others are ignored.
    unsafe {
        libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong, 0, 0, 0);
    }
}

/// Runs the calling thread under SCHED_FIFO at `priority` (1..=99).
pub fn set_fifo(priority: u8) -> Result<(), RtError> {
    let param = libc::sched_param {
        sched_priority: i32::from(priority),
    };
    // SAFETY: `param` is a valid sched_param; pid 0 is the calling thread.
    let r = unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) };
    if r == 0 {
        Ok(())
    } else {
        Err(RtError::Fifo {
            priority,
            errno: errno(),
        })
    }
}

/// Pins the calling thread to `cpu`.
pub fn pin_to_cpu(cpu: usize) -> Result<(), RtError> {
    // SAFETY: cpu_set_t is plain data; zeroed is the empty set, CPU_SET writes inside it (the
    // index is checked against its size first).
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if cpu >= 8 * std::mem::size_of::<libc::cpu_set_t>() {
            return Err(RtError::NoSuchCpu { cpu });
        }
        libc::CPU_SET(cpu, &mut set);
        if libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) != 0 {
            return Err(RtError::Pin {
                cpu,
                errno: errno(),
            });
        }
    }
    Ok(())
}

/// Locks the process' current and future memory (no page faults on the cyclic path).
pub fn lock_memory() -> Result<(), RtError> {
    // SAFETY: plain flags.
    let r = unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) };
    if r == 0 {
        Ok(())
    } else {
        Err(RtError::LockMemory { errno: errno() })
    }
}

static TERMINATE: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    TERMINATE.store(true, Ordering::SeqCst);
}

/// Installs handlers for SIGINT and SIGTERM that set the flag [`termination_requested`] reads.
pub fn install_termination_handler() {
    let handler: extern "C" fn(libc::c_int) = on_signal;
    // SAFETY: the handler only stores to an atomic, which is async-signal-safe.
    unsafe {
        libc::signal(libc::SIGINT, handler as libc::sighandler_t);
        libc::signal(libc::SIGTERM, handler as libc::sighandler_t);
    }
}

/// Whether SIGINT or SIGTERM arrived.
pub fn termination_requested() -> bool {
    TERMINATE.load(Ordering::SeqCst)
}

/// The resident memory of this process (bytes), from /proc/self/statm.
pub fn resident_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = s.split_whitespace().nth(1)?.parse().ok()?;
    // SAFETY: sysconf has no preconditions.
    let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    Some(pages * u64::try_from(page).ok()?)
}

/// Sends `signal` (`libc::SIGTERM`, `libc::SIGKILL`...) to process `pid`.
pub fn send_signal(pid: u32, signal: libc::c_int) -> Result<(), RtError> {
    let id = libc::pid_t::try_from(pid).map_err(|_| RtError::NoSuchProcess { pid })?;
    // SAFETY: kill has no memory preconditions; a wrong pid is an error return.
    if unsafe { libc::kill(id, signal) } == 0 {
        Ok(())
    } else {
        Err(RtError::Signal {
            pid,
            errno: errno(),
        })
    }
}
