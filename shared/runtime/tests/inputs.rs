//! Input signals of the process image (`config/inputs.toml`), end to end in the executive:
//! an edge of a timestamped input at a given ns gives the measuring input it feeds exactly that
//! time and the axis's position at it, as the measuring input's own edges do; a sensor on the
//! load gives the mark's position; a limit switch input stops the axis with alarm 531 in the
//! cycle of the boundary that samples it; a plain input sees levels at the boundaries only.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{AxisIndex, Cell};
use tandem_motion::catalog::alarm::{supplement, AlarmId};
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{AxisState, Command, StartMode, StopMode};
use tandem_runtime::exec::{Executive, InputSignalEdge, IoNote};
use tandem_testkit::workspace::root;

const MS: i64 = 1_000_000;

fn cell(edit: impl Fn(String) -> String) -> Cell {
    let src = std::fs::read_to_string(root().join("config/inputs.toml")).unwrap();
    tandem_config::parse("inputs.toml", &edit(src)).unwrap()
}

/// The executive of the cell, stepped cycle by cycle, with what it reported.
struct Run<'c> {
    exec: Executive<'c>,
    k: i64,
    log: Vec<u8>,
    notes: Vec<IoNote>,
    edges: Vec<InputSignalEdge>,
    /// Per step: the web's actual position.
    actual: Vec<f64>,
}

impl<'c> Run<'c> {
    fn new(cell: &'c Cell) -> Self {
        Self {
            exec: Executive::new(cell, None).unwrap(),
            k: 0,
            log: Vec::new(),
            notes: Vec::new(),
            edges: Vec::new(),
            actual: Vec::new(),
        }
    }

    /// Applies `action` to `target` with its own time `at` (between the last step and the
    /// next).
    fn apply_at(&mut self, at: i64, target: &str, action: Action) {
        let t = self.k * MS;
        let r = self
            .exec
            .apply_at(t, at, target, "test", action, &mut self.log)
            .unwrap();
        assert!(r.is_ok(), "{target}: {r:?}\n{}", self.log());
    }

    fn apply(&mut self, target: &str, action: Action) {
        self.apply_at(self.k * MS, target, action);
    }

    fn step(&mut self) {
        let t = self.k * MS;
        self.exec.step(t, &mut self.log).unwrap();
        let (notes, edges) = (&mut self.notes, &mut self.edges);
        self.exec.drain_io_notes(|n| notes.push(*n));
        self.exec.drain_input_edges(|e| edges.push(*e));
        self.exec.drain_job_notes(|_| {});
        let p = self.exec.status()[0].actual_position;
        self.actual.push(p);
        self.k += 1;
    }

    fn steps(&mut self, n: usize) {
        for _ in 0..n {
            self.step();
        }
    }

    fn log(&self) -> String {
        String::from_utf8_lossy(&self.log).into_owned()
    }

    fn alarm(&self, id: AlarmId) -> Option<u16> {
        let axis = self.exec.axis(AxisIndex(0)).unwrap();
        axis.alarms().find(|a| a.id == id).map(|a| a.supplement)
    }

    /// Powers the web and starts it at `v` (mm/s).
    fn running(&mut self, v: f64) {
        self.apply(
            "web",
            Action::Command(Command::Power {
                enable: true,
                start_mode: StartMode::PositionControlled,
                stop_mode: StopMode::Emergency,
            }),
        );
        self.apply(
            "web",
            Action::Command(Command::MoveVelocity {
                dynamics: tandem_motion::kinematics::dynamics::Dynamics {
                    velocity: v,
                    acceleration: 2000.0,
                    deceleration: 2000.0,
                    jerk: 20000.0,
                },
                direction: tandem_motion::objects::axis::VelocityDirection::Positive,
                current: false,
                position_controlled: true,
            }),
        );
    }

    /// The measured values of measuring input `m` (index in the cell): (time, value).
    fn measured(&self, m: usize) -> Vec<(i64, f64)> {
        self.notes
            .iter()
            .filter(|n| n.measured && n.object == m)
            .map(|n| (n.t_ns, n.value))
            .collect()
    }
}

/// The cell with a third measuring input on the web fed by the script's `InputEdge` (the
/// measuring input's own edges, as before input signals).
fn with_reference_input(s: String) -> String {
    s + r#"
[[measuring_inputs]]
name = "reference_reader"
axis = "web"
"#
}

#[test]
fn a_timestamped_input_edge_gives_the_measuring_input_its_time_and_the_position_at_it() {
    let cell = cell(with_reference_input);
    let (probe, reference) = (
        cell.measuring_input("probe_reader").unwrap(),
        cell.measuring_input("reference_reader").unwrap(),
    );
    let mut r = Run::new(&cell);
    r.running(200.0);
    for m in ["probe_reader", "reference_reader"] {
        r.apply(
            m,
            Action::MeasuringInput {
                cyclic: true,
                mode: 0,
                window: None,
            },
        );
    }
    // At 200 mm/s from 0.5 s on (the default dynamics reach it well before).
    r.steps(500);
    // 40 edges at odd ns between the cycles, each a 0.2 ms pulse, 37 ms apart.
    let mut times = Vec::new();
    for i in 0..40i64 {
        let at = (r.k - 1) * MS + 1 + i * 7_919 % (MS - 2);
        times.push(at);
        r.apply_at(
            at,
            "probe",
            Action::SetInput {
                value: true,
                pulse_ns: 200_000,
            },
        );
        r.apply_at(at, "reference_reader", Action::InputEdge { rising: true });
        r.steps(37);
    }
    let (got, want) = (r.measured(probe), r.measured(reference));
    assert_eq!(got.len(), 40, "{}", r.log());
    // Exactly the existing measuring input's answer, at exactly the edge's time.
    assert_eq!(got, want);
    assert_eq!(got.iter().map(|x| x.0).collect::<Vec<_>>(), times);
    // The web's actual position at the edge time: at constant velocity, between the cycles
    // that bound it.
    for (t, value) in got {
        let k = (t / MS) as usize;
        let (p0, p1) = (r.actual[k], r.actual[k + 1]);
        let at = p0 + (p1 - p0) * ((t - k as i64 * MS) as f64 / MS as f64);
        assert!((value - at).abs() < 1e-9, "at {t}: {value} vs {at}");
    }
    // Both edges of each pulse, at their times, on the timestamped input.
    let probe_signal = cell.signal("probe").unwrap().0;
    let e: Vec<_> = r
        .edges
        .iter()
        .filter(|e| e.signal == probe_signal)
        .collect();
    assert_eq!(e.len(), 80);
    for (pair, at) in e.chunks(2).zip(&times) {
        assert_eq!((pair[0].rising, pair[0].time_ns), (true, *at));
        assert_eq!((pair[1].rising, pair[1].time_ns), (false, at + 200_000));
        // Sampled at the first boundary at or after the edge.
        for x in pair {
            assert_eq!(x.sampled_ns, (x.time_ns + MS - 1) / MS * MS);
        }
    }
}

#[test]
fn a_sensor_on_the_load_gives_the_measuring_input_the_marks_position() {
    // The mark from 150 to 155 mm, both edges measured (mode 2: both edges, in S7 terms).
    let cell = cell(|s| s);
    let m = cell.measuring_input("mark_reader").unwrap();
    let mut r = Run::new(&cell);
    r.running(200.0);
    r.apply(
        "mark_reader",
        Action::MeasuringInput {
            cyclic: true,
            mode: 0,
            window: None,
        },
    );
    r.steps(1500);
    let got = r.measured(m);
    assert_eq!(got.len(), 1, "{}", r.log());
    // The sensor's edge time is the crossing rounded to the ns: at 200 mm/s the position
    // there is within 200 mm/s · 0.5 ns of the mark.
    assert!(
        (got[0].1 - 150.0).abs() <= 200.0 * 0.5e-9 + 1e-12,
        "{got:?}"
    );
    let mark = cell.signal("print_mark").unwrap().0;
    let e: Vec<_> = r.edges.iter().filter(|e| e.signal == mark).collect();
    assert_eq!(e.len(), 2);
    assert_eq!(e[0].time_ns, got[0].0);
    // The off edge 5 mm later: 25 ms at 200 mm/s.
    assert!((e[1].time_ns - e[0].time_ns - 25 * MS).abs() <= 1, "{e:?}");
}

#[test]
fn a_limit_switch_input_stops_the_axis_with_alarm_531() {
    // The switch driven by the script, not by its sensor.
    let cell = cell(|s| {
        s.replace(
            "[signals.end_of_travel.sensor]\naxis = \"web\"\nposition = 900.0",
            "[signals.unused.sensor]\naxis = \"web\"\nposition = 900.0",
        )
        .replace(
            "[signals.end_of_travel]",
            "[signals.unused]\ndevice = \"switch_io\"\nchannel = 2\n\n[signals.end_of_travel]",
        )
    });
    let mut r = Run::new(&cell);
    r.running(200.0);
    r.steps(300);
    assert_eq!(r.exec.status()[0].state, AxisState::ContinuousMotion);
    // On between the cycles: the boundary after it samples it, the axis stops in that step.
    let on = r.k * MS - 400_000;
    r.apply_at(
        on,
        "end_of_travel",
        Action::SetInput {
            value: true,
            pulse_ns: 0,
        },
    );
    assert_eq!(r.alarm(AlarmId::HwLimit), None);
    let boundary = r.k * MS;
    r.step();
    assert_eq!(
        r.alarm(AlarmId::HwLimit),
        Some(supplement::HW_LIMIT_POSITIVE),
        "{}",
        r.log()
    );
    assert!(r.log().contains(&format!(
        "t={}.{:09} web alarm 531 HwLimit",
        boundary / 1_000_000_000,
        boundary % 1_000_000_000
    )));
    let switch = cell.signal("end_of_travel").unwrap();
    assert_eq!(r.exec.signal_level(switch), Some(true));
    // Remove enable: the axis is in ErrorStop and its drive brakes to a standstill.
    assert_eq!(r.exec.status()[0].state, AxisState::ErrorStop);
    assert!(!r.exec.axis(AxisIndex(0)).unwrap().drive_outputs().enable);
    for _ in 0..2000 {
        if r.exec.status()[0].actual_velocity == 0.0 {
            return;
        }
        r.step();
    }
    panic!("no standstill\n{}", r.log());
}

#[test]
fn a_plain_input_sees_the_level_at_each_boundary_only() {
    let cell = cell(|s| s);
    let device = cell
        .devices
        .iter()
        .position(|d| d.name == "switch_io")
        .unwrap();
    let mut r = Run::new(&cell);
    r.steps(10);
    let t = r.k * MS;
    // A pulse within the cycle: not seen.
    r.apply_at(
        t - 700_000,
        "end_of_travel",
        Action::SetInput {
            value: true,
            pulse_ns: 300_000,
        },
    );
    r.step();
    // A level set between the cycles: one edge, timed at the boundary that sees it.
    r.apply_at(
        t + 400_000,
        "end_of_travel",
        Action::SetInput {
            value: true,
            pulse_ns: 0,
        },
    );
    r.step();
    assert_eq!(r.edges.len(), 1, "{:?}", r.edges);
    let e = r.edges[0];
    assert_eq!((e.rising, e.time_ns, e.sampled_ns), (true, t + MS, t + MS));
    let st = *r.exec.input_device(device).unwrap();
    assert_eq!((st.levels, st.edges, st.unseen), (1, 1, 2));
    // An output signal or an unknown one is not an input.
    let r2 = r.exec.apply_at(
        r.k * MS,
        r.k * MS,
        "web",
        "SetInput",
        Action::SetInput {
            value: true,
            pulse_ns: 0,
        },
        &mut Vec::new(),
    );
    assert!(r2.unwrap().is_err());
}
