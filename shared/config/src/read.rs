//! Reading the input files: at most a given size (a cell file, a script or a cam CSV larger
//! than any real one, `/dev/zero` or a growing file is refused, never read to the end), and
//! UTF-8 text, an invalid byte named by its line and column.

use crate::error::{ConfigError, Problem};
use std::io::Read;
use std::path::Path;

/// The largest cell file read (bytes).
pub const CELL_FILE_MAX: u64 = 4 << 20;
/// The largest script file read (bytes).
pub const SCRIPT_FILE_MAX: u64 = 4 << 20;
/// The largest cam CSV file read (bytes).
pub const CAM_FILE_MAX: u64 = 16 << 20;

/// The text of `path`, refused with a [`ConfigError`] naming the file (and, for invalid
/// UTF-8, the line) when it cannot be read, is larger than `max` bytes or is not UTF-8.
pub fn read_text(path: &Path, max: u64) -> Result<String, ConfigError> {
    let file = path.display().to_string();
    let e = |line, problem| ConfigError {
        file: file.clone(),
        line,
        key: String::new(),
        problem: Box::new(problem),
    };
    let unreadable = |err: std::io::Error| e(None, Problem::Unreadable(err.to_string()));
    let f = std::fs::File::open(path).map_err(unreadable)?;
    let mut bytes = Vec::new();
    // One byte more than allowed tells a file that is too large without reading all of it.
    f.take(max.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(unreadable)?;
    if bytes.len() as u64 > max {
        return Err(e(None, Problem::TooLarge { max }));
    }
    String::from_utf8(bytes).map_err(|err| {
        let bytes = err.as_bytes();
        let at = err.utf8_error().valid_up_to();
        let before = bytes.get(..at).unwrap_or_default();
        let line = before.iter().filter(|b| **b == b'\n').count() + 1;
        let column = at
            - before
                .iter()
                .rposition(|b| *b == b'\n')
                .map_or(0, |p| p + 1)
            + 1;
        e(
            Some(line),
            Problem::NotUtf8 {
                column,
                byte: bytes.get(at).copied().unwrap_or(0),
            },
        )
    })
}
