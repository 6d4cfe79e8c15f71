//! A deterministic fuzzer for every decoder of outside input, without a nightly toolchain
//! (docs/fuzzing.md): leading values from Zenoh (bincode) and the key expressions they come
//! on, JSON and text commands as the gateway and the node take them, cell files, script files
//! and cam CSV. Each input is generated from the seed, the target and its index alone
//! ([`generate`]), so one failure is reproduced from the three numbers the report prints.
//!
//! Inputs are mutations of real inputs (the bundled cells and scripts, valid commands and
//! wire samples made with the encoders): bit flips, insertions of syntax bytes, deletions,
//! splices between seeds, numbers replaced by boundary values, truncation and repetition (at
//! most [`MAX_INPUT`] bytes), stacked one to four deep, plus purely random bytes. A decoder
//! passes when it returns `Ok` or `Err` for each: a panic is a failure (caught with
//! `catch_unwind`), and so is an accepted leading value that does not encode back to the same
//! bytes. Times are measured per input; the caller decides what is a hang.
//!
//! ```
//! use tandem_bench::fuzz::{run, Fixture, Plan, Target, Watch};
//! let fixture = Fixture::new();
//! let plan = Plan { seed: 7, inputs: 60, targets: Target::ALL.to_vec() };
//! let report = run(&fixture, &plan, &Watch::default(), |f| eprintln!("{f}"));
//! assert_eq!(report.iter().map(|r| r.inputs).sum::<u64>(), 60);
//! assert!(report.iter().all(|r| r.failures == 0));
//! ```

use std::fmt;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;
use tandem_config::Cell;
use tandem_motion::cam::{BoundaryCondition, Cam, CamDefinition, Interpolation};
use tandem_protocol::json::{self, CommandJson};
use tandem_protocol::keys;
use tandem_protocol::wire::LeadingValueSample;

/// The largest generated input (64 KiB).
pub const MAX_INPUT: usize = 64 * 1024;

/// The most points a fuzzed cam is interpolated with (a 64 KiB CSV has a few thousand).
const MAX_CAM_POINTS: usize = 4096;

/// The bundled cells and their scripts (file name, cell, script).
const CELLS: [(&str, &str, &str); 10] = [
    (
        "analog",
        include_str!("../../../config/analog.toml"),
        include_str!("../../../config/analog-script.toml"),
    ),
    (
        "cross-cutter",
        include_str!("../../../config/cross-cutter.toml"),
        include_str!("../../../config/cross-cutter-script.toml"),
    ),
    (
        "example-cell",
        include_str!("../../../config/example-cell.toml"),
        include_str!("../../../config/example-script.toml"),
    ),
    (
        "flying-saw",
        include_str!("../../../config/flying-saw.toml"),
        include_str!("../../../config/flying-saw-script.toml"),
    ),
    (
        "glue-dot",
        include_str!("../../../config/glue-dot.toml"),
        include_str!("../../../config/glue-dot-script.toml"),
    ),
    (
        "inputs",
        include_str!("../../../config/inputs.toml"),
        include_str!("../../../config/inputs-script.toml"),
    ),
    (
        "line",
        include_str!("../../../config/line.toml"),
        include_str!("../../../config/line-script.toml"),
    ),
    (
        "press",
        include_str!("../../../config/press.toml"),
        include_str!("../../../config/press-script.toml"),
    ),
    (
        "print-mark-registration",
        include_str!("../../../config/print-mark-registration.toml"),
        include_str!("../../../config/print-mark-registration-script.toml"),
    ),
    (
        "servo",
        include_str!("../../../config/servo.toml"),
        include_str!("../../../config/servo-script.toml"),
    ),
];

/// Valid command lines for config/press.toml, as `tandem cmd` and a text query send them.
const TEXT_COMMANDS: [&str; 12] = [
    "master MC_Power",
    "master MC_Home --mode 0 --position 0.0",
    "master MC_MoveVelocity --velocity 100 --acceleration 1000 --deceleration 1000 --jerk 0",
    "shaft/master MC_MoveAbsolute --position 250.5 --velocity 50 --direction 1",
    "cyan MC_GearIn --master master --ratio_numerator 3 --ratio_denominator 5",
    "units/cyan MC_GearIn --master=shaft/master --ratio-numerator=3 --ratio-denominator=5",
    "knife MC_CamIn --master master --cam cut --master_offset 0 --slave_offset 0",
    "magenta MC_Halt --deceleration 500",
    "web MC_MoveRelative --distance -10 --velocity 1e2",
    "yellow MC_Reset",
    "master MC_Stop --deceleration 2000 --jerk 0",
    "cyan MC_PhasingRelative --master master --phase_shift 1.5 --velocity 10",
];

/// Valid JSON commands for config/press.toml, as a Zenoh query payload.
const JSON_COMMANDS: [&str; 6] = [
    r#"{"instruction": "MC_Power"}"#,
    r#"{"instruction": "MC_MoveVelocity", "params": {"velocity": 100, "acceleration": 1000}}"#,
    r#"{"instruction": "MC_GearIn", "params": {"master": "master", "ratio_numerator": 3, "ratio_denominator": 5}, "sender": "op1"}"#,
    r#"{"instruction": "MC_CamIn", "params": {"master": "shaft/master", "cam": "cut", "master_offset": -0.0}}"#,
    r#"{"instruction": "MC_Home", "params": {"mode": 0, "position": 1e3, "execute": true}}"#,
    r#"{"instruction": "MC_Reset", "params": {}, "sender": ""}"#,
];

/// What observers receive as JSON (`tandem status --zenoh` decodes these).
const OBSERVED_JSON: [&str; 3] = [
    r#"{"t_ns": 5, "epoch_ns": -1, "node": "units", "axis": "cyan", "state": "Synchronized", "position": 1.5, "velocity": 2.0, "acceleration": 0.0, "actual_position": 1.5, "actual_velocity": 2.0, "following_error": 0.0, "status_word": 1, "error_word": 0, "warning_word": 0, "alarm": 0, "sync": "GearIn", "job": 3}"#,
    r#"{"outcome": "rejected", "job": 0, "t_ns": 1000000, "error_id": "16#8003 IllegalVelocity", "message": "velocity"}"#,
    r#"{"t_ns": 1, "object": "cyan", "job": 2, "outcome": "command", "error_id": "", "message": "MC_Power: accepted", "sender": "op1"}"#,
];

/// Cam point tables (`points_csv` files).
const CAM_CSV: [&str; 5] = [
    "x,y\n0,0\n90,10\n180,20\n270,10\n360,0\n",
    "# lift\r\nleading,following\r\n0.0, 0.0\r\n40.0, 2.0 # top\r\n\r\n80.0,0.0\r\n",
    "0,0\n1e-3,1e-9\n0.5,0.25\n1,1\n",
    "-10,-5\n-5,0\n0,5\n5,0\n10,-5\n10,-4\n",
    "0,1\n360,1\n",
];

/// Numbers a mutation puts in place of a number.
const BOUNDARY_NUMBERS: [&str; 22] = [
    "0",
    "-0",
    "-0.0",
    "1",
    "-1",
    "1e308",
    "-1e308",
    "1e309",
    "1e-320",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "9223372036854775807",
    "9223372036854775808",
    "-9223372036854775808",
    "-9223372036854775809",
    "18446744073709551615",
    "18446744073709551616",
    "1e999999999",
    "4294967296",
    "0.000000000000000000000000000000000000000000001",
];

/// Bytes of the input syntaxes (TOML, JSON, CSV, command lines), inserted by a mutation.
const SYNTAX: [&[u8]; 24] = [
    b"\"", b"'", b"[", b"]", b"[[", b"{", b"}", b"=", b",", b"\n", b"\r\n", b"#", b"\\", b"--",
    b"/", b".", b" ", b"\t", b"\0", b"\xff", b"\xc3", b"\"\"\"", b"\\u0000", b"e",
];

/// A decoder under test.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// Leading values from Zenoh (`json::decode_leading_value`, bincode, 64 bytes), and the
    /// key expressions samples and queries arrive on (`keys::parse_leading_value`,
    /// `keys::parse_command`).
    Wire,
    /// JSON on Zenoh: a command query payload (`CommandJson`, then the line the node parses)
    /// and the state, event and reply JSON observers decode.
    Json,
    /// A text command line as the node parses it (`script::split_command`, then
    /// `script::parse_command` against config/press.toml).
    Text,
    /// A cell file (`tandem_config::parse`).
    Cell,
    /// A script file (`script::parse_cell` against the cell it belongs to).
    Script,
    /// Cam CSV (`cam::parse_csv`), its points interpolated (`Cam::interpolate`, every
    /// interpolation and boundary condition) and evaluated at both ends and in between.
    Cam,
}

impl Target {
    /// Every target, in report order.
    pub const ALL: [Target; 6] = [
        Target::Wire,
        Target::Json,
        Target::Text,
        Target::Cell,
        Target::Script,
        Target::Cam,
    ];

    /// The target's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Target::Wire => "wire",
            Target::Json => "json",
            Target::Text => "text",
            Target::Cell => "cell",
            Target::Script => "script",
            Target::Cam => "cam",
        }
    }

    /// The target named `name`.
    pub fn from_name(name: &str) -> Option<Target> {
        Target::ALL.into_iter().find(|t| t.name() == name)
    }

    /// A constant mixed into the seed, so targets get different streams.
    fn salt(self) -> u64 {
        match self {
            Target::Wire => 0x5752_4945,
            Target::Json => 0x4a53_4f4e,
            Target::Text => 0x5445_5854,
            Target::Cell => 0x4345_4c4c,
            Target::Script => 0x5343_5250,
            Target::Cam => 0x4341_4d00,
        }
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// splitmix64 (Steele, Lea, Flood: "Fast splittable pseudorandom number generators").
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from `seed`.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A number in `0..n` (0 for `n == 0`).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next_u64() % n as u64) as usize
        }
    }

    /// True with probability `1 / n`.
    pub fn one_in(&mut self, n: usize) -> bool {
        self.below(n) == 0
    }

    /// One element of `items` (`None` for an empty slice).
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> Option<&'a T> {
        items.get(self.below(items.len()))
    }
}

/// The cells and seeds the targets share, built once.
#[derive(Debug)]
pub struct Fixture {
    /// The bundled cells that parse, with their scripts.
    cells: Vec<(Cell, &'static str)>,
    /// config/press.toml, the cell commands are parsed against.
    press: Option<Cell>,
    /// Encoded leading values.
    samples: Vec<Vec<u8>>,
    /// Cells made from the bundled ones: config/cross-cutter.toml with cam points.
    points_cells: Vec<String>,
}

impl Default for Fixture {
    fn default() -> Self {
        Self::new()
    }
}

impl Fixture {
    /// Parses the bundled cells (those that need files beside them are left out) and encodes
    /// the wire samples.
    pub fn new() -> Self {
        let cells: Vec<(Cell, &'static str)> = CELLS
            .iter()
            .filter_map(|(name, cell, script)| {
                tandem_config::parse(name, cell).ok().map(|c| (c, *script))
            })
            .collect();
        let press = cells
            .iter()
            .find(|(c, _)| c.name == "press")
            .map(|(c, _)| c.clone());
        let samples = [
            (0, 0, 0.0, 0.0, 0.0, 0.0, 0.0, 1, 0),
            (1_000_000, 1, 12.5, 100.0, -3.0, 0.0, 360.0, 1, 2),
            (
                i64::MAX,
                u64::MAX,
                -0.0,
                f64::MAX,
                f64::MIN_POSITIVE,
                -1.0,
                1e-300,
                0,
                u32::MAX,
            ),
            (i64::MIN, 0, 1e308, -1e308, 5e-324, 0.0, 0.0, u32::MAX, 7),
        ]
        .iter()
        .map(
            |&(t_ns, seq, p, v, a, modulo_start, modulo_length, status, leader)| {
                json::encode_leading_value(&LeadingValueSample {
                    t_ns,
                    seq,
                    p,
                    v,
                    a,
                    modulo_start,
                    modulo_length,
                    status,
                    leader,
                })
            },
        )
        .collect();
        let cross_cutter = CELLS.get(1).map_or("", |c| c.1);
        let points_cells = ["cubic_spline", "linear", "bezier"]
            .iter()
            .map(|i| {
                cross_cutter
                    .replace(
                        "# points = [[0.0, 0.0], [250.0, 180.0]]",
                        "points = [[0.0, 0.0], [250.0, 180.0], [400.0, 300.0], [500.0, 360.0]]",
                    )
                    .replace("\"cubic_spline\"   #", &format!("\"{i}\" #"))
                    .replace("\"none\"        ", "\"equal_first_derivative\"")
            })
            .collect();
        Fixture {
            cells,
            press,
            samples,
            points_cells,
        }
    }

    /// The number of bundled cells that parsed (the others need files beside them).
    pub fn cells(&self) -> usize {
        self.cells.len()
    }

    /// The cells with cam points the cell target starts from too (they parse).
    pub fn points_cells(&self) -> &[String] {
        &self.points_cells
    }

    /// The seeds of `target`: real inputs to mutate.
    fn seeds(&self, target: Target) -> Vec<&[u8]> {
        match target {
            Target::Wire => {
                let mut s: Vec<&[u8]> = self.samples.iter().map(Vec::as_slice).collect();
                s.push(b"tandem/press/lv/master");
                s.push(b"tandem/press/lv/master/actual");
                s.push(b"tandem/press/cmd/units/cyan/op1");
                s
            }
            Target::Json => JSON_COMMANDS
                .iter()
                .chain(OBSERVED_JSON.iter())
                .map(|s| s.as_bytes())
                .collect(),
            Target::Text => TEXT_COMMANDS.iter().map(|s| s.as_bytes()).collect(),
            Target::Cell => CELLS
                .iter()
                .map(|(_, c, _)| c.as_bytes())
                .chain(self.points_cells.iter().map(|c| c.as_bytes()))
                .collect(),
            Target::Script => self.cells.iter().map(|(_, s)| s.as_bytes()).collect(),
            Target::Cam => CAM_CSV.iter().map(|s| s.as_bytes()).collect(),
        }
    }
}

/// The cell input `index` of the script target is parsed against.
fn script_cell(fixture: &Fixture, index: u64) -> usize {
    (index % fixture.cells.len().max(1) as u64) as usize
}

/// Input `index` of `target` for `seed`: a pure function of the three.
pub fn generate(fixture: &Fixture, seed: u64, target: Target, index: u64) -> Vec<u8> {
    let mut rng =
        Rng::new(seed ^ target.salt().rotate_left(32) ^ index.wrapping_mul(0xd6e8_feb8_6659_fd93));
    // Warm the state so that neighbouring indices diverge at once.
    rng.next_u64();
    let seeds = fixture.seeds(target);
    if rng.one_in(20) {
        let max = if rng.one_in(8) { 4096 } else { 128 };
        let n = rng.below(max);
        return (0..n).map(|_| rng.next_u64() as u8).collect();
    }
    // A script is mutated from the script of the cell it is parsed against (see [`feed`]).
    let first = if target == Target::Script {
        seeds.get(script_cell(fixture, index))
    } else {
        rng.pick(&seeds)
    };
    let mut input = first.map(|s| s.to_vec()).unwrap_or_default();
    // A well-formed input now and then checks that the seeds are accepted at all.
    let rounds = if rng.one_in(50) { 0 } else { 1 + rng.below(4) };
    for _ in 0..rounds {
        mutate(&mut rng, &mut input, &seeds, target);
    }
    input.truncate(MAX_INPUT);
    input
}

/// One mutation of `input`.
fn mutate(rng: &mut Rng, input: &mut Vec<u8>, seeds: &[&[u8]], target: Target) {
    let len = input.len();
    match rng.below(if target == Target::Wire { 12 } else { 11 }) {
        // Flip 1 to 8 bits.
        0 => {
            for _ in 0..=rng.below(8) {
                let at = rng.below(len);
                if let Some(b) = input.get_mut(at) {
                    *b ^= 1 << rng.below(8);
                }
            }
        }
        // Overwrite a byte with a random one.
        1 => {
            let at = rng.below(len);
            if let Some(b) = input.get_mut(at) {
                *b = rng.next_u64() as u8;
            }
        }
        // Insert a syntax byte sequence.
        2 => {
            let at = rng.below(len + 1);
            let s = rng.pick(&SYNTAX).copied().unwrap_or(b"");
            input.splice(at..at, s.iter().copied());
        }
        // Delete a range.
        3 => {
            let from = rng.below(len + 1);
            let to = from + rng.below((len - from).min(64) + 1);
            input.drain(from..to);
        }
        // Splice: a prefix of this input and a suffix of another seed.
        4 => {
            let other = rng.pick(seeds).copied().unwrap_or(b"");
            let cut = rng.below(len + 1);
            let from = rng.below(other.len() + 1);
            input.truncate(cut);
            input.extend_from_slice(other.get(from..).unwrap_or(b""));
        }
        // Replace a number by a boundary value.
        5 | 6 => replace_number(rng, input),
        // Truncate.
        7 => input.truncate(rng.below(len + 1)),
        // Repeat a range.
        8 => {
            let from = rng.below(len + 1);
            let to = from + rng.below((len - from).min(256) + 1);
            let piece = input.get(from..to).map(<[u8]>::to_vec).unwrap_or_default();
            let most = if rng.one_in(16) { 1000 } else { 8 };
            let times = 1 + rng.below(most);
            let room = MAX_INPUT.saturating_sub(len);
            let add: Vec<u8> = piece
                .iter()
                .copied()
                .cycle()
                .take((piece.len() * times).min(room))
                .collect();
            input.splice(to..to, add);
        }
        // Replace a quoted string by a name from the input or the dictionary.
        9 => replace_string(rng, input),
        // Duplicate, delete or swap lines.
        10 => shuffle_lines(rng, input),
        // Wire only: overwrite a field of the 64-byte sample with boundary bits.
        _ => {
            let field = rng.below(8) * 8;
            let bits: u64 = *rng
                .pick(&[
                    0,
                    u64::MAX,
                    1 << 63,
                    (1 << 63) - 1,
                    f64::NAN.to_bits(),
                    f64::INFINITY.to_bits(),
                    f64::NEG_INFINITY.to_bits(),
                    f64::MAX.to_bits(),
                    (-0.0f64).to_bits(),
                    1,
                ])
                .unwrap_or(&0);
            if let Some(b) = input.get_mut(field..field + 8) {
                b.copy_from_slice(&bits.to_le_bytes());
            }
        }
    }
}

/// Strings a mutation puts in place of a quoted string.
const NAMES: [&str; 14] = [
    "",
    " ",
    "a/b",
    "tandem/**",
    "*",
    "$*",
    "lv",
    "\\u0000",
    "\\\"",
    "\u{e9}t\u{e9}",
    "MC_GearIn",
    "master",
    "0",
    "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa",
];

/// The spans `(start, end)` of the double-quoted strings of `input` (contents only).
fn quoted(input: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut open = None;
    for (i, &b) in input.iter().enumerate() {
        match (b, open) {
            (b'"', None) => open = Some(i + 1),
            (b'"', Some(start)) => {
                spans.push((start, i));
                open = None;
            }
            (b'\n', Some(_)) => open = None,
            _ => {}
        }
    }
    spans
}

/// Replaces the contents of one quoted string of `input` by those of another, or by a name
/// from [`NAMES`].
fn replace_string(rng: &mut Rng, input: &mut Vec<u8>) {
    let spans = quoted(input);
    let Some(&(start, end)) = rng.pick(&spans) else {
        return;
    };
    let with: Vec<u8> = if rng.one_in(2) {
        rng.pick(&NAMES)
            .map(|n| n.as_bytes().to_vec())
            .unwrap_or_default()
    } else {
        rng.pick(&spans)
            .and_then(|&(a, b)| input.get(a..b))
            .map(<[u8]>::to_vec)
            .unwrap_or_default()
    };
    input.splice(start..end, with);
}

/// Duplicates a line elsewhere, deletes one, or swaps two.
fn shuffle_lines(rng: &mut Rng, input: &mut Vec<u8>) {
    let mut lines: Vec<Vec<u8>> = input.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    let (a, b) = (rng.below(lines.len()), rng.below(lines.len() + 1));
    match rng.below(3) {
        0 => {
            let line = lines.get(a).cloned().unwrap_or_default();
            lines.insert(b.min(lines.len()), line);
        }
        1 if a < lines.len() => {
            lines.remove(a);
        }
        _ if b < lines.len() => lines.swap(a, b),
        _ => {}
    }
    *input = lines.join(&b'\n');
}

/// Replaces one number token of `input` (digits with sign, point and exponent) by a boundary
/// value; inserts one somewhere when there is none.
fn replace_number(rng: &mut Rng, input: &mut Vec<u8>) {
    let starts: Vec<usize> = (0..input.len())
        .filter(|&i| {
            input.get(i).is_some_and(u8::is_ascii_digit)
                && !i
                    .checked_sub(1)
                    .and_then(|p| input.get(p))
                    .is_some_and(u8::is_ascii_digit)
        })
        .collect();
    let value = rng.pick(&BOUNDARY_NUMBERS).copied().unwrap_or("0");
    let Some(&start) = rng.pick(&starts) else {
        let at = rng.below(input.len() + 1);
        input.splice(at..at, value.bytes());
        return;
    };
    let start = match start.checked_sub(1).and_then(|p| input.get(p)) {
        Some(b'-') | Some(b'+') => start - 1,
        _ => start,
    };
    let mut end = start + 1;
    while input
        .get(end)
        .is_some_and(|b| b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'_'))
        || (input.get(end).is_some_and(|b| matches!(b, b'-' | b'+'))
            && input
                .get(end.wrapping_sub(1))
                .is_some_and(|b| matches!(b, b'e' | b'E')))
    {
        end += 1;
    }
    input.splice(start..end, value.bytes());
}

/// What went wrong with one input.
#[derive(Clone, Debug, PartialEq)]
pub enum FailureKind {
    /// The decoder panicked, with this message.
    Panic(String),
    /// The decoder accepted something it should not have, or its answer is inconsistent.
    Wrong(String),
}

/// A failed input, with what reproduces it.
#[derive(Clone, Debug)]
pub struct Failure {
    /// The run's seed.
    pub seed: u64,
    /// The target.
    pub target: Target,
    /// The input's index.
    pub index: u64,
    /// What went wrong.
    pub kind: FailureKind,
    /// The input.
    pub input: Vec<u8>,
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.kind {
            FailureKind::Panic(m) => write!(f, "PANIC ({m})")?,
            FailureKind::Wrong(m) => write!(f, "WRONG ({m})")?,
        }
        write!(
            f,
            " target {} seed {} index {}; reproduce with `cargo bench -p tandem-bench --bench fuzz -- --target {} --seed {} --index {}`; {} bytes: {}",
            self.target,
            self.seed,
            self.index,
            self.target,
            self.seed,
            self.index,
            self.input.len(),
            hex(&self.input, 512)
        )
    }
}

/// `bytes` in hex, at most `max` of them (then `...`).
pub fn hex(bytes: &[u8], max: usize) -> String {
    use std::fmt::Write as _;
    let mut s = String::with_capacity(2 * bytes.len().min(max) + 3);
    for b in bytes.iter().take(max) {
        // Writing into a String cannot fail.
        let _ = write!(s, "{b:02x}");
    }
    if bytes.len() > max {
        s.push_str("...");
    }
    s
}

/// Feeds input `index` (`input`) to a target: `Ok(true)` accepted, `Ok(false)` refused with an
/// error, `Err` a failure (a panic is caught by the caller). The index picks the cell a script
/// is parsed against.
pub fn feed(fixture: &Fixture, target: Target, index: u64, input: &[u8]) -> Result<bool, String> {
    let text = String::from_utf8_lossy(input);
    match target {
        Target::Wire => {
            let ok = match json::decode_leading_value(input) {
                Ok(s) => {
                    let back = json::encode_leading_value(&s);
                    if back != input {
                        return Err(format!(
                            "accepted leading value encodes back to {}",
                            hex(&back, 64)
                        ));
                    }
                    true
                }
                Err(_) => false,
            };
            let lv = keys::parse_leading_value("press", &text).is_some();
            let cmd = keys::parse_command("press", &text).is_some();
            Ok(ok || lv || cmd)
        }
        Target::Json => {
            let observed = serde_json::from_str::<json::AxisState>(&text).is_ok()
                | serde_json::from_str::<json::ReplyJson>(&text).is_ok()
                | serde_json::from_str::<json::EventJson>(&text).is_ok();
            let command = serde_json::from_str::<CommandJson>(&text)
                .ok()
                .and_then(|c| c.to_line().ok())
                .is_some_and(|line| command_line(fixture, &format!("cyan {line}")));
            Ok(observed || command)
        }
        Target::Text => Ok(command_line(fixture, &text)),
        Target::Cell => match tandem_config::parse("fuzz.toml", &text) {
            Ok(cell) => {
                for c in &cell.cams {
                    finite_over_range(&c.cam).map_err(|e| format!("cam `{}`: {e}", c.name))?;
                }
                Ok(true)
            }
            Err(_) => Ok(false),
        },
        Target::Script => {
            let Some((cell, _)) = fixture.cells.get(script_cell(fixture, index)) else {
                return Ok(false);
            };
            Ok(tandem_config::script::parse_cell("fuzz-script.toml", &text, cell).is_ok())
        }
        Target::Cam => cam(&text),
    }
}

/// A command line as the node parses it (services/node/src/commands.rs): split, the node
/// prefix of the object taken off, then parsed against config/press.toml.
fn command_line(fixture: &Fixture, text: &str) -> bool {
    let Some(cell) = &fixture.press else {
        return false;
    };
    let Ok(c) = tandem_config::script::split_command(text) else {
        return false;
    };
    let object = c
        .object
        .split_once('/')
        .map_or(c.object.as_str(), |(_, o)| o);
    tandem_config::script::parse_command(cell, object, &c.instruction, &c.params).is_ok()
}

/// A built cam answers finite values over its whole range (the axis that follows it takes
/// them as setpoints): checked at both ends and in the middle.
fn finite_over_range(cam: &Cam) -> Result<(), String> {
    let (x0, x1) = cam.leading_range();
    for x in [x0, x1, 0.5 * (x0 + x1)] {
        match cam.following(x) {
            Ok(v)
                if [v.value, v.first_derivative, v.second_derivative]
                    .iter()
                    .all(|c| c.is_finite()) => {}
            other => return Err(format!("{other:?} at x = {x}")),
        }
    }
    Ok(())
}

/// Cam CSV parsed, then interpolated every way and evaluated; true when some cam was built,
/// an error when a built cam answers a non-finite value inside its range.
fn cam(text: &str) -> Result<bool, String> {
    let Ok(points) = tandem_motion::cam::parse_csv(text) else {
        return Ok(false);
    };
    if points.len() > MAX_CAM_POINTS {
        return Ok(false);
    }
    let mut built = false;
    for interpolation in [
        Interpolation::Linear,
        Interpolation::CubicSpline,
        Interpolation::Bezier,
    ] {
        for boundary in [
            BoundaryCondition::None,
            BoundaryCondition::EqualFirstDerivative,
        ] {
            let def = CamDefinition {
                boundary,
                ..CamDefinition::from_points(points.clone(), interpolation)
            };
            let Ok(cam) = Cam::interpolate(&def) else {
                continue;
            };
            built = true;
            let (x0, _) = cam.leading_range();
            finite_over_range(&cam).map_err(|e| {
                format!(
                    "{interpolation:?}/{boundary:?} cam of {} points: {e}",
                    points.len()
                )
            })?;
            for x in [x0 - 1.0, f64::NAN, f64::INFINITY] {
                // Outside the range or not a number is an error; either answer passes.
                let _ = cam.following(x);
            }
            let (y0, y1) = cam.following_range();
            for y in [y0, y1, 0.5 * (y0 + y1), f64::NAN] {
                // As above: an error is an answer.
                let _ = cam.leading(y, x0);
            }
        }
    }
    Ok(built)
}

/// Which targets, how many inputs in total, from which seed.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The seed every input derives from.
    pub seed: u64,
    /// Inputs in total, shared evenly by the targets.
    pub inputs: u64,
    /// The targets.
    pub targets: Vec<Target>,
}

/// What one target did.
#[derive(Clone, Debug)]
pub struct TargetReport {
    /// The target.
    pub target: Target,
    /// Inputs fed.
    pub inputs: u64,
    /// Inputs accepted (the rest were refused with an error, or failed).
    pub accepted: u64,
    /// Panics and wrong answers.
    pub failures: u64,
    /// The slowest input's time (ns).
    pub slowest_ns: u64,
    /// The slowest input's index.
    pub slowest_index: u64,
    /// Inputs slower than the hang bound, twice.
    pub hangs: u64,
    /// Inputs slower than the hang bound once, but not when fed again (the thread was
    /// preempted).
    pub stalls: u64,
    /// Time over all inputs (ns).
    pub total_ns: u64,
}

/// The input being fed, for a watchdog thread that reports an input that never returns:
/// inputs fed so far in all (it moves while the run makes progress) and the index and target
/// of the current one.
#[derive(Debug, Default)]
pub struct Watch {
    /// Inputs fed so far.
    pub fed: AtomicU64,
    /// The current input's index.
    pub index: AtomicU64,
    /// The current target's position in [`Target::ALL`].
    pub target: AtomicU64,
}

impl Watch {
    /// The target being fed.
    pub fn target(&self) -> Target {
        let i = self.target.load(Ordering::Relaxed) as usize;
        Target::ALL.get(i).copied().unwrap_or(Target::Wire)
    }
}

/// Inputs slower than this, also when fed again, count as hangs (1 s).
pub const HANG_NS: u64 = 1_000_000_000;

/// Runs `plan`: each target gets `inputs / targets` inputs (the first ones one more for the
/// remainder); `on_failure` sees each failure as it happens. The panic hook is silenced while
/// running (a caught panic is reported through `on_failure`).
pub fn run(
    fixture: &Fixture,
    plan: &Plan,
    watch: &Watch,
    mut on_failure: impl FnMut(&Failure),
) -> Vec<TargetReport> {
    let n = plan.targets.len() as u64;
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let reports = plan
        .targets
        .iter()
        .enumerate()
        .map(|(i, &target)| {
            let count = plan.inputs / n.max(1) + u64::from((i as u64) < plan.inputs % n.max(1));
            run_target(
                fixture,
                (plan.seed, target),
                0..count,
                watch,
                &mut on_failure,
            )
        })
        .collect();
    std::panic::set_hook(hook);
    reports
}

/// Feeds inputs `indices` of one target (for a seed).
pub fn run_target(
    fixture: &Fixture,
    (seed, target): (u64, Target),
    indices: std::ops::Range<u64>,
    watch: &Watch,
    on_failure: &mut impl FnMut(&Failure),
) -> TargetReport {
    let position = Target::ALL.iter().position(|&t| t == target).unwrap_or(0);
    watch.target.store(position as u64, Ordering::Relaxed);
    let mut r = TargetReport {
        target,
        inputs: 0,
        accepted: 0,
        failures: 0,
        slowest_ns: 0,
        slowest_index: 0,
        hangs: 0,
        stalls: 0,
        total_ns: 0,
    };
    for index in indices {
        watch.index.store(index, Ordering::Relaxed);
        watch.fed.fetch_add(1, Ordering::Relaxed);
        let input = generate(fixture, seed, target, index);
        let start = Instant::now();
        let outcome = catch_unwind(AssertUnwindSafe(|| feed(fixture, target, index, &input)));
        let ns = u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
        r.inputs += 1;
        r.total_ns = r.total_ns.saturating_add(ns);
        if ns > r.slowest_ns {
            r.slowest_ns = ns;
            r.slowest_index = index;
        }
        if ns > HANG_NS {
            // Fed again: on a loaded machine a thread can be preempted for over a second. A
            // hang is an input that is slow twice.
            let again = Instant::now();
            // Its answer was taken above.
            let _ = catch_unwind(AssertUnwindSafe(|| feed(fixture, target, index, &input)));
            if again.elapsed().as_nanos() > u128::from(HANG_NS) {
                r.hangs += 1;
            } else {
                r.stalls += 1;
            }
        }
        let kind = match outcome {
            Ok(Ok(accepted)) => {
                r.accepted += u64::from(accepted);
                continue;
            }
            Ok(Err(m)) => FailureKind::Wrong(m),
            Err(p) => FailureKind::Panic(
                p.downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| p.downcast_ref::<String>().cloned())
                    .unwrap_or_default(),
            ),
        };
        r.failures += 1;
        on_failure(&Failure {
            seed,
            target,
            index,
            kind,
            input,
        });
    }
    r
}
