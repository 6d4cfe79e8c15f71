//! MC_AxCtrlSlowDownOnPressureEx_BkPlcMc (Beckhoff TwinCAT PLC Hydraulic Positioning library,
//! 4.4.1.5) on the bundled press (`config/hydraulic-press.toml`: the workpiece is the
//! cylinder's end stop at 500 mm, the positioning aims at 505 mm and creeps at 10 mm/s from
//! 500 mm). Without the limiter the creeping ram presses with the supply's force (about 31 kN);
//! with it at 10 kN the valve closes as the force reaches the set value (what the spool's lag
//! lets in stays, bounded), the move stays Busy short of its target, and `EnableRelief` takes
//! the excess back. Lowered to 5 kN it holds without `EnableRelief` (the permissible velocity
//! is 0, the zero-lapped valve closes) and backs off to 5 kN with it. Bad inputs are refused and change
//! nothing.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod hyd_rig;
use hyd_rig::Run;

use tandem_config::Cell;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::hydraulic::pressure::PressureReading;
use tandem_motion::hydraulic::slow_down::SlowDownParams;
use tandem_motion::objects::axis::{AxisState, Command};
use tandem_testkit::workspace::root;

fn press() -> Cell {
    tandem_config::load(&root().join("config/hydraulic-press.toml")).unwrap()
}

/// The press powered at 300 mm, standing.
fn powered(cell: &Cell) -> Run<'_> {
    Run::enabled_at(cell, 300.0)
}

fn slow_down(set_point: f64, enable_relief: bool) -> Command {
    Command::SlowDownOnPressure {
        enable: true,
        params: SlowDownParams {
            enable_relief,
            set_point,
            kp: 0.005,
            feed_velocity: 0.0,
            reading: PressureReading::Force,
        },
    }
}

impl Run<'_> {
    fn force(&self) -> f64 {
        self.hyd().actual.unwrap().force
    }

    /// Steps `n` cycles; the largest force seen.
    fn run(&mut self, n: usize) -> f64 {
        let mut worst = f64::MIN;
        for _ in 0..n {
            self.step();
            worst = worst.max(self.force());
        }
        worst
    }
}

#[test]
fn without_the_limiter_the_creeping_ram_presses_with_the_supply() {
    let cell = press();
    let mut r = powered(&cell);
    r.move_to(505.0, 150.0);
    r.run(3000);
    assert!(r.force() > 25_000.0, "{}", r.force());
}

#[test]
fn the_limiter_stops_the_ram_at_the_set_force_and_relief_backs_off() {
    let cell = press();
    let mut r = powered(&cell);
    r.cmd(slow_down(10_000.0, false));
    // kP · Setpoint = 50 mm/s is the fastest the limiter lets the ram travel: move at 40.
    r.move_to(505.0, 40.0);
    let peak = r.run(7000);
    let s = r.hyd().slow_down.unwrap();
    eprintln!("10 kN: force {:.1} N, peak {peak:.1} N, {s:?}", r.force());
    assert!(s.busy);
    // The limiter closes the valve as the force reaches 10 kN; what the oil pushes in
    // meanwhile stays without relief: the creep (10 mm/s) against the oil column's stiffness
    // (β·A²/V = 1200 N/mm² · 3117² mm⁴ / 1.66e6 mm³ ≈ 7 kN/mm) raises the force by 70 N per
    // ms, for the spool's 5 ms lag and about 3 ms of sampling and output delay: < 600 N.
    assert!(
        peak < 10_600.0 && r.force() > 9_900.0,
        "{peak} {}",
        r.force()
    );
    // Short of the target at the workpiece: the positioning is still under way.
    assert_eq!(r.state(), AxisState::DiscreteMotion);
    assert!((r.status().actual_position - 500.0).abs() < 0.5);
    // With relief the overshoot is taken back: 10 kN within 1 %.
    r.cmd(slow_down(10_000.0, true));
    r.run(2000);
    eprintln!("10 kN with relief: {:.1} N", r.force());
    assert!((r.force() - 10_000.0).abs() < 100.0, "{}", r.force());

    // 5 kN without relief: nothing may move, the force stays.
    r.cmd(slow_down(5_000.0, false));
    r.run(1000);
    assert!(r.force() > 9_500.0, "{}", r.force());
    assert_eq!(r.hyd().slow_down.unwrap().permissible, 0.0);
    // With relief the ram backs off until the force is 5 kN.
    r.cmd(slow_down(5_000.0, true));
    r.run(2000);
    eprintln!("5 kN with relief: {:.1} N", r.force());
    assert!((r.force() - 5_000.0).abs() < 100.0, "{}", r.force());
}

#[test]
fn bad_inputs_are_refused_and_change_nothing() {
    let cell = press();
    let mut r = powered(&cell);
    // 0.005 · 1000 = 5 mm/s is below the creep velocity of 10 mm/s.
    assert_eq!(
        r.try_cmd(slow_down(1_000.0, false)),
        Err(ErrorId::IllegalControllerParameter)
    );
    let bad_kp = Command::SlowDownOnPressure {
        enable: true,
        params: SlowDownParams {
            kp: -1.0,
            ..match slow_down(10_000.0, false) {
                Command::SlowDownOnPressure { params, .. } => params,
                _ => unreachable!(),
            }
        },
    };
    assert_eq!(r.try_cmd(bad_kp), Err(ErrorId::IllegalControllerParameter));
    assert_eq!(r.hyd().slow_down, None);
    // The limit is built for the displacement-based generator: the jerk-based one and the
    // time-based mode are refused (the library: "the axis must be distance-controlled").
    let src = std::fs::read_to_string(root().join("config/hydraulic-press.toml")).unwrap();
    for key in [
        "nProfileType = \"iTcMc_ProfileJerkBased\"",
        "bTimeBased = true",
    ] {
        let s = src.replacen("fLagAmp = 50.0", &format!("fLagAmp = 50.0\n{key}"), 1);
        let other = tandem_config::parse("hydraulic-press.toml", &s).unwrap();
        let mut o = powered(&other);
        assert_eq!(
            o.try_cmd(slow_down(10_000.0, false)),
            Err(ErrorId::IllegalControllerParameter),
            "{key}"
        );
    }
    // config/hydraulic.toml has no pressure inputs.
    let plain = tandem_config::load(&root().join("config/hydraulic.toml")).unwrap();
    let mut p = Run::enabled(&plain);
    assert_eq!(
        p.try_cmd(slow_down(10_000.0, false)),
        Err(ErrorId::IllegalControllerParameter)
    );
}
