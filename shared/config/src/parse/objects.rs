//! `[[output_cams]]`, `[[cam_tracks]]` and `[[measuring_inputs]]` (after the axes and
//! encoders: they name an axis, and their names must differ from every other object's).

use super::{pick, Ctx, FieldError};
use crate::cell::{
    AxisEntry, AxisIndex, CamTrackEntry, DigitalCamSwitchEntry, MeasuringInputEntry, Node,
    OutputCamEntry, Registration, SensorEntry,
};
use crate::error::{ConfigError, Problem};
use crate::schema::{
    CamTrackSection, CellFile, DcsSwitchSection, DigitalCamSwitchSection, MeasuringInputSection,
    OutputCamSection, RegistrationSection, SensorSection, TrackCamSection,
};
use tandem_motion::catalog::hyd_error::HydErrorCode;
use tandem_motion::objects::cam_track::{
    CamTrack, CamTrackConfig, CamTrackData, CamTrackType, TrackCam, TrackOutputInterface, MAX_CAMS,
};
use tandem_motion::objects::digital_cam_switch::{
    CamSwitch, CamSwitchMode, DcsError, DcsField, DigitalCamSwitch, SwitchDirection, TrackOptions,
};
use tandem_motion::objects::measuring::{MeasuringInput, MeasuringInputConfig, MeasuringRoute};
use tandem_motion::objects::output_cam::{
    OutputCamConfig, OutputCamParameters, OutputCamType, PositionType,
};
use tandem_motion::plant::sensor::SensorDirection;

/// The output cams, cam tracks and measuring inputs of a cell.
pub(super) struct Objects {
    /// `[[output_cams]]`.
    pub(super) output_cams: Vec<OutputCamEntry>,
    /// `[[cam_tracks]]`.
    pub(super) cam_tracks: Vec<CamTrackEntry>,
    /// `[[measuring_inputs]]`.
    pub(super) measuring_inputs: Vec<MeasuringInputEntry>,
    /// `[[digital_cam_switches]]`.
    pub(super) digital_cam_switches: Vec<DigitalCamSwitchEntry>,
}

/// What the object sections are checked against: the axes and the names already used.
struct Scope<'a> {
    cx: Ctx<'a>,
    axes: &'a [AxisEntry],
    names: Vec<String>,
}

impl Scope<'_> {
    /// Claims `name` for entry `i` of `array`; it must be new and not empty.
    fn unique(&mut self, array: &str, i: usize, name: &str) -> Result<(), ConfigError> {
        if name.is_empty() || self.names.iter().any(|n| n == name) {
            return Err(self
                .cx
                .in_array(array, i, "name", Problem::NameTaken(name.into())));
        }
        self.names.push(name.to_string());
        Ok(())
    }

    /// The axis named `name`, for `key` of entry `i` of `array` (the line is that of `axis`).
    fn axis_of(
        &self,
        array: &str,
        i: usize,
        key: &str,
        name: &str,
    ) -> Result<AxisIndex, ConfigError> {
        self.axes
            .iter()
            .position(|a| a.name == name)
            .map(AxisIndex)
            .ok_or_else(|| {
                let mut e = self.cx.in_array(
                    array,
                    i,
                    "axis",
                    Problem::Unknown {
                        what: "axis",
                        name: name.into(),
                        known: Some(self.axes.iter().map(|a| a.name.clone()).collect()),
                    },
                );
                e.key = format!("{array}[{i}].{key}");
                e
            })
    }

    /// Maps a [`FieldError`] of entry `i` of `array` to a located error.
    fn field(&self, array: &'static str, i: usize) -> impl Fn(FieldError) -> ConfigError + '_ {
        move |(k, p)| self.cx.in_array(array, i, k, p)
    }
}

/// The output cams, cam tracks and measuring inputs, in file order.
pub(super) fn objects(
    cx: Ctx<'_>,
    raw: &CellFile,
    axes: &[AxisEntry],
    nodes: &[Node],
) -> Result<Objects, ConfigError> {
    let mut scope = Scope {
        cx,
        axes,
        names: axes
            .iter()
            .map(|a| a.name.clone())
            .chain(raw.encoders.keys().cloned())
            .collect(),
    };
    let mut out = Objects {
        output_cams: Vec::new(),
        cam_tracks: Vec::new(),
        measuring_inputs: Vec::new(),
        digital_cam_switches: Vec::new(),
    };
    for (i, c) in raw.output_cams.iter().enumerate() {
        out.output_cams.push(output_cam(&mut scope, i, c)?);
    }
    for (i, c) in raw.cam_tracks.iter().enumerate() {
        out.cam_tracks.push(cam_track(&mut scope, i, c)?);
    }
    for (i, m) in raw.measuring_inputs.iter().enumerate() {
        out.measuring_inputs
            .push(measuring_input(&mut scope, nodes, i, m)?);
    }
    for (i, c) in raw.digital_cam_switches.iter().enumerate() {
        out.digital_cam_switches
            .push(digital_cam_switch(&mut scope, i, c)?);
    }
    Ok(out)
}

/// The types of output cams and cam tracks by name.
const KINDS: [(&str, u8); 2] = [("distance", 0), ("time", 1)];

fn position_type(v: &str) -> Result<PositionType, FieldError> {
    pick(
        "position",
        v,
        &[
            ("setpoint", PositionType::Setpoint),
            ("actual", PositionType::Actual),
        ],
    )
}

fn range(r: Option<[f64; 2]>) -> Result<Option<(f64, f64)>, FieldError> {
    match r {
        None => Ok(None),
        Some([lo, hi]) if lo.is_finite() && hi.is_finite() && lo < hi => Ok(Some((lo, hi))),
        Some(_) => Err((
            "working_range",
            Problem::Invalid("must be [min, max] with finite min < max"),
        )),
    }
}

fn parameters(on: f64, off: f64, h: f64) -> Result<OutputCamParameters, FieldError> {
    if !(0.0..=1e9).contains(&on) {
        return Err((
            "on_compensation",
            Problem::Invalid("must be 0..1e9 seconds"),
        ));
    }
    if !(0.0..=1e9).contains(&off) {
        return Err((
            "off_compensation",
            Problem::Invalid("must be 0..1e9 seconds"),
        ));
    }
    if !(0.0..=1e12).contains(&h) {
        return Err(("hysteresis", Problem::Invalid("must be 0..1e12")));
    }
    Ok(OutputCamParameters {
        on_compensation: on,
        off_compensation: off,
        hysteresis: h,
    })
}

/// Entry `i` of `[[output_cams]]`.
fn output_cam(
    s: &mut Scope<'_>,
    i: usize,
    c: &OutputCamSection,
) -> Result<OutputCamEntry, ConfigError> {
    let a = "output_cams";
    s.unique(a, i, &c.name)?;
    let axis = s.axis_of(a, i, "axis", &c.axis)?;
    let f = s.field(a, i);
    let cam_type = match pick("type", &c.kind, &KINDS).map_err(&f)? {
        0 => OutputCamType::Distance,
        _ => OutputCamType::Time,
    };
    let mut config = OutputCamConfig::new(cam_type);
    config.position_type = position_type(&c.position).map_err(&f)?;
    config.parameters =
        parameters(c.on_compensation, c.off_compensation, c.hysteresis).map_err(&f)?;
    config.working_range = range(c.working_range).map_err(&f)?;
    config.arming_cycles = c.arming_cycles;
    Ok(OutputCamEntry {
        name: c.name.clone(),
        axis,
        config,
        output: None,
    })
}

/// Entry `i` of `[[cam_tracks]]`, with its cams, checked by the engine.
fn cam_track(
    s: &mut Scope<'_>,
    i: usize,
    c: &CamTrackSection,
) -> Result<CamTrackEntry, ConfigError> {
    let a = "cam_tracks";
    s.unique(a, i, &c.name)?;
    let axis = s.axis_of(a, i, "axis", &c.axis)?;
    let f = s.field(a, i);
    let track_type = match pick("type", &c.kind, &KINDS).map_err(&f)? {
        0 => CamTrackType::Distance,
        _ => CamTrackType::Time,
    };
    let mut config = CamTrackConfig::new(track_type);
    config.position_type = position_type(&c.position).map_err(&f)?;
    config.working_range = range(c.working_range).map_err(&f)?;
    config.interface = pick(
        "interface",
        &c.interface,
        &[
            ("software", TrackOutputInterface::Software),
            ("timer_dq", TrackOutputInterface::TimerDq),
            ("dq_module", TrackOutputInterface::DqModule),
        ],
    )
    .map_err(&f)?;
    if !(c.track_length.is_finite() && (0.001..=1e12).contains(&c.track_length)) {
        return Err(f(("track_length", Problem::Invalid("must be 0.001..1e12"))));
    }
    if !(c.reference_position.is_finite() && c.reference_position.abs() <= 1e12) {
        return Err(f((
            "reference_position",
            Problem::Invalid("must be within ±1e12"),
        )));
    }
    if c.cams.len() > MAX_CAMS {
        return Err(f(("cams", Problem::TooManyCams(MAX_CAMS))));
    }
    let mut data = CamTrackData::new(c.reference_position, c.track_length);
    data.masking = c.masking;
    data.parameters =
        parameters(c.on_compensation, c.off_compensation, c.hysteresis).map_err(&f)?;
    for (j, cam) in c.cams.iter().enumerate() {
        let tc = track_cam(track_type, cam).map_err(|problem| {
            f((
                "cams",
                Problem::TrackCam {
                    cam: j + 1,
                    problem,
                },
            ))
        })?;
        data = data.with_cam(j, tc);
    }
    if let Err(reason) = CamTrack::new(config, data) {
        let object = "cam track";
        return Err(f(("", Problem::Rejected { object, reason })));
    }
    Ok(CamTrackEntry {
        name: c.name.clone(),
        axis,
        config,
        data,
        output: None,
    })
}

/// One cam of a cam track: `on`/`off` on a distance track, `on`/`duration` on a time track.
fn track_cam(track_type: CamTrackType, cam: &TrackCamSection) -> Result<TrackCam, &'static str> {
    if !(cam.on.is_finite() && (0.0..=1e12).contains(&cam.on)) {
        return Err("`on` must be 0..1e12 (relative to the track start)");
    }
    match track_type {
        CamTrackType::Distance => {
            let off = cam.off.ok_or("`off` is required on a distance track")?;
            if cam.duration.is_some() {
                return Err("`duration` is for time tracks");
            }
            if !(off.is_finite() && off >= cam.on && off <= 1e12) {
                return Err("`off` must be >= `on`");
            }
            Ok(TrackCam::distance(cam.on, off))
        }
        CamTrackType::Time => {
            let d = cam
                .duration
                .ok_or("`duration` (s) is required on a time track")?;
            if cam.off.is_some() {
                return Err("`off` is for distance tracks");
            }
            if !(1e-6..=1e9).contains(&d) {
                return Err("`duration` must be 1e-6..1e9 s");
            }
            Ok(TrackCam::time(cam.on, d))
        }
    }
}

/// Entry `i` of `[[measuring_inputs]]`, with its sensor and register correction, checked by
/// the engine.
fn measuring_input(
    s: &mut Scope<'_>,
    nodes: &[Node],
    i: usize,
    m: &MeasuringInputSection,
) -> Result<MeasuringInputEntry, ConfigError> {
    let a = "measuring_inputs";
    s.unique(a, i, &m.name)?;
    let axis = s.axis_of(a, i, "axis", &m.axis)?;
    let f = s.field(a, i);
    let mut config = MeasuringInputConfig::timer_di(nodes[s.axes[axis].node].cycle_ns);
    config.route = pick(
        "route",
        &m.route,
        &[
            ("timer_di", MeasuringRoute::TimerDi),
            ("central_probe", MeasuringRoute::CentralProbe),
            ("profidrive", MeasuringRoute::Profidrive),
        ],
    )
    .map_err(&f)?;
    if !(m.correction_time.is_finite() && m.correction_time.abs() <= 1.0) {
        return Err(f((
            "correction_time",
            Problem::Invalid("must be within ±1 s"),
        )));
    }
    if !(m.additional_activation_time.is_finite()
        && (0.0..=1.0).contains(&m.additional_activation_time))
    {
        return Err(f((
            "additional_activation_time",
            Problem::Invalid("must be 0..1 s"),
        )));
    }
    config.correction_time = m.correction_time;
    config.additional_activation_time = m.additional_activation_time;
    config.apply_activation_time = m.apply_activation_time;
    let sensor = match &m.sensor {
        None => None,
        Some(x) => Some(sensor(s, i, axis, &m.axis, x)?),
    };
    // Through a drive's touch probe the sensor is a mark in front of that drive's probe input.
    let on_drive = matches!(s.axes[axis].drive, crate::cell::DriveConnection::Cia402(_));
    if on_drive
        && config.route == MeasuringRoute::Profidrive
        && sensor.is_some_and(|x| x.axis != axis)
    {
        return Err(f((
            "sensor.axis",
            Problem::Invalid(
                "a sensor in front of a drive's touch probe is on the input's own axis",
            ),
        )));
    }
    let registration = match &m.registration {
        None => None,
        Some(r) => Some(registration(s, i, r)?),
    };
    if let Err(reason) = MeasuringInput::new(config) {
        let object = "measuring input";
        return Err(f(("", Problem::Rejected { object, reason })));
    }
    Ok(MeasuringInputEntry {
        name: m.name.clone(),
        axis,
        config,
        sensor,
        registration,
    })
}

/// `[measuring_inputs.sensor]` of entry `i` (on `axis`, named `axis_name`): a simulated mark
/// sensor on an axis of the same node.
fn sensor(
    s: &Scope<'_>,
    i: usize,
    axis: AxisIndex,
    axis_name: &str,
    x: &SensorSection,
) -> Result<SensorEntry, ConfigError> {
    let a = "measuring_inputs";
    let f = s.field(a, i);
    let mark = mark(x, axis).map_err(&f)?;
    let carrier = match &x.axis {
        None => axis,
        Some(n) => {
            let j = s.axis_of(a, i, "sensor.axis", n)?;
            if s.axes[j].node != s.axes[axis].node {
                let problem = Problem::SensorNode {
                    sensor_axis: n.clone(),
                    axis: axis_name.into(),
                };
                return Err(f(("sensor.axis", problem)));
            }
            j
        }
    };
    Ok(SensorEntry {
        axis: carrier,
        ..mark
    })
}

/// The mark of a simulated sensor on `carrier`, its numbers checked; an error names the key
/// under the table that holds `sensor`.
pub(super) fn mark(
    x: &SensorSection,
    carrier: AxisIndex,
) -> Result<SensorEntry, super::FieldError> {
    if !(x.position.is_finite() && x.position.abs() <= 1e12) {
        return Err(("sensor.position", Problem::Invalid("must be within ±1e12")));
    }
    if !(x.width.is_finite() && x.width > 0.0) {
        return Err((
            "sensor.width",
            Problem::Invalid("must be a positive number"),
        ));
    }
    if !(x.dead_time.is_finite() && (0.0..=1.0).contains(&x.dead_time)) {
        return Err(("sensor.dead_time", Problem::Invalid("must be 0..1 s")));
    }
    if !(x.jitter.is_finite() && (0.0..=1.0).contains(&x.jitter)) {
        return Err(("sensor.jitter", Problem::Invalid("must be 0..1 s")));
    }
    let direction = pick(
        "sensor.direction",
        &x.direction,
        &[
            ("positive", SensorDirection::Positive),
            ("negative", SensorDirection::Negative),
            ("both", SensorDirection::Both),
        ],
    )?;
    Ok(SensorEntry {
        axis: carrier,
        position: x.position,
        width: x.width,
        dead_time: x.dead_time,
        jitter_ns: (x.jitter * 1e9).round() as i64,
        seed: x.seed,
        direction,
    })
}

/// `[measuring_inputs.registration]` of entry `i`: the corrected axis, target and gain.
fn registration(
    s: &Scope<'_>,
    i: usize,
    r: &RegistrationSection,
) -> Result<Registration, ConfigError> {
    let a = "measuring_inputs";
    let f = s.field(a, i);
    let axis = s.axis_of(a, i, "registration.axis", &r.axis)?;
    if !(r.target.is_finite() && r.target.abs() <= 1e12) {
        return Err(f((
            "registration.target",
            Problem::Invalid("must be within ±1e12"),
        )));
    }
    if !(r.gain > 0.0 && r.gain <= 1.0) {
        return Err(f((
            "registration.gain",
            Problem::Invalid("must be in (0, 1]"),
        )));
    }
    Ok(Registration {
        axis,
        target: r.target,
        gain: r.gain,
    })
}

/// Switch `s` of a digital cam switch as the engine takes it; a code the engine does not know
/// or a missing key is refused as the field it belongs to.
fn cam_switch(j: usize, s: &DcsSwitchSection) -> Result<CamSwitch, DcsError> {
    let refuse = |field, code| DcsError {
        index: j,
        field,
        code,
    };
    let code = |x: i64| i32::try_from(x).unwrap_or(i32::MAX);
    let axis_direction = SwitchDirection::from_code(code(s.axis_direction))
        .map_err(|c| refuse(DcsField::AxisDirection, c))?;
    let cam_switch_mode = CamSwitchMode::from_code(code(s.cam_switch_mode))
        .map_err(|c| refuse(DcsField::CamSwitchMode, c))?;
    let (last_on_position, duration) = match cam_switch_mode {
        CamSwitchMode::Position => (
            s.last_on_position.ok_or(refuse(
                DcsField::LastOnPosition,
                HydErrorCode::ILLEGAL_VALUE,
            ))?,
            s.duration.unwrap_or(0.0),
        ),
        CamSwitchMode::Time => (
            s.last_on_position.unwrap_or(s.first_on_position),
            s.duration
                .ok_or(refuse(DcsField::Duration, HydErrorCode::ILLEGAL_VALUE))?,
        ),
    };
    Ok(CamSwitch {
        track_number: code(s.track_number),
        first_on_position: s.first_on_position,
        last_on_position,
        axis_direction,
        cam_switch_mode,
        duration,
    })
}

/// Entry `i` of `[[digital_cam_switches]]`, its switches and tracks checked by the engine; a
/// refusal names `tracks[j].<key>` or `switches[j].<key>`.
fn digital_cam_switch(
    s: &mut Scope<'_>,
    i: usize,
    c: &DigitalCamSwitchSection,
) -> Result<DigitalCamSwitchEntry, ConfigError> {
    let a = "digital_cam_switches";
    s.unique(a, i, &c.name)?;
    let axis = s.axis_of(a, i, "axis", &c.axis)?;
    let tracks: Vec<TrackOptions> = c
        .tracks
        .iter()
        .map(|t| TrackOptions {
            on_compensation: t.on_compensation,
            off_compensation: t.off_compensation,
            hysteresis: t.hysteresis,
        })
        .collect();
    let refused = |e: DcsError| {
        let (list, key) = match e.field {
            DcsField::SwitchCount => ("switches", None),
            DcsField::TrackCount => ("tracks", None),
            DcsField::TrackNumber => ("switches", Some("track_number")),
            DcsField::FirstOnPosition => ("switches", Some("first_on_position")),
            DcsField::LastOnPosition => ("switches", Some("last_on_position")),
            DcsField::AxisDirection => ("switches", Some("axis_direction")),
            DcsField::CamSwitchMode => ("switches", Some("cam_switch_mode")),
            DcsField::Duration => ("switches", Some("duration")),
            DcsField::OnCompensation => ("tracks", Some("on_compensation")),
            DcsField::OffCompensation => ("tracks", Some("off_compensation")),
            DcsField::Hysteresis => ("tracks", Some("hysteresis")),
        };
        let mut err = s.cx.in_array(a, i, list, Problem::CamSwitch(e));
        if let Some(key) = key {
            err.key = format!("{a}[{i}].{list}[{}].{key}", e.index);
        }
        err
    };
    let switches = c
        .switches
        .iter()
        .enumerate()
        .map(|(j, x)| cam_switch(j, x))
        .collect::<Result<Vec<_>, _>>()
        .map_err(refused)?;
    DigitalCamSwitch::new(&switches, &tracks).map_err(refused)?;
    Ok(DigitalCamSwitchEntry {
        name: c.name.clone(),
        axis,
        switches,
        outputs: vec![None; tracks.len()],
        tracks,
    })
}
