//! The cam track technology object and `MC_CamTrack` (S7-1500T Measuring input and cam functions
//! V5.0 function manual, 3.3 'Cam track technology object'; S7-Technology V4.1 function manual, 3.7
//! '"Cam track" technology object').
//!
//! # Interface
//!
//! Like an output cam ([`crate::objects::output_cam`]), a [`CamTrack`] is stepped once per cycle
//! with the motion of its axis ([`AxisMotion`], see [`crate::kinematics::cycle_motion`]) and
//! reports the edges of its single track output in a [`CamEdges`] list, each with its exact time
//! (ns):
//!
//! ```text
//! track.set_data(data)                        // TO data (staged, `StatusWord.X6`)
//! track.call(instance, &McCamTrack { .. })    // the FB call: applies staged data per Mode
//! track.step(&motion, &mut edges)             // once per cycle
//! ```
//!
//! # The track
//!
//! Up to [`MAX_CAMS`] cams of one type ([`CamTrackType`]) on a track of length `L` whose position
//! 0 lies at `ReferencePosition`; the track repeats in both directions. A cam takes part if it
//! exists, its bit in `CamMasking` is set (bit `i` for cam `i`, cam 1 is bit 0) and its start
//! lies in `[0, L)`. Distance cams are ON on `[On, min(Off, L)]` of every track cycle (clipped at
//! the track end; `On == Off` never switches); time cams switch on when their start is crossed in
//! either direction, for `Duration`, not retriggered while on, and keep running past the track
//! end. The track output is the OR of the cams (then `InvertOutput`, or forced ON by Mode 2).
//! Hysteresis and compensations are those of output cams (the compensations apply to the edges
//! of the track output).
//!
//! The track phase is carried on the continuous position: when the track is enabled,
//! `MatchPosition` is set as if the position had been reached by positive motion from
//! `ReferencePosition` (on a modulo axis from the reduced reference position, within one modulo
//! length), and from then on the track follows the continuous motion, so a modulo length that is
//! not a multiple of the track length carries on without realigning (S7-1500T Measuring input and
//! cam functions V5.0 function manual, 3.3.1 'Modulo function'). `MatchPosition`
//! (reported reduced on modulo axes) is the lower end of the current track cycle, `TrackPosition`
//! the position in it.
//!
//! A homing jump on a linear axis re-references the track to `ReferencePosition`; on a modulo
//! axis the jump counts as positive motion when `(new - old) mod L_mod <= L_mod / 2` and as
//! negative motion otherwise, which decides the new `MatchPosition`. Distance cams take the state
//! at the new position; time cams are not started, running ones continue.
//!
//! # MC_CamTrack
//!
//! | Mode | Enable TRUE | Enable FALSE |
//! |---|---|---|
//! | 0 | active at once; staged data at once (distance cams keep their state only where the new data sets them; running time cams end) | off at once |
//! | 1 | first activation at once; staged data at the end of the current track cycle (Status 2 meanwhile) | off at the end of the current track cycle |
//! | 2 | output forced ON at once | off at once |
//!
//! Edges caused by the FB, a homing jump or a data switch-over are reported at the cycle start
//! (or the switch-over) without compensation; an on edge whose lead reaches before a Mode 1
//! switch-over is reported at the switch-over. The output interface ([`TrackOutputInterface`])
//! caps the edges per cycle: Timer DQ one rising and one falling edge (the last of each wins),
//! DQ module one edge (the state at the end of the cycle wins), software output unlimited.
//!
//! ErrorIDs: `16#800C` second active instance, `16#800A` illegal Mode, `16#8001` while an alarm
//! is pending. Alarms: 703 (cam track data faulty; supplement = cam number 1..32, or 0 for the
//! track length / reference position), 702 (actual value not valid). `MC_Reset` acknowledges
//! them; an enabled track then resumes as at its first activation.

use crate::catalog::alarm::{AlarmId, AlarmInstance};
use crate::catalog::error_id::ErrorId;
use crate::kinematics::crossing::{point_crossings, Path, PathEvent, RangeSet};
use crate::kinematics::cycle_motion::AxisMotion;
use crate::kinematics::modulo::Modulo;
use crate::objects::measuring::MeasuringConfigError;
use crate::objects::output_cam::max_hysteresis;
pub use crate::objects::output_cam::{CamEdges, Edge, OutputCamParameters, PositionType};

/// Maximum number of cams on a track.
pub const MAX_CAMS: usize = 32;

/// Capacity of the per-cycle buffer of cam events (before they are merged into the output).
pub const EVENT_CAPACITY: usize = 256;

/// `Parameter.CamTrackType`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum CamTrackType {
    /// 0: distance cams.
    Distance = 0,
    /// 1: time cams.
    Time = 1,
}

/// Where the track output goes (`Interface.*`): decides how many edges a cycle can carry.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum TrackOutputInterface {
    /// `EnableOutput = FALSE`: computed only; every edge is reported.
    Software,
    /// TM Timer DIDQ: at most one rising and one falling edge per cycle (the last of each).
    TimerDq,
    /// Standard DQ module: at most one edge per cycle (the state at the end of the cycle).
    DqModule,
}

/// One cam of the track (`Parameter.Cam[i]`), positions relative to the track start.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct TrackCam {
    /// `Existent`.
    pub existent: bool,
    /// `OnPosition` (>= 0).
    pub on_position: f64,
    /// `OffPosition` (distance cams, >= OnPosition).
    pub off_position: f64,
    /// `Duration` (s, time cams, >= 1e-6).
    pub duration: f64,
}

impl TrackCam {
    /// An existing distance cam.
    pub const fn distance(on_position: f64, off_position: f64) -> Self {
        Self {
            existent: true,
            on_position,
            off_position,
            duration: 0.0,
        }
    }

    /// An existing time cam.
    pub const fn time(on_position: f64, duration: f64) -> Self {
        Self {
            existent: true,
            on_position,
            off_position: 0.0,
            duration,
        }
    }
}

/// The track data that can change while the track is active (staged until the FB call).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CamTrackData {
    /// `Parameter.ReferencePosition`.
    pub reference_position: f64,
    /// `Parameter.CamTrackLength` (0.001..1e12).
    pub track_length: f64,
    /// `Parameter.CamMasking` (bit `i` enables cam `i`; default all).
    pub masking: u32,
    /// Compensations and hysteresis.
    pub parameters: OutputCamParameters,
    /// `Parameter.Cam[1..32]` (index 0 is cam 1).
    pub cams: [TrackCam; MAX_CAMS],
}

impl CamTrackData {
    /// A track of `length` at `reference_position` without cams, all cams unmasked.
    pub const fn new(reference_position: f64, track_length: f64) -> Self {
        Self {
            reference_position,
            track_length,
            masking: 0xFFFF_FFFF,
            parameters: OutputCamParameters::NONE,
            cams: [TrackCam {
                existent: false,
                on_position: 0.0,
                off_position: 0.0,
                duration: 0.0,
            }; MAX_CAMS],
        }
    }

    /// The same with cam `i` (0-based) set.
    pub fn with_cam(mut self, i: usize, cam: TrackCam) -> Self {
        if let Some(c) = self.cams.get_mut(i) {
            *c = cam;
        }
        self
    }

    /// Cam `i` takes part: exists, is unmasked and starts inside `[0, L)`.
    pub fn takes_part(&self, i: usize) -> bool {
        self.cams.get(i).is_some_and(|c| {
            c.existent && (self.masking >> (i & 31)) & 1 == 1 && c.on_position < self.track_length
        })
    }

    /// Checks the data as alarm 703 would: `Err(supplement)` with the cam number (1-based) or 0.
    fn check(&self, track_type: CamTrackType) -> Result<(), u16> {
        let len = self.track_length;
        if !(0.001..=1e12).contains(&len) || !(-1e12..=1e12).contains(&self.reference_position) {
            return Err(0);
        }
        if self.parameters.check().is_err() {
            return Err(0);
        }
        for (i, c) in self.cams.iter().enumerate() {
            if !c.existent || (self.masking >> i) & 1 == 0 {
                continue;
            }
            let n = i as u16 + 1;
            if !(0.0..=1e12).contains(&c.on_position) {
                return Err(n);
            }
            match track_type {
                CamTrackType::Distance => {
                    if !(c.on_position..=1e12).contains(&c.off_position) {
                        return Err(n);
                    }
                }
                CamTrackType::Time => {
                    let p = &self.parameters;
                    if !(1e-6..=1e9).contains(&c.duration)
                        || c.duration <= p.off_compensation - p.on_compensation
                    {
                        return Err(n);
                    }
                }
            }
        }
        Ok(())
    }
}

/// Configuration of a cam track (RES tags).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CamTrackConfig {
    /// `Parameter.CamTrackType`.
    pub track_type: CamTrackType,
    /// `Parameter.PositionType`.
    pub position_type: PositionType,
    /// The output interface (edge cap).
    pub interface: TrackOutputInterface,
    /// Operating range of a linear axis (hysteresis cap).
    pub working_range: Option<(f64, f64)>,
}

impl CamTrackConfig {
    /// A setpoint track with software output.
    pub const fn new(track_type: CamTrackType) -> Self {
        Self {
            track_type,
            position_type: PositionType::Setpoint,
            interface: TrackOutputInterface::Software,
            working_range: None,
        }
    }
}

/// `MC_CamTrack.Mode`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum CamTrackMode {
    /// 0: data and disable take effect at once.
    Immediate = 0,
    /// 1: data and disable take effect at the end of the current track cycle.
    EndOfCycle = 1,
    /// 2: output forced ON.
    ForcedOn = 2,
}

impl CamTrackMode {
    /// The mode for a `Mode` input, or `16#800A`.
    pub const fn from_code(code: i32) -> Result<Self, ErrorId> {
        match code {
            0 => Ok(Self::Immediate),
            1 => Ok(Self::EndOfCycle),
            2 => Ok(Self::ForcedOn),
            _ => Err(ErrorId::IllegalMode),
        }
    }
}

/// The inputs of `MC_CamTrack`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct McCamTrack {
    /// `Enable`.
    pub enable: bool,
    /// `Mode` (default 1).
    pub mode: CamTrackMode,
    /// `InvertOutput`.
    pub invert_output: bool,
}

impl McCamTrack {
    /// Enabled with `mode`, not inverted.
    pub const fn enabled(mode: CamTrackMode) -> Self {
        Self {
            enable: true,
            mode,
            invert_output: false,
        }
    }

    /// Disabled with `mode`.
    pub const fn disabled(mode: CamTrackMode) -> Self {
        Self {
            enable: false,
            mode,
            invert_output: false,
        }
    }
}

/// The outputs of `MC_CamTrack`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct CamTrackFb {
    /// `TrackOutput` as of the last step.
    pub track_output: bool,
    /// `Busy`.
    pub busy: bool,
    /// `Error`.
    pub error: bool,
    /// `ErrorID`.
    pub error_id: ErrorId,
}

/// `<TO>.Status` of a cam track.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum CamTrackState {
    /// 0 `INACTIVE`.
    Inactive = 0,
    /// 1 `ACTIVE`.
    Active = 1,
    /// 2 `ACTIVE_WAITING_FOR_NEXT_CYCLE`: a Mode 1 change or disable waits for the track end.
    ActiveWaitingForNextCycle = 2,
}

/// The technology data block of a cam track.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CamTrackStatus {
    /// `<TO>.Status`.
    pub state: CamTrackState,
    /// `<TO>.TrackOutput` (after the edges of the last step).
    pub track_output: bool,
    /// `<TO>.SingleCamState`: bit `i` is cam `i` (cam 1 is bit 0), uninverted, uncompensated.
    pub single_cam_state: u32,
    /// `<TO>.TrackPosition`.
    pub track_position: f64,
    /// `<TO>.MatchPosition` (reduced on modulo axes).
    pub match_position: f64,
    /// `StatusWord.X4 OutputInverted`.
    pub output_inverted: bool,
    /// `StatusWord.X6 CamDataChanged`: data written but not yet in effect.
    pub cam_data_changed: bool,
    /// Hysteresis in effect (after the cap).
    pub hysteresis: f64,
    /// The configured hysteresis exceeds the cap.
    pub hysteresis_limited: bool,
    /// Pending alarm (703, 702).
    pub alarm: Option<AlarmInstance>,
    /// Output edges suppressed by the interface's per-cycle cap (since creation).
    pub edges_suppressed: u64,
    /// Cam events dropped because a cycle had more than [`EVENT_CAPACITY`] (since creation).
    pub events_dropped: u64,
}

/// One cam state change in the cycle (before merging into the output).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
struct CamEvent {
    /// Time (s after the cycle start).
    dt: f64,
    /// Earliest time of the output edge it may cause (s after the cycle start).
    floor: f64,
    /// Index of the cam.
    cam: u8,
    /// New state of the cam.
    on: bool,
    /// Motion-derived (the compensation applies).
    comp: bool,
}

/// What waits for the end of the current track cycle (Mode 1).
#[derive(Copy, Clone, Debug, PartialEq)]
enum Pending {
    None,
    Data,
    Disable,
}

/// The per-cycle processing state (separate from the path so the walk can borrow both).
#[derive(Clone, Debug)]
struct Core {
    data: CamTrackData,
    staged: CamTrackData,
    track_type: CamTrackType,
    /// Continuous axis position of a track start (`MatchPosition = anchor + k L`).
    anchor: f64,
    sets: [RangeSet; MAX_CAMS],
    /// The boundaries of the periodic `sets` in one track period, ascending by position (then
    /// by cam): `(position, cam, is the on position)`. Built with the geometry, so a cycle
    /// finds the crossed boundaries by binary search instead of visiting every cam.
    bounds: [(f64, u8, bool); 2 * MAX_CAMS],
    n_bounds: usize,
    /// Where the last stretch ended in `bounds`: (track period, index, moving up).
    cursor: Option<(i64, usize, bool)>,
    starts: [Option<f64>; MAX_CAMS],
    bits: u32,
    /// Time cams: end of the logical on time (ns).
    running: [Option<i64>; MAX_CAMS],
    pending: Pending,
    events: [CamEvent; EVENT_CAPACITY],
    n_events: usize,
    dropped: u64,
    floor: f64,
    t0_ns: i64,
    t1_ns: i64,
    modulo: Option<Modulo>,
    stopped_at: Option<f64>,
    /// A Mode 1 switch-over happened in this cycle at this time (s after the cycle start).
    switched_at: Option<f64>,
}

impl Core {
    fn push(&mut self, dt: f64, cam: usize, on: bool, comp: bool) {
        let ev = CamEvent {
            dt,
            floor: self.floor,
            cam: cam as u8,
            on,
            comp,
        };
        if let Some(slot) = self.events.get_mut(self.n_events) {
            *slot = ev;
            self.n_events += 1;
        } else {
            self.dropped += 1;
        }
    }

    fn set_bit(&mut self, i: usize, on: bool, dt: f64, comp: bool) {
        let m = 1u32 << (i & 31);
        if ((self.bits & m) != 0) == on {
            return;
        }
        if on {
            self.bits |= m;
        } else {
            self.bits &= !m;
        }
        self.push(dt, i, on, comp);
    }

    /// Rebuilds the cams' geometry for the current anchor and data.
    fn geometry(&mut self) {
        let len = self.data.track_length;
        for i in 0..MAX_CAMS {
            let c = self.data.cams.get(i).copied().unwrap_or_default();
            let part = self.data.takes_part(i);
            if let Some(s) = self.sets.get_mut(i) {
                *s = if part && self.track_type == CamTrackType::Distance {
                    RangeSet::periodic(
                        self.anchor + c.on_position,
                        self.anchor + c.off_position.min(len),
                        len,
                    )
                } else {
                    RangeSet::Empty
                };
            }
            if let Some(s) = self.starts.get_mut(i) {
                *s = (part && self.track_type == CamTrackType::Time)
                    .then_some(self.anchor + c.on_position);
            }
        }
        self.n_bounds = 0;
        for (i, set) in self.sets.iter().enumerate() {
            if let RangeSet::Periodic { lo, hi, .. } = *set {
                for b in [(lo, i as u8, true), (hi, i as u8, false)] {
                    if let Some(slot) = self.bounds.get_mut(self.n_bounds) {
                        *slot = b;
                        self.n_bounds += 1;
                    }
                }
            }
        }
        self.cursor = None;
        let n = self.n_bounds.min(self.bounds.len());
        self.bounds[..n].sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    }

    /// The anchor for an (re)activation at continuous position `x`.
    fn enable_anchor(&self, x: f64) -> f64 {
        enable_anchor(
            x,
            self.data.reference_position,
            self.data.track_length,
            self.modulo,
        )
    }

    /// Distance cams take the state at `x` (moving in `dir`), at `dt`, uncompensated.
    fn evaluate(&mut self, x: f64, dir: i8, dt: f64, comp: bool) {
        if self.track_type != CamTrackType::Distance {
            return;
        }
        for i in 0..MAX_CAMS {
            let on = self.sets.get(i).is_some_and(|s| s.contains_moving(x, dir));
            self.set_bit(i, on, dt, comp);
        }
    }

    /// Time cams end at once.
    fn end_time_cams(&mut self, dt: f64) {
        for i in 0..MAX_CAMS {
            if self.running.get(i).copied().flatten().is_some() {
                if let Some(r) = self.running.get_mut(i) {
                    *r = None;
                }
                self.set_bit(i, false, dt, false);
            }
        }
    }

    /// Applies the staged data at `x` (continuous), `dt`; keeps the anchor unless the reference
    /// position or the track length changed.
    fn apply(&mut self, x: f64, dir: i8, dt: f64, abort_time_cams: bool) {
        let old = self.data;
        self.data = self.staged;
        if old.reference_position != self.data.reference_position
            || old.track_length != self.data.track_length
        {
            self.anchor = self.enable_anchor(x);
        }
        self.geometry();
        if abort_time_cams {
            self.end_time_cams(dt);
        }
        self.evaluate(x, dir, dt, false);
    }

    fn ns(&self, dt: f64) -> i64 {
        self.t0_ns + (dt * 1e9).round() as i64
    }

    /// Trigger time cams whose start is crossed from `from` to `to` at the times `time_of`.
    fn time_cams(&mut self, from: f64, to: f64, time_of: &dyn Fn(f64) -> f64) {
        let len = self.data.track_length;
        for i in 0..MAX_CAMS {
            let Some(p) = self.starts.get(i).copied().flatten() else {
                continue;
            };
            let duration = self.data.cams.get(i).map_or(0.0, |c| c.duration);
            point_crossings(p, Some(len), from, to, |c| {
                let dt = time_of(c);
                let t_ns = self.ns(dt);
                if self
                    .running
                    .get(i)
                    .copied()
                    .flatten()
                    .is_some_and(|end| t_ns < end)
                {
                    return true;
                }
                let end = self.ns(dt + duration);
                if let Some(r) = self.running.get_mut(i) {
                    *r = Some(end);
                }
                self.set_bit(i, true, dt, true);
                if end <= self.t1_ns {
                    let dt_end = (end - self.t0_ns) as f64 * 1e-9;
                    // The end is a time, not a position: compensated like every motion edge.
                    self.push(dt_end, i, false, true);
                    self.bits &= !(1u32 << (i & 31));
                }
                true
            });
        }
    }

    /// One monotone stretch of the effective path, split at a track boundary when a Mode 1
    /// change waits for it.
    fn stretch(&mut self, from: f64, to: f64, dir: i8, time_of: &dyn Fn(f64) -> f64) {
        if self.stopped_at.is_some() {
            return;
        }
        let mut from = from;
        if self.pending != Pending::None {
            let mut boundary = None;
            point_crossings(self.anchor, Some(self.data.track_length), from, to, |c| {
                boundary = Some(c);
                false
            });
            if let Some(b) = boundary {
                self.cams_between(from, b, time_of);
                let dt = time_of(b);
                match self.pending {
                    Pending::Disable => {
                        self.stopped_at = Some(dt);
                        self.pending = Pending::None;
                        return;
                    }
                    _ => {
                        self.pending = Pending::None;
                        self.floor = dt;
                        self.switched_at = Some(dt);
                        self.apply(b, dir, dt, false);
                        from = b;
                    }
                }
            }
        }
        self.cams_between(from, to, time_of);
    }

    /// The crossings of the distance cams from `from` to `to`, in motion order, found in the
    /// sorted boundaries: the same positions (`on/off + k * length`, computed as
    /// [`RangeSet::crossings`] does) and the same half-open test, without visiting every cam.
    /// Equal positions go in cam order. Returns false (nothing done) for a stretch over more
    /// than a few track lengths; the caller then takes the cams one by one.
    fn sorted_crossings(&mut self, from: f64, to: f64, time_of: &dyn Fn(f64) -> f64) -> bool {
        const MAX_PERIODS: i64 = 8;
        let n = self.n_bounds.min(self.bounds.len());
        let (Some(&(first, ..)), Some(&(last, ..))) =
            (self.bounds[..n].first(), self.bounds[..n].last())
        else {
            return true;
        };
        let len = self.data.track_length;
        let up = to > from;
        let (min, max) = if up { (from, to) } else { (to, from) };
        if to == from || !from.is_finite() || !to.is_finite() {
            return true;
        }
        let k0 = ((min - last) / len).floor();
        let k1 = ((max - first) / len).ceil();
        let span = k1 - k0;
        if span.is_nan() || span > MAX_PERIODS as f64 {
            return false;
        }
        let (k0, k1) = (k0 as i64, k1 as i64);
        let b_at = |core: &Self, j: usize| core.bounds[..n].get(j).copied();
        if up {
            for k in k0..=k1 {
                let base = k as f64 * len;
                if last + base <= from {
                    continue;
                }
                if first + base > to {
                    break;
                }
                // The first boundary above `from`: where the last stretch ended (continuous
                // motion), else by binary search.
                let valid = |j: usize| {
                    (j == 0 || b_at(self, j - 1).is_some_and(|e| e.0 + base <= from))
                        && b_at(self, j).is_none_or(|e| e.0 + base > from)
                };
                let mut j = match self.cursor {
                    Some((ck, cj, true)) if ck == k && cj <= n && valid(cj) => cj,
                    _ => self.bounds[..n].partition_point(|e| e.0 + base <= from),
                };
                while let Some((x, cam, is_on)) = b_at(self, j) {
                    let c = x + base;
                    if c > to {
                        break;
                    }
                    self.set_bit(usize::from(cam), is_on, time_of(c), true);
                    j += 1;
                }
                self.cursor = Some((k, j, true));
            }
        } else {
            for k in (k0..=k1).rev() {
                let base = k as f64 * len;
                if first + base >= from {
                    continue;
                }
                if last + base < to {
                    break;
                }
                // Past the last boundary below `from`, then down while at or above `to`; a
                // group at one position goes in cam order.
                let valid = |end: usize| {
                    (end == 0 || b_at(self, end - 1).is_some_and(|e| e.0 + base < from))
                        && b_at(self, end).is_none_or(|e| e.0 + base >= from)
                };
                let mut end = match self.cursor {
                    Some((ck, ce, false)) if ck == k && ce <= n && valid(ce) => ce,
                    _ => self.bounds[..n].partition_point(|e| e.0 + base < from),
                };
                while let Some((x, ..)) = end.checked_sub(1).and_then(|i| b_at(self, i)) {
                    if x + base < to {
                        break;
                    }
                    let mut start = end - 1;
                    while start > 0 && b_at(self, start - 1).is_some_and(|e| e.0 == x) {
                        start -= 1;
                    }
                    for j in start..end {
                        if let Some((_, cam, is_on)) = b_at(self, j) {
                            self.set_bit(usize::from(cam), !is_on, time_of(x + base), true);
                        }
                    }
                    end = start;
                }
                self.cursor = Some((k, end, false));
            }
        }
        true
    }

    /// The crossings of the distance cams from `from` to `to`, cam by cam (any distance).
    fn cam_by_cam_crossings(&mut self, from: f64, to: f64, time_of: &dyn Fn(f64) -> f64) {
        for i in 0..MAX_CAMS {
            let set = self.sets.get(i).copied().unwrap_or(RangeSet::Empty);
            set.crossings(from, to, |c, entering| {
                self.set_bit(i, entering, time_of(c), true);
                true
            });
        }
    }

    fn cams_between(&mut self, from: f64, to: f64, time_of: &dyn Fn(f64) -> f64) {
        match self.track_type {
            CamTrackType::Distance => {
                if !self.sorted_crossings(from, to, time_of) {
                    self.cam_by_cam_crossings(from, to, time_of);
                }
            }
            CamTrackType::Time => self.time_cams(from, to, time_of),
        }
    }
}

/// The cam track technology object (see the module documentation).
#[derive(Clone, Debug)]
pub struct CamTrack {
    config: CamTrackConfig,
    core: Core,
    path: Path,
    owner: Option<u32>,
    input: McCamTrack,
    /// Processing runs.
    live: bool,
    /// Staged data waits for the next FB call.
    data_written: bool,
    /// The FB applied new data (Mode 0 at the next step).
    apply_now: bool,
    /// The output before the interface cap.
    phys: bool,
    hw_output: bool,
    last_edge_ns: i64,
    alarm: Option<AlarmInstance>,
    status: CamTrackStatus,
}

impl CamTrack {
    /// A cam track with the given configuration and data.
    pub fn new(config: CamTrackConfig, data: CamTrackData) -> Result<Self, MeasuringConfigError> {
        if data.check(config.track_type).is_err() {
            return Err(MeasuringConfigError::CamTrackData);
        }
        Ok(Self {
            config,
            core: Core {
                data,
                staged: data,
                track_type: config.track_type,
                anchor: data.reference_position,
                sets: [RangeSet::Empty; MAX_CAMS],
                bounds: [(0.0, 0, false); 2 * MAX_CAMS],
                n_bounds: 0,
                cursor: None,
                starts: [None; MAX_CAMS],
                bits: 0,
                running: [None; MAX_CAMS],
                pending: Pending::None,
                events: [CamEvent::default(); EVENT_CAPACITY],
                n_events: 0,
                dropped: 0,
                floor: f64::NEG_INFINITY,
                t0_ns: 0,
                t1_ns: 0,
                modulo: None,
                stopped_at: None,
                switched_at: None,
            },
            path: Path::default(),
            owner: None,
            input: McCamTrack::disabled(CamTrackMode::EndOfCycle),
            live: false,
            data_written: false,
            apply_now: false,
            phys: false,
            hw_output: false,
            last_edge_ns: i64::MIN,
            alarm: None,
            status: CamTrackStatus {
                state: CamTrackState::Inactive,
                track_output: false,
                single_cam_state: 0,
                track_position: 0.0,
                match_position: 0.0,
                output_inverted: false,
                cam_data_changed: false,
                hysteresis: data.parameters.hysteresis,
                hysteresis_limited: false,
                alarm: None,
                edges_suppressed: 0,
                events_dropped: 0,
            },
        })
    }

    /// The configuration.
    pub fn config(&self) -> &CamTrackConfig {
        &self.config
    }

    /// The data in effect.
    pub fn data(&self) -> &CamTrackData {
        &self.core.data
    }

    /// The status (data block).
    pub fn status(&self) -> &CamTrackStatus {
        &self.status
    }

    /// Writes the TO data (`ReferencePosition`, `CamTrackLength`, `CamMasking`, compensations,
    /// hysteresis, `Cam[]`). It is staged (`StatusWord.X6`) and takes effect with the next FB
    /// call, as that call's Mode says. Faulty data raises alarm 703 when it is applied.
    pub fn set_data(&mut self, data: CamTrackData) {
        self.core.staged = data;
        self.data_written = data != self.core.data;
        self.status.cam_data_changed = self.data_written || self.core.pending == Pending::Data;
    }

    /// `ReferencePosition` for a seamless change at the end of the current track cycle
    /// (S7-1500T Measuring input and cam functions V5.0 function manual, 3.3.3 'Changing the cam
    /// track data during operation'): `MatchPosition + L` (positive motion) or `MatchPosition - L`,
    /// reduced on modulo axes.
    pub fn next_reference_position(&self, positive: bool) -> f64 {
        next_reference_position(
            self.status.match_position,
            self.core.data.track_length,
            positive,
            self.core.modulo,
        )
    }

    fn fb(&self, busy: bool, err: Option<ErrorId>) -> CamTrackFb {
        let err = err.or(self.alarm.map(|_| ErrorId::TechnologyAlarm));
        CamTrackFb {
            track_output: self.status.track_output,
            busy,
            error: err.is_some(),
            error_id: err.unwrap_or(ErrorId::None),
        }
    }

    /// `MC_CamTrack` called by FB instance `instance` (Enable-type). Takes effect at the next
    /// step.
    pub fn call(&mut self, instance: u32, input: &McCamTrack) -> CamTrackFb {
        if self.owner.is_some_and(|o| o != instance) {
            if input.enable {
                return CamTrackFb {
                    track_output: false,
                    busy: false,
                    error: true,
                    error_id: ErrorId::OnlyOneInstance,
                };
            }
            return self.fb(false, None);
        }
        if !input.enable {
            if self.owner == Some(instance) {
                if input.mode == CamTrackMode::EndOfCycle && self.live && self.alarm.is_none() {
                    self.core.pending = Pending::Disable;
                    self.input.enable = false;
                    self.status.state = CamTrackState::ActiveWaitingForNextCycle;
                    return self.fb(true, None);
                }
                self.owner = None;
            }
            return self.fb(false, None);
        }
        if self.owner.is_none() {
            self.owner = Some(instance);
            self.live = false;
            self.core.pending = Pending::None;
        } else if self.core.pending == Pending::Disable {
            // Re-enabled before the track end: the disable is cancelled.
            self.core.pending = Pending::None;
        }
        self.input = *input;
        if self.data_written {
            self.data_written = false;
            if let Err(n) = self.core.staged.check(self.config.track_type) {
                self.alarm = Some(AlarmInstance::new(AlarmId::CamTrackDataFaulty, n));
            } else if self.live {
                match input.mode {
                    CamTrackMode::EndOfCycle => self.core.pending = Pending::Data,
                    _ => self.apply_now = true,
                }
            } else {
                self.core.data = self.core.staged;
            }
        }
        self.status.cam_data_changed = self.data_written || self.core.pending == Pending::Data;
        self.status.state = if self.core.pending != Pending::None {
            CamTrackState::ActiveWaitingForNextCycle
        } else {
            CamTrackState::Active
        };
        self.fb(true, None)
    }

    /// `MC_Reset`: acknowledges the pending alarm; an enabled track resumes at the next step.
    pub fn reset(&mut self) {
        if self.alarm.take().is_some() {
            self.live = false;
            if self.core.staged.check(self.config.track_type).is_ok() {
                self.core.data = self.core.staged;
                self.data_written = false;
            }
        }
        self.status.alarm = None;
    }

    /// The physical output for the cams' OR.
    fn physical(&self, logical: bool) -> bool {
        match self.input.mode {
            CamTrackMode::ForcedOn => true,
            _ => logical != self.input.invert_output,
        }
    }

    /// One cycle: the track output's edges of this cycle go to `edges` (cleared first).
    pub fn step(&mut self, motion: &AxisMotion, edges: &mut CamEdges) {
        edges.clear();
        let h = self.begin_cycle(motion);
        let bits_before = self.core.bits;

        let enabled = self.owner.is_some();
        if enabled
            && !motion.valid
            && self.alarm.is_none()
            && self.config.position_type == PositionType::Actual
        {
            self.alarm = Some(AlarmInstance::new(AlarmId::PositionValueInvalid, 0));
        }
        if !enabled || self.alarm.is_some() || !motion.valid {
            self.stop();
            self.output(edges, motion, bits_before, None);
            return;
        }

        self.enter_cycle(motion);
        self.end_time_cams(motion);
        self.walk_path(motion, h);
        self.track_position(motion);

        let cut = self.core.stopped_at;
        if cut.is_some() {
            // A Mode 1 disable reached the end of the track cycle.
            self.owner = None;
            self.stop();
        }
        self.output(edges, motion, bits_before, cut);
    }

    /// Resets the per-cycle state of the core and limits the hysteresis (a quarter of the modulo
    /// length or working range); returns the effective hysteresis.
    fn begin_cycle(&mut self, motion: &AxisMotion) -> f64 {
        self.core.n_events = 0;
        self.core.floor = f64::NEG_INFINITY;
        self.core.t0_ns = motion.t0_ns;
        self.core.t1_ns = motion.t1_ns;
        self.core.modulo = motion.modulo;
        self.core.stopped_at = None;
        self.core.switched_at = None;

        let cap = max_hysteresis(motion.modulo.map(|m| m.length), self.config.working_range);
        let h_cfg = self.core.data.parameters.hysteresis;
        let h = cap.map_or(h_cfg, |c| h_cfg.min(c));
        self.status.hysteresis = h;
        self.status.hysteresis_limited = h < h_cfg;
        h
    }

    /// The state at the cycle start: set up on the first enabled cycle; a position jump
    /// (treated as motion by at most half a modulo length) or newly written data applied.
    fn enter_cycle(&mut self, motion: &AxisMotion) {
        let x0 = motion.start.p;
        if !self.live {
            self.live = true;
            self.path.reset(motion);
            self.core.running = [None; MAX_CAMS];
            self.core.bits = 0;
            self.core.anchor = self.core.enable_anchor(x0);
            self.core.geometry();
            self.core.evaluate(x0, self.path.dir, 0.0, false);
            self.last_edge_ns = self.last_edge_ns.max(motion.t0_ns);
        } else {
            if let Some(j) = motion.jump {
                self.path.reset(motion);
                if let Some(m) = motion.modulo {
                    // Treated as motion by at most half a modulo length (S7-1500T Measuring input
                    // and cam functions V5.0 function manual, 3.3.1 'Modulo function' (homing)).
                    let diff = m.forward(x0 - j, x0);
                    let as_motion = if diff <= 0.5 * m.length {
                        diff
                    } else {
                        diff - m.length
                    };
                    self.core.anchor += j - as_motion;
                    self.core.geometry();
                }
                self.core.evaluate(x0, self.path.dir, 0.0, false);
            }
            if core::mem::take(&mut self.apply_now) {
                self.core.floor = 0.0;
                self.last_edge_ns = self.last_edge_ns.max(motion.t0_ns);
                self.core.apply(x0, self.path.dir, 0.0, true);
            }
        }
    }

    /// Time cams whose logical on time ends in this cycle switch off (they stay `running`
    /// until the end of the cycle, so that a crossing before the end does not retrigger them).
    fn end_time_cams(&mut self, motion: &AxisMotion) {
        for i in 0..MAX_CAMS {
            if let Some(end) = self.core.running.get(i).copied().flatten() {
                if end <= motion.t1_ns {
                    let dt = ((end - motion.t0_ns) as f64 * 1e-9).max(0.0);
                    self.core.set_bit(i, false, dt, true);
                }
            }
        }
    }

    /// Walks the effective path of the cycle (hysteresis `h`): the cams' crossings become
    /// events; ended time cams are released at the cycle end.
    fn walk_path(&mut self, motion: &AxisMotion, h: f64) {
        let mut path = self.path;
        let core = &mut self.core;
        path.walk(motion, h, |ev| match ev {
            PathEvent::Move { run, from, to } => {
                core.stretch(from, to, run.dir(), &|c| run.time_of(c));
            }
            PathEvent::Sweep { dt, dir, from, to } => {
                core.stretch(from, to, dir, &|_| dt);
            }
            PathEvent::Turn { dt, dir, at } => {
                if core.stopped_at.is_none() {
                    core.evaluate(at, dir, dt, true);
                }
            }
        });
        self.path = path;
        for r in self.core.running.iter_mut() {
            if r.is_some_and(|end| end <= motion.t1_ns) {
                *r = None;
            }
        }
    }

    /// Match and track position at the cycle end.
    fn track_position(&mut self, motion: &AxisMotion) {
        let x1 = motion.end.p;
        let k = cycle_index(x1, self.core.anchor, self.core.data.track_length);
        let m_cont = self.core.anchor + k * self.core.data.track_length;
        self.status.track_position = x1 - m_cont;
        self.status.match_position = motion.modulo.map_or(m_cont, |m| m.wrap(m_cont));
    }

    fn stop(&mut self) {
        self.live = false;
        self.core.bits = 0;
        self.core.running = [None; MAX_CAMS];
        self.core.pending = Pending::None;
    }

    /// Merges the cam events of the cycle into the track output: the state at the cycle start
    /// (with the current FB inputs), then the events in time order (equal times together),
    /// compensation, the monotone clamp, `cut` (processing ends there), the interface cap; and
    /// updates the status.
    fn output(
        &mut self,
        edges: &mut CamEdges,
        motion: &AxisMotion,
        bits_before: u32,
        cut: Option<f64>,
    ) {
        let n = self.core.n_events.min(EVENT_CAPACITY);
        let mut order = [0u16; EVENT_CAPACITY];
        let order = &mut order[..n];
        self.sort_events(order);
        let raw = self.raw_edges(order, motion, bits_before, cut);
        // Interface cap.
        self.cap_to_interface(&raw, edges);
        self.update_status(&raw, edges);
    }

    /// The indices of the cycle's cam events in time order (equal times in the order found).
    fn sort_events(&self, order: &mut [u16]) {
        for (i, o) in order.iter_mut().enumerate() {
            *o = i as u16;
        }
        let evs = &self.core.events[..order.len()];
        order.sort_unstable_by(|&a, &b| {
            let (ea, eb) = (&evs[a as usize], &evs[b as usize]);
            ea.dt.total_cmp(&eb.dt).then(a.cmp(&b))
        });
    }

    /// The track output's edges before the interface cap: the state at the cycle start, then
    /// the events in `order` (equal times together) with compensation, the monotone clamp and
    /// `cut`.
    fn raw_edges(
        &mut self,
        order: &[u16],
        motion: &AxisMotion,
        bits_before: u32,
        cut: Option<f64>,
    ) -> CamEdges {
        let p = self.core.data.parameters;
        let live = self.live || cut.is_some();
        let mut raw = CamEdges::default();
        let mut phys = self.phys;
        let mut last = self.last_edge_ns;
        let mut bits = bits_before;
        let t0 = motion.t0_ns;
        let mut push = |raw: &mut CamEdges, t: i64, on: bool, cam: u8, phys: &mut bool| {
            let t = t.max(last);
            last = t;
            *phys = on;
            raw.push(Edge {
                time_ns: t,
                on,
                cam,
            });
        };
        // The state at the cycle start: the cams before their events, the current FB inputs.
        let first_dt = order
            .first()
            .map_or(f64::INFINITY, |&o| self.core.events[o as usize].dt);
        if first_dt > 0.0 {
            let want = live && self.physical(bits != 0) && cut.is_none_or(|c| c > 0.0);
            if want != phys {
                push(&mut raw, t0, want, 0, &mut phys);
            }
        }
        let mut i = 0;
        while i < order.len() {
            let dt = self.core.events[order[i] as usize].dt;
            if cut.is_some_and(|c| dt > c) {
                break;
            }
            let mut cause = 0u8;
            let mut comp = false;
            let mut floor = f64::NEG_INFINITY;
            while let Some(e) = order.get(i).map(|&o| self.core.events[o as usize]) {
                if e.dt != dt {
                    break;
                }
                let m = 1u32 << (e.cam & 31);
                if e.on {
                    bits |= m;
                } else {
                    bits &= !m;
                }
                // Several cams at one time: the highest index is the cause (independent of
                // the order the crossings were found in).
                cause = cause.max(e.cam);
                comp |= e.comp;
                floor = floor.max(e.floor);
                i += 1;
            }
            let want = live && self.physical(bits != 0) && cut.is_none_or(|c| dt < c);
            if want != phys {
                let lead = match (comp, want) {
                    (false, _) => 0.0,
                    (true, true) => p.on_compensation,
                    (true, false) => p.off_compensation,
                };
                let t = motion.ns((dt - lead).max(floor));
                push(&mut raw, t, want, cause, &mut phys);
            }
        }
        if let Some(c) = cut {
            if phys {
                push(&mut raw, motion.ns(c), false, 0, &mut phys);
            }
        }
        // Edges after a switch-over never come before it, in later cycles too.
        let floor_ns = self.core.switched_at.map_or(i64::MIN, |dt| motion.ns(dt));
        self.last_edge_ns = last.max(floor_ns);
        self.phys = phys;
        raw
    }

    /// Passes the raw edges to `edges` as the output interface can switch them (software: all;
    /// TM Timer DQ: the last rising and falling edge; DQ module: the last edge).
    fn cap_to_interface(&mut self, raw: &CamEdges, edges: &mut CamEdges) {
        let mut hw = self.hw_output;
        match self.config.interface {
            TrackOutputInterface::Software => {
                for e in raw.as_slice() {
                    edges.push(*e);
                    hw = e.on;
                }
            }
            TrackOutputInterface::TimerDq => {
                // The last rising and the last falling edge, in the order they came.
                let r = raw.as_slice();
                let last_on = r.iter().rposition(|e| e.on);
                let last_off = r.iter().rposition(|e| !e.on);
                let (a, b) = match (last_on, last_off) {
                    (Some(x), Some(y)) if y < x => (Some(y), Some(x)),
                    (x, y) => (x, y),
                };
                for e in [a, b].into_iter().flatten().filter_map(|i| r.get(i)) {
                    if e.on != hw {
                        edges.push(*e);
                        hw = e.on;
                    }
                }
            }
            TrackOutputInterface::DqModule => {
                if let Some(e) = raw.as_slice().last() {
                    if e.on != hw {
                        edges.push(*e);
                        hw = e.on;
                    }
                }
            }
        }
        self.hw_output = hw;
    }

    /// The status after the cycle's output: suppressed and dropped edges, the output, the cams'
    /// state and the track state.
    fn update_status(&mut self, raw: &CamEdges, edges: &CamEdges) {
        self.status.edges_suppressed +=
            raw.len().saturating_sub(edges.len()) as u64 + raw.dropped();
        self.status.events_dropped += core::mem::take(&mut self.core.dropped);
        self.status.track_output = self.hw_output;
        self.status.single_cam_state = if self.live { self.core.bits } else { 0 };
        self.status.output_inverted = self.owner.is_some() && self.input.invert_output;
        self.status.alarm = self.alarm;
        self.status.cam_data_changed = self.data_written || self.core.pending == Pending::Data;
        self.status.state = if self.owner.is_none() || self.alarm.is_some() {
            CamTrackState::Inactive
        } else if self.core.pending != Pending::None {
            CamTrackState::ActiveWaitingForNextCycle
        } else {
            CamTrackState::Active
        };
    }
}

/// `ReferencePosition` for a seamless Mode 1 change (S7-1500T Measuring input and cam functions
/// V5.0 function manual, 3.3.3 'Changing the cam track data during operation'): `match +
/// length` for positive motion, `match - length` for negative, reduced into the modulo range.
pub fn next_reference_position(
    match_position: f64,
    length: f64,
    positive: bool,
    modulo: Option<Modulo>,
) -> f64 {
    let r = if positive {
        match_position + length
    } else {
        match_position - length
    };
    modulo.map_or(r, |m| m.wrap(r))
}

/// The continuous position of a track start for enabling a track at `x` (S7-1500T Measuring input
/// and cam functions V5.0 function manual, 3.3.1 'Modulo function'): as if `x`
/// had been reached by positive motion from `reference` (on a modulo axis from the reduced
/// reference, within one modulo length).
fn enable_anchor(x: f64, reference: f64, length: f64, modulo: Option<Modulo>) -> f64 {
    match modulo {
        None => reference,
        Some(m) => {
            let mut d = m.forward(reference, x);
            if m.length - d <= 1e-9 * m.length {
                d = 0.0;
            }
            let mut tp = d.rem_euclid(length);
            if length - tp <= 1e-9 * length {
                tp = 0.0;
            }
            x - tp
        }
    }
}

/// Index of the track cycle containing `x` (an exact boundary belongs to the new cycle).
fn cycle_index(x: f64, anchor: f64, length: f64) -> f64 {
    let q = (x - anchor) / length;
    let r = q.round();
    if (q - r).abs() <= 1e-12 * q.abs().max(1.0) {
        r
    } else {
        q.floor()
    }
}

/// `MatchPosition` (reduced on modulo axes) and `TrackPosition` for enabling a track at
/// `position` (S7-1500T Measuring input and cam functions V5.0 function manual, 3.3.1 'Modulo
/// function').
pub fn match_on_enable(
    position: f64,
    reference: f64,
    length: f64,
    modulo: Option<Modulo>,
) -> (f64, f64) {
    let anchor = enable_anchor(position, reference, length, modulo);
    let m = anchor + cycle_index(position, anchor, length) * length;
    (modulo.map_or(m, |md| md.wrap(m)), position - m)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;

    /// xorshift64*, uniform in [0, 1).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            let mut x = self.0;
            x ^= x >> 12;
            x ^= x << 25;
            x ^= x >> 27;
            self.0 = x;
            (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The cam events of a stretch by time; events at one time are merged by the output, so
    /// their order does not matter (they are sorted by cam).
    fn ordered(core: &Core) -> Vec<(f64, u8, bool)> {
        let mut v: Vec<(f64, u8, bool)> = core.events[..core.n_events]
            .iter()
            .map(|e| (e.dt, e.cam, e.on))
            .collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        v
    }

    /// The binary search over the sorted boundaries finds exactly the events of the cam-by-cam
    /// walk, at the same times, on random tracks (shared boundaries, cams ending at the track
    /// length) and random runs of four stretches in both directions up to several track
    /// lengths (the search resumes where the last stretch ended).
    #[test]
    fn sorted_crossings_match_the_cam_by_cam_walk() {
        let mut rng = Rng(0x7a3d_0004_c0ff_ee01);
        let mut events = 0usize;
        for case in 0..4000 {
            let len = 5.0 + 95.0 * rng.next();
            let n_cams = 1 + (rng.next() * 32.0) as usize;
            let grid = len / 16.0;
            let mut data = CamTrackData::new(0.0, len);
            for i in 0..n_cams {
                // Half the cams on a coarse grid, so that boundaries coincide.
                let (on, off) = if rng.next() < 0.5 {
                    let a = (rng.next() * 16.0).floor() * grid;
                    (a, a + (1.0 + (rng.next() * 16.0).floor()) * grid)
                } else {
                    let a = rng.next() * len;
                    (a, a + rng.next() * len)
                };
                data = data.with_cam(i, TrackCam::distance(on, off.min(len)));
            }
            let Ok(track) = CamTrack::new(CamTrackConfig::new(CamTrackType::Distance), data) else {
                continue;
            };
            let mut a = track.core.clone();
            a.anchor = (rng.next() - 0.5) * 1000.0;
            a.geometry();
            a.bits = (rng.next() * f64::from(u32::MAX)) as u32;
            let mut b = a.clone();
            let from = a.anchor + (rng.next() - 0.5) * 4.0 * len;
            let from = if rng.next() < 0.2 {
                // Start on a boundary.
                a.anchor + (rng.next() * 16.0).floor() * grid
            } else {
                from
            };
            // Four stretches in a row (random directions), so that the cursor of one stretch
            // serves the next.
            let mut from = from;
            for step in 0..4 {
                let span = (rng.next() - 0.5) * 2.0 * len * [0.05, 1.0, 9.0][(case + step) % 3];
                let to = from + span;
                let time_of = |c: f64| (c - from) / span;
                a.n_events = 0;
                a.dropped = 0;
                b.n_events = 0;
                b.dropped = 0;
                if !a.sorted_crossings(from, to, &time_of) {
                    a.cam_by_cam_crossings(from, to, &time_of);
                }
                b.cam_by_cam_crossings(from, to, &time_of);
                if b.dropped == 0 {
                    assert_eq!(
                        ordered(&a),
                        ordered(&b),
                        "case {case}.{step}: {from} -> {to}"
                    );
                } else {
                    // Beyond the capacity the two keep different events (by time, by cam).
                    assert_eq!(a.n_events as u64 + a.dropped, b.n_events as u64 + b.dropped);
                }
                assert_eq!(a.bits, b.bits, "case {case}.{step}");
                events += a.n_events;
                // Mostly continuous; sometimes the next stretch starts elsewhere (a jump, or a
                // hysteresis sweep), where the cursor must not be trusted.
                from = if rng.next() < 0.3 {
                    to + (rng.next() - 0.5) * 0.5 * len
                } else {
                    to
                };
            }
        }
        assert!(events > 80_000, "the stretches crossed {events} boundaries");
    }
}
