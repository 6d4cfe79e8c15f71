//! A hydraulic axis end to end in the executive (`config/hydraulic.toml`): a `kind = "hydraulic"`
//! axis on a simulated valve and cylinder through the process image. Its positionings run the
//! hydraulic library's displacement-based generator, the valve output comes from its position
//! controller and Finish stage; a move lands in the target window in both directions of the
//! differential cylinder; a 20 % overlap valve creeps short of its target without overlap
//! compensation and lands with it; MC_Halt stops on the generator's ramp with its deceleration;
//! a velocity motion after a positioning closes the position loop without a step; bad
//! parameters are refused naming the key.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod hyd_rig;
use hyd_rig::{Run, MS};

use tandem_config::{AxisIndex, Cell};
use tandem_motion::hydraulic::generator::HydState;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{
    AxisState, Command, Direction, StartMode, StopMode, VelocityDirection,
};
use tandem_runtime::exec::Executive;
use tandem_testkit::workspace::root;

fn source() -> String {
    std::fs::read_to_string(root().join("config/hydraulic.toml")).unwrap()
}

/// The bundled cell with `from` replaced by `to` (which must occur).
fn cell(edits: &[(&str, &str)]) -> Cell {
    let mut s = source();
    for (from, to) in edits {
        assert!(s.contains(from), "{from}");
        s = s.replacen(from, to, 1);
    }
    tandem_config::parse("hydraulic.toml", &s).unwrap()
}

impl Run<'_> {
    /// Steps until the positioning job is Done (or `max` cycles): the states the generator
    /// passed (deduplicated) and the largest change of the set velocity per cycle before idle.
    fn run_move(&mut self, max: usize) -> (Vec<HydState>, f64) {
        let (mut states, mut worst, mut last_v) = (Vec::new(), 0.0_f64, None::<f64>);
        for _ in 0..max {
            self.step();
            let h = self.hyd();
            if states.last() != Some(&h.state) {
                states.push(h.state);
            }
            let v = self.exec.status()[0].velocity;
            if h.state != HydState::Idle {
                if let Some(l) = last_v {
                    worst = worst.max((v - l).abs() / 1e-3);
                }
            }
            last_v = Some(v);
            if self.exec.status()[0].motion_job.is_none() {
                return (states, worst);
            }
        }
        panic!("the move did not end within {max} cycles\n{}", self.log());
    }
}

#[test]
fn a_positioning_runs_the_displacement_profile_and_lands_in_the_target_window_both_ways() {
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    for (target, velocity) in [(350.0, 120.0), (120.0, 150.0)] {
        r.move_to(target, velocity);
        let (states, worst) = r.run_move(8000);
        assert_eq!(
            states,
            [
                HydState::TcAcc,
                HydState::ConstVelo,
                HydState::PcDec,
                HydState::CreepVelo,
                HydState::Idle
            ],
            "to {target}"
        );
        // Done: idle, InTargRng and InTarget (0.2 mm for 0.2 s).
        let h = r.hyd();
        assert!(h.in_target && h.in_target_range && h.engaged, "{h:?}");
        assert_eq!(h.target, target);
        let s = r.exec.status()[0];
        assert!(
            (s.actual_position - target).abs() < 0.2,
            "at {} for {target}",
            s.actual_position
        );
        // The set position is the target at standstill (the controller's setpoint).
        assert_eq!(s.position, target);
        // The time ramps within fAcc / fDec (400 mm/s²); the square-root ramp follows the
        // actual position and may exceed it where the cylinder runs ahead (docs/hydraulics.md).
        assert!(worst <= 2.0 * 400.0, "{worst} mm/s² to {target}");
        // It stands and stays there.
        for _ in 0..500 {
            r.step();
        }
        let s = r.exec.status()[0];
        assert!((s.actual_position - target).abs() < 0.2, "{s:?}");
        assert!(s.actual_velocity.abs() < 0.5, "{s:?}");
    }
}

#[test]
fn overlap_compensation_makes_a_20_percent_overlap_valve_land() {
    let overlap = ("overlap = 0.05 ", "overlap = 0.20 ");
    // Without compensation the controller's output at standstill stays inside the overlap:
    // the cylinder creeps to a halt short of the target and never reports InTarget.
    let short = cell(&[
        overlap,
        ("fValve_OverlapCompP = 0.05", "fValve_OverlapCompP = 0.0"),
    ]);
    let mut r = Run::enabled(&short);
    r.move_to(300.0, 120.0);
    for _ in 0..6000 {
        r.step();
    }
    let s = r.exec.status()[0];
    let h = r.hyd();
    assert!(s.motion_job.is_some(), "Done without landing: {s:?}");
    assert!(!h.in_target, "{h:?}");
    assert!(
        300.0 - s.actual_position > 0.2,
        "reached {} without compensation",
        s.actual_position
    );
    // With the overlap compensated it lands within the window and reports Done.
    let comp = cell(&[
        overlap,
        ("fValve_OverlapCompP = 0.05", "fValve_OverlapCompP = 0.20"),
    ]);
    let mut r = Run::enabled(&comp);
    r.move_to(300.0, 120.0);
    r.run_move(8000);
    let s = r.exec.status()[0];
    assert!((s.actual_position - 300.0).abs() < 0.2, "{s:?}");
}

#[test]
fn mc_halt_stops_on_the_generator_ramp_and_a_velocity_motion_takes_over_without_a_step() {
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    r.move_to(450.0, 120.0);
    r.until(3000, "travel", |r| r.hyd().state == HydState::ConstVelo);
    for _ in 0..200 {
        r.step();
    }
    // MC_Halt with 300 mm/s² (below the axis' 400): 120 mm/s down in 0.4 s on the
    // generator's time ramp.
    r.cmd(Command::Halt {
        deceleration: 300.0,
        jerk: -1.0,
        abort_acceleration: false,
    });
    let v0 = r.exec.status()[0].velocity;
    assert!((v0 - 120.0).abs() < 1e-9, "{v0}");
    let mut ramp = 0;
    let mut last = v0;
    loop {
        r.step();
        let (h, v) = (r.hyd(), r.exec.status()[0].velocity);
        if h.state != HydState::TcDec {
            break;
        }
        // 300 mm/s² x 1 ms a cycle.
        assert!((last - v - 0.3).abs() < 1e-9, "{last} -> {v}");
        last = v;
        ramp += 1;
        assert!(ramp < 1000, "no end of the stop ramp");
    }
    // 120 / 0.3 = 400 decrements (the last may leave a rounding residue for one more cycle).
    assert!(
        (399..=401).contains(&ramp),
        "{ramp} cycles in the stop ramp"
    );
    assert_eq!(r.hyd().state, HydState::Idle);
    // MC_MoveVelocity: a profile from the standing setpoint; the generator lets go and the
    // position controller acts while moving.
    r.until(2000, "halt done", |r| r.status().motion_job.is_none());
    let p0 = r.exec.status()[0].position;
    r.cmd(Command::MoveVelocity {
        dynamics: Dynamics {
            velocity: 50.0,
            acceleration: 400.0,
            deceleration: 400.0,
            jerk: 100000.0,
        },
        direction: VelocityDirection::Positive,
        current: false,
        position_controlled: true,
    });
    r.step();
    let s = r.exec.status()[0];
    assert!((s.position - p0).abs() < 0.01, "{} after {p0}", s.position);
    assert!(!r.hyd().engaged);
    for _ in 0..1000 {
        r.step();
    }
    let s = r.exec.status()[0];
    assert!((s.actual_velocity - 50.0).abs() < 2.0, "{s:?}");
    // Closed loop: the actual position follows the set position within a millimetre.
    assert!((s.position - s.actual_position).abs() < 1.0, "{s:?}");
}

#[test]
fn bad_hydraulic_parameters_are_refused_naming_the_key() {
    let src = source();
    for (from, to, key) in [
        (
            "fRefVelo = 327.06",
            "fRefVelo = -1.0",
            "axes.ram.hydraulic.fRefVelo",
        ),
        (
            "fMonTargetRange = 0.2 ",
            "fMonTargetRange = 0.0 ",
            "axes.ram.hydraulic.fMonTargetRange",
        ),
        (
            "fLagAmp = 50.0",
            "fLagAmp = -2.0",
            "axes.ram.hydraulic.fLagAmp",
        ),
        (
            "fLagAmp = 50.0",
            "fLagAmp = 50.0\nfLagAmpTi = -1.0",
            "axes.ram.hydraulic.fLagAmpTi",
        ),
        (
            "fLagAmp = 50.0",
            "fLagAmp = 50.0\nfTargetClamping = 11.0",
            "axes.ram.hydraulic.fTargetClamping",
        ),
        (
            "overlap = 0.05",
            "overlap = 1.5",
            "devices.ram_valve.cylinder.overlap",
        ),
        (
            "kind = \"hydraulic\"",
            "kind = \"positioning\"",
            "axes.ram.hydraulic",
        ),
    ] {
        assert!(src.contains(from), "{from}");
        let e = tandem_config::parse("hydraulic.toml", &src.replacen(from, to, 1)).unwrap_err();
        assert!(e.to_string().contains(key), "{from} -> {to}: {e}");
    }
}

/// The press (`config/hydraulic-press.toml` with its script) through the executive: contact,
/// MC_AxCtrlPressure_BkPlcMc holds 20 kN within 2 % for the second before the decompression,
/// 2 kN within 5 % before the release, and the ram returns to 300 mm in position control.
#[test]
fn the_press_holds_its_force_under_the_force_controller_and_returns() {
    let root = root();
    let cell = tandem_config::load(&root.join("config/hydraulic-press.toml")).unwrap();
    let src = std::fs::read_to_string(root.join("config/hydraulic-press-script.toml")).unwrap();
    let script =
        tandem_config::script::parse_cell("hydraulic-press-script.toml", &src, &cell).unwrap();
    let mut exec = Executive::new(&cell, None).unwrap();
    let mut log = Vec::new();
    let (mut worst_20k, mut worst_2k) = (0.0_f64, 0.0_f64);
    let mut controlled = 0;
    hyd_rig::replay(&mut exec, &script, &mut log, |k, exec| {
        let h = exec.axis(AxisIndex(0)).unwrap().hydraulic_status().unwrap();
        let force = h.actual.expect("pressure inputs").force;
        if h.pressure_control.is_some() {
            controlled += 1;
        }
        if (3000..4000).contains(&k) {
            worst_20k = worst_20k.max((force - 20_000.0).abs() / 20_000.0);
        }
        if (4300..4500).contains(&k) {
            worst_2k = worst_2k.max((force - 2_000.0).abs() / 2_000.0);
        }
    });
    let log = String::from_utf8(log).unwrap();
    eprintln!(
        "20 kN: {:.3} %, 2 kN: {:.3} %",
        worst_20k * 100.0,
        worst_2k * 100.0
    );
    assert!(worst_20k <= 0.02, "20 kN held within {worst_20k}\n{log}");
    assert!(worst_2k <= 0.05, "2 kN held within {worst_2k}\n{log}");
    // The controller ran from its enable (2.5 s) to its release (4.5 s).
    assert_eq!(controlled, 2000, "{log}");
    let s = exec.status()[0];
    assert_eq!(
        (s.state, s.position),
        (AxisState::Standstill, 300.0),
        "{log}"
    );
    assert!((s.actual_position - 300.0).abs() < 0.2, "{s:?}");
    assert!(
        log.contains("MC_AxCtrlPressure_BkPlcMc job 4: Done"),
        "{log}"
    );
}

#[test]
fn pressure_control_is_refused_without_pressure_inputs_and_with_bad_parameters() {
    use tandem_motion::catalog::error_id::ErrorId;
    let pressure = |enable, kp: f64, windup_limit: f64| {
        Action::Command(Command::PressureControl {
            enable,
            set_value: 1000.0,
            kp,
            tn: 0.0,
            preset: 0.0,
            windup_limit,
            force: true,
        })
    };
    // config/hydraulic.toml has no pressure inputs.
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    let t = r.k * MS;
    let out = r
        .exec
        .apply_at(t, t, "ram", "test", pressure(true, 1e-5, 1.0), &mut r.log)
        .unwrap();
    assert_eq!(out, Err(ErrorId::IllegalControllerParameter));
    // The press has them; a negative kP or a WindupLimit of 0 is refused and changes nothing.
    let root = root();
    let press = tandem_config::load(&root.join("config/hydraulic-press.toml")).unwrap();
    let mut r = Run::enabled(&press);
    for bad in [pressure(true, -1.0, 1.0), pressure(true, 1e-5, 0.0)] {
        let t = r.k * MS;
        let out = r
            .exec
            .apply_at(t, t, "ram", "test", bad, &mut r.log)
            .unwrap();
        assert_eq!(out, Err(ErrorId::IllegalControllerParameter));
        r.step();
        assert_eq!(r.state(), AxisState::Standstill);
        assert!(r.hyd().pressure_control.is_none());
    }
}

/// MC_Power_BkPlcMc's feed enables: a positioning towards a direction without its enable is
/// refused (16#80F6); a move whose enable drops pauses (iTcHydStateFeedStopPos) with the set
/// velocity down to 0 and the ram standing, and ends at its target once the enable returns.
#[test]
fn a_missing_feed_enable_refuses_a_move_and_pauses_a_running_one() {
    use tandem_motion::catalog::error_id::ErrorId;
    let feed = |positive, negative| Command::HydPower {
        enable: true,
        enable_positive: positive,
        enable_negative: negative,
    };
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    r.cmd(feed(false, true));
    let t = r.k * MS;
    let mv = Action::Command(Command::MoveAbsolute {
        position: 300.0,
        dynamics: Dynamics {
            velocity: 120.0,
            acceleration: -1.0,
            deceleration: -1.0,
            jerk: -1.0,
        },
        direction: Direction::Shortest,
    });
    let out = r
        .exec
        .apply_at(t, t, "ram", "test", mv, &mut r.log)
        .unwrap();
    assert_eq!(out, Err(ErrorId::NoFeedEnable));
    // Allowed again: the move starts; its enable drops in travel.
    r.cmd(feed(true, true));
    r.move_to(300.0, 120.0);
    r.until(3000, "travel", |r| r.hyd().state == HydState::ConstVelo);
    r.cmd(feed(false, true));
    r.until(1000, "paused", |r| {
        r.hyd().state == HydState::FeedStop && r.status().velocity == 0.0
    });
    assert_eq!(
        r.hyd().state.name(r.hyd().positive),
        "iTcHydStateFeedStopPos"
    );
    for _ in 0..300 {
        r.step();
    }
    let s = r.exec.status()[0];
    assert!(s.actual_velocity.abs() < 1.0, "{s:?}");
    assert!(s.motion_job.is_some(), "the move waits");
    r.cmd(feed(true, true));
    r.run_move(8000);
    let s = r.exec.status()[0];
    assert!((s.actual_position - 300.0).abs() < 0.2, "{s:?}");
}

/// The cell with a zero-overlap valve whose spool is 0.3 V off zero and nothing compensated:
/// at standstill the position controller holds the cylinder with a standing lag.
fn offset_valve(extra: &[(&str, &str)]) -> Cell {
    let mut edits = vec![
        ("overlap = 0.05 ", "overlap = 0.0 "),
        ("offset = 0.01 ", "offset = 0.03 "),
        ("fValve_OverlapCompP = 0.05", "fValve_OverlapCompP = 0.0"),
        ("fZeroCompensation = -0.1", "fZeroCompensation = 0.0"),
    ];
    edits.extend_from_slice(extra);
    cell(&edits)
}

impl Run<'_> {
    /// Moves to `target` and stands there `cycles` more: the set position minus the actual
    /// one at the end.
    fn standing_lag(&mut self, target: f64, cycles: usize) -> f64 {
        self.move_to(target, 120.0);
        self.run_move(8000);
        for _ in 0..cycles {
            self.step();
        }
        let s = self.exec.status()[0];
        s.position - s.actual_position
    }
}

/// MC_AxCtrlAutoZero_BkPlcMc on the simulated valve: the 0.3 V offset leaves a standing lag of
/// 0.136 mm (-0.03 of full scale at the valve is -0.03 · 0.6947 before Finish divides a
/// retracting output by fAreaRatio, over fLagAmp 50 / fRefVelo 327); the compensation, enabled
/// at standstill, integrates to -0.3 V within 5 % and the lag goes, Done once it has levelled
/// out; the value stays when it is disabled.
#[test]
fn auto_zero_removes_a_0_3_v_offset_of_a_zero_overlap_valve() {
    let cell = offset_valve(&[("fLagAmp = 50.0", "fLagAmp = 50.0\nfLagAmpDx = 0.002")]);
    let mut r = Run::enabled(&cell);
    let before = r.standing_lag(300.0, 1000);
    assert!(
        (before - -0.136).abs() < 0.01,
        "lag {before} mm without AutoZero"
    );
    let params = tandem_motion::hydraulic::auto_zero::AutoZeroParams {
        enable_on_moving: false,
        offset_limit: 1.0,
        tn: 10.0,
        threshold: 0.01,
        filter: 2.0,
    };
    r.cmd(Command::AutoZero {
        enable: true,
        params,
    });
    // Tn 10 s: the offset decays with a 10 s time constant; 60 s is six of them.
    let mut done_at = None;
    for k in 0..60_000 {
        r.step();
        let (status, on) = r.hyd().auto_zero.unwrap();
        assert!(on && !status.limiting, "{status:?}");
        if status.done && done_at.is_none() {
            done_at = Some(k);
        }
    }
    let (status, _) = r.hyd().auto_zero.unwrap();
    assert!(
        (status.compensation - -0.3).abs() < 0.015,
        "fZeroCompensation {} V",
        status.compensation
    );
    assert!(done_at.is_some(), "{status:?}");
    let s = r.exec.status()[0];
    let after = s.position - s.actual_position;
    assert!(after.abs() < 0.01, "lag {after} mm with AutoZero");
    // The compensation reaches the valve: its output at standstill is about -0.3 V + the P
    // part of the remaining lag.
    let out = r.exec.analog_drive(0).unwrap().link.normalized;
    assert!((out - -0.03).abs() < 0.003, "output {out}");
    // Disabled, the value stays and the next move lands without a lag.
    r.cmd(Command::AutoZero {
        enable: false,
        params,
    });
    let lag = r.standing_lag(150.0, 1000);
    assert!(lag.abs() < 0.01, "lag {lag} mm after a move");
    assert_eq!(
        r.hyd().auto_zero.unwrap().0.compensation,
        status.compensation
    );
}

#[test]
fn auto_zero_is_refused_on_an_overlap_valve_and_with_bad_parameters() {
    use tandem_motion::catalog::error_id::ErrorId;
    let good = tandem_motion::hydraulic::auto_zero::AutoZeroParams::default();
    let refused = |r: &mut Run, params| {
        let t = r.k * MS;
        let action = Action::Command(Command::AutoZero {
            enable: true,
            params,
        });
        let out = r
            .exec
            .apply_at(t, t, "ram", "test", action, &mut r.log)
            .unwrap();
        assert_eq!(out, Err(ErrorId::IllegalControllerParameter), "{params:?}");
        r.step();
        assert!(r.hyd().auto_zero.is_none());
    };
    // The bundled valve has overlap compensation: "only for zero overlap valves".
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    refused(&mut r, good);
    let cell = offset_valve(&[]);
    let mut r = Run::enabled(&cell);
    for bad in [
        tandem_motion::hydraulic::auto_zero::AutoZeroParams { tn: 0.0, ..good },
        tandem_motion::hydraulic::auto_zero::AutoZeroParams {
            offset_limit: 10.5,
            ..good
        },
    ] {
        refused(&mut r, bad);
    }
}

/// The position controller's I part (fLagAmpTi as Ki, beyond fLagAmpDx) removes the standing
/// lag of the same offset; without it the lag stays.
#[test]
fn the_i_part_removes_the_standing_lag_of_a_valve_offset() {
    let cell = offset_valve(&[(
        "fLagAmp = 50.0",
        "fLagAmp = 50.0\nfLagAmpTi = 200.0\nfLagAmpDx = 0.002\nfLagAmpWuL = 0.1",
    )]);
    let mut r = Run::enabled(&cell);
    let lag = r.standing_lag(300.0, 3000);
    assert!(lag.abs() < 0.005, "lag {lag} mm with the I part");
    let cell = offset_valve(&[]);
    let mut r = Run::enabled(&cell);
    let lag = r.standing_lag(300.0, 3000);
    assert!(lag.abs() > 0.12, "lag {lag} mm without it");
}

/// fTargetClamping: at the target the generator's pressing output (with the sign of the
/// approach) reaches the valve in place of the position controller; the free cylinder is
/// pushed on beyond its target.
#[test]
fn target_clamping_presses_on_at_the_target() {
    let cell = cell(&[("fLagAmp = 50.0", "fLagAmp = 50.0\nfTargetClamping = 1.5")]);
    let mut r = Run::enabled(&cell);
    r.move_to(300.0, 120.0);
    r.until(8000, "creep", |r| r.hyd().state == HydState::CreepVelo);
    r.until(8000, "idle", |r| r.hyd().state == HydState::Idle);
    r.step();
    let link = r.exec.analog_drive(0).unwrap().link;
    // (1.5 V - 0.1 V of zero compensation) / 10 V.
    assert!((link.normalized - 0.14).abs() < 1e-12, "{link:?}");
    let p = r.exec.status()[0].actual_position;
    for _ in 0..200 {
        r.step();
    }
    assert!(r.exec.status()[0].actual_position > p + 1.0);
    // Moving back, the pressing output is negative at the target.
    r.move_to(200.0, 120.0);
    r.until(8000, "creep", |r| r.hyd().state == HydState::CreepVelo);
    r.until(8000, "idle", |r| r.hyd().state == HydState::Idle);
    r.step();
    let link = r.exec.analog_drive(0).unwrap().link;
    assert!((link.normalized - -0.16).abs() < 1e-12, "{link:?}");
}

/// The table of the library's FAQ #22 (a cylinder half as fast retracting, a zero-overlap valve
/// with a bend at 40 %), in its file format (tabs, a comma as decimal separator in one line).
const FAQ22_CURVE: &str = "-0.500\t-1.000\n-0.430\t-0.900\n-0.360\t-0.800\n-0.290\t-0.700\n\
    -0.220\t-0.600\n-0.150\t-0.500\n-0.080\t-0.400\n-0.060\t-0.300\n-0.040\t-0.200\n\
    -0.020\t-0.100\n0.000\t0.000\n0.040\t0.100\n0.080\t0.200\n0.120\t0.300\n0.160\t0.400\n\
    0.300\t0.500\n0.440\t0.600\n0.580\t0.700\n0.720\t0.800\n0.860\t0.900\n1,000\t1.000\n";

/// The bundled cell with `characteristic_curve = "<curve file>"`, both written to a fresh
/// directory and loaded from there (the file is read relative to the cell file).
fn with_curve(curve: &str, dir: &str) -> Result<Cell, tandem_config::ConfigError> {
    let dir = tandem_testkit::scratch::fresh_dir(&format!("{dir}-{}", std::process::id()));
    std::fs::write(dir.join("ram.curve"), curve).unwrap();
    let src = source().replacen(
        "fLagAmp = 50.0",
        "fLagAmp = 50.0\ncharacteristic_curve = \"ram.curve\"",
        1,
    );
    std::fs::write(dir.join("cell.toml"), src).unwrap();
    let cell = tandem_config::load(&dir.join("cell.toml"));
    tandem_testkit::scratch::remove_dir(&dir);
    cell
}

/// `characteristic_curve`: Finish linearises with the table (MC_AxRtFinishLinear_BkPlcMc): while
/// the generator travels (no position control) the valve's output is the table's output for
/// the set velocity plus the zero compensation, to the bit.
#[test]
fn a_characteristic_curve_from_the_cell_file_linearises_the_valve_output() {
    use tandem_motion::hydraulic::valve_table::{ValveTable, MAX_POINTS};
    let cell = with_curve(FAQ22_CURVE, "hyd-curve").unwrap();
    let mut buf = [(0.0, 0.0); MAX_POINTS];
    let table = ValveTable::parse(FAQ22_CURVE, &mut buf).unwrap();
    let mut r = Run::enabled(&cell);
    r.move_to(400.0, 120.0);
    r.until(3000, "travel", |r| r.hyd().state == HydState::ConstVelo);
    let mut seen = 0;
    while r.hyd().state == HydState::ConstVelo {
        let v = r.exec.status()[0].velocity;
        r.step();
        let link = r.exec.analog_drive(0).unwrap().link;
        if r.hyd().state == HydState::ConstVelo {
            // 120 mm/s of 327.06: 0.3669, between (0.300, 0.5) and (0.440, 0.6); -0.1 V.
            let want = table.output(v / 327.06, 0.0) - 0.01;
            assert_eq!(link.normalized, want, "at {v} mm/s");
            assert!((want - 0.537).abs() < 0.001, "{want}");
            seen += 1;
        }
    }
    assert!(seen > 100, "{seen} cycles of travel");
}

/// A curve file that breaks one of the library's table rules is refused naming the key, the
/// file, the rule and the library's error code.
#[test]
fn a_characteristic_curve_that_breaks_a_table_rule_is_refused() {
    for (curve, what) in [
        ("-1.0 -1.0\n0.5 0.5\n1.0 1.0\n", "zero point"),
        ("-1.0 -1.0\n0.0 0.0\n0.0 0.5\n1.0 1.0\n", "not higher"),
        ("-1.0 -1.0\n0.0 0.0\n1.0 x\n", "line 3"),
        ("-1.0 -1.0\n0.0 0.0\n1.5 1.0\n", "1.5"),
    ] {
        let e = with_curve(curve, "hyd-curve-bad").unwrap_err().to_string();
        assert!(
            e.contains("axes.ram.hydraulic.characteristic_curve")
                && e.contains("ram.curve")
                && e.contains(what)
                && e.contains("16#"),
            "{curve:?}: {e}"
        );
    }
    let e = with_curve("", "hyd-curve-empty").unwrap_err().to_string();
    assert!(e.contains("at least 2 points"), "{e}");
}

/// The bundled cell with the axis' `valve_output` (and `bDrive_*` lines) and the valve's
/// `valve_input`.
fn valve_forms(axis: &str, valve: &str) -> Cell {
    cell(&[
        ("fLagAmp = 50.0", &format!("fLagAmp = 50.0\n{axis}")),
        (
            "load = 0.0 ",
            &format!("valve_input = \"{valve}\"\nload = 0.0 "),
        ),
    ])
}

/// The drive stage's forms (MC_AxRtDrive_BkPlcMc) on a valve wired for each: the positioning
/// out and back lands in the target window as with the ±10 V word, and the words and bits
/// written are the form's: two coils one per direction, one coil around its centre, a current
/// valve's magnitude with its direction bits.
#[test]
fn each_valve_output_form_positions_a_valve_wired_for_it() {
    for (axis, valve) in [
        ("valve_output = \"two_coil\"", "two_coil"),
        ("valve_output = \"one_coil\"", "one_coil"),
        ("bDrive_AbsoluteOutput = true", "current"),
    ] {
        let cell = valve_forms(axis, valve);
        let mut r = Run::enabled(&cell);
        for (target, positive) in [(350.0, true), (120.0, false)] {
            r.move_to(target, 120.0);
            r.until(3000, "travel", |r| r.hyd().state == HydState::ConstVelo);
            let c = r.exec.analog_drive(0).unwrap().latched;
            match (valve, positive) {
                ("two_coil", true) => assert!(c.words.word > 0 && c.words.word_b == 0, "{c:?}"),
                ("two_coil", false) => assert!(c.words.word == 0 && c.words.word_b > 0, "{c:?}"),
                ("one_coil", true) => assert!(c.words.word > 16384, "{c:?}"),
                ("one_coil", false) => assert!((0..16384).contains(&c.words.word), "{c:?}"),
                _ => assert!(c.words.word > 0, "{c:?}"),
            }
            assert_eq!(
                (c.words.move_positive, c.words.move_negative),
                (positive, !positive)
            );
            r.run_move(8000);
            let s = r.exec.status()[0];
            assert!(
                (s.actual_position - target).abs() < 0.2 && r.hyd().in_target,
                "{valve}: at {} for {target}",
                s.actual_position
            );
        }
    }
}

/// A form that does not match the valve's wiring misbehaves in the simulator as on the
/// machine: two coils on a ±10 V valve never retract it (its negative half reads the coil A
/// word, 0); `bDrive_Reversed` on a plain valve drives it away from the target.
#[test]
fn a_valve_output_that_does_not_match_the_wiring_misbehaves_as_on_the_machine() {
    let cell = valve_forms("valve_output = \"two_coil\"", "voltage");
    let mut r = Run::enabled(&cell);
    r.move_to(50.0, 120.0);
    for _ in 0..1000 {
        r.step();
    }
    assert!(r.exec.status()[0].actual_position > 99.0, "it retracted");
    let cell = valve_forms("bDrive_Reversed = true", "voltage");
    let mut r = Run::enabled(&cell);
    r.move_to(350.0, 120.0);
    for _ in 0..300 {
        r.step();
    }
    assert!(
        r.exec.status()[0].actual_position < 95.0,
        "it did not run away"
    );
}

#[test]
fn bad_valve_output_settings_are_refused_naming_the_key() {
    let src = source();
    for (from, to, key) in [
        (
            "fLagAmp = 50.0",
            "fLagAmp = 50.0\nvalve_output = \"two_coil\"\nbDrive_AbsoluteOutput = true",
            "axes.ram.hydraulic.bDrive_AbsoluteOutput",
        ),
        (
            "fLagAmp = 50.0",
            "fLagAmp = 50.0\nvalve_output = \"current\"",
            "axes.ram.hydraulic.valve_output",
        ),
        (
            "load = 0.0 ",
            "valve_input = \"three_coil\"\nload = 0.0 ",
            "devices.ram_valve.valve_input",
        ),
    ] {
        let e = tandem_config::parse("hydraulic.toml", &src.replacen(from, to, 1)).unwrap_err();
        assert!(e.to_string().contains(key), "{to}: {e}");
    }
}

/// fReposDistance on the simulated cylinder: without a position controller at standstill
/// (fLagAmp 0) a valve whose offset is a little beyond its overlap lets the ram drift away
/// from its target after the move; with fReposDistance 1 mm the generator starts again to the
/// same target whenever the drift exceeds it, and the ram stays near its target.
#[test]
fn automatic_repositioning_brings_a_drifting_ram_back_to_its_target() {
    let drifting = [
        ("offset = 0.01 ", "offset = 0.062 "),
        ("fLagAmp = 50.0", "fLagAmp = 0.0"),
    ];
    let run = |repos: &str| {
        let mut edits = drifting.to_vec();
        edits.push(("fMonTargetFilter = 0.2", repos));
        let cell = cell(&edits);
        let mut r = Run::enabled(&cell);
        r.move_to(300.0, 120.0);
        r.run_move(8000);
        let (mut starts, mut worst, mut idle) = (0, 0.0_f64, true);
        for _ in 0..8000 {
            r.step();
            let now_idle = r.in_state(HydState::Idle);
            if idle && !now_idle {
                starts += 1;
            }
            idle = now_idle;
            worst = worst.max((r.status().actual_position - 300.0).abs());
        }
        (starts, worst)
    };
    let (starts, worst) = run("fMonTargetFilter = 0.2\nfReposDistance = 1.0");
    assert!(
        starts >= 1 && worst < 1.5,
        "{starts} starts, {worst} mm away"
    );
    let (starts, worst) = run("fMonTargetFilter = 0.2");
    assert!(
        starts == 0 && worst > 3.0,
        "{starts} starts, {worst} mm away"
    );
}

/// The following error of a hydraulic axis is its lag behind the set position of the last
/// command (the library's `fSetPos - fActPos`): with the monitoring on (2 mm) the move out
/// and back raises no alarm, the lag stays near a millimetre in the displacement mode, and an
/// axis enabled again after a reset starts with none (it once compared the start position).
#[test]
fn the_following_error_of_a_hydraulic_axis_is_its_lag_behind_the_set_position() {
    let cell = cell(&[(
        "enable = false                    # the displacement mode",
        "enable = true\nmin_value = 2.0\nmax_value = 2.0\nmin_velocity = 1.0\n# the displacement mode",
    )]);
    let mut r = Run::enabled(&cell);
    let (mut worst, mut set) = (0.0_f64, r.status().position);
    for (target, velocity) in [(350.0, 120.0), (120.0, 150.0)] {
        r.move_to(target, velocity);
        for _ in 0..4000 {
            r.step();
            let s = r.status();
            assert_eq!(s.error_word, 0, "{s:?}\n{}", r.log());
            assert!(
                (s.following_error - (set - s.actual_position)).abs() < 1e-9,
                "{s:?} after the set position {set}"
            );
            set = s.position;
            worst = worst.max(s.following_error.abs());
        }
    }
    assert!(worst > 0.1 && worst < 1.5, "{worst} mm");
    // Disabled and enabled again where it stands: no following error from an old reference.
    r.cmd(Command::Power {
        enable: false,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    });
    r.until(100, "disabled", |r| r.state() == AxisState::Disabled);
    r.cmd(Command::Power {
        enable: true,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    });
    r.until(100, "enabled", |r| r.state() == AxisState::Standstill);
    for _ in 0..500 {
        r.step();
        let s = r.status();
        assert!(s.error_word == 0 && s.following_error.abs() < 0.2, "{s:?}");
    }
}
