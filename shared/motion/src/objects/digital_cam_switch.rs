//! `MC_DigitalCamSwitch_BkPlcMc` of the Beckhoff TwinCAT PLC Hydraulic Positioning library
//! (its section 'MC_DigitalCamSwitch_BkPlcMc (from V3.0)' and the types
//! 'MC_CAMSWITCH_REF_BkPlcMc', 'MC_TRACK_REF_BkPlcMc', 'OUTPUT_REF_BkPlcMc'): software cams
//! switched by the **actual** position, direction and velocity of an axis, several switches per
//! output, position and time switches mixed on one output.
//!
//! # Interface
//!
//! ```text
//! let mut dcs = DigitalCamSwitch::new(&switches, &tracks)?;   // checked, allocated here only
//! dcs.call(McDigitalCamSwitch { enable, enable_mask });       // the FB's inputs, any time
//! let bits = dcs.step(actual_position, actual_velocity, dt);  // once per cycle: OutputBits
//! ```
//!
//! # Switching rules
//!
//! - **Evaluated once per cycle** on the actual position `p` and velocity `v` of that cycle,
//!   as the library's FB is called once per PLC cycle: edges fall on cycle boundaries (the
//!   library's resolution; tandem's output cams compute exact crossing times instead). There
//!   are no modulo positions (the library has none for cams).
//! - **Position switch** (`CamSwitchMode` 0): ON while the position lies in
//!   `[FirstOnPosition, LastOnPosition]` and the direction is allowed. `AxisDirection` 0 both,
//!   1 positive, 2 negative; the direction is the sign of the actual velocity; at `v == 0` the
//!   direction of the last motion holds (inferred: the library does not say; so a directional
//!   cam stays on when the axis stops inside it, and is off if the axis never moved).
//! - **Time switch** (`CamSwitchMode` 1): switches on when the axis crosses `FirstOnPosition`
//!   in an allowed direction (a crossing between two cycles; not on the enable cycle, which has
//!   no previous position: inferred), and stays on for `Duration` whatever the axis does; not
//!   retriggered while on (inferred, as S7's time cams). `LastOnPosition` is ignored.
//! - **Tracks**: switch `TrackNumber` `n` (1..=[`TRACKS`]) drives track `n`, whose output is
//!   bit `n - 1` of `OutputBits`. The library never states this mapping (its example numbers
//!   tracks from 1, `OutputBits` is a 32-bit UDINT, its sample says "maximum 32" tracks and its
//!   digital-output FBs number outputs 0..31); inferred: `ciBkPlcMc_TrackRef_MinIdx = 1`, track
//!   `n` on bit `n - 1`. The switches of a track are OR'ed; bit `k` of the output is then ANDed
//!   with bit `k` of `EnableMask`.
//! - **Compensation** (per track, s): positive delays the signal, negative gives it early. It is
//!   the library's time-to-distance projection with the actual velocity: a switch's on edge is
//!   evaluated on `p - v * OnCompensation`, its off edge on `p - v * OffCompensation`. At
//!   constant velocity a position switch therefore turns on where the axis is
//!   `FirstOnPosition + v * OnCompensation` (moving positive; `LastOnPosition + v * ...` moving
//!   negative) and off likewise with `OffCompensation`; exact only at constant velocity, as the
//!   library says. Which projection a point uses follows the direction of motion: moving
//!   positive the axis enters over `FirstOnPosition` and leaves over `LastOnPosition`, moving
//!   negative the reverse (inferred). A switch shorter than `v * (OnCompensation -
//!   OffCompensation)` does not switch at that velocity. A time switch's trigger is projected with `OnCompensation`; its on time is
//!   `Duration + OffCompensation - OnCompensation` (the off edge `Duration + OffCompensation`
//!   after the uncompensated crossing; inferred), none when that is not positive.
//! - **Hysteresis** (per track, position units): after a switching point (`FirstOnPosition` or
//!   `LastOnPosition` of a switch) fired at actual position `p_f`, that point is not evaluated
//!   again until `|p - p_f| >= Hysteresis`; the other point of the switch still is. A point
//!   fires when the (projected) position crosses it, whether or not the direction filter lets
//!   the switch's output change (inferred).
//! - **Enable** (level) controls everything: FALSE clears the outputs and every switch's state
//!   (`InOperation`, `Busy` FALSE); TRUE evaluates (`InOperation`, `Busy` TRUE; inferred: Busy
//!   as for PLCopen's Enable-type FBs). `EnableMask` masks the outputs only: the switches keep
//!   being evaluated, so a mask bit set mid-cam shows the cam at once (inferred).
//!
//! # Decisions on the reference's inconsistencies
//!
//! - The library's Sample 8 calls the −1000…1000 switch "positive direction"; the FB's example
//!   table gives it `AxisDirection` 0 (both). The table is followed (it is the definition the
//!   signal diagram shows).
//! - Sample 8 calls `OnCompensation = −0.125` a "switch-on delay of 0.125 s"; the track type
//!   says a negative compensation gives the signal early. The type is followed.
//! - The `TrackNumber` → bit mapping the reference leaves open: bit `TrackNumber − 1` (above).
//!
//! # Compared with the S7 output cam
//!
//! [`crate::objects::output_cam`] shares none of this math: S7's compensations are lead times
//! (positive = earlier) applied to exact crossing times, its hysteresis is a band armed at a
//! direction reversal that freezes position and direction, its directions are 1/2/3. The
//! library's sign is the opposite (positive = delayed), the compensation is a projection with
//! the actual velocity evaluated per cycle, and the hysteresis locks a switching point after it
//! fired.
//!
//! # Refusals
//!
//! A switch set or track set is checked whole and refused with the first bad entry, changing
//! nothing ([`DcsError`]; the library lists no codes for this FB, these are inferred from its
//! code list): `TrackNumber` outside 1..=[`TRACKS`] or beyond the tracks given
//! `dwTcHydErrCdIllegalOutputNumber` (16#4104, "output number outside the permitted range");
//! `AxisDirection` or `CamSwitchMode` not one of theirs `dwTcHydErrCdNotSupport` (16#4107);
//! a position not finite or beyond 1e12, `LastOnPosition < FirstOnPosition` on a position
//! switch, a negative or non-finite `Duration`, a compensation beyond ±[`COMPENSATION_MAX`] s,
//! a negative hysteresis `dwTcHydAdsErrIllegalValue` (16#0706); more than [`SWITCHES`] switches
//! or [`TRACKS`] tracks `dwTcHydAdsErrInvalidIdxOffset` (16#0703, "index out of bounds").

use crate::catalog::hyd_error::HydErrorCode;

/// Most tracks (`ciBkPlcMc_TrackRef_MaxIdx`): one per bit of the UDINT `OutputBits`; the
/// library's sample says "maximum 32".
pub const TRACKS: usize = 32;

/// Most switches of one object (`ciBkPlcMc_CamSwitchRef_MaxIdx`, whose value the library does
/// not print; inferred: two per track).
pub const SWITCHES: usize = 64;

/// Largest |compensation| accepted (s).
pub const COMPENSATION_MAX: f64 = 100.0;

/// Largest |position| and hysteresis accepted.
const POSITION_MAX: f64 = 1e12;

/// `MC_CAMSWITCH_REFTYPE_BkPlcMc.AxisDirection`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SwitchDirection {
    /// 0: both directions.
    Both = 0,
    /// 1: positive direction.
    Positive = 1,
    /// 2: negative direction.
    Negative = 2,
}

impl SwitchDirection {
    /// The direction for an `AxisDirection` code, or `dwTcHydErrCdNotSupport`.
    pub const fn from_code(code: i32) -> Result<Self, HydErrorCode> {
        match code {
            0 => Ok(Self::Both),
            1 => Ok(Self::Positive),
            2 => Ok(Self::Negative),
            _ => Err(HydErrorCode::NOT_SUPPORT),
        }
    }

    /// Whether the direction `dir` (+1, -1, 0 for none yet) is allowed.
    const fn allows(self, dir: i8) -> bool {
        match self {
            Self::Both => true,
            Self::Positive => dir > 0,
            Self::Negative => dir < 0,
        }
    }
}

/// `MC_CAMSWITCH_REFTYPE_BkPlcMc.CamSwitchMode`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum CamSwitchMode {
    /// 0: position-based (`FirstOnPosition..LastOnPosition`).
    Position = 0,
    /// 1: time-based (trigger at `FirstOnPosition`, on for `Duration`).
    Time = 1,
}

impl CamSwitchMode {
    /// The mode for a `CamSwitchMode` code, or `dwTcHydErrCdNotSupport`.
    pub const fn from_code(code: i32) -> Result<Self, HydErrorCode> {
        match code {
            0 => Ok(Self::Position),
            1 => Ok(Self::Time),
            _ => Err(HydErrorCode::NOT_SUPPORT),
        }
    }
}

/// One switch (`MC_CAMSWITCH_REFTYPE_BkPlcMc` without its private members).
#[derive(Copy, Clone, Debug, PartialEq)]
#[doc(alias = "MC_CAMSWITCH_REFTYPE_BkPlcMc")]
pub struct CamSwitch {
    /// `TrackNumber`: the track (1..=[`TRACKS`]) whose output bit `TrackNumber - 1` it drives.
    pub track_number: i32,
    /// `FirstOnPosition`: start; the trigger position of a time switch.
    pub first_on_position: f64,
    /// `LastOnPosition`: end (position switches).
    pub last_on_position: f64,
    /// `AxisDirection`.
    pub axis_direction: SwitchDirection,
    /// `CamSwitchMode`.
    pub cam_switch_mode: CamSwitchMode,
    /// `Duration` (s, time switches).
    pub duration: f64,
}

impl CamSwitch {
    /// A position switch on `track` over `[first, last]` in `direction`.
    pub const fn position(track: i32, first: f64, last: f64, direction: SwitchDirection) -> Self {
        Self {
            track_number: track,
            first_on_position: first,
            last_on_position: last,
            axis_direction: direction,
            cam_switch_mode: CamSwitchMode::Position,
            duration: 0.0,
        }
    }

    /// A time switch on `track` triggered at `first` in `direction`, on for `duration` s.
    pub const fn time(track: i32, first: f64, duration: f64, direction: SwitchDirection) -> Self {
        Self {
            track_number: track,
            first_on_position: first,
            last_on_position: first,
            axis_direction: direction,
            cam_switch_mode: CamSwitchMode::Time,
            duration,
        }
    }
}

/// The options of one track (`MC_TRACK_REFTYPE_BkPlcMc`).
#[derive(Copy, Clone, Debug, PartialEq)]
#[doc(alias = "MC_TRACK_REFTYPE_BkPlcMc")]
pub struct TrackOptions {
    /// `OnCompensation` (s): positive delays the on edge, negative gives it early.
    pub on_compensation: f64,
    /// `OffCompensation` (s): positive delays the off edge, negative gives it early.
    pub off_compensation: f64,
    /// `Hysteresis` (position units, >= 0).
    pub hysteresis: f64,
}

impl TrackOptions {
    /// No compensation, no hysteresis.
    pub const NONE: Self = Self {
        on_compensation: 0.0,
        off_compensation: 0.0,
        hysteresis: 0.0,
    };
}

/// Which entry a [`DcsError`] names.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum DcsField {
    /// The number of switches.
    SwitchCount,
    /// The number of tracks.
    TrackCount,
    /// `TrackNumber` of a switch.
    TrackNumber,
    /// `FirstOnPosition` of a switch.
    FirstOnPosition,
    /// `LastOnPosition` of a switch.
    LastOnPosition,
    /// `AxisDirection` of a switch (a code the library does not know).
    AxisDirection,
    /// `CamSwitchMode` of a switch (a code the library does not know).
    CamSwitchMode,
    /// `Duration` of a switch.
    Duration,
    /// `OnCompensation` of a track.
    OnCompensation,
    /// `OffCompensation` of a track.
    OffCompensation,
    /// `Hysteresis` of a track.
    Hysteresis,
}

/// A refused switch or track set: which entry (0-based index in its list), which field and the
/// library's error code.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct DcsError {
    /// Index of the switch or track (0 for a count).
    pub index: usize,
    /// What was wrong.
    pub field: DcsField,
    /// `ErrorID`.
    pub code: HydErrorCode,
}

impl core::fmt::Display for DcsError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let what = match self.field {
            DcsField::SwitchCount => {
                return write!(f, "more than {SWITCHES} switches: {}", self.code)
            }
            DcsField::TrackCount => return write!(f, "more than {TRACKS} tracks: {}", self.code),
            DcsField::TrackNumber => "switch TrackNumber",
            DcsField::FirstOnPosition => "switch FirstOnPosition",
            DcsField::LastOnPosition => "switch LastOnPosition",
            DcsField::AxisDirection => "switch AxisDirection",
            DcsField::CamSwitchMode => "switch CamSwitchMode",
            DcsField::Duration => "switch Duration",
            DcsField::OnCompensation => "track OnCompensation",
            DcsField::OffCompensation => "track OffCompensation",
            DcsField::Hysteresis => "track Hysteresis",
        };
        write!(f, "{what} of entry {}: {}", self.index + 1, self.code)
    }
}

impl std::error::Error for DcsError {}

/// The inputs of `MC_DigitalCamSwitch_BkPlcMc`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct McDigitalCamSwitch {
    /// `Enable` (level): controls everything.
    pub enable: bool,
    /// `EnableMask`: bit `k` lets track `k + 1`'s output through.
    pub enable_mask: u32,
}

/// The outputs of `MC_DigitalCamSwitch_BkPlcMc` and the `OUTPUT_REF_BkPlcMc` it writes.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct DigitalCamSwitchStatus {
    /// `Outputs.OutputBits`: bit `n - 1` is track `n`, after `EnableMask`.
    #[doc(alias = "OutputBits")]
    pub output_bits: u32,
    /// `InOperation`: enabled and evaluating.
    pub in_operation: bool,
    /// `Busy`.
    pub busy: bool,
    /// `Error`: never set at run time (the switch set is checked when it is given).
    pub error: bool,
    /// `ErrorID`.
    pub error_id: HydErrorCode,
}

/// The run-time state of one switch (the library's private `nCurrentState`, `bTriggered`,
/// `fTimer`).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
struct SwitchState {
    /// The switch's output.
    on: bool,
    /// Position switch: the projected position is at or past `FirstOnPosition`.
    past_first: bool,
    /// Position switch: the projected position is at or before `LastOnPosition`.
    before_last: bool,
    /// Where `FirstOnPosition` last fired (hysteresis lock), if still locked.
    lock_first: Option<f64>,
    /// Where `LastOnPosition` last fired, if still locked.
    lock_last: Option<f64>,
    /// Time switch: the on time left (s).
    timer: f64,
    /// Time switch: the projected trigger position of the previous cycle.
    prev_q: Option<f64>,
}

/// The digital cam switch (see the module documentation).
#[derive(Clone, Debug)]
#[doc(alias = "MC_DigitalCamSwitch_BkPlcMc")]
pub struct DigitalCamSwitch {
    switches: Vec<CamSwitch>,
    states: Vec<SwitchState>,
    tracks: [TrackOptions; TRACKS],
    n_tracks: usize,
    input: McDigitalCamSwitch,
    /// Started: the first cycle after the enable was evaluated.
    running: bool,
    /// The last direction of motion (+1, -1, 0 none yet).
    direction: i8,
    status: DigitalCamSwitchStatus,
}

fn position_ok(x: f64) -> bool {
    x.is_finite() && x.abs() <= POSITION_MAX
}

/// Checks a switch set against `n_tracks` tracks.
fn check_switches(switches: &[CamSwitch], n_tracks: usize) -> Result<(), DcsError> {
    let err = |index, field, code| Err(DcsError { index, field, code });
    if switches.len() > SWITCHES {
        return err(0, DcsField::SwitchCount, HydErrorCode::INVALID_IDX_OFFSET);
    }
    for (i, s) in switches.iter().enumerate() {
        let track_ok = usize::try_from(s.track_number).is_ok_and(|n| (1..=n_tracks).contains(&n));
        if !track_ok {
            return err(
                i,
                DcsField::TrackNumber,
                HydErrorCode::ILLEGAL_OUTPUT_NUMBER,
            );
        }
        if !position_ok(s.first_on_position) {
            return err(i, DcsField::FirstOnPosition, HydErrorCode::ILLEGAL_VALUE);
        }
        match s.cam_switch_mode {
            CamSwitchMode::Position => {
                if !position_ok(s.last_on_position) || s.last_on_position < s.first_on_position {
                    return err(i, DcsField::LastOnPosition, HydErrorCode::ILLEGAL_VALUE);
                }
            }
            CamSwitchMode::Time => {
                if !(s.duration.is_finite() && s.duration >= 0.0) {
                    return err(i, DcsField::Duration, HydErrorCode::ILLEGAL_VALUE);
                }
            }
        }
    }
    Ok(())
}

/// Checks a track set.
fn check_tracks(tracks: &[TrackOptions]) -> Result<(), DcsError> {
    let err = |index, field, code| Err(DcsError { index, field, code });
    if tracks.len() > TRACKS {
        return err(0, DcsField::TrackCount, HydErrorCode::INVALID_IDX_OFFSET);
    }
    let comp_ok = |c: f64| c.is_finite() && c.abs() <= COMPENSATION_MAX;
    for (i, t) in tracks.iter().enumerate() {
        if !comp_ok(t.on_compensation) {
            return err(i, DcsField::OnCompensation, HydErrorCode::ILLEGAL_VALUE);
        }
        if !comp_ok(t.off_compensation) {
            return err(i, DcsField::OffCompensation, HydErrorCode::ILLEGAL_VALUE);
        }
        if !(t.hysteresis >= 0.0 && t.hysteresis <= POSITION_MAX) {
            return err(i, DcsField::Hysteresis, HydErrorCode::ILLEGAL_VALUE);
        }
    }
    Ok(())
}

/// Whether a lock set at `at` still holds at `p` (moved less than `h` away).
fn still_locked(lock: Option<f64>, p: f64, h: f64) -> Option<f64> {
    lock.filter(|at| (p - at).abs() < h)
}

/// What one cycle's evaluation of a switch works with.
#[derive(Copy, Clone, Debug)]
struct Cycle {
    p: f64,
    v: f64,
    dt: f64,
    direction: i8,
}

impl SwitchState {
    /// One cycle of a position switch.
    fn position(&mut self, s: &CamSwitch, t: &TrackOptions, c: Cycle, first_cycle: bool) {
        let q_on = c.p - c.v * t.on_compensation;
        let q_off = c.p - c.v * t.off_compensation;
        let (f, l) = (s.first_on_position, s.last_on_position);
        // Moving positive the axis enters over FirstOn (an on edge) and leaves over LastOn (an
        // off edge); moving negative the other way round. At standstill both are `p`.
        let (q_first, q_last) = if c.v >= 0.0 {
            (q_on, q_off)
        } else {
            (q_off, q_on)
        };
        let past = q_first >= f;
        let before = q_last <= l;
        if first_cycle {
            // No point has fired yet: the sides are where the axis is.
            self.past_first = past;
            self.before_last = before;
        } else {
            self.lock_first = still_locked(self.lock_first, c.p, t.hysteresis);
            self.lock_last = still_locked(self.lock_last, c.p, t.hysteresis);
            if self.lock_first.is_none() && past != self.past_first {
                self.past_first = past;
                self.lock_first = Some(c.p);
            }
            if self.lock_last.is_none() && before != self.before_last {
                self.before_last = before;
                self.lock_last = Some(c.p);
            }
        }
        self.on = self.past_first && self.before_last && s.axis_direction.allows(c.direction);
    }

    /// One cycle of a time switch.
    fn time(&mut self, s: &CamSwitch, t: &TrackOptions, c: Cycle) {
        if self.on {
            self.timer -= c.dt;
            // Within a nanosecond of the end counts as the end (the sum of cycle times).
            if self.timer <= 1e-9 {
                self.on = false;
            }
        }
        let q = c.p - c.v * t.on_compensation;
        let f = s.first_on_position;
        self.lock_first = still_locked(self.lock_first, c.p, t.hysteresis);
        let crossed = self.prev_q.and_then(|prev| {
            if prev < f && q >= f {
                Some(1)
            } else if prev > f && q <= f {
                Some(-1)
            } else {
                None
            }
        });
        self.prev_q = Some(q);
        let Some(dir) = crossed.filter(|_| self.lock_first.is_none()) else {
            return;
        };
        self.lock_first = Some(c.p);
        let on_time = s.duration + t.off_compensation - t.on_compensation;
        if !self.on && s.axis_direction.allows(dir) && on_time > 1e-9 {
            self.on = true;
            self.timer = on_time;
        }
    }
}

impl DigitalCamSwitch {
    /// An object with `switches` on `tracks` (track `n` is `tracks[n - 1]`), disabled, mask 0.
    /// The only allocation.
    pub fn new(switches: &[CamSwitch], tracks: &[TrackOptions]) -> Result<Self, DcsError> {
        check_tracks(tracks)?;
        check_switches(switches, tracks.len())?;
        let mut t = [TrackOptions::NONE; TRACKS];
        for (d, s) in t.iter_mut().zip(tracks) {
            *d = *s;
        }
        let mut list = Vec::with_capacity(SWITCHES);
        list.extend_from_slice(switches);
        Ok(Self {
            switches: list,
            states: vec![SwitchState::default(); SWITCHES],
            tracks: t,
            n_tracks: tracks.len(),
            input: McDigitalCamSwitch {
                enable: false,
                enable_mask: 0,
            },
            running: false,
            direction: 0,
            status: DigitalCamSwitchStatus {
                output_bits: 0,
                in_operation: false,
                busy: false,
                error: false,
                error_id: HydErrorCode(0),
            },
        })
    }

    /// Replaces the switch set (`Switches`), checked against the tracks; a refused set changes
    /// nothing. The switches' states restart (as a fresh enable). No allocation.
    pub fn set_switches(&mut self, switches: &[CamSwitch]) -> Result<(), DcsError> {
        check_switches(switches, self.n_tracks)?;
        self.switches.clear();
        self.switches.extend_from_slice(switches);
        self.restart();
        Ok(())
    }

    /// Replaces the options of the tracks (`TrackOptions`); a refused set changes nothing, and
    /// so does a set with fewer tracks than a switch uses.
    pub fn set_track_options(&mut self, tracks: &[TrackOptions]) -> Result<(), DcsError> {
        check_tracks(tracks)?;
        check_switches(&self.switches, tracks.len())?;
        self.tracks = [TrackOptions::NONE; TRACKS];
        for (d, s) in self.tracks.iter_mut().zip(tracks) {
            *d = *s;
        }
        self.n_tracks = tracks.len();
        Ok(())
    }

    /// The FB's inputs (level-type: they hold until the next call). `Enable` FALSE clears the
    /// outputs and the switches' states at once.
    pub fn call(&mut self, input: McDigitalCamSwitch) {
        if !input.enable {
            self.restart();
            self.status.output_bits = 0;
        }
        self.input = input;
        self.status.in_operation = input.enable;
        self.status.busy = input.enable;
    }

    fn restart(&mut self) {
        self.running = false;
        for s in &mut self.states {
            *s = SwitchState::default();
        }
    }

    /// One cycle with the axis' actual position and velocity, `dt` (s) since the last cycle:
    /// returns `OutputBits` (see the module documentation).
    pub fn step(&mut self, actual_position: f64, actual_velocity: f64, dt: f64) -> u32 {
        // The direction of the last motion is followed while disabled too.
        if actual_velocity > 0.0 {
            self.direction = 1;
        } else if actual_velocity < 0.0 {
            self.direction = -1;
        }
        if !self.input.enable {
            self.status.output_bits = 0;
            return 0;
        }
        let c = Cycle {
            p: actual_position,
            v: actual_velocity,
            dt: dt.max(0.0),
            direction: self.direction,
        };
        let first_cycle = !self.running;
        self.running = true;
        let mut bits = 0u32;
        for (s, st) in self.switches.iter().zip(self.states.iter_mut()) {
            // Checked when given: 1..=TRACKS.
            let k = usize::try_from(s.track_number.saturating_sub(1)).unwrap_or(0);
            let t = self.tracks.get(k).copied().unwrap_or(TrackOptions::NONE);
            match s.cam_switch_mode {
                CamSwitchMode::Position => st.position(s, &t, c, first_cycle),
                CamSwitchMode::Time => st.time(s, &t, c),
            }
            if st.on {
                bits |= 1u32.checked_shl(k as u32).unwrap_or(0);
            }
        }
        self.status.output_bits = bits & self.input.enable_mask;
        self.status.output_bits
    }

    /// The FB's outputs as of the last call or step.
    pub fn status(&self) -> &DigitalCamSwitchStatus {
        &self.status
    }

    /// The switches.
    pub fn switches(&self) -> &[CamSwitch] {
        &self.switches
    }

    /// The options of the tracks (track `n` is element `n - 1`).
    pub fn track_options(&self) -> &[TrackOptions] {
        self.tracks.get(..self.n_tracks).unwrap_or(&[])
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;
    use SwitchDirection::{Both, Negative, Positive};

    const DT: f64 = 0.001;

    fn enabled(switches: &[CamSwitch], tracks: &[TrackOptions]) -> DigitalCamSwitch {
        let mut d = DigitalCamSwitch::new(switches, tracks).unwrap();
        d.call(McDigitalCamSwitch {
            enable: true,
            enable_mask: u32::MAX,
        });
        d
    }

    /// Runs at constant velocity `v` from `p0` for `n` cycles (position `p0 + k v dt` at cycle
    /// `k`); returns the positions where bit 0 switched (on, off).
    fn edges(d: &mut DigitalCamSwitch, p0: f64, v: f64, n: usize) -> Vec<(f64, bool)> {
        let mut out = Vec::new();
        let mut last = d.status().output_bits & 1 != 0;
        for k in 0..n {
            let p = p0 + k as f64 * v * DT;
            let on = d.step(p, v, DT) & 1 != 0;
            if on != last {
                out.push((p, on));
                last = on;
            }
        }
        out
    }

    fn near(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-6
    }

    #[test]
    fn a_position_switch_at_constant_velocity_switches_where_the_compensation_projects() {
        let track = |on, off| TrackOptions {
            on_compensation: on,
            off_compensation: off,
            hysteresis: 0.0,
        };
        // Positive, v = 1000/s, 1 unit per cycle: on early by 125 (−0.125 s), off late by 250.
        let mut d = enabled(
            &[CamSwitch::position(1, 2000.0, 3000.0, Both)],
            &[track(-0.125, 0.25)],
        );
        let e = edges(&mut d, 0.0, 1000.0, 5000);
        assert_eq!(e.len(), 2, "{e:?}");
        assert!(near(e[0].0, 1875.0) && e[0].1, "{e:?}");
        // Off when p - 250 > 3000: the first cycle past 3250.
        assert!(near(e[1].0, 3251.0) && !e[1].1, "{e:?}");
        // Negative: on at LastOn + 125 (early, i.e. higher), off at FirstOn - 250 (late).
        let mut d = enabled(
            &[CamSwitch::position(1, 2000.0, 3000.0, Both)],
            &[track(-0.125, 0.25)],
        );
        let e = edges(&mut d, 5000.0, -1000.0, 5000);
        assert!(near(e[0].0, 3125.0) && e[0].1, "{e:?}");
        assert!(near(e[1].0, 1749.0) && !e[1].1, "{e:?}");
        // Opposite signs: on late by 100 (+0.1 s), off early by 50 (−0.05 s).
        let mut d = enabled(
            &[CamSwitch::position(1, 2000.0, 3000.0, Both)],
            &[track(0.1, -0.05)],
        );
        let e = edges(&mut d, 0.0, 1000.0, 5000);
        assert!(near(e[0].0, 2100.0) && near(e[1].0, 2951.0), "{e:?}");
        let mut d = enabled(
            &[CamSwitch::position(1, 2000.0, 3000.0, Both)],
            &[track(0.1, -0.05)],
        );
        let e = edges(&mut d, 5000.0, -1000.0, 5000);
        assert!(near(e[0].0, 2900.0) && near(e[1].0, 2049.0), "{e:?}");
    }

    #[test]
    fn the_direction_filter_passes_only_the_allowed_direction_and_holds_it_at_standstill() {
        let sw = [CamSwitch::position(1, 10.0, 20.0, Positive)];
        let mut d = enabled(&sw, &[TrackOptions::NONE]);
        // Never moved: no direction, off even inside.
        assert_eq!(d.step(15.0, 0.0, DT), 0);
        assert_eq!(d.step(15.0, 1.0, DT), 1);
        // Stopping inside keeps the last direction.
        assert_eq!(d.step(15.0, 0.0, DT), 1);
        // Reversal inside switches it off.
        assert_eq!(d.step(15.0, -1.0, DT), 0);
        let sw = [CamSwitch::position(1, 10.0, 20.0, Negative)];
        let mut d = enabled(&sw, &[TrackOptions::NONE]);
        assert_eq!(d.step(15.0, 1.0, DT), 0);
        assert_eq!(d.step(15.0, -1.0, DT), 1);
    }

    #[test]
    fn hysteresis_suppresses_the_chatter_of_a_noisy_actual_position() {
        // The axis creeps up through 100 with ±0.4 noise, then leaves and comes back down.
        let noise = [0.4, -0.3, 0.1, -0.4, 0.35, -0.2, 0.0, -0.35];
        let path: Vec<f64> = (0..400)
            .map(|k| 98.0 + 0.01 * k as f64 + noise[k % noise.len()])
            .chain((0..400).map(|k| 102.0 - 0.01 * k as f64 + noise[k % noise.len()]))
            .collect();
        let count_edges = |h: f64| {
            let track = TrackOptions {
                hysteresis: h,
                ..TrackOptions::NONE
            };
            let mut d = enabled(&[CamSwitch::position(1, 100.0, 200.0, Both)], &[track]);
            let mut last = 0;
            let mut edges = Vec::new();
            for (k, p) in path.iter().enumerate() {
                let v = if k < 400 { 10.0 } else { -10.0 };
                let b = d.step(*p, v, DT);
                if b != last {
                    edges.push((k, b));
                    last = b;
                }
            }
            edges
        };
        // Without hysteresis the noise chatters the output.
        assert!(count_edges(0.0).len() > 10, "{:?}", count_edges(0.0));
        // With 1.0: one on edge going up, one off edge coming down (after moving away).
        let e = count_edges(1.0);
        assert_eq!(e.len(), 2, "{e:?}");
        assert_eq!((e[0].1, e[1].1), (1, 0));
        assert!(e[0].0 < 400 && e[1].0 >= 400, "{e:?}");
    }

    #[test]
    fn a_time_switch_stays_on_for_its_duration_in_cycles_in_either_direction() {
        let sw = [CamSwitch::time(1, 3000.0, 1.35, Both)];
        for v in [1000.0, -1000.0] {
            let mut d = enabled(&sw, &[TrackOptions::NONE]);
            let p0 = if v > 0.0 { 2000.0 } else { 4000.0 };
            let mut on = 0;
            let mut first = None;
            for k in 0..3000 {
                let p = p0 + k as f64 * v * DT;
                if d.step(p, v, DT) & 1 != 0 {
                    on += 1;
                    first.get_or_insert(k);
                }
            }
            // 1.35 s at 1 ms: 1350 cycles, from the cycle that reaches 3000.
            assert_eq!((on, first), (1350, Some(1000)), "v = {v}");
        }
        // Positive only: the negative crossing does not trigger.
        let mut d = enabled(
            &[CamSwitch::time(1, 3000.0, 1.35, Positive)],
            &[TrackOptions::NONE],
        );
        assert!((0..3000).all(|k| d.step(4000.0 - k as f64, -1000.0, DT) == 0));
    }

    #[test]
    fn switches_of_a_track_are_ored_and_enable_mask_and_enable_gate_the_bits() {
        let sw = [
            CamSwitch::position(1, 0.0, 10.0, Both),
            CamSwitch::position(1, 20.0, 30.0, Both),
            CamSwitch::position(2, 5.0, 25.0, Both),
        ];
        let mut d = enabled(&sw, &[TrackOptions::NONE; 2]);
        assert_eq!(d.step(5.0, 1.0, DT), 0b11);
        assert_eq!(d.step(15.0, 1.0, DT), 0b10);
        assert_eq!(d.step(25.0, 1.0, DT), 0b11);
        assert_eq!(d.step(35.0, 1.0, DT), 0b00);
        d.call(McDigitalCamSwitch {
            enable: true,
            enable_mask: 0b10,
        });
        assert_eq!(d.step(25.0, -1.0, DT), 0b10);
        assert_eq!(d.status().output_bits, 0b10);
        d.call(McDigitalCamSwitch {
            enable: false,
            enable_mask: 0b11,
        });
        assert_eq!(d.status().output_bits, 0);
        assert!(!d.status().in_operation && !d.status().busy);
        assert_eq!(d.step(25.0, -1.0, DT), 0);
        d.call(McDigitalCamSwitch {
            enable: true,
            enable_mask: 0b11,
        });
        assert!(d.status().in_operation);
        assert_eq!(d.step(25.0, -1.0, DT), 0b11);
    }

    #[test]
    fn a_bad_set_is_refused_with_its_code_and_changes_nothing() {
        let good = [CamSwitch::position(1, 0.0, 10.0, Both)];
        let tracks = [TrackOptions::NONE; 2];
        let mut d = enabled(&good, &tracks);
        let refuse = |d: &mut DigitalCamSwitch, s: CamSwitch, field, code: u32| {
            let e = d.set_switches(&[good[0], s]).unwrap_err();
            assert_eq!(
                e,
                DcsError {
                    index: 1,
                    field,
                    code: HydErrorCode(code)
                },
                "{s:?}"
            );
        };
        refuse(
            &mut d,
            CamSwitch::position(3, 0.0, 1.0, Both),
            DcsField::TrackNumber,
            0x4104,
        );
        refuse(
            &mut d,
            CamSwitch::position(0, 0.0, 1.0, Both),
            DcsField::TrackNumber,
            0x4104,
        );
        refuse(
            &mut d,
            CamSwitch::position(1, 2.0, 1.0, Both),
            DcsField::LastOnPosition,
            0x0706,
        );
        refuse(
            &mut d,
            CamSwitch::time(1, 2.0, -0.1, Both),
            DcsField::Duration,
            0x0706,
        );
        refuse(
            &mut d,
            CamSwitch::position(1, f64::NAN, 1.0, Both),
            DcsField::FirstOnPosition,
            0x0706,
        );
        assert_eq!(d.switches(), &good);
        assert_eq!(d.step(5.0, 1.0, DT), 1);
        let too_many = [good[0]; SWITCHES + 1];
        assert_eq!(
            d.set_switches(&too_many).unwrap_err().code,
            HydErrorCode(0x0703)
        );
        let bad = TrackOptions {
            hysteresis: -1.0,
            ..TrackOptions::NONE
        };
        assert_eq!(
            d.set_track_options(&[bad]).unwrap_err().field,
            DcsField::Hysteresis
        );
        let bad = TrackOptions {
            on_compensation: 1e3,
            ..TrackOptions::NONE
        };
        assert_eq!(
            d.set_track_options(&[bad]).unwrap_err().field,
            DcsField::OnCompensation
        );
        // Fewer tracks than a switch uses.
        let two = [CamSwitch::position(2, 0.0, 1.0, Both)];
        d.set_switches(&two).unwrap();
        assert_eq!(
            d.set_track_options(&[TrackOptions::NONE])
                .unwrap_err()
                .field,
            DcsField::TrackNumber
        );
        assert_eq!(d.track_options().len(), 2);
        assert_eq!(SwitchDirection::from_code(3), Err(HydErrorCode(0x4107)));
        assert_eq!(CamSwitchMode::from_code(2), Err(HydErrorCode(0x4107)));
    }
}
