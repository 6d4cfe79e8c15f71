//! The automatic identification of a hydraulic axis, `MC_AxUtiAutoIdent_BkPlcMc` (Beckhoff
//! TwinCAT PLC Hydraulic Positioning library, 4.4.9.7.1), configured by the members of
//! `ST_TcMcAutoIdent` (4.3.23) that tandem implements ([`AutoIdentParams`]).
//!
//! Open loop: each cycle [`AutoIdent::step`] takes the actual position and velocity and gives the
//! normalised valve output (±1.0 = ±10 V), no position controller. The sequence, as the library
//! describes it, each part run when its `Enable…` is set:
//! 1. **End of travel** (`EnableEndOfTravel`): drive with `EndOfTravel_NegativLimit` against the
//!    negative stop until the axis stands, then with `EndOfTravel_PositivLimit` against the
//!    positive one: `EndOfTravel_Negativ`/`Positiv`.
//! 2. **Overlap and offset** (`EnableOverlap`, `EnableZeroAdjust`): into the window of 80 % of the
//!    travel around its centre, then the smallest positive output `u+` and the largest negative
//!    output `u-` that move the axis (a ramp from standstill until the axis has moved
//!    [`AutoIdentParams::move_threshold`]; a coarse ramp, then one ten times slower from
//!    shortly before the coarse result). Inferred (the library says only "by offsetting these
//!    parameters"): the overlap is `(u+ - u-) / 2` (`fValve_OverlapCompP` and `…M`), the output
//!    that centres the spool is `(u+ + u-) / 2`, so `fZeroCompensation = 10 V · (u+ + u-) / 2`
//!    (the valve's own offset is its negative).
//! 3. **Area ratio** (`EnableArreaRatio`): into the window, then 1 V each way for 1 s (plus the
//!    overlap and zero compensation found in 2: inferred, a valve with 10 % overlap would not open
//!    at 1 V); the velocity of each is the slope of a least-squares line of position over the
//!    second half-second; `fAreaRatio = |v-| / |v+|` (as Finish uses it: above 1 when the
//!    positive direction is the slower one).
//! 4. **Characteristic curve** (`EnableValveCharacteristic`): `ValveCharacteristicTblCount`
//!    points, the outputs in equal steps from -1.0 to 1.0 (the library's export form). For each
//!    output `k/M` (`M = (count - 1) / 2`), first positive then negative, growing: the axis goes to
//!    its start (halfway between the end of travel and `ValveCharacteristicLowEnd`, resp.
//!    `…HighEnd`), pauses `ValveCharacteristicRecovery` at output 0 (`InRecovery`), ramps the
//!    output up (`ValveCharacteristicRamp`: seconds for 10 V), waits `ValveCharacteristicSettling`
//!    and measures the velocity as the slope of a least-squares line of position over time while
//!    the axis is between LowEnd and HighEnd (until it leaves, or after
//!    [`AutoIdentParams::measure_timeout`]; a point that does not reach the measuring stroke in
//!    that time is fitted over the whole time since settling: inferred, an output within the
//!    overlap never gets there). A velocity not above the previous one of its direction is raised
//!    just above it and counted ([`AutoIdentResult::monotonic_warnings`]). A velocity at or
//!    beyond `EndOfVelocity_…Limit`, an output beyond `EndOfTravel_…Limit` or a measurement that
//!    starts too late (`ValveCharacteristicMinCycle`: the output must be established while the
//!    axis is still half of it short of the measuring stroke's centre) ends the direction; its
//!    further points are extrapolated from the last two (the library replaces them with values
//!    of the reference velocity in the last case; tandem extrapolates in all three, a stated
//!    deviation). The outputs of the curve are the outputs beyond the zero compensation of 2
//!    (inferred: `MC_AxRtFinishLinear_BkPlcMc` adds `fZeroCompensation` after the table). The
//!    reference velocity `fRefVelo` is the larger velocity at ±1.0 (inferred), the table's
//!    velocities are normalised to it.
//!
//! Inferred, too: a standstill is [`AutoIdentParams::standstill_velocity`] held for
//! [`AutoIdentParams::standstill_time`]; moves between the parts run open loop with the
//! end-of-travel limit of their direction; each part fails after
//! [`AutoIdentParams::phase_timeout`] (`dwTcHydErrCdFuncTimeout`). Not built: the reversal of
//! the output when the positive stop lies below the negative one (tandem stops with
//! `dwTcHydErrCdNotMoving`), `DecelerationFactor` (the measuring strokes end with output 0),
//! `ValveCharacteristicType`, `EnableNoUturn`, the encoder increments, the `Wait` input.
//!
//! Pure: no IO, no clock (the cycle time is an input), no allocation (the curve is held in
//! fixed arrays of at most 99 points).

use nalgebra::{Matrix2, Vector2};

use crate::catalog::hyd_error::HydErrorCode;
use crate::hydraulic::valve_table::{TableError, ValveTable};

/// The most points of a characteristic curve the identification measures (`ValveCharacteristicTblCount`).
pub const MAX_TBL_COUNT: usize = 99;

/// Points per direction at most.
const HALF: usize = (MAX_TBL_COUNT - 1) / 2;

/// The parameters of the identification, `ST_TcMcAutoIdent` (4.3.23) under tandem's names (the
/// library's as `doc(alias)`), and tandem's own for what the library leaves open (inferred).
#[doc(alias = "ST_TcMcAutoIdent")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AutoIdentParams {
    /// `EnableEndOfTravel`: find the end stops; else [`Self::end_of_travel_negativ`] and
    /// [`Self::end_of_travel_positiv`] are given.
    #[doc(alias = "EnableEndOfTravel")]
    pub enable_end_of_travel: bool,
    /// `EndOfTravel_Negativ` (mm): the negative end, given when not identified.
    #[doc(alias = "EndOfTravel_Negativ")]
    pub end_of_travel_negativ: f64,
    /// `EndOfTravel_Positiv` (mm): the positive end, given when not identified.
    #[doc(alias = "EndOfTravel_Positiv")]
    pub end_of_travel_positiv: f64,
    /// `EndOfTravel_NegativLimit` (V, a magnitude in 0 < x ≤ 10): the largest negative output.
    #[doc(alias = "EndOfTravel_NegativLimit")]
    pub end_of_travel_negativ_limit: f64,
    /// `EndOfTravel_PositivLimit` (V, 0 < x ≤ 10): the largest positive output.
    #[doc(alias = "EndOfTravel_PositivLimit")]
    pub end_of_travel_positiv_limit: f64,
    /// `EndOfVelocity_NegativLimit` (mm/s, a magnitude ≥ 0; 0: none): the curve's measurement
    /// ends in the negative direction at this velocity.
    #[doc(alias = "EndOfVelocity_NegativLimit")]
    pub end_of_velocity_negativ_limit: f64,
    /// `EndOfVelocity_PositivLimit` (mm/s, ≥ 0; 0: none).
    #[doc(alias = "EndOfVelocity_PositivLimit")]
    pub end_of_velocity_positiv_limit: f64,
    /// `EnableOverlap`: identify the overlap.
    #[doc(alias = "EnableOverlap")]
    pub enable_overlap: bool,
    /// `EnableZeroAdjust`: identify the offset.
    #[doc(alias = "EnableZeroAdjust")]
    pub enable_zero_adjust: bool,
    /// `EnableArreaRatio` (the library's spelling): identify the area ratio.
    #[doc(alias = "EnableArreaRatio")]
    pub enable_arrea_ratio: bool,
    /// `EnableValveCharacteristic`: measure the characteristic curve.
    #[doc(alias = "EnableValveCharacteristic")]
    pub enable_valve_characteristic: bool,
    /// `ValveCharacteristicTblCount`: points of the curve, odd, 3..=99.
    #[doc(alias = "ValveCharacteristicTblCount")]
    pub tbl_count: usize,
    /// `ValveCharacteristicLowEnd` (mm): the measuring stroke's lower end.
    #[doc(alias = "ValveCharacteristicLowEnd")]
    pub low_end: f64,
    /// `ValveCharacteristicHighEnd` (mm): its upper end.
    #[doc(alias = "ValveCharacteristicHighEnd")]
    pub high_end: f64,
    /// `ValveCharacteristicRamp` (s, ≥ 0): the time the output takes to rise by 10 V.
    #[doc(alias = "ValveCharacteristicRamp")]
    pub ramp: f64,
    /// `ValveCharacteristicSettling` (s, ≥ 0): the wait after the ramp.
    #[doc(alias = "ValveCharacteristicSettling")]
    pub settling: f64,
    /// `ValveCharacteristicRecovery` (s, ≥ 0): the pause at output 0 before each measuring run.
    #[doc(alias = "ValveCharacteristicRecovery")]
    pub recovery: f64,
    /// `ValveCharacteristicMinCycle` (mm, ≥ 0): see the module documentation.
    #[doc(alias = "ValveCharacteristicMinCycle")]
    pub min_cycle: f64,
    /// tandem: below this velocity (mm/s, > 0) the axis stands.
    pub standstill_velocity: f64,
    /// tandem: for this long (s, > 0).
    pub standstill_time: f64,
    /// tandem: the distance (mm, > 0) after which the overlap search takes the axis as moving.
    pub move_threshold: f64,
    /// tandem: the coarse overlap search's ramp (normalised output per s, > 0; the fine one is
    /// ten times slower).
    pub search_rate: f64,
    /// tandem: the longest measurement of a curve point (s, > 0).
    pub measure_timeout: f64,
    /// tandem: the longest part of the sequence (s, > 0).
    pub phase_timeout: f64,
}

impl Default for AutoIdentParams {
    /// Everything enabled, 3 V limits, no velocity limits, 21 points; the measuring stroke and
    /// the ends of travel are the application's (0).
    fn default() -> Self {
        Self {
            enable_end_of_travel: true,
            end_of_travel_negativ: 0.0,
            end_of_travel_positiv: 0.0,
            end_of_travel_negativ_limit: 3.0,
            end_of_travel_positiv_limit: 3.0,
            end_of_velocity_negativ_limit: 0.0,
            end_of_velocity_positiv_limit: 0.0,
            enable_overlap: true,
            enable_zero_adjust: true,
            enable_arrea_ratio: true,
            enable_valve_characteristic: true,
            tbl_count: 21,
            low_end: 0.0,
            high_end: 0.0,
            ramp: 0.5,
            settling: 0.2,
            recovery: 0.5,
            min_cycle: 0.0,
            standstill_velocity: 0.5,
            standstill_time: 0.2,
            move_threshold: 0.05,
            search_rate: 0.02,
            measure_timeout: 10.0,
            phase_timeout: 120.0,
        }
    }
}

/// Why the identification refused its parameters or stopped.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum AutoIdentError {
    /// `ValveCharacteristicTblCount` even or outside 3..=99 (`dwTcHydErrCdTblEntryCount`).
    TblCount {
        /// The count given.
        count: usize,
    },
    /// A parameter out of its range (`dwTcHydAdsErrIllegalValue`).
    Param {
        /// The library's (or tandem's) name of it.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// Parameters changed while the identification runs (`dwTcHydAdsErrBusy`).
    Busy,
    /// A part of the sequence took longer than `phase_timeout` (`dwTcHydErrCdFuncTimeout`).
    Timeout {
        /// The step it was in.
        step: i16,
    },
    /// The axis did not move, or moved the wrong way (`dwTcHydErrCdNotMoving`).
    NotMoving {
        /// The step it was in.
        step: i16,
    },
    /// The travel is too short for the measuring stroke or the stops lie the wrong way round
    /// (`dwTcHydErrDistanceInsufficient`).
    DistanceInsufficient {
        /// The negative end (mm).
        negativ: f64,
        /// The positive end (mm).
        positiv: f64,
    },
    /// The measured curve is not a valid table.
    Table(TableError),
}

impl AutoIdentError {
    /// The library's error code.
    pub fn code(&self) -> HydErrorCode {
        match self {
            Self::TblCount { .. } => HydErrorCode::TBL_ENTRY_COUNT,
            Self::Param { .. } => HydErrorCode::ILLEGAL_VALUE,
            Self::Busy => HydErrorCode(0x0708),
            Self::Timeout { .. } => HydErrorCode(0x4B07),
            Self::NotMoving { .. } => HydErrorCode(0x435D),
            Self::DistanceInsufficient { .. } => HydErrorCode(0x4FF2),
            Self::Table(e) => e.code(),
        }
    }
}

impl core::fmt::Display for AutoIdentError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::TblCount { count } => write!(
                f,
                "ValveCharacteristicTblCount {count}: must be odd and within 3 and 99"
            ),
            Self::Param { name, value } => write!(f, "{name} {value}: out of its range"),
            Self::Busy => write!(f, "the identification is running"),
            Self::Timeout { step } => write!(f, "step {step} did not complete in time"),
            Self::NotMoving { step } => {
                write!(
                    f,
                    "step {step}: the axis did not move, or not the right way"
                )
            }
            Self::DistanceInsufficient { negativ, positiv } => write!(
                f,
                "travel {negativ}..{positiv} mm: too short for the measuring stroke"
            ),
            Self::Table(e) => write!(f, "the measured curve: {e}"),
        }
    }
}

impl std::error::Error for AutoIdentError {}

/// What the identification found (valid once [`AutoIdent::done`]; each value stays at 0 when
/// its part was not enabled).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct AutoIdentResult {
    /// `EndOfTravel_Negativ` (mm).
    #[doc(alias = "EndOfTravel_Negativ")]
    pub end_of_travel_negativ: f64,
    /// `EndOfTravel_Positiv` (mm).
    #[doc(alias = "EndOfTravel_Positiv")]
    pub end_of_travel_positiv: f64,
    /// `EndOfTravel_NegativDone`.
    #[doc(alias = "EndOfTravel_NegativDone")]
    pub end_of_travel_negativ_done: bool,
    /// `EndOfTravel_PositivDone`.
    #[doc(alias = "EndOfTravel_PositivDone")]
    pub end_of_travel_positiv_done: bool,
    /// The smallest output that moves the axis positively (normalised).
    pub output_p: f64,
    /// The largest output that moves it negatively (normalised).
    pub output_m: f64,
    /// `fValve_OverlapCompP` (normalised): `(u+ - u-) / 2`.
    #[doc(alias = "fValve_OverlapCompP")]
    pub overlap_comp_p: f64,
    /// `fValve_OverlapCompM` (normalised): the same (one overlap from two thresholds).
    #[doc(alias = "fValve_OverlapCompM")]
    pub overlap_comp_m: f64,
    /// `fZeroCompensation` (V): `10 · (u+ + u-) / 2`.
    #[doc(alias = "fZeroCompensation")]
    pub zero_compensation: f64,
    /// The velocity at +1 V (mm/s).
    pub velocity_p: f64,
    /// The velocity at -1 V (mm/s, negative).
    pub velocity_m: f64,
    /// `fAreaRatio`: `|v-| / |v+|`.
    #[doc(alias = "fAreaRatio")]
    pub area_ratio: f64,
    /// `fRefVelo` (mm/s): the larger velocity at ±1.0 of the curve.
    #[doc(alias = "fRefVelo")]
    pub ref_velo: f64,
    /// Points of the curve whose velocity was raised to keep it increasing.
    pub monotonic_warnings: u32,
    /// Points of the curve measured (the others extrapolated).
    pub measured_points: u32,
}

/// A straight line `x = a + b·t` fitted by least squares from running sums (no storage).
#[derive(Copy, Clone, Debug, Default)]
struct LineFit {
    n: f64,
    st: f64,
    stt: f64,
    sx: f64,
    stx: f64,
    t_first: f64,
    t_last: f64,
}

impl LineFit {
    fn add(&mut self, t: f64, x: f64) {
        if self.n == 0.0 {
            self.t_first = t;
        }
        self.t_last = t;
        let t = t - self.t_first;
        self.n += 1.0;
        self.st += t;
        self.stt += t * t;
        self.sx += x;
        self.stx += t * x;
    }

    /// The time the samples span (s).
    fn span(&self) -> f64 {
        self.t_last - self.t_first
    }

    /// The slope `b` of the normal equations `[n Σt; Σt Σt²]·[a b]ᵀ = [Σx Σtx]ᵀ`.
    fn slope(&self) -> Option<f64> {
        if self.n < 2.0 {
            return None;
        }
        let m = Matrix2::new(self.n, self.st, self.st, self.stt);
        let rhs = Vector2::new(self.sx, self.stx);
        m.lu().solve(&rhs).map(|ab| ab[1]).filter(|b| b.is_finite())
    }
}

/// A part of the sequence.
#[derive(Copy, Clone, Debug, PartialEq)]
enum Stage {
    EndNeg,
    EndPos,
    Search { dir: f64, fine: bool },
    Ratio { dir: f64 },
    Curve { k: usize, dir: f64 },
}

/// Where a part is.
#[derive(Copy, Clone, Debug, PartialEq)]
enum Sub {
    /// Drive open loop into the window `lo..=hi`.
    Approach { lo: f64, hi: f64 },
    /// Output 0 until the axis stands.
    Standstill,
    /// Output 0 for `ValveCharacteristicRecovery`.
    Recovery,
    /// Ramp the output to the point's.
    Ramp,
    /// Hold it for `ValveCharacteristicSettling`.
    Settling,
    /// The part's own action.
    Act,
}

/// The curve measured so far, per direction (index 0: positive).
#[derive(Copy, Clone, Debug)]
struct Curve {
    velocity: [[f64; HALF]; 2],
    measured: [usize; 2],
    finished: [bool; 2],
}

/// The automatic identification (see the module documentation).
#[doc(alias = "MC_AxUtiAutoIdent_BkPlcMc")]
#[derive(Clone, Debug)]
pub struct AutoIdent {
    p: AutoIdentParams,
    stage: Option<Stage>,
    sub: Sub,
    /// Time in the current part, in the current sub-step (s).
    t_stage: f64,
    t_sub: f64,
    still: f64,
    u: f64,
    x0: f64,
    fit: LineFit,
    fit_all: LineFit,
    coarse: [f64; 2],
    curve: Curve,
    r: AutoIdentResult,
    table: Option<ValveTable>,
    done: bool,
    error: Option<AutoIdentError>,
}

/// `1` for a positive direction, `0` for a negative one (the curve's index).
fn side(dir: f64) -> usize {
    usize::from(dir < 0.0)
}

impl AutoIdent {
    /// An identification with parameters `p`, checked ([`AutoIdentParams`]), idle.
    pub fn new(p: AutoIdentParams) -> Result<Self, AutoIdentError> {
        check(&p)?;
        Ok(Self::fresh(p))
    }

    /// Idle with `p` (checked by the caller), nothing found.
    fn fresh(p: AutoIdentParams) -> Self {
        Self {
            p,
            stage: None,
            sub: Sub::Act,
            t_stage: 0.0,
            t_sub: 0.0,
            still: 0.0,
            u: 0.0,
            x0: 0.0,
            fit: LineFit::default(),
            fit_all: LineFit::default(),
            coarse: [0.0; 2],
            curve: Curve {
                velocity: [[0.0; HALF]; 2],
                measured: [0; 2],
                finished: [false; 2],
            },
            r: AutoIdentResult::default(),
            table: None,
            done: false,
            error: None,
        }
    }

    /// New parameters, checked; refused while busy. A refusal changes nothing.
    pub fn set_params(&mut self, p: AutoIdentParams) -> Result<(), AutoIdentError> {
        if self.busy() {
            return Err(AutoIdentError::Busy);
        }
        check(&p)?;
        self.p = p;
        Ok(())
    }

    /// The parameters.
    pub fn params(&self) -> &AutoIdentParams {
        &self.p
    }

    /// `Execute`'s rising edge: starts the identification from the beginning (the previous
    /// results are cleared).
    #[doc(alias = "Execute")]
    pub fn execute(&mut self) {
        let p = self.p;
        *self = Self::fresh(p);
        self.r.end_of_travel_negativ = p.end_of_travel_negativ;
        self.r.end_of_travel_positiv = p.end_of_travel_positiv;
        self.r.end_of_travel_negativ_done = !p.enable_end_of_travel;
        self.r.end_of_travel_positiv_done = !p.enable_end_of_travel;
        self.advance(None);
    }

    /// `Busy`.
    pub fn busy(&self) -> bool {
        self.stage.is_some()
    }

    /// `Done`: every enabled part completed.
    pub fn done(&self) -> bool {
        self.done
    }

    /// `Error` and `ErrorID`.
    pub fn error(&self) -> Option<AutoIdentError> {
        self.error
    }

    /// `InRecovery`: the recovery pause before a measuring run.
    #[doc(alias = "InRecovery")]
    pub fn in_recovery(&self) -> bool {
        self.busy() && self.sub == Sub::Recovery
    }

    /// What was found so far.
    pub fn result(&self) -> &AutoIdentResult {
        &self.r
    }

    /// `ValveCharacteristicTable`: the measured curve, once done.
    #[doc(alias = "ValveCharacteristicTable")]
    pub fn table(&self) -> Option<&ValveTable> {
        self.table.as_ref()
    }

    /// `Step`, the sequence's step: 0 idle; 10/11 the negative/positive end of travel; 20..23
    /// the overlap searches (coarse +, coarse -, fine +, fine -); 30/31 the area ratio (+, -);
    /// 100 + 2k (+) and 101 + 2k (-) the curve's point k; then +1000 while approaching,
    /// +2000 waiting for standstill, +3000 in recovery, +4000 ramping, +5000 settling.
    #[doc(alias = "Step")]
    pub fn step_number(&self) -> i16 {
        let Some(stage) = self.stage else {
            return 0;
        };
        let base: usize = match stage {
            Stage::EndNeg => 10,
            Stage::EndPos => 11,
            Stage::Search { dir, fine } => 20 + side(dir) + 2 * usize::from(fine),
            Stage::Ratio { dir } => 30 + side(dir),
            Stage::Curve { k, dir } => 100 + 2 * k + side(dir),
        };
        let sub = match self.sub {
            Sub::Act => 0,
            Sub::Approach { .. } => 1000,
            Sub::Standstill => 2000,
            Sub::Recovery => 3000,
            Sub::Ramp => 4000,
            Sub::Settling => 5000,
        };
        i16::try_from(base + sub).unwrap_or(i16::MAX)
    }

    /// One cycle of `dt` seconds with the actual position (mm) and velocity (mm/s): the valve
    /// output (normalised, ±1.0 = ±10 V). 0 when idle, done or failed; a `dt` that is not a
    /// positive finite time changes nothing.
    pub fn step(&mut self, dt: f64, x: f64, v: f64) -> f64 {
        if !(dt.is_finite() && dt > 0.0) || self.stage.is_none() {
            return if self.stage.is_some() { self.u } else { 0.0 };
        }
        self.t_stage += dt;
        self.t_sub += dt;
        if self.t_stage > self.p.phase_timeout {
            self.fail(AutoIdentError::Timeout {
                step: self.step_number(),
            });
            return 0.0;
        }
        match self.sub {
            Sub::Approach { lo, hi } => self.approach(lo, hi, x),
            Sub::Standstill => {
                self.u = 0.0;
                if self.stands(dt, v) {
                    self.begin_act(x);
                }
            }
            Sub::Recovery => {
                self.u = 0.0;
                if self.t_sub >= self.p.recovery {
                    self.enter(Sub::Ramp);
                }
            }
            Sub::Ramp | Sub::Settling => self.curve_ramp(dt, x),
            Sub::Act => self.act(dt, x, v),
        }
        if self.stage.is_none() {
            self.u = 0.0;
        }
        // The output's range (the point ±1.0 plus a zero compensation lies beyond it).
        self.u.clamp(-1.0, 1.0)
    }

    fn enter(&mut self, sub: Sub) {
        self.sub = sub;
        self.t_sub = 0.0;
        self.still = 0.0;
    }

    fn fail(&mut self, e: AutoIdentError) {
        self.error = Some(e);
        self.stage = None;
        self.u = 0.0;
    }

    /// Whether the axis has stood for `standstill_time` (counted from this cycle on).
    fn stands(&mut self, dt: f64, v: f64) -> bool {
        if v.abs() < self.p.standstill_velocity {
            self.still += dt;
        } else {
            self.still = 0.0;
        }
        self.still >= self.p.standstill_time
    }

    /// The output that centres the spool (normalised), once found.
    fn zero(&self) -> f64 {
        self.r.zero_compensation / 10.0
    }

    fn limit(&self, dir: f64) -> f64 {
        if dir > 0.0 {
            self.p.end_of_travel_positiv_limit / 10.0
        } else {
            self.p.end_of_travel_negativ_limit / 10.0
        }
    }

    fn approach(&mut self, lo: f64, hi: f64, x: f64) {
        if x < lo {
            self.u = self.limit(1.0) + self.zero();
        } else if x > hi {
            self.u = -self.limit(-1.0) + self.zero();
        } else {
            self.u = 0.0;
            self.enter(Sub::Standstill);
        }
    }

    /// The centre window: 80 % of the travel around its middle.
    fn centre_window(&self) -> (f64, f64) {
        let (n, p) = (self.r.end_of_travel_negativ, self.r.end_of_travel_positiv);
        let c = 0.5 * (n + p);
        (c - 0.4 * (p - n), c + 0.4 * (p - n))
    }

    /// Starts the next enabled part after `from` (or finishes).
    fn advance(&mut self, from: Option<Stage>) {
        let next = self.next_stage(from);
        self.stage = next;
        self.t_stage = 0.0;
        self.fit = LineFit::default();
        self.fit_all = LineFit::default();
        let Some(stage) = next else {
            self.finish();
            return;
        };
        let (n, p) = (self.r.end_of_travel_negativ, self.r.end_of_travel_positiv);
        match stage {
            Stage::EndNeg | Stage::EndPos => {
                self.enter(Sub::Act);
                self.u = 0.0;
            }
            Stage::Search { .. } | Stage::Ratio { .. } => {
                let (lo, hi) = self.centre_window();
                self.enter(Sub::Approach { lo, hi });
            }
            Stage::Curve { dir, .. } => {
                let (lo, hi) = if dir > 0.0 {
                    (f64::NEG_INFINITY, 0.5 * (n + self.p.low_end))
                } else {
                    (0.5 * (p + self.p.high_end), f64::INFINITY)
                };
                self.enter(Sub::Approach { lo, hi });
            }
        }
    }

    /// The part after `from` that is enabled.
    fn next_stage(&self, from: Option<Stage>) -> Option<Stage> {
        let p = &self.p;
        let search = p.enable_overlap || p.enable_zero_adjust;
        let mut s = from;
        loop {
            s = match s {
                None => Some(Stage::EndNeg),
                Some(Stage::EndNeg) => Some(Stage::EndPos),
                Some(Stage::EndPos) => Some(Stage::Search {
                    dir: 1.0,
                    fine: false,
                }),
                Some(Stage::Search { dir, fine }) => match (dir > 0.0, fine) {
                    (true, f) => Some(Stage::Search { dir: -1.0, fine: f }),
                    (false, false) => Some(Stage::Search {
                        dir: 1.0,
                        fine: true,
                    }),
                    (false, true) => Some(Stage::Ratio { dir: 1.0 }),
                },
                Some(Stage::Ratio { dir }) if dir > 0.0 => Some(Stage::Ratio { dir: -1.0 }),
                Some(Stage::Ratio { .. }) => Some(Stage::Curve { k: 1, dir: 1.0 }),
                Some(Stage::Curve { k, dir }) if dir > 0.0 => Some(Stage::Curve { k, dir: -1.0 }),
                Some(Stage::Curve { k, .. }) => Some(Stage::Curve { k: k + 1, dir: 1.0 }),
            };
            let enabled = match s {
                Some(Stage::EndNeg | Stage::EndPos) => p.enable_end_of_travel,
                Some(Stage::Search { .. }) => search,
                Some(Stage::Ratio { .. }) => p.enable_arrea_ratio,
                Some(Stage::Curve { k, dir }) => {
                    if !p.enable_valve_characteristic
                        || k > (p.tbl_count - 1) / 2
                        || self.curve.finished.iter().all(|&f| f)
                    {
                        return None;
                    }
                    !self.curve.finished.get(side(dir)).copied().unwrap_or(true)
                        && self.point_output(k, dir).abs() <= self.limit(dir) + 1e-12
                }
                None => return None,
            };
            if enabled {
                return s;
            }
        }
    }

    /// The part's action starts (after its approach and standstill).
    fn begin_act(&mut self, x: f64) {
        self.x0 = x;
        match self.stage {
            Some(Stage::Search { dir, fine }) => {
                self.u = if fine {
                    // Shortly (0.2 V) before where the coarse search found motion.
                    let c = self.coarse.get(side(dir)).copied().unwrap_or(0.0);
                    c - dir * 0.02
                } else {
                    self.zero()
                };
                self.enter(Sub::Act);
            }
            Some(Stage::Curve { .. }) => self.enter(Sub::Recovery),
            _ => self.enter(Sub::Act),
        }
    }

    fn act(&mut self, dt: f64, x: f64, v: f64) {
        match self.stage {
            Some(Stage::EndNeg) => self.end_of_travel(dt, x, v, -1.0),
            Some(Stage::EndPos) => self.end_of_travel(dt, x, v, 1.0),
            Some(Stage::Search { dir, fine }) => self.search(dt, x, dir, fine),
            Some(Stage::Ratio { dir }) => self.ratio(x, dir),
            Some(Stage::Curve { k, dir }) => self.measure(x, k, dir),
            None => {}
        }
    }

    /// Against a stop with the limited output until the axis stands (after having had
    /// `standstill_time` to start).
    fn end_of_travel(&mut self, dt: f64, x: f64, v: f64, dir: f64) {
        self.u = dir * self.limit(dir);
        if self.t_sub < self.p.standstill_time {
            return;
        }
        if !self.stands(dt, v) {
            return;
        }
        let stage = self.stage;
        if dir < 0.0 {
            self.r.end_of_travel_negativ = x;
            self.r.end_of_travel_negativ_done = true;
        } else {
            self.r.end_of_travel_positiv = x;
            self.r.end_of_travel_positiv_done = true;
            let (n, p) = (self.r.end_of_travel_negativ, self.r.end_of_travel_positiv);
            if p <= n {
                self.fail(AutoIdentError::NotMoving {
                    step: self.step_number(),
                });
                return;
            }
            let q = &self.p;
            if q.enable_valve_characteristic && (q.low_end < n || q.high_end > p) {
                self.fail(AutoIdentError::DistanceInsufficient {
                    negativ: n,
                    positiv: p,
                });
                return;
            }
        }
        self.advance(stage);
    }

    /// The output ramps from standstill until the axis has moved `move_threshold`.
    fn search(&mut self, dt: f64, x: f64, dir: f64, fine: bool) {
        let rate = self.p.search_rate / if fine { 10.0 } else { 1.0 };
        if (x - self.x0).abs() >= self.p.move_threshold {
            if (x - self.x0) * dir < 0.0 {
                self.fail(AutoIdentError::NotMoving {
                    step: self.step_number(),
                });
                return;
            }
            let found = self.u;
            if let Some(c) = self.coarse.get_mut(side(dir)) {
                *c = found;
            }
            if fine {
                if dir > 0.0 {
                    self.r.output_p = found;
                } else {
                    self.r.output_m = found;
                    self.overlap_found();
                }
            }
            self.u = 0.0;
            self.advance(self.stage);
            return;
        }
        self.u += dir * rate * dt;
        if self.u * dir > self.limit(dir) + self.zero() * dir {
            self.fail(AutoIdentError::NotMoving {
                step: self.step_number(),
            });
        }
    }

    fn overlap_found(&mut self) {
        let (up, um) = (self.r.output_p, self.r.output_m);
        if self.p.enable_overlap {
            self.r.overlap_comp_p = 0.5 * (up - um);
            self.r.overlap_comp_m = self.r.overlap_comp_p;
        }
        if self.p.enable_zero_adjust {
            self.r.zero_compensation = 10.0 * 0.5 * (up + um);
        }
    }

    /// 1 V (beyond the compensations) for 1 s; the velocity from the second half-second.
    fn ratio(&mut self, x: f64, dir: f64) {
        let ovl = if dir > 0.0 {
            self.r.overlap_comp_p
        } else {
            self.r.overlap_comp_m
        };
        self.u = dir * (0.1 + ovl) + self.zero();
        if self.t_sub >= 0.5 {
            self.fit.add(self.t_sub, x);
        }
        if self.t_sub < 1.0 {
            return;
        }
        let Some(v) = self.fit.slope().filter(|v| v * dir > 0.0) else {
            self.fail(AutoIdentError::NotMoving {
                step: self.step_number(),
            });
            return;
        };
        if dir > 0.0 {
            self.r.velocity_p = v;
        } else {
            self.r.velocity_m = v;
            self.r.area_ratio = self.r.velocity_m.abs() / self.r.velocity_p.abs();
        }
        self.u = 0.0;
        self.advance(self.stage);
    }

    /// The point's output: `k / M` in direction `dir` (normalised, beyond the zero).
    fn point_output(&self, k: usize, dir: f64) -> f64 {
        let m = (self.p.tbl_count - 1) / 2;
        dir * k as f64 / m as f64
    }

    /// The ramp to the point's output, then the settling time.
    fn curve_ramp(&mut self, dt: f64, x: f64) {
        let Some(Stage::Curve { k, dir }) = self.stage else {
            return;
        };
        let target = self.point_output(k, dir) + self.zero();
        if self.sub == Sub::Ramp {
            let rate = if self.p.ramp > 0.0 {
                1.0 / self.p.ramp
            } else {
                f64::INFINITY
            };
            let step = (rate * dt).min(2.0);
            self.u = if (target - self.u).abs() <= step {
                target
            } else {
                self.u + step.copysign(target - self.u)
            };
            if self.u == target {
                self.enter(Sub::Settling);
            }
            return;
        }
        self.u = target;
        if self.t_sub < self.p.settling {
            return;
        }
        // ValveCharacteristicMinCycle: the output must be established half of it short of the
        // measuring stroke's centre.
        let centre = 0.5 * (self.p.low_end + self.p.high_end);
        if (centre - x) * dir < 0.5 * self.p.min_cycle {
            self.end_direction(dir);
            self.u = 0.0;
            self.advance(self.stage);
            return;
        }
        self.enter(Sub::Act);
    }

    fn end_direction(&mut self, dir: f64) {
        if let Some(f) = self.curve.finished.get_mut(side(dir)) {
            *f = true;
        }
    }

    /// The measurement of a curve point: a line through position over time while on the
    /// measuring stroke.
    fn measure(&mut self, x: f64, k: usize, dir: f64) {
        let (lo, hi) = (self.p.low_end, self.p.high_end);
        self.fit_all.add(self.t_sub, x);
        if (lo..=hi).contains(&x) {
            self.fit.add(self.t_sub, x);
        }
        let beyond = if dir > 0.0 { x > hi } else { x < lo };
        if !beyond && self.t_sub < self.p.measure_timeout {
            return;
        }
        let fit = if self.fit.span() >= 0.1 {
            self.fit
        } else {
            self.fit_all
        };
        let v = fit.slope().unwrap_or(0.0);
        let s = side(dir);
        let limit = if dir > 0.0 {
            self.p.end_of_velocity_positiv_limit
        } else {
            self.p.end_of_velocity_negativ_limit
        };
        if let (Some(slot), Some(n)) = (
            self.curve
                .velocity
                .get_mut(s)
                .and_then(|a| a.get_mut(k.saturating_sub(1))),
            self.curve.measured.get_mut(s),
        ) {
            *slot = v;
            *n = k;
        }
        if limit > 0.0 && v.abs() >= limit {
            self.end_direction(dir);
        }
        self.u = 0.0;
        self.advance(self.stage);
    }

    /// The end: the curve completed, corrected, extrapolated and normalised into the table.
    fn finish(&mut self) {
        self.stage = None;
        self.u = 0.0;
        if self.p.enable_valve_characteristic {
            match self.build_table() {
                Ok(t) => self.table = Some(t),
                Err(e) => {
                    self.error = Some(e);
                    return;
                }
            }
        }
        self.done = true;
    }

    fn build_table(&mut self) -> Result<ValveTable, AutoIdentError> {
        let m = (self.p.tbl_count - 1) / 2;
        let mut v = [[0.0; HALF]; 2];
        let mut warnings = 0;
        for s in 0..2 {
            let (meas, vel) = match (self.curve.measured.get(s), self.curve.velocity.get(s)) {
                (Some(&n), Some(vel)) => (n, vel),
                _ => continue,
            };
            if meas == 0 {
                return Err(AutoIdentError::NotMoving { step: 100 });
            }
            let out = v
                .get_mut(s)
                .ok_or(AutoIdentError::NotMoving { step: 100 })?;
            warnings += complete_side(out, vel, meas, m);
        }
        self.r.monotonic_warnings = warnings;
        self.r.measured_points = self.curve.measured.iter().map(|&n| n as u32).sum();
        let v_end = |s: usize| {
            v.get(s)
                .and_then(|a| a.get(m.saturating_sub(1)))
                .copied()
                .unwrap_or(0.0)
                .abs()
        };
        let ref_velo = v_end(0).max(v_end(1));
        self.r.ref_velo = ref_velo;
        let mut points = [(0.0, 0.0); MAX_TBL_COUNT];
        for (i, pt) in points.iter_mut().enumerate().take(2 * m + 1) {
            let (s, k) = if i < m { (1, m - i) } else { (0, i - m) };
            let dir = if s == 0 { 1.0 } else { -1.0 };
            let vel = if k == 0 {
                0.0
            } else {
                dir * v
                    .get(s)
                    .and_then(|a| a.get(k.saturating_sub(1)))
                    .copied()
                    .unwrap_or(0.0)
                    .abs()
            };
            *pt = (vel / ref_velo, self.point_output(k, dir));
        }
        ValveTable::new(points.get(..2 * m + 1).unwrap_or(&[])).map_err(AutoIdentError::Table)
    }
}

/// One direction of the curve, `m` points from `meas` measured velocities (magnitudes, growing;
/// `out[k-1]` for output `k/m`): raised where not increasing (counted), the rest extrapolated
/// linearly from the last two points (the zero point and the first when only one was measured).
/// Returns the number of raised points.
fn complete_side(out: &mut [f64; HALF], vel: &[f64; HALF], meas: usize, m: usize) -> u32 {
    let mut warnings = 0;
    let mut prev = 0.0;
    for k in 1..=m {
        let val = if k <= meas {
            vel.get(k.saturating_sub(1)).copied().unwrap_or(0.0).abs()
        } else {
            let (v1, v2) = extrapolation_base(out, k);
            v2 + (v2 - v1)
        };
        let val = if k <= meas && val <= prev {
            warnings += 1;
            // Just above the previous one (inferred: the library corrects without saying how).
            prev + 1e-6 * (1.0 + prev)
        } else {
            val.max(prev + 1e-6 * (1.0 + prev))
        };
        if let Some(o) = out.get_mut(k.saturating_sub(1)) {
            *o = val;
        }
        prev = val;
    }
    warnings
}

/// The two points before `k` (velocities at outputs `k-2` and `k-1`; 0 at output 0).
fn extrapolation_base(out: &[f64; HALF], k: usize) -> (f64, f64) {
    let at = |j: usize| {
        if j == 0 {
            0.0
        } else {
            out.get(j - 1).copied().unwrap_or(0.0)
        }
    };
    (at(k.saturating_sub(2)), at(k.saturating_sub(1)))
}

/// The checks of [`AutoIdentParams`].
fn check(p: &AutoIdentParams) -> Result<(), AutoIdentError> {
    if p.tbl_count % 2 == 0 || !(3..=MAX_TBL_COUNT).contains(&p.tbl_count) {
        return Err(AutoIdentError::TblCount { count: p.tbl_count });
    }
    let bad = |name, value| Err(AutoIdentError::Param { name, value });
    let volts = [
        ("EndOfTravel_NegativLimit", p.end_of_travel_negativ_limit),
        ("EndOfTravel_PositivLimit", p.end_of_travel_positiv_limit),
    ];
    for (name, value) in volts {
        if !(value > 0.0 && value <= 10.0) {
            return bad(name, value);
        }
    }
    let non_negative = [
        (
            "EndOfVelocity_NegativLimit",
            p.end_of_velocity_negativ_limit,
        ),
        (
            "EndOfVelocity_PositivLimit",
            p.end_of_velocity_positiv_limit,
        ),
        ("ValveCharacteristicRamp", p.ramp),
        ("ValveCharacteristicSettling", p.settling),
        ("ValveCharacteristicRecovery", p.recovery),
        ("ValveCharacteristicMinCycle", p.min_cycle),
    ];
    for (name, value) in non_negative {
        if !(value.is_finite() && value >= 0.0) {
            return bad(name, value);
        }
    }
    let positive = [
        ("standstill_velocity", p.standstill_velocity),
        ("standstill_time", p.standstill_time),
        ("move_threshold", p.move_threshold),
        ("search_rate", p.search_rate),
        ("measure_timeout", p.measure_timeout),
        ("phase_timeout", p.phase_timeout),
    ];
    for (name, value) in positive {
        if !(value.is_finite() && value > 0.0) {
            return bad(name, value);
        }
    }
    let ends = [
        ("EndOfTravel_Negativ", p.end_of_travel_negativ),
        ("EndOfTravel_Positiv", p.end_of_travel_positiv),
        ("ValveCharacteristicLowEnd", p.low_end),
        ("ValveCharacteristicHighEnd", p.high_end),
    ];
    for (name, value) in ends {
        if !value.is_finite() {
            return bad(name, value);
        }
    }
    if !p.enable_end_of_travel && p.end_of_travel_positiv <= p.end_of_travel_negativ {
        return bad("EndOfTravel_Positiv", p.end_of_travel_positiv);
    }
    if p.enable_valve_characteristic {
        if p.high_end <= p.low_end {
            return bad("ValveCharacteristicHighEnd", p.high_end);
        }
        if p.min_cycle > p.high_end - p.low_end {
            return bad("ValveCharacteristicMinCycle", p.min_cycle);
        }
        if !p.enable_end_of_travel
            && (p.low_end < p.end_of_travel_negativ || p.high_end > p.end_of_travel_positiv)
        {
            return Err(AutoIdentError::DistanceInsufficient {
                negativ: p.end_of_travel_negativ,
                positiv: p.end_of_travel_positiv,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    fn ok_params() -> AutoIdentParams {
        AutoIdentParams {
            low_end: 150.0,
            high_end: 350.0,
            ..AutoIdentParams::default()
        }
    }

    /// Each refusal with its code; the identification keeps its parameters.
    #[test]
    fn bad_parameters_are_refused_with_their_codes_and_change_nothing() {
        let good = ok_params();
        let mut id = AutoIdent::new(good).unwrap();
        type Edit = fn(&mut AutoIdentParams);
        let cases: &[(Edit, u32, &str)] = &[
            (|p| p.tbl_count = 20, 0x4A02, ""),
            (|p| p.tbl_count = 1, 0x4A02, ""),
            (|p| p.tbl_count = 101, 0x4A02, ""),
            (|p| p.tbl_count = 0, 0x4A02, ""),
            (
                |p| p.end_of_travel_negativ_limit = 0.0,
                0x0706,
                "EndOfTravel_NegativLimit",
            ),
            (
                |p| p.end_of_travel_positiv_limit = 10.5,
                0x0706,
                "EndOfTravel_PositivLimit",
            ),
            (
                |p| p.end_of_travel_positiv_limit = f64::NAN,
                0x0706,
                "EndOfTravel_PositivLimit",
            ),
            (
                |p| p.end_of_velocity_negativ_limit = -1.0,
                0x0706,
                "EndOfVelocity_NegativLimit",
            ),
            (
                |p| p.end_of_velocity_positiv_limit = f64::INFINITY,
                0x0706,
                "EndOfVelocity_PositivLimit",
            ),
            (|p| p.ramp = -0.1, 0x0706, "ValveCharacteristicRamp"),
            (
                |p| p.settling = f64::NAN,
                0x0706,
                "ValveCharacteristicSettling",
            ),
            (|p| p.recovery = -1.0, 0x0706, "ValveCharacteristicRecovery"),
            (
                |p| p.min_cycle = -1.0,
                0x0706,
                "ValveCharacteristicMinCycle",
            ),
            (
                |p| p.min_cycle = 201.0,
                0x0706,
                "ValveCharacteristicMinCycle",
            ),
            (
                |p| p.standstill_velocity = 0.0,
                0x0706,
                "standstill_velocity",
            ),
            (|p| p.standstill_time = 0.0, 0x0706, "standstill_time"),
            (|p| p.move_threshold = -0.1, 0x0706, "move_threshold"),
            (|p| p.search_rate = 0.0, 0x0706, "search_rate"),
            (|p| p.measure_timeout = 0.0, 0x0706, "measure_timeout"),
            (|p| p.phase_timeout = f64::NAN, 0x0706, "phase_timeout"),
            (
                |p| p.low_end = f64::NAN,
                0x0706,
                "ValveCharacteristicLowEnd",
            ),
            (|p| p.high_end = 150.0, 0x0706, "ValveCharacteristicHighEnd"),
            (
                |p| {
                    p.enable_end_of_travel = false;
                    p.end_of_travel_positiv = -1.0;
                },
                0x0706,
                "EndOfTravel_Positiv",
            ),
            (
                |p| {
                    p.enable_end_of_travel = false;
                    p.end_of_travel_positiv = 300.0;
                },
                0x4FF2,
                "",
            ),
        ];
        for (i, (edit, code, name)) in cases.iter().enumerate() {
            let mut p = good;
            edit(&mut p);
            let e = AutoIdent::new(p).unwrap_err();
            assert_eq!(e.code().0, *code, "case {i}: {e}");
            if let AutoIdentError::Param { name: n, .. } = e {
                assert_eq!(n, *name, "case {i}");
            }
            assert!(!e.to_string().is_empty());
            let again = id.set_params(p).unwrap_err();
            assert_eq!(again.code(), e.code(), "case {i}");
            assert_eq!(id.params(), &good, "case {i}: changed");
        }
        // Odd counts 3..=99 are taken.
        for n in [3, 21, 99] {
            assert!(AutoIdent::new(AutoIdentParams {
                tbl_count: n,
                ..good
            })
            .is_ok());
        }
        // While it runs, new parameters are refused (dwTcHydAdsErrBusy).
        id.execute();
        assert!(id.busy());
        let e = id.set_params(good).unwrap_err();
        assert_eq!(e.code().0, 0x0708);
    }

    /// The least-squares line's slope: exact for a line, the mean slope through noise.
    #[test]
    fn the_line_fit_gives_the_slope() {
        let mut f = LineFit::default();
        for i in 0..100 {
            let t = 3.0 + f64::from(i) * 1e-3;
            f.add(t, 12.5 + 40.0 * t + if i % 2 == 0 { 0.01 } else { -0.01 });
        }
        // ±0.01 mm alternating over 0.1 s tilts the line by at most 0.01 mm/s.
        assert!((f.slope().unwrap() - 40.0).abs() < 1e-2, "{:?}", f.slope());
        assert!((f.span() - 0.099).abs() < 1e-12);
        let mut exact = LineFit::default();
        for i in 0..500 {
            let t = 7.0 + f64::from(i) * 1e-3;
            exact.add(t, -3.0 - 250.0 * t);
        }
        assert!((exact.slope().unwrap() + 250.0).abs() < 1e-9);
        let mut one = LineFit::default();
        one.add(1.0, 1.0);
        assert_eq!(one.slope(), None);
    }

    /// A falling point is raised above its neighbour and counted; the unmeasured points are
    /// extrapolated from the last two.
    #[test]
    fn the_curve_is_corrected_and_extrapolated() {
        let mut out = [0.0; HALF];
        let mut vel = [0.0; HALF];
        vel[..3].copy_from_slice(&[10.0, 30.0, 25.0]);
        let w = complete_side(&mut out, &vel, 3, 5);
        assert_eq!(w, 1);
        assert_eq!(out[..2], [10.0, 30.0]);
        assert!(out[2] > 30.0 && out[2] < 30.001);
        // Extrapolated from the last two, 30 and just above it: growing, barely.
        assert!(out[3] > out[2] && out[4] > out[3]);
        let mut out = [0.0; HALF];
        vel[..2].copy_from_slice(&[10.0, 30.0]);
        assert_eq!(complete_side(&mut out, &vel, 2, 4), 0);
        assert_eq!(out[..4], [10.0, 30.0, 50.0, 70.0]);
        // One measured point: extrapolated from the zero point.
        let mut out = [0.0; HALF];
        complete_side(&mut out, &vel, 1, 3);
        assert_eq!(out[..3], [10.0, 20.0, 30.0]);
    }

    /// An ideal axis: velocity 200 mm/s per unit of output beyond a 5 % overlap (offset
    /// 0.01), stops at 0 and 500 mm.
    fn ideal(u: f64) -> f64 {
        let s = u + 0.01;
        if s.abs() <= 0.05 {
            0.0
        } else {
            200.0 * (s - 0.05f64.copysign(s))
        }
    }

    fn run(p: AutoIdentParams) -> AutoIdent {
        let mut id = AutoIdent::new(p).unwrap();
        id.execute();
        let (mut x, mut v, dt) = (250.0, 0.0, 1e-3);
        let mut t = 0.0;
        while id.busy() && t < 2000.0 {
            let u = id.step(dt, x, v);
            v = ideal(u);
            let nx = (x + v * dt).clamp(0.0, 500.0);
            v = (nx - x) / dt;
            x = nx;
            t += dt;
        }
        id
    }

    /// On an ideal linear axis, a velocity limit ends the positive measurement and the rest of
    /// the curve is extrapolated exactly; a 5 V limit does the same for the negative side.
    #[test]
    fn limits_end_a_direction_and_the_rest_is_extrapolated() {
        let id = run(AutoIdentParams {
            end_of_velocity_positiv_limit: 60.0,
            end_of_travel_negativ_limit: 5.0,
            end_of_travel_positiv_limit: 10.0,
            tbl_count: 11,
            recovery: 0.1,
            ..ok_params()
        });
        assert!(id.done(), "{:?}", id.error());
        let r = id.result();
        assert!((r.overlap_comp_p - 0.05).abs() < 0.002, "{r:?}");
        assert!((r.zero_compensation + 0.1).abs() < 0.01, "{r:?}");
        // Positive: 0.2 and 0.4 (… 0.2 → 30, 0.4 → 70 mm/s ≥ 60: stop); negative: up to -0.4
        // (-0.6 is beyond 5 V): 2 + 2 points.
        assert_eq!(r.measured_points, 4, "{r:?}");
        let t = id.table().unwrap();
        // Exact on a linear axis beyond the overlap: at output 1.0 (0.99 applied: beyond the
        // zero compensation) the velocity is 200·(1.0 - 0.05) = 190.
        assert!((r.ref_velo - 190.0).abs() < 1.0, "{}", r.ref_velo);
        let (v_min, o_min) = t.points().next().unwrap();
        assert_eq!(o_min, -1.0);
        assert!((v_min * r.ref_velo + 190.0).abs() < 1.0, "{v_min}");
        assert_eq!(r.monotonic_warnings, 0);
    }

    #[test]
    fn step_numbers_follow_the_sequence() {
        let mut id = AutoIdent::new(ok_params()).unwrap();
        assert_eq!(id.step_number(), 0);
        assert_eq!(id.step(1e-3, 0.0, 0.0), 0.0);
        id.execute();
        assert_eq!(id.step_number(), 10);
        let u = id.step(1e-3, 250.0, 0.0);
        assert!((u + 0.3).abs() < 1e-12, "{u}");
        // A cycle time that is no time changes nothing.
        assert_eq!(id.step(f64::NAN, 250.0, 0.0), u);
        assert_eq!(id.step_number(), 10);
    }
}
