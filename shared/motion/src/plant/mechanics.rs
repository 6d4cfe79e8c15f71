//! Encoder values and drive increments to the axis' technological units, as S7-1500T configures
//! them (S7-1500T Motion Control V4.0 function manual, 'Drive and encoder connection' (actual
//! value types) and 'Mechanics').
//!
//! - [`RawCounter`] extends the wrapping raw word of an encoder (a 32-bit counter, the CiA 402
//!   position actual value 0x6064, a 25-bit SSI word) into an exact `i64` count across any number
//!   of wraps, with integer arithmetic only.
//! - [`Scaling`] converts counts to positions, velocities and torques and positions back to counts
//!   and to a drive's 32-bit position increments (CiA 402 0x607A), from an [`EncoderConfig`] and
//!   the [`Mechanics`] (load gear, leadscrew, inversion, efficiency).
//! - [`AbsoluteAdjustment`] is the retentive result of an absolute encoder adjustment (MC_Home
//!   modes 6 and 7) with its fixed byte layout, for the node to retain on disk.
//!
//! # Exactness
//!
//! A position is always computed from the whole `i64` count, never accumulated, so nothing drifts
//! however long the axis runs (the manual's 'Common axis basics', long-term accuracy: positions
//! are accumulated from encoder increments with no rounding drift). The units per count
//! (`denominator * units_per_load_revolution / (counts_per_revolution * numerator)` for an
//! encoder on the motor shaft) are held to about 104 significant bits as an unevaluated sum of
//! two `f64` (double-double; the gear's product with the pitch is taken exactly), and the product
//! with the count is formed exactly before its one rounding (Dekker's product, no FMA needed). So
//! a position is the exact product of the count and the configured ratio rounded once to the
//! nearest `f64` (half an ulp; a tie closer than 2^-100 of the value may round the other way):
//! when the exact position is representable it is returned exactly (after 10^6 revolutions of a
//! 3:1 gear a rotary axis reads exactly 360e6 °), and positions never decrease as the count
//! grows. [`Scaling::count`] returns the count whose position is nearest; since two counts
//! `|c| <= 2^52` apart by one are at least an ulp apart, `count(position(c)) == c` for every
//! `|c| <= 2^52` (tested over random configurations). Beyond 2^53 counts an `f64` position can
//! no longer tell neighbouring counts apart; the manual's own limit is of that order
//! (9.0E12 mm at 1000 increments/unit, alarms 307/308).
//!
//! Nothing here allocates; every method is `O(1)`.

use core::fmt;

/// S7 `StepsPerRevolution`: the upper limit of its range.
pub const MAX_STEPS_PER_REVOLUTION: u32 = 8_388_608;
/// S7 `FineResolutionXist1`: the upper limit of its range (bits).
pub const MAX_FINE_RESOLUTION_BITS: u8 = 31;
/// The widest raw word a [`RawCounter`] extends (bits).
pub const MAX_RAW_BITS: u8 = 32;
/// The smallest leadscrew pitch or distance per revolution (units). Inferred: the manual's
/// lengths span 0.001..1e12 (e.g. `Modulo.Length`); the margin keeps the conversion's
/// arithmetic far from underflow and overflow.
pub const MIN_LENGTH: f64 = 1e-12;
/// The largest leadscrew pitch or distance per revolution (units).
pub const MAX_LENGTH: f64 = 1e12;
/// Units per load revolution of a rotary axis (degrees).
pub const DEGREES_PER_REVOLUTION: f64 = 360.0;

/// The type of an encoder's actual value (S7 `Sensor[n].Type`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[doc(alias = "Sensor.Type")]
pub enum EncoderKind {
    /// 0: incremental; the position after power-on is arbitrary and the axis needs homing.
    Incremental,
    /// 1: absolute; the measuring range exceeds the traversing range. Adjusted once (MC_Home 6/7);
    /// the offset is retentive.
    Absolute,
    /// 2: cyclic absolute; the measuring range is smaller than the traversing range, so the count
    /// of traversed encoder ranges is retentive too. Moving more than half the encoder range while
    /// powered off corrupts the position (the manual says so; nothing can detect it).
    CyclicAbsolute,
}

impl EncoderKind {
    /// The S7 `Sensor[n].Type` value (0, 1, 2).
    pub const fn s7_type(self) -> u8 {
        match self {
            Self::Incremental => 0,
            Self::Absolute => 1,
            Self::CyclicAbsolute => 2,
        }
    }
}

/// Where the encoder sits (S7 `Sensor[n].MountingMode`).
#[derive(Copy, Clone, Debug, PartialEq)]
#[doc(alias = "Sensor.MountingMode")]
pub enum Mounting {
    /// 0: on the motor shaft; one encoder revolution is one motor revolution, and the load gear
    /// and leadscrew lie between it and the load.
    MotorShaft,
    /// 1: on the load side; one encoder revolution is one load revolution (the leadscrew still
    /// applies on a linear axis).
    LoadSide,
    /// 2: an external measuring system; one encoder revolution is `distance_per_revolution`
    /// units, neither gear nor leadscrew applies.
    External {
        /// `Sensor[n].Parameter.DistancePerRevolution` (units, [`MIN_LENGTH`]..=[`MAX_LENGTH`]).
        distance_per_revolution: f64,
    },
}

/// An encoder's configuration (S7 `Sensor[n].*`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct EncoderConfig {
    /// `Sensor[n].Type`.
    pub kind: EncoderKind,
    /// `Sensor[n].Parameter.StepsPerRevolution` (1..=8388608).
    #[doc(alias = "StepsPerRevolution")]
    pub steps_per_revolution: u32,
    /// `Sensor[n].Parameter.FineResolutionXist1` (0..=31 bits): the raw value counts
    /// `steps_per_revolution * 2^fine_resolution_bits` per revolution. 0 for a CiA 402 0x6064.
    #[doc(alias = "FineResolutionXist1")]
    pub fine_resolution_bits: u8,
    /// `Sensor[n].Parameter.DeterminableRevolutions`: the multiturn range of an absolute or cyclic
    /// absolute encoder (1 = single turn, >= 1); ignored for an incremental encoder.
    #[doc(alias = "DeterminableRevolutions")]
    pub determinable_revolutions: u32,
    /// Width of the raw word that wraps (1..=32 bits): 32 for a 32-bit counter or a CiA 402
    /// 0x6064, e.g. 25 for an SSI encoder (IEC 61800-7-201 (CiA 402) drive profile, 0x6064; the
    /// EL5001 SSI counter value). For a cyclic absolute encoder its range
    /// (`steps * 2^fine * revolutions`) must be exactly `2^raw_bits`; for an absolute encoder
    /// at most that.
    pub raw_bits: u8,
    /// `Sensor[n].InverseDirection`: the actual value counts the other way.
    #[doc(alias = "Sensor.InverseDirection")]
    pub inverse: bool,
    /// `Sensor[n].MountingMode`.
    pub mounting: Mounting,
}

/// The mechanics between motor and load (S7 `LoadGear.*`, `Mechanics.LeadScrew`,
/// `Actor.InverseDirection`, `Actor.Efficiency`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Mechanics {
    /// `LoadGear.Numerator`: motor revolutions (>= 1) ...
    #[doc(alias = "LoadGear.Numerator")]
    pub load_gear_numerator: u32,
    /// `LoadGear.Denominator`: ... per this many load revolutions (>= 1).
    #[doc(alias = "LoadGear.Denominator")]
    pub load_gear_denominator: u32,
    /// `Mechanics.LeadScrew`: a linear axis moves this many units per load revolution
    /// ([`MIN_LENGTH`]..=[`MAX_LENGTH`]). `None`: a rotary axis, whose unit is the degree: 360
    /// units per load revolution ([`DEGREES_PER_REVOLUTION`]).
    #[doc(alias = "Mechanics.LeadScrew")]
    pub leadscrew_pitch: Option<f64>,
    /// `Actor.InverseDirection`: the drive's setpoint (increments, velocity, torque) is inverted.
    #[doc(alias = "Actor.InverseDirection")]
    pub inverse_drive: bool,
    /// `Actor.Efficiency` of the gear and leadscrew, for the torque/force conversion (0 < e <= 1;
    /// inferred: 0 is refused, since the conversion back to a motor torque divides by it).
    #[doc(alias = "Actor.Efficiency")]
    pub efficiency: f64,
    /// The drive's position increments per motor revolution, in which it takes its target
    /// (IEC 61800-7-201 (CiA 402) drive profile, 0x607A target position, scaled by 0x608F position
    /// encoder resolution with 0x6091 gear ratio and 0x6092 feed constant at 1:1; inferred: those
    /// two left at their defaults). `None`: the encoder's `steps * 2^fine` per revolution, right
    /// when the encoder is the drive's motor encoder (0x6064 and 0x607A in the same increments).
    #[doc(alias = "0x608F")]
    pub drive_increments_per_revolution: Option<u32>,
}

impl Default for Mechanics {
    /// A rotary axis directly on the motor: gear 1:1, no inversion, efficiency 1, the drive in
    /// the encoder's increments.
    fn default() -> Self {
        Self {
            load_gear_numerator: 1,
            load_gear_denominator: 1,
            leadscrew_pitch: None,
            inverse_drive: false,
            efficiency: 1.0,
            drive_increments_per_revolution: None,
        }
    }
}

/// The field of an [`EncoderConfig`] or [`Mechanics`] that a [`MechanicsError`] names.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum MechanicsField {
    /// [`EncoderConfig::steps_per_revolution`].
    StepsPerRevolution,
    /// [`EncoderConfig::fine_resolution_bits`].
    FineResolutionBits,
    /// [`EncoderConfig::determinable_revolutions`].
    DeterminableRevolutions,
    /// [`EncoderConfig::raw_bits`].
    RawBits,
    /// [`Mounting::External::distance_per_revolution`].
    DistancePerRevolution,
    /// [`Mechanics::load_gear_numerator`].
    LoadGearNumerator,
    /// [`Mechanics::load_gear_denominator`].
    LoadGearDenominator,
    /// [`Mechanics::leadscrew_pitch`].
    LeadscrewPitch,
    /// [`Mechanics::efficiency`].
    Efficiency,
    /// [`Mechanics::drive_increments_per_revolution`].
    DriveIncrementsPerRevolution,
}

impl MechanicsField {
    /// The field's name and its S7 tag.
    pub const fn text(self) -> &'static str {
        match self {
            Self::StepsPerRevolution => {
                "steps_per_revolution (Sensor[n].Parameter.StepsPerRevolution)"
            }
            Self::FineResolutionBits => {
                "fine_resolution_bits (Sensor[n].Parameter.FineResolutionXist1)"
            }
            Self::DeterminableRevolutions => {
                "determinable_revolutions (Sensor[n].Parameter.DeterminableRevolutions)"
            }
            Self::RawBits => "raw_bits",
            Self::DistancePerRevolution => {
                "distance_per_revolution (Sensor[n].Parameter.DistancePerRevolution)"
            }
            Self::LoadGearNumerator => "load_gear_numerator (LoadGear.Numerator)",
            Self::LoadGearDenominator => "load_gear_denominator (LoadGear.Denominator)",
            Self::LeadscrewPitch => "leadscrew_pitch (Mechanics.LeadScrew)",
            Self::Efficiency => "efficiency (Actor.Efficiency)",
            Self::DriveIncrementsPerRevolution => "drive_increments_per_revolution (0x608F)",
        }
    }
}

/// The rule a field of an [`EncoderConfig`] or [`Mechanics`] breaks.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum MechanicsRule {
    /// An integer outside `min..=max`.
    OutOfRange {
        /// The value given.
        found: u64,
        /// The smallest value allowed.
        min: u64,
        /// The largest value allowed.
        max: u64,
    },
    /// A length (pitch, distance per revolution) outside [`MIN_LENGTH`]`..=`[`MAX_LENGTH`] units
    /// (not a number, not positive, or too small or large for the conversion's arithmetic).
    LengthOutOfRange,
    /// An efficiency outside `(0, 1]`.
    NotFraction,
    /// An absolute encoder whose range (`steps * 2^fine * revolutions` counts) exceeds the raw
    /// word (`2^raw_bits`).
    RangeExceedsRawWord {
        /// The encoder's range in counts.
        range: u128,
        /// The raw word's width.
        raw_bits: u8,
    },
    /// A cyclic absolute encoder whose range is not exactly the raw word's `2^raw_bits` (its
    /// count of traversed ranges is only meaningful when the word wraps where the range does;
    /// inferred).
    RangeNotRawWord {
        /// The encoder's range in counts.
        range: u128,
        /// The raw word's width.
        raw_bits: u8,
    },
}

impl fmt::Display for MechanicsRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::OutOfRange { found, min, max } => {
                write!(f, "is {found}, must be in {min}..={max}")
            }
            Self::LengthOutOfRange => {
                write!(f, "must be a number from {MIN_LENGTH:e} to {MAX_LENGTH:e}")
            }
            Self::NotFraction => f.write_str("must be greater than 0 and at most 1"),
            Self::RangeExceedsRawWord { range, raw_bits } => write!(
                f,
                "the absolute encoder's range of {range} counts exceeds the {raw_bits}-bit raw word"
            ),
            Self::RangeNotRawWord { range, raw_bits } => write!(
                f,
                "the cyclic absolute encoder's range of {range} counts must be exactly the \
                 {raw_bits}-bit raw word (2^{raw_bits})"
            ),
        }
    }
}

/// An encoder or mechanics value that cannot be used: which field, and the rule it breaks.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct MechanicsError {
    /// The field.
    pub field: MechanicsField,
    /// The rule it breaks.
    pub rule: MechanicsRule,
}

impl fmt::Display for MechanicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.field.text(), self.rule)
    }
}

impl std::error::Error for MechanicsError {}

fn in_range(field: MechanicsField, found: u64, min: u64, max: u64) -> Result<(), MechanicsError> {
    if (min..=max).contains(&found) {
        Ok(())
    } else {
        Err(MechanicsError {
            field,
            rule: MechanicsRule::OutOfRange { found, min, max },
        })
    }
}

fn length(field: MechanicsField, x: f64) -> Result<(), MechanicsError> {
    if (MIN_LENGTH..=MAX_LENGTH).contains(&x) {
        Ok(())
    } else {
        Err(MechanicsError {
            field,
            rule: MechanicsRule::LengthOutOfRange,
        })
    }
}

/// Extends a wrapping raw word of `raw_bits` bits into an exact `i64` count.
///
/// Each [`update`](Self::update) adds the shortest signed difference from the previous raw value
/// modulo `2^raw_bits`, a number in `[-2^(raw_bits-1), 2^(raw_bits-1))`; so the count is exact
/// across any number of wraps as long as the encoder moves less than half its raw range per
/// update (a full half range backwards is still read right). Integer arithmetic only. The count
/// always equals the raw value modulo `2^raw_bits`, so `count >> raw_bits` is the number of
/// traversed ranges ([`ranges`](Self::ranges)), what a cyclic absolute encoder retains (S7-1500T
/// Motion Control V4.0 function manual, 'Drive and encoder connection', actual value types).
///
/// After `2^63` counts the count wraps (`i64` wrapping addition); at `2^34` counts per
/// revolution that is `2^29` revolutions. A modulo axis can [`rebase`](Self::rebase) by whole
/// periods long before.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
#[doc(alias = "0x6064")]
pub struct RawCounter {
    raw_bits: u8,
    mask: u64,
    half: u64,
    raw: u64,
    count: i64,
}

impl RawCounter {
    /// A counter of `raw_bits` (1..=32, not checked) at raw value `raw` and count `count`.
    const fn build(raw_bits: u8, raw: u32, count: i64) -> Self {
        let modulus = 1u64 << raw_bits;
        Self {
            raw_bits,
            mask: modulus - 1,
            half: modulus >> 1,
            raw: raw as u64 & (modulus - 1),
            count,
        }
    }

    fn with_count(raw_bits: u8, raw: u32, count: i64) -> Result<Self, MechanicsError> {
        in_range(
            MechanicsField::RawBits,
            u64::from(raw_bits),
            1,
            u64::from(MAX_RAW_BITS),
        )?;
        Ok(Self::build(raw_bits, raw, count))
    }

    /// Starts at `first_raw` read as an unsigned number (`0..2^raw_bits`; bits above `raw_bits`
    /// are ignored): the count of an SSI or a 32-bit counter. `raw_bits` must be in 1..=32.
    pub fn new(raw_bits: u8, first_raw: u32) -> Result<Self, MechanicsError> {
        let mut c = Self::with_count(raw_bits, first_raw, 0)?;
        c.count = c.raw as i64; // < 2^32: exact.
        Ok(c)
    }

    /// Starts at `first_raw` read as a two's complement number of `raw_bits` bits: the count of a
    /// signed word such as the CiA 402 0x6064 (INT32).
    pub fn new_signed(raw_bits: u8, first_raw: u32) -> Result<Self, MechanicsError> {
        let mut c = Self::with_count(raw_bits, first_raw, 0)?;
        c.count = c.signed_difference(0, c.raw);
        Ok(c)
    }

    /// Resumes after a restart from the count retained before it (`retained`, e.g. of a cyclic
    /// absolute encoder) and the first raw value now: the count moves from `retained` by the
    /// shortest difference to `first_raw`. Exact while the encoder moved less than half its raw
    /// range since the count was retained (see [`retain_due`](Self::retain_due)).
    pub fn resume(raw_bits: u8, retained: i64, first_raw: u32) -> Result<Self, MechanicsError> {
        let mut c = Self::with_count(raw_bits, 0, retained)?;
        // The raw value the retained count stood for.
        c.raw = (retained as u64) & c.mask;
        c.update(first_raw);
        Ok(c)
    }

    /// The shortest signed difference from raw `from` to raw `to`, in `[-half, half)`.
    #[inline]
    fn signed_difference(&self, from: u64, to: u64) -> i64 {
        let d = to.wrapping_sub(from) & self.mask;
        // Both terms are below 2^32: exact in i64.
        if d >= self.half {
            d as i64 - (self.mask as i64 + 1)
        } else {
            d as i64
        }
    }

    /// Takes this cycle's raw value (bits above `raw_bits` are ignored) and returns the count.
    #[inline]
    pub fn update(&mut self, raw: u32) -> i64 {
        let raw = u64::from(raw) & self.mask;
        let d = self.signed_difference(self.raw, raw);
        self.raw = raw;
        self.count = self.count.wrapping_add(d);
        self.count
    }

    /// The count of a raw value near the present one, without taking it: e.g. a touch probe's
    /// latched position (CiA 402 0x60BA, in the same increments), which lies less than half the
    /// raw range from the present position.
    #[inline]
    pub fn nearest(&self, raw: u32) -> i64 {
        let raw = u64::from(raw) & self.mask;
        self.count
            .wrapping_add(self.signed_difference(self.raw, raw))
    }

    /// The count.
    pub fn count(&self) -> i64 {
        self.count
    }

    /// The last raw value (masked to `raw_bits`).
    pub fn raw(&self) -> u32 {
        // Masked to at most 32 bits.
        self.raw as u32
    }

    /// The width of the raw word.
    pub fn raw_bits(&self) -> u8 {
        self.raw_bits
    }

    /// The number of traversed raw ranges: `floor(count / 2^raw_bits)`.
    pub fn ranges(&self) -> i64 {
        self.count >> self.raw_bits
    }

    /// Whether the count moved a quarter of the raw range or more away from `retained`, the
    /// count last retained. Retaining the count whenever this is true keeps a
    /// [`resume`](Self::resume) exact as long as the encoder moves less than a quarter range
    /// while the node is off (inferred: the manual allows half a range while powered off with a
    /// retentive memory written at power loss; a file cannot be written every cycle, so a
    /// quarter range is spent on the motion since the last write).
    pub fn retain_due(&self, retained: i64) -> bool {
        let quarter = (self.half >> 1).max(1);
        self.count.wrapping_sub(retained).unsigned_abs() >= quarter
    }

    /// Shifts the count by `-delta` (e.g. whole modulo periods of counts), keeping it equal to
    /// the raw value modulo `2^raw_bits` only if `delta` is a multiple of it. Refuses (and
    /// changes nothing) on overflow.
    pub fn rebase(&mut self, delta: i64) -> Option<i64> {
        self.count = self.count.checked_sub(delta)?;
        Some(self.count)
    }
}

/// Splits `a` into two halves of 26 and 27 significant bits whose sum is `a` (Veltkamp).
#[inline]
fn split(a: f64) -> (f64, f64) {
    let t = 134_217_729.0 * a; // 2^27 + 1
    let hi = t - (t - a);
    (hi, a - hi)
}

/// `a * b` as `p + e` exactly, `p` the rounded product (Dekker; no FMA needed; exact while no
/// overflow or underflow occurs, which the magnitudes here exclude).
#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// A ratio between counts and units, units per count held as an unevaluated sum `hi + lo`
/// (double-double, about 104 significant bits), so that a count's position is the correctly
/// rounded product but for ties within 2^-100 of a rounding boundary.
#[derive(Copy, Clone, Debug, PartialEq)]
struct Ratio {
    /// Counts per period (>= 1, < 2^87).
    counts_per_period: u128,
    /// Units per period (finite, > 0).
    units_per_period: f64,
    /// Units per count, high part (the rounded ratio).
    hi: f64,
    /// Units per count, low part.
    lo: f64,
    /// `lo / hi`, for the first estimate of [`Ratio::counts`] (the same value it divided out
    /// each call before).
    lo_over_hi: f64,
    /// `hi` split in halves ([`split`]), for the exact products of [`Ratio::units`] (the same
    /// halves [`two_product`] would split it into each call).
    hi_split: (f64, f64),
    /// `1 / hi`, for velocities in counts per second by a product.
    per_hi: f64,
    /// `(1 - lo / hi) / hi`, counts per unit to first order in `lo / hi`: the first estimate of
    /// [`Ratio::counts`] by a product instead of a division.
    per_unit: f64,
    /// The counts per period as a double, when it is exact (`0.0` when not).
    counts_per_period_f64: f64,
    /// `|count|` below this has an exact product with `units_per_period` (at most 53
    /// significant bits), for [`Ratio::units`]'s quotient; 0 when the units or the counts per
    /// period are not exact doubles (the quotient is then never taken).
    quotient_limit: u64,
}

/// The number of significant bits of the finite, non-zero `x` (1..=53; 53 for subnormals,
/// which never occur here).
fn significant_bits(x: f64) -> u32 {
    let bits = x.to_bits();
    let exponent = (bits >> 52) & 0x7FF;
    if exponent == 0 {
        return 53;
    }
    let mantissa = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
    53 - mantissa.trailing_zeros()
}

/// `x` rounded to an integer (ties away from zero, as `f64::round`) for `|x| < 2^52`, without
/// the library call `f64::round` is without SSE4.1: `x as i64` truncates and the fraction
/// `x - trunc(x)` is exact there. Beyond `2^52` (every double an integer) and for NaN (0) the
/// saturating cast, as `f64::round` followed by `as i64`.
#[inline]
fn round_to_i64(x: f64) -> i64 {
    if x.is_nan() || x.abs() >= 4_503_599_627_370_496.0 {
        return x as i64;
    }
    let i = x as i64;
    let f = x - i as f64;
    if f >= 0.5 {
        i + 1
    } else if f <= -0.5 {
        i - 1
    } else {
        i
    }
}

impl Ratio {
    /// `counts_per_period` counts are `periods * unit` units (`periods` a gear's whole number
    /// of revolutions, `unit` the units of one; their product is taken exactly).
    fn new(counts_per_period: u128, periods: u32, unit: f64) -> Self {
        let (a_hi, a_lo) = two_product(f64::from(periods), unit);
        // u128 to f64 rounds to nearest; the rest is below 2^35, exact.
        let b_hi = counts_per_period as f64;
        let b_lo = (counts_per_period as i128 - b_hi as i128) as f64;
        let hi = a_hi / b_hi;
        let (p, e) = two_product(hi, b_hi);
        // a - hi * b, with a_hi - p exact (Sterbenz: p is within an ulp of a_hi).
        let residual = (((a_hi - p) - e) + a_lo) - hi * b_lo;
        let lo = residual / b_hi;
        // The quotient `count * a / b` is one product and one division when both are exact
        // doubles: the product exact for counts of at most `53 - significant_bits(a)` bits.
        let exact = a_lo == 0.0 && b_lo == 0.0 && a_hi.is_finite() && a_hi != 0.0;
        let quotient_limit = if exact {
            1u64 << (53 - significant_bits(a_hi))
        } else {
            0
        };
        Self {
            counts_per_period,
            units_per_period: a_hi,
            hi,
            lo,
            lo_over_hi: lo / hi,
            hi_split: split(hi),
            per_hi: 1.0 / hi,
            per_unit: (1.0 - lo / hi) / hi,
            counts_per_period_f64: if exact { b_hi } else { 0.0 },
            quotient_limit,
        }
    }

    /// Units of `count`, the correctly rounded `count * a / b` by one exact product and one
    /// division where [`Ratio::new`] found `a` (units per period) and `b` (counts per period)
    /// exact doubles and `count * a` is exact (`|count| < quotient_limit`); the double-double
    /// product ([`Ratio::units_double_double`]) elsewhere. The two agree wherever the
    /// double-double product is correctly rounded (all but ties within 2^-100 of a rounding
    /// boundary; a quotient of integers below 2^53 has none: `count * a / b` is either a
    /// double or at least 2^-53 / b of an ulp from the half-way point), which the unit test
    /// below checks on random scalings and counts.
    #[inline]
    fn units(&self, count: i64) -> f64 {
        if count.unsigned_abs() < self.quotient_limit {
            // Both operands exact: IEEE division rounds the exact quotient correctly.
            return (count as f64 * self.units_per_period) / self.counts_per_period_f64;
        }
        self.units_double_double(count)
    }

    /// Units of `count`: the product with both parts, `count` itself split when beyond 2^53.
    #[inline]
    fn units_double_double(&self, count: i64) -> f64 {
        let c_hi = count as f64;
        let c_lo = if count.unsigned_abs() <= 1 << 53 {
            0.0
        } else {
            // |count - c_hi| <= 2^10: exact (i128: c_hi may be 2^63, beyond i64).
            (i128::from(count) - c_hi as i128) as f64
        };
        // `two_product(c_hi, hi)` with `hi`'s halves split once: the same operations.
        let p = c_hi * self.hi;
        let (ah, al) = split(c_hi);
        let (bh, bl) = self.hi_split;
        let e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
        p + (e + c_hi * self.lo + c_lo * self.hi)
    }

    /// The count whose units are nearest to `x` (of two equally near, either); saturates at the
    /// ends of i64, 0 for NaN.
    #[inline]
    fn counts(&self, x: f64) -> i64 {
        if x.is_nan() {
            return 0;
        }
        if x.is_infinite() {
            return if x > 0.0 { i64::MAX } else { i64::MIN };
        }
        // The common case without a division or the double-double products. For |c| <= 2^40
        // (|lo| <= hi·2^-53): `c·hi - x` as computed is within 3·2^-12·hi of `units(c) - x`,
        // and two neighbouring `units` are at least (1 - 2^-11)·hi apart. So `|c·hi - x| <
        // 0.49·hi` puts `units(c)` within 0.491·hi of `x` and its neighbour towards `x` more
        // than 0.508·hi away: `refine` would keep `c` at its first comparison, and no other
        // count passes the test. So it does not matter how `c` was estimated: the product with
        // `per_unit`, truncated after adding half a count, is the same count as the division
        // below wherever it passes. Float to integer casts saturate.
        let e = x * self.per_unit;
        let c = (e + 0.5f64.copysign(e)) as i64;
        if c.unsigned_abs() <= 1 << 40 && ((c as f64) * self.hi - x).abs() < 0.49 * self.hi {
            return c;
        }
        // x / (hi + lo) to first order in lo / hi: within a count of the nearest for
        // |count| <= 2^52.
        let q = x / self.hi;
        let c = (q - q * self.lo_over_hi).round() as i64;
        if c.unsigned_abs() <= 1 << 40 && ((c as f64) * self.hi - x).abs() < 0.49 * self.hi {
            return c;
        }
        self.refine(c, x)
    }

    /// Steps from `c` towards `x` while the next count is nearer (positions grow with the count,
    /// so the nearest count lies that way; at most a few steps).
    #[inline]
    fn refine(&self, mut c: i64, x: f64) -> i64 {
        let mut u = self.units(c);
        let up = u < x;
        for _ in 0..4 {
            if u == x {
                break;
            }
            let next = if up {
                c.saturating_add(1)
            } else {
                c.saturating_sub(1)
            };
            let v = self.units(next);
            if (v - x).abs() < (u - x).abs() {
                (c, u) = (next, v);
            } else {
                break;
            }
        }
        c
    }
}

/// The conversion between an encoder's counts (and a drive's increments) and the axis' units.
///
/// Built by [`Scaling::new`] from an [`EncoderConfig`] and the [`Mechanics`]; `Copy`, and every
/// method is pure and allocation-free. A count is one `2^-fine` step of the encoder: the raw
/// value as a [`RawCounter`] extends it.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Scaling {
    encoder: EncoderConfig,
    mechanics: Mechanics,
    /// Encoder counts to units (before inversion).
    sensor: Ratio,
    /// Drive increments to units (before inversion).
    drive: Ratio,
    /// -1 when the encoder is inverted, else 1.
    sensor_sign: f64,
    /// -1 when the drive is inverted, else 1.
    drive_sign: f64,
    /// Load torque (or force) per motor torque.
    torque_factor: f64,
}

impl Scaling {
    /// Validates `encoder` and `mechanics` and builds the conversion. Refuses, naming the field
    /// and the rule, any value outside the S7 ranges ('Mechanics': steps 1..=8388608, fine
    /// resolution 0..=31 bits, gear 1..=4294967295 : 1..=4294967295), a pitch or distance per
    /// revolution outside [`MIN_LENGTH`]..=[`MAX_LENGTH`], a raw word outside 1..=32 bits, an
    /// absolute encoder range that does not fit the raw word, and an efficiency outside (0, 1].
    pub fn new(encoder: &EncoderConfig, mechanics: &Mechanics) -> Result<Self, MechanicsError> {
        validate_encoder(encoder)?;
        validate_mechanics(mechanics)?;
        let counts_per_revolution = counts_per_revolution(encoder);
        let numerator = u128::from(mechanics.load_gear_numerator);
        let denominator = mechanics.load_gear_denominator;
        let load_units = mechanics.leadscrew_pitch.unwrap_or(DEGREES_PER_REVOLUTION);
        let sensor = match encoder.mounting {
            // `numerator` motor revolutions are `denominator` load revolutions.
            Mounting::MotorShaft => {
                Ratio::new(counts_per_revolution * numerator, denominator, load_units)
            }
            Mounting::LoadSide => Ratio::new(counts_per_revolution, 1, load_units),
            Mounting::External {
                distance_per_revolution,
            } => Ratio::new(counts_per_revolution, 1, distance_per_revolution),
        };
        let drive_per_revolution = mechanics
            .drive_increments_per_revolution
            .map_or(counts_per_revolution, u128::from);
        let drive = Ratio::new(drive_per_revolution * numerator, denominator, load_units);
        let sign = |inverse: bool| if inverse { -1.0 } else { 1.0 };
        let gear = f64::from(mechanics.load_gear_numerator) / f64::from(denominator);
        // Energy: F dx = e T dtheta, with dtheta = 2 pi gear per load revolution of `pitch`.
        let per_load_revolution = match mechanics.leadscrew_pitch {
            Some(pitch) => core::f64::consts::TAU / pitch,
            None => 1.0,
        };
        Ok(Self {
            encoder: *encoder,
            mechanics: *mechanics,
            sensor,
            drive,
            sensor_sign: sign(encoder.inverse),
            drive_sign: sign(mechanics.inverse_drive),
            torque_factor: sign(mechanics.inverse_drive)
                * mechanics.efficiency
                * gear
                * per_load_revolution,
        })
    }

    /// The encoder configuration.
    pub fn encoder(&self) -> &EncoderConfig {
        &self.encoder
    }

    /// The mechanics.
    pub fn mechanics(&self) -> &Mechanics {
        &self.mechanics
    }

    /// Encoder counts per encoder revolution: `steps_per_revolution * 2^fine_resolution_bits`.
    pub fn counts_per_revolution(&self) -> u64 {
        // At most 2^23 * 2^31 = 2^54.
        counts_per_revolution(&self.encoder) as u64
    }

    /// A [`RawCounter`] for this encoder's raw word, started at `first_raw` (unsigned).
    pub fn raw_counter(&self, first_raw: u32) -> RawCounter {
        // `raw_bits` was validated by `new`.
        let c = RawCounter::build(self.encoder.raw_bits, first_raw, 0);
        RawCounter {
            count: c.raw as i64,
            ..c
        }
    }

    /// The position (units) of encoder count `count`, with the encoder's inversion, the fine
    /// resolution, its mounting, the load gear and the leadscrew. No offset: add the homing or
    /// [`AbsoluteAdjustment`] offset.
    #[inline]
    pub fn position(&self, count: i64) -> f64 {
        self.sensor_sign * self.sensor.units(count)
    }

    /// The encoder count whose [`position`](Self::position) is nearest to `position`
    /// (saturating at the ends of `i64`; 0 for NaN).
    #[inline]
    pub fn count(&self, position: f64) -> i64 {
        self.sensor.counts(self.sensor_sign * position)
    }

    /// The velocity (units/s) of `counts_per_s` encoder counts per second.
    #[inline]
    pub fn velocity(&self, counts_per_s: f64) -> f64 {
        self.sensor_sign * counts_per_s * self.sensor.hi
    }

    /// Encoder counts per second of `units_per_s`.
    #[inline]
    pub fn counts_per_second(&self, units_per_s: f64) -> f64 {
        self.sensor_sign * units_per_s / self.sensor.hi
    }

    /// The drive's target in its position increments for `position` (no offset), wrapping like
    /// the 32-bit counter of the CiA 402 0x607A target position: the nearest increment, with the
    /// drive's inversion, modulo 2^32 as an `i32`.
    #[inline]
    #[doc(alias = "0x607A")]
    pub fn drive_increments(&self, position: f64) -> i32 {
        // Truncation to the low 32 bits is the wrap of the drive's counter.
        self.drive.counts(self.drive_sign * position) as i32
    }

    /// The position (units, no offset) of the drive's extended increment count `increments`
    /// (e.g. a CiA 402 0x6064 or 0x60BA extended by a [`RawCounter`]).
    #[inline]
    pub fn drive_position(&self, increments: i64) -> f64 {
        self.drive_sign * self.drive.units(increments)
    }

    /// Drive increments per second of `units_per_s` (a CSV target 0x60FF or a velocity offset
    /// 0x60B1 in increments/s).
    #[inline]
    #[doc(alias = "0x60FF")]
    pub fn drive_increments_per_second(&self, units_per_s: f64) -> f64 {
        self.drive_sign * units_per_s / self.drive.hi
    }

    /// [`drive_increments_per_second`](Self::drive_increments_per_second) rounded to the
    /// nearest integer (ties away from zero) and saturated to an `i32`, as a CSV target 0x60FF
    /// or a velocity offset 0x60B1 is written: the same integer, by a product with `1 / hi`
    /// where that is provably the same. For `|r| < 2^31` the product and the quotient differ by
    /// at most 2 ulp of `r`, below 2^-20; a product whose fraction is within 0.49999 of the
    /// nearest integer `n` puts the quotient within 0.5 of `n` too. Elsewhere (near a tie, out
    /// of range, NaN) the quotient, rounded as before.
    #[inline]
    pub fn drive_increments_per_second_i32(&self, units_per_s: f64) -> i32 {
        let r = self.drive_sign * units_per_s * self.drive.per_hi;
        if r.abs() < 2_147_483_647.0 {
            let n = round_to_i64(r);
            if (r - n as f64).abs() < 0.499_99 {
                // |n| < 2^31: in range.
                return n as i32;
            }
        }
        self.drive_increments_per_second(units_per_s)
            .round()
            .clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
    }

    /// The load torque (rotary axis, in the motor torque's unit) or force (linear axis, in the
    /// torque's unit per position unit: N·m per mm is kN) that `motor_torque` produces: gear,
    /// leadscrew (`2π / pitch`), efficiency and the drive's inversion.
    #[inline]
    pub fn load_torque(&self, motor_torque: f64) -> f64 {
        motor_torque * self.torque_factor
    }

    /// The motor torque that produces `load` (the inverse of [`load_torque`](Self::load_torque)).
    #[inline]
    pub fn motor_torque(&self, load: f64) -> f64 {
        load / self.torque_factor
    }

    /// Load torque or force per motor torque (see [`load_torque`](Self::load_torque)).
    pub fn torque_factor(&self) -> f64 {
        self.torque_factor
    }

    /// A 64-bit fingerprint (FNV-1a) of what maps counts to positions: the encoder's kind, raw
    /// word, multiturn range, inversion and the count-to-unit ratio. An [`AbsoluteAdjustment`]
    /// made under another fingerprint is void (S7-1500T Motion Control V4.0 function manual,
    /// 'When Homed is lost': an encoder configuration change needs a new adjustment).
    pub fn fingerprint(&self) -> u64 {
        let e = &self.encoder;
        let mut h = Fnv::new();
        h.bytes(&[e.kind.s7_type(), e.raw_bits, u8::from(e.inverse)]);
        h.bytes(&e.determinable_revolutions.to_le_bytes());
        h.bytes(&self.sensor.counts_per_period.to_le_bytes());
        h.bytes(&self.sensor.units_per_period.to_bits().to_le_bytes());
        h.finish()
    }
}

/// FNV-1a, 64 bits.
struct Fnv(u64);

impl Fnv {
    const fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 = (self.0 ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3);
        }
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

fn counts_per_revolution(e: &EncoderConfig) -> u128 {
    u128::from(e.steps_per_revolution) << e.fine_resolution_bits
}

fn validate_encoder(e: &EncoderConfig) -> Result<(), MechanicsError> {
    use MechanicsField as F;
    in_range(
        F::StepsPerRevolution,
        u64::from(e.steps_per_revolution),
        1,
        u64::from(MAX_STEPS_PER_REVOLUTION),
    )?;
    in_range(
        F::FineResolutionBits,
        u64::from(e.fine_resolution_bits),
        0,
        u64::from(MAX_FINE_RESOLUTION_BITS),
    )?;
    in_range(
        F::RawBits,
        u64::from(e.raw_bits),
        1,
        u64::from(MAX_RAW_BITS),
    )?;
    if let Mounting::External {
        distance_per_revolution,
    } = e.mounting
    {
        length(F::DistancePerRevolution, distance_per_revolution)?;
    }
    if e.kind == EncoderKind::Incremental {
        return Ok(());
    }
    in_range(
        F::DeterminableRevolutions,
        u64::from(e.determinable_revolutions),
        1,
        u64::from(u32::MAX),
    )?;
    let range = counts_per_revolution(e) * u128::from(e.determinable_revolutions);
    let word = 1u128 << e.raw_bits;
    let rule = match e.kind {
        EncoderKind::CyclicAbsolute if range != word => MechanicsRule::RangeNotRawWord {
            range,
            raw_bits: e.raw_bits,
        },
        _ if range > word => MechanicsRule::RangeExceedsRawWord {
            range,
            raw_bits: e.raw_bits,
        },
        _ => return Ok(()),
    };
    Err(MechanicsError {
        field: F::DeterminableRevolutions,
        rule,
    })
}

fn validate_mechanics(m: &Mechanics) -> Result<(), MechanicsError> {
    use MechanicsField as F;
    let max = u64::from(u32::MAX);
    in_range(
        F::LoadGearNumerator,
        u64::from(m.load_gear_numerator),
        1,
        max,
    )?;
    in_range(
        F::LoadGearDenominator,
        u64::from(m.load_gear_denominator),
        1,
        max,
    )?;
    if let Some(pitch) = m.leadscrew_pitch {
        length(F::LeadscrewPitch, pitch)?;
    }
    if !(m.efficiency > 0.0 && m.efficiency <= 1.0) {
        return Err(MechanicsError {
            field: F::Efficiency,
            rule: MechanicsRule::NotFraction,
        });
    }
    if let Some(n) = m.drive_increments_per_revolution {
        in_range(F::DriveIncrementsPerRevolution, u64::from(n), 1, max)?;
    }
    Ok(())
}

/// The absolute encoder adjustment (S7-1500T Motion Control V4.0 function manual, 'Direct homing
/// and absolute adjustment'; MC_Home mode 6 relative, mode 7 absolute): an offset added to the
/// encoder's position, retentive in S7 as `StatusSensor[n].AbsEncoderOffset`, plus, for a cyclic
/// absolute encoder, the count when retained (its traversed ranges and raw value; see
/// [`RawCounter::resume`]).
///
/// [`to_bytes`](Self::to_bytes) gives a fixed little-endian layout of [`ADJUSTMENT_LEN`] bytes:
/// `[0]` version ([`ADJUSTMENT_VERSION`]), `[1..9]` offset (f64), `[9..17]` count (i64),
/// `[17..25]` the [`Scaling::fingerprint`] it was made under (u64).
#[derive(Copy, Clone, Debug, PartialEq)]
#[doc(alias = "AbsEncoderOffset")]
pub struct AbsoluteAdjustment {
    /// `StatusSensor[n].AbsEncoderOffset` (units): actual position = encoder position + offset.
    pub offset: f64,
    /// The encoder count when retained: for a cyclic absolute encoder, `count >> raw_bits` is the
    /// number of traversed ranges S7 retains, the low bits the raw value then. Any value for the
    /// other kinds (0 by convention).
    pub count: i64,
    /// The [`Scaling::fingerprint`] of the configuration it was made under.
    pub fingerprint: u64,
}

/// The version byte of [`AbsoluteAdjustment::to_bytes`].
pub const ADJUSTMENT_VERSION: u8 = 1;
/// The length of [`AbsoluteAdjustment::to_bytes`].
pub const ADJUSTMENT_LEN: usize = 25;

/// Why bytes are not an [`AbsoluteAdjustment`].
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum AdjustmentError {
    /// Not [`ADJUSTMENT_LEN`] bytes.
    Length {
        /// The length expected.
        expected: usize,
        /// The length found.
        found: usize,
    },
    /// A version byte this build does not read.
    Version {
        /// The version expected.
        expected: u8,
        /// The version found.
        found: u8,
    },
    /// The offset is not a finite number.
    NotFinite,
}

impl fmt::Display for AdjustmentError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Length { expected, found } => write!(
                f,
                "absolute encoder adjustment: {found} bytes, expected {expected}"
            ),
            Self::Version { expected, found } => write!(
                f,
                "absolute encoder adjustment: version {found}, this build reads version {expected}"
            ),
            Self::NotFinite => f.write_str("absolute encoder adjustment: offset not finite"),
        }
    }
}

impl std::error::Error for AdjustmentError {}

impl AbsoluteAdjustment {
    /// MC_Home mode 7 (absolute encoder adjustment, absolute): the offset that makes the actual
    /// position at encoder count `count` equal to `position`.
    pub fn absolute(scaling: &Scaling, count: i64, position: f64) -> Self {
        Self {
            offset: position - scaling.position(count),
            count,
            fingerprint: scaling.fingerprint(),
        }
    }

    /// MC_Home mode 6 (absolute encoder adjustment, relative): the actual position shifted by
    /// `shift`, the encoder standing at `count`.
    pub fn relative(self, scaling: &Scaling, count: i64, shift: f64) -> Self {
        Self {
            offset: self.offset + shift,
            count,
            fingerprint: scaling.fingerprint(),
        }
    }

    /// The actual position at encoder count `count`: the encoder's position plus the offset.
    #[inline]
    pub fn position(&self, scaling: &Scaling, count: i64) -> f64 {
        scaling.position(count) + self.offset
    }

    /// Whether it was made under `scaling`'s configuration (else it is void and the axis is not
    /// homed).
    pub fn matches(&self, scaling: &Scaling) -> bool {
        self.fingerprint == scaling.fingerprint()
    }

    /// The fixed little-endian layout (see the type's documentation).
    pub fn to_bytes(&self) -> [u8; ADJUSTMENT_LEN] {
        let mut b = [0u8; ADJUSTMENT_LEN];
        b[0] = ADJUSTMENT_VERSION;
        b[1..9].copy_from_slice(&self.offset.to_le_bytes());
        b[9..17].copy_from_slice(&self.count.to_le_bytes());
        b[17..25].copy_from_slice(&self.fingerprint.to_le_bytes());
        b
    }

    /// Reads [`to_bytes`](Self::to_bytes)' layout; refuses a wrong length, an unknown version
    /// or a non-finite offset.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, AdjustmentError> {
        let b: &[u8; ADJUSTMENT_LEN] = bytes.try_into().map_err(|_| AdjustmentError::Length {
            expected: ADJUSTMENT_LEN,
            found: bytes.len(),
        })?;
        let [version, rest @ ..] = b;
        if *version != ADJUSTMENT_VERSION {
            return Err(AdjustmentError::Version {
                expected: ADJUSTMENT_VERSION,
                found: *version,
            });
        }
        let mut offset = [0u8; 8];
        let mut count = [0u8; 8];
        let mut fingerprint = [0u8; 8];
        offset.copy_from_slice(&rest[0..8]);
        count.copy_from_slice(&rest[8..16]);
        fingerprint.copy_from_slice(&rest[16..24]);
        let offset = f64::from_le_bytes(offset);
        if !offset.is_finite() {
            return Err(AdjustmentError::NotFinite);
        }
        Ok(Self {
            offset,
            count: i64::from_le_bytes(count),
            fingerprint: u64::from_le_bytes(fingerprint),
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;
    use proptest::prelude::*;
    use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

    /// The drive's ratio of a scaling: `increments` per motor revolution, gear `n : d`, an
    /// optional leadscrew `pitch` (rotary: 360° per load revolution).
    fn drive_ratio(increments: u32, n: u32, d: u32, pitch: Option<f64>) -> Ratio {
        let units = pitch.unwrap_or(DEGREES_PER_REVOLUTION);
        Ratio::new(u128::from(increments) * u128::from(n), d, units)
    }

    /// Issue 11's drives bench: the quotient `count * a / b` of [`Ratio::units`] is the very
    /// double the double-double product gives, on random scalings (some with inexact units
    /// per period, which take the double-double path) and counts of every size up to 2^52,
    /// and the velocity in increments/s by a product rounds to the integer the quotient does.
    #[test]
    fn the_quotient_is_the_double_double_product() {
        let config = Config {
            cases: 20_000,
            failure_persistence: None,
            ..Config::default()
        };
        let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[11; 32]);
        let mut runner = TestRunner::new_with_rng(config, rng);
        let mechanics = (
            prop::sample::select(vec![1000u32, 4096, 10_000, 1 << 20, 8_388_608, 1 << 23]),
            1u32..100,
            1u32..100,
            prop::option::of(prop::sample::select(vec![5.0, 10.0, 2.54, 0.1, 7.5, 1e-3])),
        );
        let count = (0u32..53, any::<i64>(), -1e6f64..1e6);
        let quotients = std::cell::Cell::new(0u32);
        runner
            .run(&(mechanics, count), |((inc, n, d, pitch), (bits, c, v))| {
                let r = drive_ratio(inc, n, d, pitch);
                // A count of `bits` bits at most, either sign.
                let c = c >> (63 - bits);
                prop_assert_eq!(
                    r.units(c).to_bits(),
                    r.units_double_double(c).to_bits(),
                    "count {} of {:?}",
                    c,
                    r
                );
                if c.unsigned_abs() < r.quotient_limit && c != 0 {
                    quotients.set(quotients.get() + 1);
                }
                let s = Scaling {
                    encoder: EncoderConfig {
                        kind: EncoderKind::Incremental,
                        steps_per_revolution: inc,
                        fine_resolution_bits: 0,
                        determinable_revolutions: 1,
                        raw_bits: 32,
                        inverse: false,
                        mounting: Mounting::MotorShaft,
                    },
                    mechanics: Mechanics::default(),
                    sensor: r,
                    drive: r,
                    sensor_sign: 1.0,
                    drive_sign: 1.0,
                    torque_factor: 1.0,
                };
                let by_quotient =
                    s.drive_increments_per_second(v)
                        .round()
                        .clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32;
                prop_assert_eq!(s.drive_increments_per_second_i32(v), by_quotient);
                Ok(())
            })
            .unwrap();
        // The quotient was taken in a good share of the cases.
        let quotients = quotients.get();
        assert!(quotients > 5_000, "{quotients} quotients");
    }

    #[test]
    fn rounding_without_the_library_call_is_f64_round() {
        for x in [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.499_999_999_999_999_94,
            1e15 + 0.5,
            4.5e15,
            -4.5e15,
            9.3e18,
            -9.3e18,
            1e300,
            f64::NAN,
            f64::INFINITY,
            -f64::INFINITY,
        ] {
            assert_eq!(round_to_i64(x), x.round() as i64, "{x}");
        }
    }
}
