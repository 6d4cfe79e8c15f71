//! tandem-config: the cell file (TOML) to a validated, typed configuration.
//!
//! Every error is a [`ConfigError`]: the file, the line and the key, and the [`Problem`] (what
//! is wrong, with its data). The same crate parses instruction names and parameters
//! ([`command`]) and simulator scripts ([`script`]) for the simulator and the CLI.
//!
//! Axes, encoders and leaders are referred to by typed indices: [`AxisIndex`],
//! [`EncoderIndex`] and [`Leader`] (an axis or an encoder); [`Cell::leader_id`] gives a
//! leader's id in commands and on the wire (axes first, then encoders).
//!
//! ```
//! let src = r#"
//! [cell]
//! name = "demo"
//!
//! [[nodes]]
//! name = "n"
//! cycle_us = 1000
//!
//! [axes.x]
//! node = "n"
//!
//! [axes.x.dynamics]
//! max_velocity = 100.0
//! max_acceleration = 1000.0
//! max_deceleration = 1000.0
//! max_jerk = 10000.0
//! velocity = 50.0
//! acceleration = 500.0
//! deceleration = 500.0
//! jerk = 5000.0
//! emergency_deceleration = 2000.0
//! "#;
//! let cell = tandem_config::parse("demo.toml", src).unwrap();
//! assert_eq!(cell.axes[0].name, "x");
//! assert_eq!(cell.nodes[0].cycle_ns, 1_000_000);
//!
//! let bad = src.replace("node = \"n\"", "node = \"m\"");
//! let e = tandem_config::parse("demo.toml", &bad).unwrap_err();
//! assert_eq!(e.key, "axes.x.node");
//! assert_eq!(*e.problem, tandem_config::Problem::UnknownNode("m".into()));
//! assert_eq!(
//!     e.to_string(),
//!     "demo.toml:10: axes.x.node: unknown node `m` (define it in [[nodes]])"
//! );
//! ```

mod cell;
pub mod command;
mod error;
mod parse;
pub mod read;
mod schema;
pub mod script;
pub mod security;

pub use cell::{
    AnalogChannelParams, AnalogDriveConnection, AxisEntry, AxisIndex, AxisInputs, CamEntry,
    CamTrackEntry, Cell, Cia402Connection, CounterParams, Coupling, DeviceEntry, DeviceIndex,
    DeviceKind, DigitalCamSwitchEntry, DigitalInputParams, DigitalOutputParams, DriveConnection,
    EncoderEntry, EncoderIndex, EncoderSource, EthercatDriveParams, EthercatIdentity, EthercatRole,
    EthercatSegment, EthercatSubDevice, InputBindings, Leader, LeadingValueConfig,
    MeasuringInputEntry, Node, OutputCamEntry, Realtime, Registration, SensorEntry,
    SignalDirection, SignalEntry, SignalIndex, SignalType, ETHERCAT_AIO_CHANNELS,
    ETHERCAT_ENC_COUNTER, LEADING_BUFFER, MAX_CHANNELS,
};
pub use error::{ConfigError, DelayShortfall, Problem, SegmentProblem};
pub use parse::{load, locate, locate_in_array, parse};
pub use security::{Role, Security, SecurityMode};

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[cell]
name = "t"

[[nodes]]
name = "n"
cycle_us = 1000

[axes.x]
node = "n"

[axes.x.dynamics]
max_velocity = 100.0
max_acceleration = 1000.0
max_deceleration = 1000.0
max_jerk = 10000.0
velocity = 50.0
acceleration = 500.0
deceleration = 500.0
jerk = 5000.0
emergency_deceleration = 2000.0
"#;

    #[test]
    fn parses_a_minimal_cell() {
        let c = parse("cell.toml", GOOD).unwrap();
        assert_eq!(c.axes.len(), 1);
        assert_eq!(c.nodes[0].cycle_ns, 1_000_000);
        assert_eq!(c.axes[0].config.cycle, 0.001);
    }

    #[test]
    fn leaders_are_axes_then_encoders() {
        let src = format!(
            "{GOOD}\n[encoders.e]\nnode = \"n\"\nsource = \"profile\"\nprofile = [[0.0, 1.0]]\n"
        );
        let c = parse("cell.toml", &src).unwrap();
        let e = Leader::Encoder(EncoderIndex(0));
        assert_eq!(c.leader_id(Leader::Axis(AxisIndex(0))), 0);
        assert_eq!(c.leader_id(e), 1);
        assert_eq!(c.leader(1), Some(e));
        assert_eq!(c.leader(2), None);
        assert_eq!(c.leader_named("e"), Some(e));
        assert_eq!(c.leader_name(e), "e");
        assert_eq!(c.leader_node(e), Some(0));
        assert_eq!(c.coupling(AxisIndex(0), e), Some(Coupling::Setpoint));
        assert_eq!(c.axes[AxisIndex(0)].name, "x");
    }

    #[test]
    fn the_command_rate_has_defaults_and_is_checked() {
        let c = parse("cell.toml", GOOD).unwrap();
        assert_eq!((c.command_rate_hz, c.command_burst), (20.0, 40));
        let with = |k: &str| GOOD.replacen("[cell]\n", &format!("[cell]\n{k}\n"), 1);
        let c = parse("cell.toml", &with("command_rate_hz = 5.0")).unwrap();
        assert_eq!(c.command_rate_hz, 5.0);
        for (bad, key) in [
            ("command_rate_hz = 0.0", "cell.command_rate_hz"),
            ("command_rate_hz = 1e9", "cell.command_rate_hz"),
            ("command_burst = 0", "cell.command_burst"),
        ] {
            let e = parse("cell.toml", &with(bad)).unwrap_err();
            assert_eq!(e.key, key, "{bad}");
        }
    }

    #[test]
    fn errors_name_file_line_and_key() {
        let bad = GOOD.replace("max_velocity = 100.0", "max_velocity = 0.0");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!(e.key, "axes.x.dynamics.max_velocity");
        assert_eq!(e.line, Some(13));
        assert!(e
            .to_string()
            .starts_with("cell.toml:13: axes.x.dynamics.max_velocity: must be"));
        let bad = GOOD.replace("node = \"n\"", "node = \"m\"");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!((e.key.as_str(), e.line), ("axes.x.node", Some(10)));
        assert!(e.problem.to_string().contains("unknown node `m`"));
        let bad = GOOD.replace("cycle_us = 1000", "cycle_us = 1100");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert!(
            e.problem
                .to_string()
                .contains("not a positive multiple of the base tick"),
            "{e}"
        );
        let bad = GOOD.replace("max_jerk = 10000.0", "max_jerk = 10000.0\nmax_jrk = 1.0");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!(e.line, Some(17));
        assert!(
            e.problem.to_string().contains("unknown field `max_jrk`"),
            "{e}"
        );
        let bad = GOOD.replace("node = \"n\"", "node = \"n\"\nkind = \"servo\"");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!(e.key, "axes.x.kind");
        assert!(e
            .problem
            .to_string()
            .contains("`servo` is not one of speed, positioning"));
    }

    #[test]
    fn output_cams_cam_tracks_and_measuring_inputs_are_validated_by_key() {
        let objects = format!(
            "{GOOD}\n[[output_cams]]\nname = \"cam\"\naxis = \"x\"\ntype = \"time\"\n\n[[cam_tracks]]\nname = \"track\"\naxis = \"x\"\ntrack_length = 100.0\ncams = [{{ on = 10.0, off = 20.0 }}]\n\n[[measuring_inputs]]\nname = \"mark\"\naxis = \"x\"\ncorrection_time = 0.001\n\n[measuring_inputs.sensor]\nposition = 5.0\nwidth = 1.0\njitter = 0.000002\n"
        );
        let c = parse("cell.toml", &objects).unwrap();
        assert_eq!(c.output_cams.len(), 1);
        assert_eq!(
            c.output_cams[0].config.cam_type,
            tandem_motion::objects::output_cam::OutputCamType::Time
        );
        assert_eq!(c.cam_tracks[0].data.cams[0].off_position, 20.0);
        assert!(!c.cam_tracks[0].data.cams[1].existent);
        assert_eq!(c.measuring_inputs[0].config.correction_time, 0.001);
        assert_eq!(c.measuring_inputs[0].config.servo_cycle_ns, 1_000_000);
        assert_eq!(c.measuring_inputs[0].sensor.unwrap().jitter_ns, 2000);
        let line_of =
            |src: &str, pat: &str| src.lines().position(|l| l.starts_with(pat)).unwrap() + 1;
        // A misspelt key names itself.
        let bad = objects.replace("type = \"time\"", "tipe = \"time\"");
        let e = parse("cell.toml", &bad).unwrap_err();
        assert!(
            e.problem.to_string().contains("unknown field `tipe`"),
            "{e}"
        );
        assert_eq!(e.line, Some(line_of(&bad, "tipe")));
        // Bad values name the array entry and the key, with its line.
        for (from, to, key, msg) in [
            (
                "type = \"time\"",
                "type = \"switch\"",
                "output_cams[0].type",
                "`switch` is not one of distance, time",
            ),
            (
                "axis = \"x\"\ntype",
                "axis = \"y\"\ntype",
                "output_cams[0].axis",
                "unknown axis `y`",
            ),
            (
                "track_length = 100.0",
                "track_length = 0.0",
                "cam_tracks[0].track_length",
                "must be 0.001..1e12",
            ),
            (
                "off = 20.0",
                "off = 5.0",
                "cam_tracks[0].cams",
                "cam 1: `off` must be >= `on`",
            ),
            (
                "width = 1.0",
                "width = 0.0",
                "measuring_inputs[0].sensor.width",
                "must be a positive number",
            ),
            (
                "name = \"mark\"",
                "name = \"x\"",
                "measuring_inputs[0].name",
                "names must be unique",
            ),
        ] {
            let bad = objects.replacen(from, to, 1);
            let e = parse("cell.toml", &bad).unwrap_err();
            assert_eq!(e.key, key, "{e}");
            assert!(e.problem.to_string().contains(msg), "{e}");
            assert!(e.to_string().contains(&format!("{key}: ")), "{e}");
            assert!(e.line.is_some(), "{e}");
        }
        let bad = objects.replacen("track_length = 100.0", "track_length = 0.0", 1);
        let e = parse("cell.toml", &bad).unwrap_err();
        assert_eq!(e.line, Some(line_of(&bad, "track_length")));
        // Register correction.
        let reg = format!(
            "{objects}\n[measuring_inputs.registration]\naxis = \"x\"\ntarget = 5.0\ngain = 0.5\n"
        );
        let c = parse("cell.toml", &reg).unwrap();
        let r = c.measuring_inputs[0].registration.unwrap();
        assert_eq!((r.axis, r.target, r.gain), (AxisIndex(0), 5.0, 0.5));
        let e = parse("cell.toml", &reg.replace("gain = 0.5", "gain = 2.0")).unwrap_err();
        assert_eq!(e.key, "measuring_inputs[0].registration.gain", "{e}");
        let e = parse(
            "cell.toml",
            &reg.replace("axis = \"x\"\ntarget", "axis = \"w\"\ntarget"),
        )
        .unwrap_err();
        assert_eq!(e.key, "measuring_inputs[0].registration.axis", "{e}");
        assert!(e.problem.to_string().contains("unknown axis `w`"), "{e}");
    }
}
