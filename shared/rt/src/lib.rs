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

/// Makes the program `c` starts receive SIGTERM when the thread that starts it ends (its
/// supervisor died, even by kill -9): `prctl(PR_SET_PDEATHSIG, SIGTERM)` in the child before
/// `exec`. A child whose parent died between the fork and the prctl exits at once. The parent
/// is the *thread* that spawns: spawn from a thread that lives as long as the supervision.
pub fn die_with_parent(c: &mut std::process::Command) {
    use std::os::unix::process::CommandExt;
    // SAFETY: getpid has no preconditions.
    let parent = unsafe { libc::getpid() };
    // SAFETY: the closure runs in the forked child before exec and calls only prctl and
    // getppid, both async-signal-safe; it allocates nothing (the error is built from a raw
    // OS error number).
    unsafe {
        c.pre_exec(move || {
            if libc::prctl(
                libc::PR_SET_PDEATHSIG,
                libc::SIGTERM as libc::c_ulong,
                0,
                0,
                0,
            ) != 0
            {
                return Err(std::io::Error::last_os_error());
            }
            if libc::getppid() != parent {
                // The supervisor died before the prctl: its signal will never come.
                return Err(std::io::Error::from_raw_os_error(libc::ESRCH));
            }
            Ok(())
        });
    }
}

/// An exclusive lock on a file, held until dropped or until the process ends (also by kill
/// -9: the kernel releases a `flock` with the process' last file descriptor).
#[derive(Debug)]
pub struct RunLock {
    /// The open lock file; closing it releases the lock.
    _file: std::fs::File,
}

/// Why [`RunLock::acquire`] failed.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum LockError {
    /// Another process holds the lock; the pid it wrote into the file, if readable.
    Held {
        /// The holder's process id.
        pid: Option<u32>,
    },
    /// The lock file could not be created, locked or written.
    Io {
        /// The OS error.
        errno: i32,
    },
}

impl std::fmt::Display for LockError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::Held { pid: Some(pid) } => write!(f, "held by process {pid}"),
            Self::Held { pid: None } => f.write_str("held by another process"),
            Self::Io { errno } => write!(f, "{}", std::io::Error::from_raw_os_error(errno)),
        }
    }
}

impl std::error::Error for LockError {}

impl RunLock {
    /// Takes the exclusive lock on `path` (created, with its directory, if missing) without
    /// waiting, and writes this process' id into it.
    pub fn acquire(path: &std::path::Path) -> Result<Self, LockError> {
        use std::io::{Read, Seek, Write};
        use std::os::fd::AsRawFd;
        let io = |e: std::io::Error| LockError::Io {
            errno: e.raw_os_error().unwrap_or(0),
        };
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(io)?;
        }
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(io)?;
        // SAFETY: the descriptor is open (owned by `file`); flock has no memory preconditions.
        if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
            let e = errno();
            if e != libc::EWOULDBLOCK {
                return Err(LockError::Io { errno: e });
            }
            let mut s = String::new();
            // An unreadable file only loses the pid in the message.
            let _ = file.read_to_string(&mut s);
            return Err(LockError::Held {
                pid: s.trim().parse().ok(),
            });
        }
        file.set_len(0).map_err(io)?;
        file.rewind().map_err(io)?;
        write!(file, "{}", std::process::id()).map_err(io)?;
        file.flush().map_err(io)?;
        Ok(Self { _file: file })
    }
}

/// The bytes free for unprivileged users on the file system of `path` (statvfs), e.g. of
/// `/dev/shm`, where iceoryx2 keeps its shared memory.
pub fn free_bytes(path: &std::path::Path) -> Option<u64> {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(path.as_os_str().as_bytes()).ok()?;
    // SAFETY: statvfs is plain data, zeroed is a valid value; `c` is a NUL-terminated path.
    let mut s: libc::statvfs = unsafe { std::mem::zeroed() };
    // SAFETY: both pointers are valid for the call.
    if unsafe { libc::statvfs(c.as_ptr(), &mut s) } != 0 {
        return None;
    }
    s.f_bavail.checked_mul(s.f_frsize)
}
