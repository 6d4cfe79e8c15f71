//! The jerk-based set value generator of a hydraulic axis, `iTcMc_ProfileJerkBased`
//! (Beckhoff TwinCAT PLC Hydraulic Positioning library, 'Profile types' and
//! `E_TcMcProfileType`), and the selection of the generator (`nProfileType`) with the
//! time-based mode (`bTimeBased`).
//!
//! The library's profile, in its words: "a time-controlled acceleration phase (with optional
//! jerk limitation), a displacement-controlled braking ramp based on the square root generator
//! principle, and a target approach with jerk limitation": the start ramp "1" to the travel
//! velocity "2", the optional jerk limitation "6"; at "a point recalculated at the start" the
//! displacement-controlled braking ramp "3" "until the distance to the target has reduced to
//! the residual distance"; then "the deceleration "4" is reduced with limited jerk "5" towards
//! the target" and the axis goes over to its idle behaviour. Start ramp: the smallest of
//! `fMaxAcc`, `fAcc` and the command's acceleration; travel: of `fRefVelo`, `fMaxVelo` and the
//! command's velocity; braking: of `fMaxDec`, `fDec` and the command's deceleration; the
//! transfer to the target: `fMaxJerk` and the command's `Jerk`, `fBrakeDistance` and
//! `fBrakeDeadTime`. There is no creep phase.
//!
//! The library gives no formula; what follows is inferred and stated (docs/hydraulics.md,
//! "The jerk-based generator"):
//! - **`nJerkEnabled`** (a WORD, default `16#0101`: "at which transitions in the profile jerk
//!   limitation is to be applied") has three bits here: [`JERK_ACC_BUILD_UP`] (`16#0001`, the
//!   acceleration is built up with limited jerk at the start of a time-controlled ramp: a start,
//!   a change of velocity, a stop), [`JERK_ACC_REDUCTION`] (`16#0002`, it is reduced with
//!   limited jerk at the ramp's end: reaching the travel velocity, standstill after a stop) and
//!   [`JERK_TARGET_APPROACH`] (`16#0100`, the deceleration is reduced with limited jerk into the
//!   target). The default sets exactly the two transitions the library's profile figure marks,
//!   "6" and "5". Any other bit is refused (the library documents none).
//! - **The jerk** of a move is the smaller of `fMaxJerk` and the command's `Jerk` when that is
//!   above 0 (the library: "If this parameter is 0.0, it is replaced by a default value from the
//!   axis parameters"; `McPara_MaxJerk` bounds what the application may command).
//! - **The braking curve** is the set speed as a function of the remaining distance `d`, with
//!   the deceleration `D` and the jerk `J`: the square root `v = sqrt(2·D·(d - D³/(24·J²)))` down
//!   to the residual distance `d_r = D³/(6·J²)`, where the speed is `D²/(2·J)`; below it the
//!   deceleration falls linearly in time from `D` to 0 (jerk `J`), which as a function of the
//!   distance is `v = cbrt(4.5·J·d²)` and ends at the target with speed and deceleration 0.
//!   The two branches meet with the same speed and deceleration. Without
//!   [`JERK_TARGET_APPROACH`] the square root runs to the target: `v = sqrt(2·D·d)`.
//! - **The brake point** is the remaining distance where the curve's speed is the travel
//!   velocity, computed at the start. A move too short to reach its velocity gets the highest
//!   peak velocity whose start ramp and braking curve fit its distance (found at the start by
//!   bisection on closed-form distances), so that a jerk-limited reduction of the acceleration
//!   ends on the curve.
//! - **Displacement-controlled** means the remaining distance is measured from the position
//!   the generator is given each cycle (the actual position; the time-based mode gives the set
//!   position, which makes the whole profile a function of time), down to the residual
//!   distance. The last part, the jerk-limited reduction, is **time-controlled** from where it
//!   begins (the cubic law sampled once a cycle overshoots in its last three cycles; its exact
//!   continuation in time does not): it starts on the cubic branch of the curve at the sampled
//!   distance, so that the jerk is exactly `J`, and ends after `sqrt(2·v/J)` seconds.
//! - **The braking distance** ends the move as with the displacement-based generator: once the
//!   remaining distance is at most `fBrakeDistance + fBrakeDeadTime·|v_act|` the generator is
//!   idle and the set position is the target, the position controller at standstill takes the
//!   rest (in the library's displacement mode the set position "jumps to the target once the
//!   braking distance is reached").
//! - **Time-controlled ramps** (start, change of velocity, stop, feed stop) are exact
//!   three-segment jerk profiles (build-up, constant acceleration, reduction), each jerk
//!   segment present when its bit is set and a step of the acceleration otherwise, sampled
//!   once a cycle: the acceleration changes by at most `J·dt` per cycle where jerk-limited. A
//!   stop with `fStopRamp` (or the command's deceleration, `MC_Stop_BkPlcMc`) uses the move's
//!   jerk ("MaxJerk is used if a jerk-limiting control value generator is selected"); an
//!   emergency stop with `fEmergencyRamp` has none.
//! - **Restart while moving** (a new target or velocity): the ramp starts from the current
//!   speed and acceleration. A speed above the new braking curve is taken down to the curve at
//!   once (the square-root generator's behaviour; the library warns that the new target can be
//!   overshot), a move the other way first stops with `fStopRamp`, as the displacement-based
//!   generator does.
//!
//! The electric axes' planner (`kinematics::profile`, the S7 velocity profile) has one jerk for
//! every transition; `nJerkEnabled` chooses transitions separately and the braking is a
//! function of the distance, so the ramp here is its own three segments with the same closed
//! forms. With both acceleration bits set the ramp is the planner's `plan_velocity`, which the
//! tests check sample by sample.
//!
//! Pure: no IO, no clock (the cycle time is an input), no allocation.

use super::generator::{CtrlBasedGenerator, GeneratorError, GeneratorParams, HydState};
use super::profile_core::{check_move, GeneratorCore, ProfileGenerator};
use crate::catalog::hyd_error::HydErrorCode;

/// `nJerkEnabled` bit `16#0001`: the acceleration of a time-controlled ramp is built up with
/// limited jerk (inferred).
pub const JERK_ACC_BUILD_UP: u16 = 0x0001;
/// `nJerkEnabled` bit `16#0002`: the acceleration of a time-controlled ramp is reduced with
/// limited jerk at its end (inferred).
pub const JERK_ACC_REDUCTION: u16 = 0x0002;
/// `nJerkEnabled` bit `16#0100`: the deceleration is reduced with limited jerk into the target
/// (inferred).
pub const JERK_TARGET_APPROACH: u16 = 0x0100;
/// The bits of `nJerkEnabled` this generator knows.
pub const JERK_ENABLED_BITS: u16 = JERK_ACC_BUILD_UP | JERK_ACC_REDUCTION | JERK_TARGET_APPROACH;

/// The jerk parameters (members of `ST_TcHydAxParam`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct JerkParams {
    /// `fMaxJerk` (mm/s³, > 0).
    #[doc(alias = "fMaxJerk")]
    pub max_jerk: f64,
    /// `nJerkEnabled`: which transitions are jerk-limited ([`JERK_ENABLED_BITS`]).
    #[doc(alias = "nJerkEnabled")]
    pub jerk_enabled: u16,
}

impl Default for JerkParams {
    /// The library's defaults: `fMaxJerk` 1000 mm/s³, `nJerkEnabled` `16#0101`.
    fn default() -> Self {
        Self {
            max_jerk: 1000.0,
            jerk_enabled: 0x0101,
        }
    }
}

impl JerkParams {
    /// Refuses a jerk that is not finite and above 0 and bits outside [`JERK_ENABLED_BITS`].
    pub fn check(&self) -> Result<(), GeneratorError> {
        if !(self.max_jerk.is_finite() && self.max_jerk > 0.0) {
            return Err(GeneratorError::Invalid {
                name: "fMaxJerk",
                value: self.max_jerk,
            });
        }
        if self.jerk_enabled & !JERK_ENABLED_BITS != 0 {
            return Err(GeneratorError::Invalid {
                name: "nJerkEnabled",
                value: f64::from(self.jerk_enabled),
            });
        }
        Ok(())
    }

    fn on(&self, bit: u16) -> bool {
        self.jerk_enabled & bit != 0
    }
}

/// The library's error code of a refusal of the jerk-based generator: `dwTcHydErrCdJerk`
/// (`16#430B`) for the jerk, else as [`GeneratorError::code`].
pub fn error_code(e: &GeneratorError) -> HydErrorCode {
    match e {
        GeneratorError::Invalid {
            name: "fMaxJerk" | "Jerk" | "nJerkEnabled",
            ..
        } => HydErrorCode(0x430B),
        _ => e.code(),
    }
}

/// The set value generator of a hydraulic axis, `nProfileType` (`E_TcMcProfileType`): the
/// two a cell file can select.
#[doc(alias = "E_TcMcProfileType")]
#[doc(alias = "nProfileType")]
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum ProfileType {
    /// `iTcMc_ProfileCtrlBased` (3; the default; `iTcMc_ProfileConstAcc`, 0, is its old name).
    #[default]
    CtrlBased,
    /// `iTcMc_ProfileJerkBased` (5).
    JerkBased,
}

impl ProfileType {
    /// The enumeration's names and numbers a cell file may give, with what they select
    /// (`iTcMc_ProfileConstAcc` "has been replaced by iTcMc_ProfileCtrlBased").
    pub const NAMES: [(&'static str, u16, ProfileType); 3] = [
        ("iTcMc_ProfileConstAcc", 0, ProfileType::CtrlBased),
        ("iTcMc_ProfileCtrlBased", 3, ProfileType::CtrlBased),
        ("iTcMc_ProfileJerkBased", 5, ProfileType::JerkBased),
    ];

    /// The library's name.
    pub const fn name(self) -> &'static str {
        match self {
            Self::CtrlBased => "iTcMc_ProfileCtrlBased",
            Self::JerkBased => "iTcMc_ProfileJerkBased",
        }
    }

    /// The library's number.
    pub const fn number(self) -> u16 {
        match self {
            Self::CtrlBased => 3,
            Self::JerkBased => 5,
        }
    }

    /// The type of the library's name `name` (see [`ProfileType::NAMES`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::NAMES
            .iter()
            .find(|(n, _, _)| *n == name)
            .map(|(_, _, t)| *t)
    }

    /// The type of the library's number `n` (see [`ProfileType::NAMES`]).
    pub fn from_number(n: i64) -> Option<Self> {
        Self::NAMES
            .iter()
            .find(|(_, k, _)| i64::from(*k) == n)
            .map(|(_, _, t)| *t)
    }
}

/// Which generator runs a hydraulic axis' positionings, and how.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct ProfileSelection {
    /// `nProfileType`.
    pub profile_type: ProfileType,
    /// `fMaxJerk`, `nJerkEnabled` (the jerk-based generator's).
    pub jerk: JerkParams,
    /// `bTimeBased`: "the profile calculations are timer-controlled. The position controller is
    /// always active." The generator is given the set position in place of the actual one
    /// while it moves, and the position controller acts during the move.
    #[doc(alias = "bTimeBased")]
    pub time_based: bool,
}

/// A time-controlled change of the speed: build-up of the acceleration (jerk `1/iu`, a step
/// when `iu` is 0), constant acceleration, reduction (jerk `1/id`). In the ramp's own frame
/// (`sgn` +1 speeding up, -1 slowing down) the speed rises from `v0` to `v1`.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
struct Ramp {
    sgn: f64,
    v0: f64,
    a0: f64,
    v1: f64,
    iu: f64,
    id: f64,
    ap: f64,
    t1: f64,
    t2: f64,
    t3: f64,
}

impl Ramp {
    /// From speed `v` and acceleration `a` (along the motion) to speed `v1` with the bound
    /// `bound` (> 0) and the jerks `ju`, `jd` (`INFINITY`: a step).
    fn new(v: f64, a: f64, v1: f64, bound: f64, ju: f64, jd: f64) -> Self {
        let sgn = if v1 >= v { 1.0 } else { -1.0 };
        let (v0, a0, dv) = (sgn * v, sgn * a, (v1 - v).abs());
        let (iu, id) = (1.0 / ju, 1.0 / jd);
        let mut ap = if iu + id > 0.0 {
            ((2.0 * dv + a0 * a0 * iu) / (iu + id)).sqrt().min(bound)
        } else {
            bound
        };
        // The acceleration the ramp starts from: the current one when it is built up with
        // limited jerk, else the peak at once.
        let mut start = if iu > 0.0 { a0 } else { ap };
        let (mut t1, mut t2) = (0.0, 0.0);
        if start > ap && id > 0.0 {
            // More acceleration than the change allows: reduce from it at once (the end speed
            // is passed by the excess, then taken).
            ap = start;
        } else if ap > 0.0 {
            start = start.min(ap);
            t1 = (ap - start) * iu;
            let dv13 = (ap * ap - start * start) * iu * 0.5 + ap * ap * id * 0.5;
            t2 = ((dv - dv13) / ap).max(0.0);
        }
        Self {
            sgn,
            v0,
            a0: start,
            v1: sgn * v1,
            iu,
            id,
            ap,
            t1,
            t2,
            t3: ap * id,
        }
    }

    /// The duration (s).
    fn duration(&self) -> f64 {
        self.t1 + self.t2 + self.t3
    }

    /// Speed, acceleration (along the motion) and distance travelled at `t` seconds from the
    /// start (after the end: the end speed, acceleration 0, distance extrapolated).
    fn at(&self, t: f64) -> (f64, f64, f64) {
        let (v0, a0, ap) = (self.v0, self.a0, self.ap);
        let ju = if self.iu > 0.0 { 1.0 / self.iu } else { 0.0 };
        let jd = if self.id > 0.0 { 1.0 / self.id } else { 0.0 };
        let t1 = t.clamp(0.0, self.t1);
        let (mut v, mut a) = (v0 + a0 * t1 + 0.5 * ju * t1 * t1, a0 + ju * t1);
        let mut s = v0 * t1 + 0.5 * a0 * t1 * t1 + ju * t1 * t1 * t1 / 6.0;
        let t2 = (t - self.t1).clamp(0.0, self.t2);
        if t > self.t1 {
            a = ap;
            s += v * t2 + 0.5 * ap * t2 * t2;
            v += ap * t2;
        }
        let t3 = (t - self.t1 - self.t2).clamp(0.0, self.t3);
        if t > self.t1 + self.t2 {
            s += v * t3 + 0.5 * ap * t3 * t3 - jd * t3 * t3 * t3 / 6.0;
            v += ap * t3 - 0.5 * jd * t3 * t3;
            a = ap - jd * t3;
        }
        if t >= self.duration() {
            s += self.v1 * (t - self.duration());
            (v, a) = (self.v1, 0.0);
        }
        (self.sgn * v, self.sgn * a, self.sgn * s)
    }
}

/// The braking curve of a move: the set speed as a function of the remaining distance.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
struct Curve {
    dec: f64,
    jerk: f64,
    /// The deceleration is reduced with limited jerk into the target.
    jerk_end: bool,
}

impl Curve {
    /// `d_r = D³/(6·J²)`: below it the jerk-limited end (0 without).
    fn residual(&self) -> f64 {
        if self.jerk_end {
            self.dec.powi(3) / (6.0 * self.jerk * self.jerk)
        } else {
            0.0
        }
    }

    /// The set speed at remaining distance `d`.
    fn speed(&self, d: f64) -> f64 {
        if d <= 0.0 {
            0.0
        } else if d < self.residual() {
            (4.5 * self.jerk * d * d).cbrt()
        } else {
            let d0 = self.residual() * 0.25;
            (2.0 * self.dec * (d - d0)).sqrt()
        }
    }

    /// The remaining distance where the set speed is `v` (the inverse of [`Curve::speed`]).
    fn distance(&self, v: f64) -> f64 {
        let vr = if self.jerk_end {
            self.dec * self.dec / (2.0 * self.jerk)
        } else {
            0.0
        };
        if v <= 0.0 {
            0.0
        } else if v < vr {
            (v * v * v / (4.5 * self.jerk)).sqrt()
        } else {
            self.residual() * 0.25 + v * v / (2.0 * self.dec)
        }
    }
}

/// A move the generator runs (the command's values, limited by the parameters).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
struct JerkMove {
    /// The travel velocity the command asked for (limited).
    velocity: f64,
    /// The peak velocity of the start ramp (the travel velocity, or less for a short move).
    peak: f64,
    acc: f64,
    jerk: f64,
    curve: Curve,
    /// Remaining distance at which the braking ramp begins.
    brake_point: f64,
}

/// Where the generator is within a move.
#[derive(Copy, Clone, Debug, PartialEq)]
enum Phase {
    /// A time-controlled ramp (start, change of velocity, stop) `t` seconds in.
    Ramp { ramp: Ramp, t: f64 },
    /// The displacement-controlled square-root ramp (or travel, in `ConstVelo`).
    Curve,
    /// The jerk-limited end into the target, `rest` seconds before its end.
    Final { rest: f64 },
}

/// The jerk-based generator `iTcMc_ProfileJerkBased` (see the module documentation).
#[doc(alias = "iTcMc_ProfileJerkBased")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct JerkBasedGenerator {
    c: GeneratorCore,
    j: JerkParams,
    phase: Phase,
    mv: JerkMove,
}

impl JerkBasedGenerator {
    /// The generator with parameters `p` and `j`, idle at position `x`; the parameters are
    /// checked as the displacement-based generator checks them, and the jerk's.
    pub fn new(p: GeneratorParams, j: JerkParams, x: f64) -> Result<Self, GeneratorError> {
        CtrlBasedGenerator::new(p, x)?;
        j.check()?;
        let dec = p.dec.min(p.max_dec);
        Ok(Self {
            c: GeneratorCore::idle_at(p, x),
            j,
            phase: Phase::Curve,
            mv: JerkMove {
                acc: p.acc.min(p.max_acc),
                jerk: j.max_jerk,
                curve: Curve {
                    dec,
                    jerk: j.max_jerk,
                    jerk_end: j.on(JERK_TARGET_APPROACH),
                },
                ..JerkMove::default()
            },
        })
    }

    /// `fMaxJerk` and `nJerkEnabled`.
    pub fn jerk_params(&self) -> &JerkParams {
        &self.j
    }

    /// The residual distance of the running move: where the jerk-limited end begins.
    pub fn residual_distance(&self) -> f64 {
        self.mv.curve.residual()
    }

    /// The peak velocity of the running move's start ramp (its velocity, or less for a move
    /// too short to reach it).
    pub fn peak_velocity(&self) -> f64 {
        self.mv.peak
    }

    /// The set acceleration of the last cycle (mm/s², signed).
    pub fn acceleration(&self) -> f64 {
        self.c.acceleration
    }

    /// Whether the running move is in its jerk-limited end into the target.
    pub fn in_final_approach(&self) -> bool {
        matches!(self.phase, Phase::Final { .. }) && self.c.state == HydState::PcDec
    }

    /// Starts a move to `target` (`MC_MoveAbsolute_BkPlcMc`) from the actual position
    /// `actual` with the command's `jerk` (0: `fMaxJerk`); the other inputs as
    /// [`CtrlBasedGenerator::move_absolute`].
    pub fn move_absolute(
        &mut self,
        target: f64,
        velocity: f64,
        (acceleration, deceleration, jerk): (f64, f64, f64),
        actual: f64,
    ) -> Result<(), GeneratorError> {
        check_move(
            target,
            velocity,
            &[
                ("Acceleration", acceleration),
                ("Deceleration", deceleration),
                ("Jerk", jerk),
            ],
        )?;
        let limit = |param: f64, cmd: f64| if cmd > 0.0 { param.min(cmd) } else { param };
        let positive = target >= actual;
        if !self.feed_enabled(positive) && target != actual {
            return Err(GeneratorError::FeedEnable { positive });
        }
        let p = &self.c.p;
        let jerk = limit(self.j.max_jerk, jerk);
        self.c.target = target;
        self.mv = JerkMove {
            velocity: velocity.min(p.ref_velo).min(p.max_velo),
            acc: limit(p.acc.min(p.max_acc), acceleration),
            jerk,
            curve: Curve {
                dec: limit(p.dec.min(p.max_dec), deceleration),
                jerk,
                jerk_end: self.j.on(JERK_TARGET_APPROACH),
            },
            ..self.mv
        };
        if self.c.velocity == 0.0 {
            self.c.position = actual;
            self.c.acceleration = 0.0;
        }
        let moving_other_way = self.c.velocity != 0.0 && (self.c.velocity > 0.0) != positive;
        self.c.reverse_pending = moving_other_way;
        if moving_other_way {
            self.begin_stop(HydState::TcDec, self.c.stop_ramp_dec());
        } else {
            self.c.positive = positive;
            self.begin_move();
        }
        Ok(())
    }

    /// The speed and the acceleration along the motion.
    fn along(&self) -> (f64, f64) {
        let sign = self.c.sign();
        (self.c.velocity * sign, self.c.acceleration * sign)
    }

    /// The jerks of a time-controlled ramp's build-up and reduction with jerk `j`.
    fn ramp_jerks(&self, j: f64) -> (f64, f64) {
        let pick = |bit| if self.j.on(bit) { j } else { f64::INFINITY };
        (pick(JERK_ACC_BUILD_UP), pick(JERK_ACC_REDUCTION))
    }

    /// The start ramp of the move from the set position and the set speed: its peak velocity
    /// (the highest whose ramp and braking curve fit the remaining distance) and its brake
    /// point.
    fn begin_move(&mut self) {
        let (v, a) = self.along();
        let m = self.mv;
        let sign = self.c.sign();
        let d = (self.c.target - self.c.position) * sign;
        let (ju, jd) = self.ramp_jerks(m.jerk);
        let ramp_to = |peak: f64| {
            let bound = if peak >= v { m.acc } else { m.curve.dec };
            Ramp::new(v, a, peak, bound, ju, jd)
        };
        let need = |peak: f64| {
            let r = ramp_to(peak);
            r.at(r.duration()).2 + m.curve.distance(peak)
        };
        let peak = if need(m.velocity) <= d {
            m.velocity
        } else if need(0.0) > d {
            // Not even a stop fits: the braking curve takes the speed at once.
            v
        } else {
            let (mut lo, mut hi) = (0.0, m.velocity);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if need(mid) <= d {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        };
        self.mv.peak = peak;
        self.mv.brake_point = m.curve.distance(peak);
        self.phase = Phase::Ramp {
            ramp: ramp_to(peak),
            t: 0.0,
        };
        self.c.state = HydState::TcAcc;
    }

    /// A time-controlled ramp to standstill with deceleration `dec` in state `state` (an
    /// emergency stop without jerk limitation).
    fn ramp_down(&mut self, state: HydState, dec: f64) {
        let (v, a) = self.along();
        let (ju, jd) = if state == HydState::EmergencyBreak {
            (f64::INFINITY, f64::INFINITY)
        } else {
            self.ramp_jerks(self.mv.jerk)
        };
        self.c.stop_dec = dec;
        self.phase = Phase::Ramp {
            ramp: Ramp::new(v, a, 0.0, dec, ju, jd),
            t: 0.0,
        };
        self.c.state = state;
    }

    /// The state machine of one cycle.
    fn cycle(&mut self, dt: f64, actual: f64, actual_velocity: f64) {
        let moving = matches!(
            self.c.state,
            HydState::TcAcc | HydState::ConstVelo | HydState::PcDec
        );
        if moving && !self.feed_enabled(self.c.positive) {
            self.c.reverse_pending = false;
            self.begin_stop(HydState::FeedStop, self.c.stop_ramp_dec());
        }
        match self.c.state {
            HydState::Idle => self.idle(actual),
            HydState::FeedStop if self.feed_enabled(self.c.positive) => {
                // The enable is back: the move goes on from the speed the stop came down to.
                self.begin_move();
                self.travel(dt, actual, actual_velocity);
            }
            HydState::TcDec | HydState::EmergencyBreak | HydState::FeedStop => self.stopping(dt),
            _ => self.travel(dt, actual, actual_velocity),
        }
    }

    /// Idle: the set position is the target; the automatic start by `fReposDistance`.
    fn idle(&mut self, actual: f64) {
        self.c.velocity = 0.0;
        self.c.acceleration = 0.0;
        self.c.position = self.c.target;
        let off = (actual - self.c.target).abs();
        if self.c.p.repos_distance > 0.0 && off > self.c.p.repos_distance {
            self.c.positive = self.c.target >= actual;
            self.c.position = actual;
            self.c.repositioned += 1;
            self.begin_move();
        }
    }

    /// A time-controlled stop ramp; at standstill the reversal waiting for it starts, or the
    /// axis is idle (a feed stop waits).
    fn stopping(&mut self, dt: f64) {
        let Phase::Ramp { ramp, t } = self.phase else {
            self.begin_stop(self.c.state, self.c.stop_dec);
            return;
        };
        let t = t + dt;
        self.phase = Phase::Ramp { ramp, t };
        let (v, a, _) = ramp.at(t);
        self.set(v.max(0.0), a, dt);
        if t >= ramp.duration() || v <= 0.0 {
            self.set(0.0, 0.0, 0.0);
            if self.c.state == HydState::FeedStop {
                return;
            }
            if self.c.reverse_pending && self.c.state == HydState::TcDec {
                self.c.reverse_pending = false;
                self.c.positive = !self.c.positive;
                self.begin_move();
            } else {
                self.c.reverse_pending = false;
                self.c.state = HydState::Idle;
                self.c.target = self.c.position;
            }
        }
    }

    /// A cycle of the move: the start ramp or travel until the braking curve, the curve down
    /// to the residual distance, the jerk-limited end; idle within the braking distance.
    fn travel(&mut self, dt: f64, actual: f64, actual_velocity: f64) {
        let sign = self.c.sign();
        let m = self.mv;
        let approach = if self.c.positive || !self.c.p.asymmetrical {
            self.c.p.approach_p
        } else {
            self.c.p.approach_m
        };
        let remaining = (self.c.target - actual) * sign;
        let braking = approach.brake_distance + approach.brake_dead_time * actual_velocity.abs();
        if remaining <= braking {
            return self.arrive();
        }
        if let Phase::Final { rest } = self.phase {
            return self.final_approach(rest - dt, dt);
        }
        // The curve at the distance left at the end of this cycle at the present speed (the
        // set values are those of the cycle's end).
        let now = self.along().0;
        let ahead = remaining - now * dt;
        let curve = m.curve.speed(ahead);
        let (speed, acc) = match self.phase {
            Phase::Ramp { ramp, t } if self.c.state == HydState::TcAcc => {
                let t = t + dt;
                self.phase = Phase::Ramp { ramp, t };
                let (v, a, _) = ramp.at(t);
                if t >= ramp.duration() {
                    self.c.state = HydState::ConstVelo;
                }
                (v, a)
            }
            _ if self.c.state == HydState::PcDec => (now, 0.0),
            _ => (m.peak, 0.0),
        };
        if speed < curve && self.c.state != HydState::PcDec {
            return self.set(speed, acc, dt);
        }
        self.c.state = HydState::PcDec;
        self.phase = Phase::Curve;
        if remaining < m.curve.residual() {
            // The jerk-limited end from the cubic branch at this distance, `rest` seconds
            // before the target (d = J·rest³/6), then exact in time.
            let rest = (6.0 * remaining / m.curve.jerk).cbrt();
            return self.final_approach(rest - dt, dt);
        }
        // Never above the curve; below it (an actual position lagging, a restart) up again
        // with the acceleration, as the displacement-based generator does.
        let s = curve.min(speed.max(now + m.acc * dt));
        if ahead <= 0.0 || 0.5 * (now + s) * dt >= remaining {
            // The target within this cycle.
            return self.arrive();
        }
        self.set(s, if s > now { m.acc } else { -m.curve.dec }, dt);
    }

    /// The jerk-limited end, `rest` seconds before it ends: speed `J·rest²/2`, deceleration
    /// `J·rest`, the distance to its end `J·rest³/6` (exact between the samples).
    fn final_approach(&mut self, rest: f64, dt: f64) {
        let j = self.mv.curve.jerk;
        if rest <= 0.0 {
            return self.arrive();
        }
        let before = rest + dt;
        let ds = j * (before.powi(3) - rest.powi(3)) / 6.0;
        let sign = self.c.sign();
        self.phase = Phase::Final { rest };
        self.c.velocity = sign * 0.5 * j * rest * rest;
        self.c.acceleration = -sign * j * rest;
        self.c.position += sign * ds;
    }

    /// The move ends: idle, the set position the target.
    fn arrive(&mut self) {
        self.c.state = HydState::Idle;
        self.phase = Phase::Curve;
        self.c.velocity = 0.0;
        self.c.acceleration = 0.0;
        self.c.position = self.c.target;
    }

    /// Sets the speed `s` and acceleration `a` along the motion and integrates the set
    /// position over `dt`.
    fn set(&mut self, s: f64, a: f64, dt: f64) {
        let sign = self.c.sign();
        let v = s * sign;
        self.c.position += 0.5 * (self.c.velocity + v) * dt;
        self.c.velocity = v;
        self.c.acceleration = a * sign;
    }
}

impl ProfileGenerator for JerkBasedGenerator {
    fn core(&self) -> &GeneratorCore {
        &self.c
    }

    fn core_mut(&mut self) -> &mut GeneratorCore {
        &mut self.c
    }

    /// The time-based mode gives the set position and velocity of the last cycle as `actual`.
    fn advance(&mut self, dt: f64, actual: f64, actual_velocity: f64) {
        self.cycle(dt, actual, actual_velocity);
    }

    fn begin_stop(&mut self, state: HydState, dec: f64) {
        self.ramp_down(state, dec);
    }

    fn brake_point(&self) -> f64 {
        self.mv.brake_point
    }
}

/// The generator `nProfileType` selects, behind one interface (the axis runs either).
#[doc(alias = "nProfileType")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Generator {
    /// `iTcMc_ProfileCtrlBased`.
    CtrlBased(CtrlBasedGenerator),
    /// `iTcMc_ProfileJerkBased`.
    JerkBased(JerkBasedGenerator),
}

impl Generator {
    /// The generator `sel` selects with parameters `p`, idle at position `x`.
    pub fn new(sel: &ProfileSelection, p: GeneratorParams, x: f64) -> Result<Self, GeneratorError> {
        Ok(match sel.profile_type {
            ProfileType::CtrlBased => Self::CtrlBased(CtrlBasedGenerator::new(p, x)?),
            ProfileType::JerkBased => Self::JerkBased(JerkBasedGenerator::new(p, sel.jerk, x)?),
        })
    }

    /// Which one it is.
    pub fn profile_type(&self) -> ProfileType {
        match self {
            Self::CtrlBased(_) => ProfileType::CtrlBased,
            Self::JerkBased(_) => ProfileType::JerkBased,
        }
    }

    /// [`CtrlBasedGenerator::limit_velocity`] (MC_AxCtrlSlowDownOnPressureEx_BkPlcMc); the
    /// jerk-based generator takes no limit (the instruction refuses it).
    pub fn limit_velocity(&mut self, limit: f64) {
        if let Self::CtrlBased(g) = self {
            g.limit_velocity(limit);
        }
    }

    /// [`CtrlBasedGenerator::limited`]; false for the jerk-based generator.
    pub fn limited(&self) -> bool {
        match self {
            Self::CtrlBased(g) => g.limited(),
            Self::JerkBased(_) => false,
        }
    }

    /// A move as [`CtrlBasedGenerator::move_absolute`] (the jerk-based one with `fMaxJerk`).
    pub fn move_absolute(
        &mut self,
        target: f64,
        velocity: f64,
        acceleration: f64,
        deceleration: f64,
        actual: f64,
    ) -> Result<(), GeneratorError> {
        self.move_with_jerk(target, velocity, (acceleration, deceleration, 0.0), actual)
    }

    /// A move with the command's acceleration, deceleration and jerk (the displacement-based
    /// generator has no use for the jerk).
    pub fn move_with_jerk(
        &mut self,
        target: f64,
        velocity: f64,
        (acceleration, deceleration, jerk): (f64, f64, f64),
        actual: f64,
    ) -> Result<(), GeneratorError> {
        match self {
            Self::CtrlBased(g) => {
                g.move_absolute(target, velocity, acceleration, deceleration, actual)
            }
            Self::JerkBased(g) => {
                g.move_absolute(target, velocity, (acceleration, deceleration, jerk), actual)
            }
        }
    }
}

impl ProfileGenerator for Generator {
    fn core(&self) -> &GeneratorCore {
        match self {
            Self::CtrlBased(g) => g.core(),
            Self::JerkBased(g) => g.core(),
        }
    }

    fn core_mut(&mut self) -> &mut GeneratorCore {
        match self {
            Self::CtrlBased(g) => g.core_mut(),
            Self::JerkBased(g) => g.core_mut(),
        }
    }

    fn advance(&mut self, dt: f64, actual: f64, actual_velocity: f64) {
        match self {
            Self::CtrlBased(g) => g.advance(dt, actual, actual_velocity),
            Self::JerkBased(g) => g.advance(dt, actual, actual_velocity),
        }
    }

    fn begin_stop(&mut self, state: HydState, dec: f64) {
        match self {
            Self::CtrlBased(g) => g.begin_stop(state, dec),
            Self::JerkBased(g) => g.begin_stop(state, dec),
        }
    }

    fn brake_point(&self) -> f64 {
        match self {
            Self::CtrlBased(g) => g.brake_point(),
            Self::JerkBased(g) => g.brake_point(),
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;
    use crate::hydraulic::generator::Approach;
    use crate::hydraulic::generator::Setpoint;
    use crate::kinematics::profile::{plan_velocity, Limits, State};
    use proptest::prelude::*;

    const DT: f64 = 1e-3;

    /// `fAcc` = `fMaxAcc` = `fDec` = `fMaxDec` = 500 mm/s², no braking distance (the curve
    /// runs into the target).
    fn params() -> GeneratorParams {
        let approach = Approach {
            creep_speed: 10.0,
            creep_distance: 1.0,
            brake_distance: 0.0,
            brake_dead_time: 0.0,
        };
        GeneratorParams {
            acc: 500.0,
            max_acc: 500.0,
            dec: 500.0,
            max_dec: 500.0,
            approach_p: approach,
            approach_m: approach,
            ..GeneratorParams::default()
        }
    }

    fn jerk(max_jerk: f64, jerk_enabled: u16) -> JerkParams {
        JerkParams {
            max_jerk,
            jerk_enabled,
        }
    }

    /// One cycle's output with the generator's acceleration and phase.
    #[derive(Copy, Clone, Debug)]
    struct Sample {
        s: Setpoint,
        a: f64,
        last: bool,
    }

    /// Runs `g` on an ideal axis (the actual position is the set position of the cycle
    /// before, as the time-based mode gives it) until idle or `cycles`.
    fn run(g: &mut JerkBasedGenerator, cycles: usize) -> Vec<Sample> {
        let mut out = Vec::new();
        let (mut x, mut v) = (g.c.position, g.c.velocity);
        for _ in 0..cycles {
            let s = g.step(DT, x, v);
            out.push(Sample {
                s,
                a: g.acceleration(),
                last: g.in_final_approach(),
            });
            (x, v) = (s.position, s.velocity);
            if s.state == HydState::Idle {
                break;
            }
        }
        out
    }

    #[test]
    fn a_move_runs_the_jerk_profile_with_its_numbers() {
        // fRefVelo 500, velocity 100, acceleration and deceleration 500, fMaxJerk 5000,
        // nJerkEnabled 16#0101, 0 → 100 mm.
        // Start ramp: the acceleration built up in 500/5000 = 0.1 s (+25 mm/s, J·t³/6 =
        // 0.8333 mm), then 500 mm/s² from 25 to 100 mm/s in 0.15 s (25·0.15 + 250·0.15² =
        // 9.375 mm): 0.25 s, 10.2083 mm, the acceleration dropped at once (bit 16#0002 clear).
        // Braking curve: residual distance D³/(6J²) = 1.25e8/1.5e8 = 0.8333 mm at D²/(2J) =
        // 25 mm/s; square root offset D³/(24J²) = 0.2083 mm; brake point 0.2083 + 100²/1000 =
        // 10.2083 mm before the target, at 89.7917 mm, reached after 0.25 + (89.7917 -
        // 10.2083)/100 = 1.0458 s. Then 0.15 s of square root (100 → 25 mm/s at 500) and 0.1 s
        // of jerk-limited end: at the target after 1.2958 s.
        let mut g = JerkBasedGenerator::new(params(), jerk(5000.0, 0x0101), 0.0).unwrap();
        g.move_absolute(100.0, 100.0, (0.0, 0.0, 0.0), 0.0).unwrap();
        assert!((g.brake_point() - (0.25 / 1.2 + 10.0)).abs() < 1e-12);
        assert!((g.residual_distance() - 1.0 / 1.2).abs() < 1e-12);
        assert_eq!(g.peak_velocity(), 100.0);
        let out = run(&mut g, 10_000);
        let mut states: Vec<HydState> = out.iter().map(|x| x.s.state).collect();
        states.dedup();
        assert_eq!(
            states,
            [
                HydState::TcAcc,
                HydState::ConstVelo,
                HydState::PcDec,
                HydState::Idle
            ]
        );
        // The ramp: 250 cycles (the 250th sample ends it at 100 mm/s).
        let acc = out.iter().filter(|x| x.s.state == HydState::TcAcc).count();
        assert_eq!(acc, 249);
        // The jerk phase: the acceleration rises by J·dt = 5 mm/s² a cycle to 500 at 0.1 s.
        for (k, x) in out.iter().take(100).enumerate() {
            assert!((x.a - 5.0 * (k + 1) as f64).abs() < 1e-9, "{k}: {x:?}");
        }
        // The brake starts on the first cycle that will have at most 10.2083 mm left at its
        // end (100 mm/s · 1 ms = 0.1 mm less than at its start): the position of the cycle
        // before at 89.6917 or more, reached at 0.25 + (89.6917 - 10.2083)/100 = 1.04483 s,
        // so the sample of 1.046 s.
        let brake = out
            .iter()
            .position(|x| x.s.state == HydState::PcDec)
            .unwrap();
        assert_eq!(brake + 1, 1046, "brake start cycle");
        let before = out[brake - 1].s.position;
        assert!((89.6917..89.6917 + 0.1).contains(&before), "{before}");
        // Never faster than 100 mm/s, never more than 500 mm/s² (the generator's acceleration
        // exactly; the change of the set velocity within the square root's sampling, which
        // reads the distance a cycle late: 500·(1 + 2·500·dt/v)).
        for w in out.windows(2) {
            let (v0, v1) = (w[0].s.velocity, w[1].s.velocity);
            assert!((0.0..=100.0 + 1e-12).contains(&v1));
            assert!(w[1].a.abs() <= 500.0 + 1e-9, "{w:?}");
            let slack = 1.0 + 2.0 * 500.0 * DT / v1.abs().max(1.0);
            assert!((v1 - v0).abs() / DT <= 500.0 * slack + 1e-9, "{w:?}");
        }
        // The jerk-limited end: the acceleration falls by at most J·dt a cycle, to the
        // target, where the set velocity is below J·dt²/2 one cycle before idle.
        let last: Vec<_> = out.iter().filter(|x| x.last).collect();
        assert!((95..=101).contains(&last.len()), "{}", last.len());
        for w in last.windows(2) {
            assert!((w[1].a - w[0].a).abs() <= 5000.0 * DT + 1e-9, "{w:?}");
        }
        let end = out.last().unwrap().s;
        assert_eq!(
            (end.state, end.velocity, end.position),
            (HydState::Idle, 0.0, 100.0)
        );
        let before = out[out.len() - 2].s;
        assert!(
            before.velocity <= 0.5 * 5000.0 * DT * DT + 1e-12,
            "{before:?}"
        );
        assert!(100.0 - before.position <= 5000.0 * DT.powi(3) / 6.0 + 1e-12);
        // At the target after 1.2958 s, give or take the sampling.
        assert!((1294..=1299).contains(&out.len()), "{}", out.len());
    }

    #[test]
    fn with_both_acceleration_bits_the_start_ramp_is_the_electric_planners() {
        // 16#0103: the build-up and the reduction jerk-limited, as S7's velocity profile and
        // `plan_velocity` ramp: each sample of the start ramp is the planner's.
        let mut g = JerkBasedGenerator::new(params(), jerk(4000.0, 0x0103), 0.0).unwrap();
        g.move_absolute(1000.0, 300.0, (0.0, 0.0, 0.0), 0.0)
            .unwrap();
        let lim = Limits {
            vel: 300.0,
            acc: 500.0,
            dec: 500.0,
            jerk: 4000.0,
        };
        let prof = plan_velocity(State::rest(0.0), 300.0, &lim).unwrap();
        let out = run(&mut g, 2000);
        let mut n = 0;
        for (k, x) in out.iter().enumerate() {
            if x.s.state != HydState::TcAcc {
                break;
            }
            let want = prof.at((k + 1) as f64 * DT);
            assert!((x.s.velocity - want.v).abs() < 1e-9, "{k}: {x:?} {want:?}");
            assert!((x.a - want.a).abs() < 1e-9, "{k}: {x:?} {want:?}");
            n += 1;
        }
        // 300 mm/s at 500 with jerk 4000: 0.125 + 0.475 + 0.125 s.
        assert_eq!(n + 1, 725);
    }

    #[test]
    fn without_jerk_bits_the_profile_is_a_ramp_and_a_square_root_to_the_target() {
        // 16#0000: the acceleration at once (500·dt = 0.5 mm/s in the first cycle), the brake
        // point 100²/(2·500) = 10 mm, the square root sqrt(2·500·d) down to the target.
        let mut g = JerkBasedGenerator::new(params(), jerk(5000.0, 0), 0.0).unwrap();
        g.move_absolute(100.0, 100.0, (0.0, 0.0, 0.0), 0.0).unwrap();
        assert!((g.brake_point() - 10.0).abs() < 1e-12);
        assert_eq!(g.residual_distance(), 0.0);
        let out = run(&mut g, 10_000);
        assert!((out[0].s.velocity - 0.5).abs() < 1e-12);
        // In the square root: the distance at the cycle's end at the speed of its start.
        let (mut x, mut v) = (0.0, 0.0);
        for o in &out {
            if o.s.state == HydState::PcDec {
                let want = (1000.0_f64 * (100.0 - x - v * DT)).sqrt().min(100.0);
                assert!((o.s.velocity - want).abs() < 1e-9, "{o:?} {want}");
            }
            (x, v) = (o.s.position, o.s.velocity);
        }
        assert!(out.iter().all(|o| !o.last));
        assert_eq!(out.last().unwrap().s.position, 100.0);
    }

    #[test]
    fn a_short_move_peaks_where_its_ramp_and_curve_meet() {
        // 16#0103, 7.7083 mm at 100 mm/s: a ramp to 50 mm/s with both jerks (0.1 s up to
        // 500 mm/s², 0.1 s down: mean 25 mm/s over 0.2 s, 5 mm) and the curve from 50 mm/s
        // (0.2083 + 50²/1000 = 2.7083 mm) fill it exactly: the peak is 50 mm/s.
        let d = 5.0 + 0.25 / 1.2 + 2.5;
        let mut g = JerkBasedGenerator::new(params(), jerk(5000.0, 0x0103), 0.0).unwrap();
        g.move_absolute(d, 100.0, (0.0, 0.0, 0.0), 0.0).unwrap();
        assert!(
            (g.peak_velocity() - 50.0).abs() < 1e-9,
            "{}",
            g.peak_velocity()
        );
        assert!((g.brake_point() - (0.25 / 1.2 + 2.5)).abs() < 1e-9);
        let out = run(&mut g, 5000);
        let top = out.iter().map(|x| x.s.velocity).fold(0.0, f64::max);
        assert!((top - 50.0).abs() < 0.1, "{top}");
        assert_eq!(out.last().unwrap().s.position, d);
    }

    #[test]
    fn the_commands_jerk_and_deceleration_shape_the_end() {
        // Jerk 2500 (below fMaxJerk): residual distance 500³/(6·2500²) = 3.3333 mm; a jerk
        // above fMaxJerk takes fMaxJerk; deceleration 250: 250³/(6·5000²) = 0.10417 mm.
        let mut g = JerkBasedGenerator::new(params(), jerk(5000.0, 0x0101), 0.0).unwrap();
        g.move_absolute(100.0, 100.0, (0.0, 0.0, 2500.0), 0.0)
            .unwrap();
        assert!((g.residual_distance() - 10.0 / 3.0).abs() < 1e-12);
        g.move_absolute(100.0, 100.0, (0.0, 0.0, 1e6), 0.0).unwrap();
        assert!((g.residual_distance() - 1.0 / 1.2).abs() < 1e-12);
        g.move_absolute(100.0, 100.0, (0.0, 250.0, 0.0), 0.0)
            .unwrap();
        assert!((g.residual_distance() - 250.0_f64.powi(3) / 1.5e8).abs() < 1e-12);
        let out = run(&mut g, 10_000);
        assert_eq!(out.last().unwrap().s.position, 100.0);
    }

    #[test]
    fn a_stop_ramps_down_with_the_jerk_of_the_build_up() {
        let mut g = JerkBasedGenerator::new(params(), jerk(5000.0, 0x0101), 0.0).unwrap();
        g.move_absolute(1000.0, 100.0, (0.0, 0.0, 0.0), 0.0)
            .unwrap();
        run(&mut g, 400);
        assert_eq!(g.state(), HydState::ConstVelo);
        // 500 mm/s²: built up in 0.1 s (-25 mm/s), then 75 mm/s in 0.15 s: 250 cycles.
        g.stop_with(500.0);
        let out = run(&mut g, 1000);
        assert_eq!(out.len(), 250);
        for (k, x) in out.iter().take(100).enumerate() {
            assert!((x.a + 5.0 * (k + 1) as f64).abs() < 1e-9, "{k}: {x:?}");
        }
        let last = out.last().unwrap().s;
        assert_eq!((last.state, last.velocity), (HydState::Idle, 0.0));
        assert_eq!(g.target(), last.position);
        // An emergency stop has no jerk: fEmergencyRamp 0.1 s from 500 mm/s, 5000 mm/s².
        g.move_absolute(2000.0, 100.0, (0.0, 0.0, 0.0), g.c.position)
            .unwrap();
        run(&mut g, 400);
        g.emergency_stop();
        let out = run(&mut g, 1000);
        assert_eq!(out.len(), 20);
        assert!((out[0].s.velocity - 95.0).abs() < 1e-9);
    }

    #[test]
    fn a_restart_while_moving_goes_on_without_a_step_and_lands() {
        let mut g = JerkBasedGenerator::new(params(), jerk(5000.0, 0x0103), 0.0).unwrap();
        g.move_absolute(400.0, 200.0, (0.0, 0.0, 0.0), 0.0).unwrap();
        let out = run(&mut g, 300);
        assert_eq!(out.last().unwrap().s.state, HydState::TcAcc);
        // Mid-ramp: a new target and a lower velocity.
        g.move_absolute(300.0, 80.0, (0.0, 0.0, 0.0), g.c.position)
            .unwrap();
        let mut all = out;
        all.extend(run(&mut g, 20_000));
        for w in all.windows(2) {
            let dv = (w[1].s.velocity - w[0].s.velocity).abs() / DT;
            let slack = 1.0 + 2.0 * 500.0 * DT / w[1].s.velocity.abs().max(1.0);
            assert!(dv <= 500.0 * slack + 1e-9, "{w:?}");
            assert!(w[1].s.velocity >= 0.0);
        }
        assert_eq!(all.last().unwrap().s.position, 300.0);
        // The other way: the stop ramp first, then the move.
        g.move_absolute(600.0, 100.0, (0.0, 0.0, 0.0), g.c.position)
            .unwrap();
        run(&mut g, 1000);
        g.move_absolute(0.0, 50.0, (0.0, 0.0, 0.0), g.c.position)
            .unwrap();
        let out = run(&mut g, 50_000);
        let mut states: Vec<(HydState, bool)> =
            out.iter().map(|x| (x.s.state, x.s.positive)).collect();
        states.dedup();
        assert_eq!(states[0], (HydState::TcDec, true));
        assert_eq!(states[1], (HydState::TcAcc, false));
        assert_eq!(out.last().unwrap().s.position, 0.0);
    }

    #[test]
    fn the_braking_distance_and_dead_time_end_the_move_early() {
        let mut p = params();
        p.approach_p.brake_distance = 0.5;
        p.approach_p.brake_dead_time = 0.05;
        let mut g = JerkBasedGenerator::new(p, jerk(5000.0, 0x0101), 0.0).unwrap();
        g.move_absolute(100.0, 100.0, (0.0, 0.0, 0.0), 0.0).unwrap();
        let out = run(&mut g, 10_000);
        // Idle on the first cycle that sees d <= 0.5 + 0.05·|v|. On the square root v² =
        // 1000·(d - 0.2083): v² - 50·v - 291.7 = 0, v = 55.3 mm/s at d = 3.26 mm (the curve
        // read a cycle ahead, 0.055 mm, puts the sampled end a little closer).
        let n = out.len();
        let seen = |k: usize| (100.0 - out[k].s.position, out[k].s.velocity);
        let (d, v) = seen(n - 2);
        assert!(d <= 0.5 + 0.05 * v, "{:?}", out[n - 2]);
        let (d1, v1) = seen(n - 3);
        assert!(d1 > 0.5 + 0.05 * v1, "{:?}", out[n - 3]);
        assert!((3.1..3.35).contains(&d), "{d}");
        assert_eq!(out.last().unwrap().s.position, 100.0);
    }

    #[test]
    fn the_negative_direction_lands_and_the_feed_stop_pauses() {
        let mut g = JerkBasedGenerator::new(params(), jerk(5000.0, 0x0101), 100.0).unwrap();
        g.move_absolute(0.0, 100.0, (0.0, 0.0, 0.0), 100.0).unwrap();
        run(&mut g, 300);
        g.set_feed_enables(true, false);
        let out = run(&mut g, 1000);
        assert!(out.iter().all(|x| x.s.state == HydState::FeedStop));
        assert_eq!(out.last().unwrap().s.velocity, 0.0);
        g.set_feed_enables(true, true);
        let out = run(&mut g, 10_000);
        assert!(out.iter().all(|x| x.s.velocity <= 0.0 && !x.s.positive));
        assert_eq!(out.last().unwrap().s.position, 0.0);
    }

    #[test]
    fn bad_parameters_and_commands_are_refused_and_change_nothing() {
        let e = JerkBasedGenerator::new(params(), jerk(0.0, 0x0101), 0.0).unwrap_err();
        assert_eq!(
            e,
            GeneratorError::Invalid {
                name: "fMaxJerk",
                value: 0.0
            }
        );
        assert_eq!(error_code(&e).name(), "dwTcHydErrCdJerk");
        let e = JerkBasedGenerator::new(params(), jerk(1000.0, 0x0200), 0.0).unwrap_err();
        assert_eq!(error_code(&e).0, 0x430B);
        let mut p = params();
        p.max_dec = -1.0;
        let e = JerkBasedGenerator::new(p, JerkParams::default(), 0.0).unwrap_err();
        assert_eq!(error_code(&e).name(), "dwTcHydErrCdDec");
        let mut g = JerkBasedGenerator::new(params(), JerkParams::default(), 0.0).unwrap();
        let before = g;
        assert!(g.move_absolute(10.0, 10.0, (0.0, 0.0, -1.0), 0.0).is_err());
        assert!(g
            .move_absolute(10.0, 10.0, (0.0, 0.0, f64::NAN), 0.0)
            .is_err());
        assert!(g
            .move_absolute(f64::NAN, 10.0, (0.0, 0.0, 0.0), 0.0)
            .is_err());
        assert_eq!(g, before);
        assert_eq!(
            ProfileType::from_name("iTcMc_ProfileJerkBased"),
            Some(ProfileType::JerkBased)
        );
        assert_eq!(ProfileType::from_number(0), Some(ProfileType::CtrlBased));
        assert_eq!(ProfileType::from_number(4), None);
        assert_eq!(ProfileType::JerkBased.number(), 5);
    }

    fn config() -> ProptestConfig {
        ProptestConfig {
            cases: 128,
            failure_persistence: None,
            rng_seed: proptest::test_runner::RngSeed::Fixed(0x6a65_726b),
            ..ProptestConfig::default()
        }
    }

    proptest! {
        #![proptest_config(config())]

        /// Over distances, velocities and limits: the velocity within the travel velocity
        /// and of the move's sign, the generator's acceleration within fAcc / fDec, the
        /// acceleration changing by at most J·dt a cycle within the jerk-limited
        /// transitions, the set position approaching the target monotonically without
        /// passing it, and idle exactly at the target.
        #[test]
        fn limits_hold_and_the_move_lands(
            d in 0.5_f64..400.0,
            v in 5.0_f64..400.0,
            acc in 50.0_f64..3000.0,
            dec in 50.0_f64..3000.0,
            j in 500.0_f64..100_000.0,
            bits in prop::sample::select(vec![0_u16, 0x0001, 0x0002, 0x0100, 0x0101, 0x0103]),
            up in any::<bool>(),
        ) {
            let mut p = params();
            (p.acc, p.max_acc, p.dec, p.max_dec) = (acc, acc, dec, dec);
            let (x0, target) = if up { (0.0, d) } else { (d, 0.0) };
            let sign = if up { 1.0 } else { -1.0 };
            let mut g = JerkBasedGenerator::new(p, jerk(j, bits), x0).unwrap();
            g.move_absolute(target, v, (0.0, 0.0, 0.0), x0).unwrap();
            let cycles = (4.0 * (d / v + v / acc.min(dec) + 2.0 * acc.max(dec) / j) / DT) as usize + 100;
            let out = run(&mut g, cycles);
            let end = out.last().unwrap().s;
            prop_assert_eq!((end.state, end.position), (HydState::Idle, target));
            let mut x = x0;
            for (k, o) in out.iter().enumerate() {
                let s = o.s.velocity * sign;
                prop_assert!((0.0..=v.min(500.0) * (1.0 + 1e-12)).contains(&s), "{k}: {o:?}");
                prop_assert!(o.a.abs() <= acc.max(dec) * (1.0 + 1e-9), "{k}: {o:?}");
                let step = (o.s.position - x) * sign;
                prop_assert!(step >= -1e-12, "{k}: backwards {o:?}");
                prop_assert!((target - o.s.position) * sign >= -1e-9, "{k}: passed {o:?}");
                x = o.s.position;
            }
            for w in out.windows(2) {
                let both = |f: fn(&Sample) -> bool| f(&w[0]) && f(&w[1]);
                let ramp = both(|x| x.s.state == HydState::TcAcc);
                let building = ramp && w[1].a.abs() > w[0].a.abs();
                let limited = (building && bits & JERK_ACC_BUILD_UP != 0)
                    || (ramp && !building && bits & JERK_ACC_REDUCTION != 0)
                    || both(|x| x.last);
                if limited {
                    prop_assert!((w[1].a - w[0].a).abs() <= j * DT * (1.0 + 1e-9) + 1e-9, "{w:?}");
                }
            }
        }
    }
}
