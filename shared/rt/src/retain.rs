//! Retained data ("retentive" in S7: the absolute encoder adjustment, the count of traversed
//! ranges of a cyclic absolute encoder; S7-1500T Motion Control V4.0 function manual, 'Drive and
//! encoder connection' and 'Direct homing and absolute adjustment'): small named records kept in a
//! directory beside the cell and read back when a node restarts.
//!
//! A record is replaced atomically: written to a temporary file of a name no record can have,
//! synced, renamed over the record, and the directory synced; so a writer killed at any instant
//! leaves either the old record or the new one, whole. Each record carries a magic, a format
//! version, the payload's length and a CRC-32 of header and payload, so a file damaged by anything
//! else is reported as a [`RetainError`], never used. Temporary files of writers that died are
//! ignored by [`RetainStore::load`] and removed by [`RetainStore::open`].
//!
//! Record layout (little-endian): `[0..4]` magic `TNRT`, `[4..6]` format version
//! ([`FORMAT_VERSION`]), `[6..8]` reserved (0), `[8..12]` payload length, `[12..16]` CRC-32
//! (IEEE 802.3, reflected, as zlib) of bytes `[0..12]` followed by the payload; then the payload.
//!
//! This is file IO for the node's edge (start-up and the non-cyclic threads), never for the
//! cyclic thread: a store allocates and waits for the disk.
//!
//! ```no_run
//! use tandem_rt::retain::RetainStore;
//! # fn main() -> Result<(), tandem_rt::retain::RetainError> {
//! let store = RetainStore::open(std::path::Path::new("cell.retain"))?;
//! store.store("axis1.abs_adjustment", &[1, 2, 3])?;
//! assert_eq!(store.load("axis1.abs_adjustment")?, Some(vec![1, 2, 3]));
//! # Ok(())
//! # }
//! ```

use std::fmt;
use std::fs::{self, File, OpenOptions};
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The first four bytes of every record.
pub const MAGIC: [u8; 4] = *b"TNRT";
/// The record format this build writes and reads.
pub const FORMAT_VERSION: u16 = 1;
/// The length of a record's header.
pub const HEADER_LEN: usize = 16;
/// The largest payload a record holds (retained data is small; a larger file is damaged).
pub const MAX_PAYLOAD: usize = 1 << 20;
/// The longest record name.
pub const MAX_NAME_LEN: usize = 64;
/// The suffix that marks a temporary file (before the writer's process id and sequence).
const TEMP_MARK: &str = ".tmp.";

/// What was being done when a [`RetainError`] arose.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RetainOp {
    /// Opening (or creating) the directory.
    Open,
    /// Storing a record.
    Store,
    /// Loading a record.
    Load,
}

/// Why a record name is refused.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum NameProblem {
    /// The name is empty.
    Empty,
    /// The name is longer than [`MAX_NAME_LEN`] bytes.
    TooLong {
        /// Its length in bytes.
        len: usize,
    },
    /// The name starts with `.` (reserved for temporary files; also excludes `.` and `..`).
    LeadingDot,
    /// A character other than ASCII letters, digits, `.`, `_` and `-` (a path separator, a
    /// space, a NUL...).
    Character {
        /// The character.
        found: char,
    },
}

/// What went wrong with a record or the directory.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RetainCause {
    /// The record name is refused.
    BadName(NameProblem),
    /// A payload larger than [`MAX_PAYLOAD`] bytes.
    TooLarge {
        /// Its length.
        len: usize,
    },
    /// The operating system refused a call.
    Io {
        /// The kind of error.
        kind: io::ErrorKind,
        /// The OS error number, if there is one.
        errno: Option<i32>,
    },
    /// The directory's path is not a directory.
    NotADirectory,
    /// The file is shorter than a header.
    Truncated {
        /// Its length.
        len: u64,
    },
    /// The file does not start with [`MAGIC`]: not a record.
    Magic {
        /// The first bytes found.
        found: [u8; 4],
    },
    /// A format version this build does not read.
    Version {
        /// The version found.
        found: u16,
    },
    /// The header's payload length differs from the file's.
    Length {
        /// The payload length in the header.
        header: u32,
        /// The payload bytes in the file (at most [`MAX_PAYLOAD`] + 1 are read).
        file: u64,
    },
    /// The checksum does not match: the file is damaged.
    Checksum {
        /// The CRC-32 in the header.
        stored: u32,
        /// The CRC-32 of the file's contents.
        computed: u32,
    },
}

impl fmt::Display for RetainCause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::BadName(NameProblem::Empty) => f.write_str("empty record name"),
            Self::BadName(NameProblem::TooLong { len }) => {
                write!(f, "record name of {len} bytes (at most {MAX_NAME_LEN})")
            }
            Self::BadName(NameProblem::LeadingDot) => {
                f.write_str("a record name must not start with `.`")
            }
            Self::BadName(NameProblem::Character { found }) => write!(
                f,
                "{found:?} in a record name (ASCII letters, digits, `.`, `_`, `-` only)"
            ),
            Self::TooLarge { len } => {
                write!(f, "payload of {len} bytes (at most {MAX_PAYLOAD})")
            }
            Self::Io { kind, errno } => match errno {
                Some(e) => write!(f, "{}", io::Error::from_raw_os_error(e)),
                None => write!(f, "{kind}"),
            },
            Self::NotADirectory => f.write_str("not a directory"),
            Self::Truncated { len } => {
                write!(f, "damaged: {len} bytes, shorter than a record header")
            }
            Self::Magic { found } => write!(f, "not a retained record (starts with {found:02x?})"),
            Self::Version { found } => write!(
                f,
                "record format version {found}, this build reads version {FORMAT_VERSION}"
            ),
            Self::Length { header, file } => write!(
                f,
                "damaged: the header says {header} payload bytes, the file has {file}"
            ),
            Self::Checksum { stored, computed } => write!(
                f,
                "damaged: checksum {computed:#010x}, the header says {stored:#010x}"
            ),
        }
    }
}

/// A retained record or its directory could not be used: what was being done, to which record
/// and file, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RetainError {
    /// What was being done.
    pub op: RetainOp,
    /// The record's name (the directory's path for [`RetainOp::Open`]).
    pub name: String,
    /// The file (or directory) concerned.
    pub path: PathBuf,
    /// Why.
    pub cause: RetainCause,
}

impl fmt::Display for RetainError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (name, path, cause) = (&self.name, self.path.display(), &self.cause);
        match self.op {
            RetainOp::Open => write!(f, "retained data directory {path}: {cause}"),
            RetainOp::Store => write!(f, "storing retained record `{name}` ({path}): {cause}"),
            RetainOp::Load => write!(f, "loading retained record `{name}` ({path}): {cause}"),
        }
    }
}

impl std::error::Error for RetainError {}

/// The CRC-32 table (IEEE 802.3 polynomial, reflected), built at compile time.
const CRC_TABLE: [u32; 256] = {
    let mut table = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        table[i] = c;
        i += 1;
    }
    table
};

/// CRC-32 (as zlib's `crc32`) of the concatenation of `parts`.
pub fn crc32(parts: &[&[u8]]) -> u32 {
    let mut c = !0u32;
    for part in parts {
        for &b in *part {
            // The index is masked to 0..=255.
            c = CRC_TABLE[((c ^ u32::from(b)) & 0xFF) as usize] ^ (c >> 8);
        }
    }
    !c
}

/// Checks a record name: 1..=64 bytes of ASCII letters, digits, `.`, `_`, `-`, not starting
/// with `.`.
pub fn check_name(name: &str) -> Result<(), NameProblem> {
    if name.is_empty() {
        return Err(NameProblem::Empty);
    }
    if name.len() > MAX_NAME_LEN {
        return Err(NameProblem::TooLong { len: name.len() });
    }
    if name.starts_with('.') {
        return Err(NameProblem::LeadingDot);
    }
    match name
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-')))
    {
        Some(found) => Err(NameProblem::Character { found }),
        None => Ok(()),
    }
}

/// The header of a record of `payload`.
fn header(payload: &[u8]) -> Option<[u8; HEADER_LEN]> {
    let len = u32::try_from(payload.len()).ok()?;
    let mut h = [0u8; HEADER_LEN];
    h[0..4].copy_from_slice(&MAGIC);
    h[4..6].copy_from_slice(&FORMAT_VERSION.to_le_bytes());
    h[8..12].copy_from_slice(&len.to_le_bytes());
    let crc = crc32(&[&h[0..12], payload]);
    h[12..16].copy_from_slice(&crc.to_le_bytes());
    Some(h)
}

/// The payload of record `bytes` (the whole file, or its first `MAX_PAYLOAD + HEADER_LEN + 1`
/// bytes), or why it is not a record.
fn parse(bytes: &[u8]) -> Result<&[u8], RetainCause> {
    let Some((head, payload)) = bytes.split_first_chunk::<HEADER_LEN>() else {
        return Err(RetainCause::Truncated {
            len: bytes.len() as u64,
        });
    };
    let word = |at: usize| [head[at], head[at + 1], head[at + 2], head[at + 3]];
    let found = word(0);
    if found != MAGIC {
        return Err(RetainCause::Magic { found });
    }
    let version = u16::from_le_bytes([head[4], head[5]]);
    if version != FORMAT_VERSION {
        return Err(RetainCause::Version { found: version });
    }
    let len = u32::from_le_bytes(word(8));
    if u64::from(len) != payload.len() as u64 {
        return Err(RetainCause::Length {
            header: len,
            file: payload.len() as u64,
        });
    }
    let stored = u32::from_le_bytes(word(12));
    let computed = crc32(&[&head[0..12], payload]);
    if stored != computed {
        return Err(RetainCause::Checksum { stored, computed });
    }
    Ok(payload)
}

fn io_cause(e: &io::Error) -> RetainCause {
    RetainCause::Io {
        kind: e.kind(),
        errno: e.raw_os_error(),
    }
}

/// Syncs directory `dir` (so a rename or a new entry in it is on disk).
fn sync_dir(dir: &Path) -> io::Result<()> {
    File::open(dir)?.sync_all()
}

/// The process id in a temporary file's name (`.<name>.tmp.<pid>.<seq>`), if it is one.
fn temp_owner(file_name: &str) -> Option<u32> {
    if !file_name.starts_with('.') {
        return None;
    }
    let (rest, seq) = file_name.rsplit_once('.')?;
    let (rest, pid) = rest.rsplit_once('.')?;
    seq.parse::<u64>().ok()?;
    rest.ends_with(TEMP_MARK.trim_end_matches('.'))
        .then(|| pid.parse().ok())
        .flatten()
}

/// Whether process `pid` no longer exists (signal 0 tests for it without sending anything).
fn process_gone(pid: u32) -> bool {
    matches!(
        crate::send_signal(pid, 0),
        Err(crate::RtError::Signal { errno, .. }) if errno == libc::ESRCH
    )
}

/// A directory of retained records.
#[derive(Debug)]
pub struct RetainStore {
    dir: PathBuf,
    /// Makes each temporary file name of this process unique.
    sequence: AtomicU64,
}

impl RetainStore {
    /// Opens the directory `dir`, creating it (and syncing its parent) if it does not exist, and
    /// removes the temporary files left by writers whose process is gone.
    pub fn open(dir: &Path) -> Result<Self, RetainError> {
        let err = |cause| RetainError {
            op: RetainOp::Open,
            name: dir.display().to_string(),
            path: dir.to_path_buf(),
            cause,
        };
        if !dir.exists() {
            fs::create_dir_all(dir).map_err(|e| err(io_cause(&e)))?;
            if let Some(parent) = dir.parent().filter(|p| !p.as_os_str().is_empty()) {
                sync_dir(parent).map_err(|e| err(io_cause(&e)))?;
            }
        }
        if !dir.is_dir() {
            return Err(err(RetainCause::NotADirectory));
        }
        let store = Self {
            dir: dir.to_path_buf(),
            sequence: AtomicU64::new(0),
        };
        store
            .remove_stale_temporaries()
            .map_err(|e| err(io_cause(&e)))?;
        Ok(store)
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The file of record `name` (not checked).
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Removes `.<name>.tmp.<pid>.<seq>` files whose writer process is gone.
    fn remove_stale_temporaries(&self) -> io::Result<()> {
        for entry in fs::read_dir(&self.dir)? {
            let entry = entry?;
            let Some(pid) = entry.file_name().to_str().and_then(temp_owner) else {
                continue;
            };
            if pid != std::process::id() && process_gone(pid) {
                match fs::remove_file(entry.path()) {
                    // Another process may have cleaned it up at the same moment.
                    Err(e) if e.kind() == io::ErrorKind::NotFound => {}
                    other => other?,
                }
            }
        }
        Ok(())
    }

    /// Replaces record `name` with `payload`, atomically: the new record is written to a
    /// temporary file, synced, renamed over the record, and the directory is synced. On an
    /// error the old record is unchanged.
    pub fn store(&self, name: &str, payload: &[u8]) -> Result<(), RetainError> {
        let path = self.path(name);
        let err = |cause| RetainError {
            op: RetainOp::Store,
            name: name.to_owned(),
            path: path.clone(),
            cause,
        };
        check_name(name).map_err(|p| err(RetainCause::BadName(p)))?;
        let too_large = RetainCause::TooLarge { len: payload.len() };
        if payload.len() > MAX_PAYLOAD {
            return Err(err(too_large));
        }
        let head = header(payload).ok_or_else(|| err(too_large))?;
        let seq = self.sequence.fetch_add(1, Ordering::Relaxed);
        let temp = self
            .dir
            .join(format!(".{name}{TEMP_MARK}{}.{seq}", std::process::id()));
        let written = write_synced(&temp, &head, payload).and_then(|()| fs::rename(&temp, &path));
        if let Err(e) = written {
            // The write already failed; a temporary file left behind is removed by the next
            // `open`, so a failure to remove it now adds nothing to report.
            let _ = fs::remove_file(&temp);
            return Err(err(io_cause(&e)));
        }
        sync_dir(&self.dir).map_err(|e| err(io_cause(&e)))
    }

    /// Reads record `name`: `None` if there is none, its payload if it is whole, an error naming
    /// the file if it is damaged or of another format.
    pub fn load(&self, name: &str) -> Result<Option<Vec<u8>>, RetainError> {
        let path = self.path(name);
        let err = |cause| RetainError {
            op: RetainOp::Load,
            name: name.to_owned(),
            path: path.clone(),
            cause,
        };
        check_name(name).map_err(|p| err(RetainCause::BadName(p)))?;
        let file = match File::open(&path) {
            Ok(f) => f,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(err(io_cause(&e))),
        };
        let mut bytes = Vec::new();
        // At most one byte more than the largest record, so a huge file is not read whole.
        let limit = (HEADER_LEN + MAX_PAYLOAD + 1) as u64;
        file.take(limit)
            .read_to_end(&mut bytes)
            .map_err(|e| err(io_cause(&e)))?;
        let payload = parse(&bytes).map_err(err)?;
        Ok(Some(payload.to_vec()))
    }
}

/// Writes `head` and `payload` to a new file `path` and syncs it.
fn write_synced(path: &Path, head: &[u8], payload: &[u8]) -> io::Result<()> {
    let mut f = OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .open(path)?;
    f.write_all(head)?;
    f.write_all(payload)?;
    f.sync_all()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    /// A fresh directory under the system's temporary directory, removed when dropped.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(tag: &str) -> Self {
            let dir =
                std::env::temp_dir().join(format!("tandem-retain-{tag}-{}", std::process::id()));
            // A leftover of an earlier run may or may not exist.
            let _ = fs::remove_dir_all(&dir);
            Self(dir)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            // Best effort: the directory is under the temporary directory anyway.
            let _ = fs::remove_dir_all(&self.0);
        }
    }

    #[test]
    fn crc32_known_answer() {
        // The CRC-32 check value of "123456789" (zlib, IEEE 802.3).
        assert_eq!(crc32(&[b"123456789"]), 0xCBF4_3926);
        assert_eq!(crc32(&[b"1234", b"56789"]), 0xCBF4_3926);
        assert_eq!(crc32(&[]), 0);
    }

    #[test]
    fn store_load_round_trip_and_absent_record() {
        let t = TempDir::new("round-trip");
        let s = RetainStore::open(&t.0.join("nested")).unwrap();
        assert_eq!(s.load("axis1").unwrap(), None);
        s.store("axis1", b"hello").unwrap();
        assert_eq!(s.load("axis1").unwrap().as_deref(), Some(&b"hello"[..]));
        s.store("axis1", b"").unwrap();
        assert_eq!(s.load("axis1").unwrap(), Some(vec![]));
        let big = vec![0xA5u8; MAX_PAYLOAD];
        s.store("big", &big).unwrap();
        assert_eq!(s.load("big").unwrap(), Some(big));
        let e = s.store("big", &vec![0u8; MAX_PAYLOAD + 1]).unwrap_err();
        assert_eq!(
            e.cause,
            RetainCause::TooLarge {
                len: MAX_PAYLOAD + 1
            }
        );
        // The file is the header followed by the payload.
        let bytes = fs::read(s.path("axis1")).unwrap();
        assert_eq!(bytes.len(), HEADER_LEN);
        assert_eq!(&bytes[0..4], b"TNRT");
        assert_eq!(&bytes[4..6], &[1, 0]);
    }

    #[test]
    fn a_corrupted_byte_is_a_checksum_error_naming_the_file() {
        let t = TempDir::new("corrupt");
        let s = RetainStore::open(&t.0).unwrap();
        s.store("axis1.adjustment", &[7u8; 25]).unwrap();
        let path = s.path("axis1.adjustment");
        let mut bytes = fs::read(&path).unwrap();
        for at in [HEADER_LEN, HEADER_LEN + 24, 6, 13] {
            let mut damaged = bytes.clone();
            damaged[at] ^= 0x10;
            fs::write(&path, &damaged).unwrap();
            let e = s.load("axis1.adjustment").unwrap_err();
            assert!(
                matches!(e.cause, RetainCause::Checksum { .. }),
                "byte {at}: {e}"
            );
            assert_eq!(e.op, RetainOp::Load);
            assert_eq!(e.path, path);
            assert!(e.to_string().contains(&path.display().to_string()), "{e}");
            assert!(e.to_string().contains("damaged"), "{e}");
        }
        // Truncated, lengthened, not a record.
        fs::write(&path, &bytes[..HEADER_LEN - 1]).unwrap();
        let e = s.load("axis1.adjustment").unwrap_err();
        assert_eq!(e.cause, RetainCause::Truncated { len: 15 });
        bytes.push(0);
        fs::write(&path, &bytes).unwrap();
        let e = s.load("axis1.adjustment").unwrap_err();
        assert_eq!(
            e.cause,
            RetainCause::Length {
                header: 25,
                file: 26
            }
        );
        fs::write(&path, b"[axes.x]\nkind = \"rotary\"\n").unwrap();
        let e = s.load("axis1.adjustment").unwrap_err();
        assert!(matches!(e.cause, RetainCause::Magic { .. }), "{e}");
        // A store over a damaged record replaces it.
        s.store("axis1.adjustment", b"new").unwrap();
        assert_eq!(s.load("axis1.adjustment").unwrap(), Some(b"new".to_vec()));
    }

    #[test]
    fn a_wrong_version_is_refused() {
        let t = TempDir::new("version");
        let s = RetainStore::open(&t.0).unwrap();
        s.store("r", b"payload").unwrap();
        let path = s.path("r");
        let mut bytes = fs::read(&path).unwrap();
        // Version 2 with a valid checksum: a record of a later format.
        bytes[4..6].copy_from_slice(&2u16.to_le_bytes());
        let crc = crc32(&[&bytes[0..12], &bytes[HEADER_LEN..]]);
        bytes[12..16].copy_from_slice(&crc.to_le_bytes());
        fs::write(&path, &bytes).unwrap();
        let e = s.load("r").unwrap_err();
        assert_eq!(e.cause, RetainCause::Version { found: 2 });
        assert!(e.to_string().contains("version 2"), "{e}");
    }

    #[test]
    fn bad_names_are_refused() {
        let t = TempDir::new("names");
        let s = RetainStore::open(&t.0).unwrap();
        let long = "x".repeat(MAX_NAME_LEN + 1);
        let cases = [
            ("", NameProblem::Empty),
            ("a/b", NameProblem::Character { found: '/' }),
            ("../escape", NameProblem::LeadingDot),
            ("..", NameProblem::LeadingDot),
            (".hidden", NameProblem::LeadingDot),
            ("a b", NameProblem::Character { found: ' ' }),
            ("a\0b", NameProblem::Character { found: '\0' }),
            ("a\\b", NameProblem::Character { found: '\\' }),
            ("achse-ü", NameProblem::Character { found: 'ü' }),
            (long.as_str(), NameProblem::TooLong { len: 65 }),
        ];
        for (name, problem) in cases {
            let e = s.store(name, b"x").unwrap_err();
            assert_eq!(e.cause, RetainCause::BadName(problem), "{name:?}");
            assert_eq!(e.op, RetainOp::Store);
            let e = s.load(name).unwrap_err();
            assert_eq!(e.cause, RetainCause::BadName(problem), "{name:?}");
        }
        assert!(check_name(&"x".repeat(MAX_NAME_LEN)).is_ok());
        assert!(check_name("axis_1.abs-adjustment").is_ok());
        // Nothing was written.
        assert_eq!(fs::read_dir(&t.0).unwrap().count(), 0);
    }

    #[test]
    fn stale_temporaries_are_ignored_then_removed() {
        let t = TempDir::new("stale");
        let s = RetainStore::open(&t.0).unwrap();
        s.store("r", b"old").unwrap();
        // A process that is gone: a child that has exited and been reaped.
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let stale = t.0.join(format!(".r.tmp.{dead}.0"));
        fs::write(&stale, b"half a rec").unwrap();
        // A temporary of a live process (this one) is kept.
        let live = t.0.join(format!(".r.tmp.{}.99", std::process::id()));
        fs::write(&live, b"in flight").unwrap();
        assert_eq!(s.load("r").unwrap(), Some(b"old".to_vec()));
        s.store("r", b"new").unwrap();
        assert_eq!(s.load("r").unwrap(), Some(b"new".to_vec()));
        assert!(stale.exists() && live.exists());
        let s = RetainStore::open(&t.0).unwrap();
        assert!(!stale.exists(), "the dead writer's temporary is removed");
        assert!(live.exists(), "a live writer's temporary is kept");
        assert_eq!(s.load("r").unwrap(), Some(b"new".to_vec()));
        assert_eq!(temp_owner(".r.tmp.123.4"), Some(123));
        assert_eq!(temp_owner("r.tmp.123.4"), None);
        assert_eq!(temp_owner(".r.123.4"), None);
        assert_eq!(temp_owner(".r.tmp.x.4"), None);
    }

    #[test]
    fn open_refuses_a_file() {
        let t = TempDir::new("notdir");
        fs::create_dir_all(&t.0).unwrap();
        let file = t.0.join("plain");
        fs::write(&file, b"x").unwrap();
        let e = RetainStore::open(&file).unwrap_err();
        assert_eq!(e.cause, RetainCause::NotADirectory);
        assert_eq!(e.op, RetainOp::Open);
    }
}
