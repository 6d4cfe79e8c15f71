//! The Beckhoff hydraulic library's own stop, position and jog instructions on the simulated
//! valve and cylinder of `config/hydraulic.toml`, through the executive: MC_EmergencyStop_BkPlcMc
//! ramps at fRefVelo / RampTime (or fEmergencyRamp) and then holds the valve output word at 0
//! while Execute stays TRUE, refusing motion; MC_ImmediateStop_BkPlcMc writes 0 at once;
//! MC_RampedStop_BkPlcMc ramps in time without a lock; MC_SetPosition_BkPlcMc during a move shifts
//! every position by exactly the offset with the valve output unchanged; MC_SetReferenceFlag_BkPlcMc
//! sets and clears the homed status; an electric axis refuses them (16#8002).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod hyd_rig;
use hyd_rig::Run;

use tandem_config::Cell;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::hydraulic::generator::HydState;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{AxisState, Command, HydJogMode, StartMode, StopMode};
use tandem_motion::objects::job::Instruction;
use tandem_runtime::exec::Executive;
use tandem_testkit::workspace::root;

/// fRefVelo of config/hydraulic.toml.
const REF_VELO: f64 = 327.06;

fn cell(file: &str) -> Cell {
    let s = std::fs::read_to_string(root().join("config").join(file)).unwrap();
    tandem_config::parse(file, &s).unwrap()
}

impl<'c> Run<'c> {
    /// Starts a move to 450 mm at 200 mm/s and steps into its travel phase.
    fn travelling(cell: &'c Cell) -> Self {
        let mut r = Self::enabled(cell);
        r.try_move_to(450.0, 200.0).unwrap();
        r.until(3000, "travel", |r| r.hyd().state == HydState::ConstVelo);
        r
    }

    /// Steps while the set velocity falls: each cycle's decrease (mm/s), until it is 0.
    fn ramp_down(&mut self, max: usize) -> Vec<f64> {
        let mut steps = Vec::new();
        let mut v = self.status().velocity;
        for _ in 0..max {
            self.step();
            let now = self.status().velocity;
            if now == 0.0 {
                return steps;
            }
            steps.push(v - now);
            v = now;
        }
        panic!("no standstill within {max} cycles\n{}", self.log());
    }

    /// The motion job, if any.
    fn job(&self) -> Option<Instruction> {
        self.status().motion_job.map(|(_, i)| i)
    }
}

/// The emergency ramp: the set velocity falls by exactly fRefVelo / RampTime · dt per cycle
/// (RampTime 2 s: 0.16353 mm/s a millisecond), the job stays until it is 0 and is then Done;
/// from there the valve's output word is exactly 0 while Execute stays TRUE, the ram stands,
/// the axis is Stopping and refuses a move (16#80F0) and another stop; Execute FALSE releases
/// it and the next move lands.
#[test]
fn emergency_stop_ramps_at_ref_velo_over_ramp_time_then_locks_the_valve_output() {
    let cell = cell("hydraulic.toml");
    let mut r = Run::travelling(&cell);
    r.cmd(Command::EmergencyStop {
        execute: true,
        ramp_time: 2.0,
    });
    assert_eq!(r.job(), Some(Instruction::EmergencyStop));
    let steps = r.ramp_down(3000);
    let per_cycle = REF_VELO / 2.0 * 1e-3;
    // From 200 mm/s: 200 / 0.16353 = 1223 cycles (the last one shorter).
    assert!(steps.len() > 1200, "{} cycles", steps.len());
    for d in &steps[..steps.len() - 1] {
        assert!((d - per_cycle).abs() < 1e-9, "{d} per cycle");
    }
    assert_eq!(r.hyd().state, HydState::Idle);
    r.step();
    assert_eq!(r.job(), None, "Done once the control value is 0");
    for _ in 0..500 {
        r.step();
        assert_eq!(r.word(), 0);
        assert_eq!(r.state(), AxisState::Stopping);
    }
    assert!(r.status().actual_velocity.abs() < 1.0);
    assert_eq!(r.try_move_to(300.0, 100.0), Err(ErrorId::AxisLocked));
    assert_eq!(
        r.try_cmd(Command::RampedStop { ramp_time: 1.0 }),
        Err(ErrorId::AxisLocked)
    );
    // Released: the position controller acts again (the valve's zero compensation alone is
    // -0.1 V, a word of -276) and a move lands.
    r.cmd(Command::EmergencyStop {
        execute: false,
        ramp_time: 2.0,
    });
    r.step();
    assert_ne!(r.word(), 0);
    assert_eq!(r.state(), AxisState::Standstill);
    r.try_move_to(300.0, 100.0).unwrap();
    r.until(8000, "landed", |r| r.job().is_none());
    assert!((r.status().actual_position - 300.0).abs() < 0.2);
}

/// Without a RampTime the ramp is fEmergencyRamp (0.1 s from fRefVelo: 3.2706 mm/s a cycle),
/// in iTcHydStateEmergencyBreak.
#[test]
fn emergency_stop_without_ramp_time_takes_f_emergency_ramp() {
    let cell = cell("hydraulic.toml");
    let mut r = Run::travelling(&cell);
    r.cmd(Command::EmergencyStop {
        execute: true,
        ramp_time: 0.0,
    });
    r.step();
    assert_eq!(r.hyd().state, HydState::EmergencyBreak);
    let steps = r.ramp_down(1000);
    assert!(steps.len() > 55, "{} cycles", steps.len());
    for d in &steps[..steps.len() - 1] {
        assert!((d - REF_VELO / 0.1 * 1e-3).abs() < 1e-9, "{d} per cycle");
    }
    r.step();
    r.step();
    assert_eq!(r.word(), 0);
}

/// MC_ImmediateStop_BkPlcMc: the output word is 0 from the next cycle on (no ramp), the move is
/// aborted, the axis refuses motion until Execute is FALSE.
#[test]
fn immediate_stop_writes_0_at_once_and_locks() {
    let cell = cell("hydraulic.toml");
    let mut r = Run::travelling(&cell);
    r.step();
    assert!(r.word() > 10_000, "travelling at 200 mm/s: {}", r.word());
    r.cmd(Command::ImmediateStop { execute: true });
    assert_eq!(r.job(), None);
    for _ in 0..1000 {
        r.step();
        assert_eq!(r.word(), 0);
    }
    assert!(r.status().actual_velocity.abs() < 1.0);
    assert_eq!(r.try_move_to(300.0, 100.0), Err(ErrorId::AxisLocked));
    // Execute FALSE of the other stop does not release it.
    r.cmd(Command::EmergencyStop {
        execute: false,
        ramp_time: 0.0,
    });
    assert_eq!(r.try_move_to(300.0, 100.0), Err(ErrorId::AxisLocked));
    r.cmd(Command::ImmediateStop { execute: false });
    r.try_move_to(300.0, 100.0).unwrap();
    r.until(8000, "landed", |r| r.job().is_none());
    assert!((r.status().actual_position - 300.0).abs() < 0.2);
}

/// MC_RampedStop_BkPlcMc: a time ramp of the set velocity at fRefVelo / RampTime, Done at 0, no
/// lock (the valve output is the controller's again and a move is accepted); a new move aborts
/// a running one.
#[test]
fn ramped_stop_is_a_time_ramp_without_a_lock() {
    let cell = cell("hydraulic.toml");
    let mut r = Run::travelling(&cell);
    r.cmd(Command::RampedStop { ramp_time: 1.5 });
    assert_eq!(r.job(), Some(Instruction::RampedStop));
    let steps = r.ramp_down(3000);
    for d in &steps[..steps.len() - 1] {
        assert!((d - REF_VELO / 1.5 * 1e-3).abs() < 1e-9, "{d} per cycle");
    }
    r.step();
    assert_eq!(r.job(), None);
    assert_eq!(r.state(), AxisState::Standstill);
    r.try_move_to(150.0, 100.0).unwrap();
    r.until(3000, "travel", |r| r.hyd().state == HydState::ConstVelo);
    r.cmd(Command::RampedStop { ramp_time: 1.5 });
    r.try_move_to(120.0, 100.0).unwrap();
    assert_eq!(r.job(), Some(Instruction::MoveAbsolute));
    r.until(8000, "landed", |r| r.job().is_none());
    assert!((r.status().actual_position - 120.0).abs() < 0.2);
}

/// The stops' refusals: on a standing axis they are Done at once; a disabled axis refuses
/// (16#800F); an electric axis refuses every instruction of the library (16#8002).
#[test]
fn refusals_of_the_library_instructions() {
    let cell_h = cell("hydraulic.toml");
    let mut r = Run::enabled(&cell_h);
    r.cmd(Command::RampedStop { ramp_time: 1.0 });
    assert_eq!(r.job(), None);
    r.cmd(Command::Power {
        enable: false,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    });
    r.until(1000, "disabled", |r| r.state() == AxisState::Disabled);
    assert_eq!(
        r.try_cmd(Command::EmergencyStop {
            execute: true,
            ramp_time: 0.0
        }),
        Err(ErrorId::NotEnabled)
    );
    let cell_e = cell("analog.toml");
    let mut exec = Executive::new(&cell_e, None).unwrap();
    let mut log = Vec::new();
    exec.step(0, &mut log).unwrap();
    for c in [
        Command::EmergencyStop {
            execute: true,
            ramp_time: 0.0,
        },
        Command::ImmediateStop { execute: true },
        Command::RampedStop { ramp_time: 0.0 },
        Command::HydSetPosition {
            position: 0.0,
            relative: false,
        },
        Command::SetReferenceFlag {
            reference_flag: true,
        },
        Command::ResetAndStop {
            deceleration: 0.0,
            ramp_time: 0.0,
        },
        Command::MoveJoySticked {
            execute: true,
            joystick: 0.1,
            acceleration: 0.0,
            deceleration: 0.0,
        },
    ] {
        let out = exec
            .apply_at(0, 0, "slide", "test", Action::Command(c), &mut log)
            .unwrap();
        assert_eq!(out, Err(ErrorId::IllegalObject), "{c:?}");
    }
}

/// MC_SetPosition_BkPlcMc during a move, against the same move undisturbed: from the command
/// on, the actual and the set position are shifted by exactly the offset every cycle, the valve
/// output word is the same (no jump), and the move ends at the shifted target. Relative
/// (+50 mm) and absolute (actual := 0) modes.
#[test]
fn set_position_during_a_move_shifts_everything_without_a_jump() {
    let cell = cell("hydraulic.toml");
    for relative in [true, false] {
        let mut a = Run::travelling(&cell);
        let mut b = Run::travelling(&cell);
        let before = b.status().actual_position;
        let position = if relative { 50.0 } else { 0.0 };
        b.cmd(Command::HydSetPosition { position, relative });
        let offset = if relative { 50.0 } else { -before };
        let mut worst_word = 0_i32;
        for _ in 0..8000 {
            a.step();
            b.step();
            let (sa, sb) = (a.status(), b.status());
            assert!(
                (sb.actual_position - sa.actual_position - offset).abs() < 1e-6,
                "actual {} vs {}",
                sb.actual_position,
                sa.actual_position
            );
            assert!(
                (sb.position - sa.position - offset).abs() < 1e-6,
                "set {} vs {}",
                sb.position,
                sa.position
            );
            worst_word = worst_word.max((i32::from(a.word()) - i32::from(b.word())).abs());
            if a.job().is_none() && b.job().is_none() {
                break;
            }
        }
        assert!(worst_word <= 1, "valve words differ by {worst_word}");
        assert_eq!(b.job(), None);
        assert!((b.hyd().target - (450.0 + offset)).abs() < 1e-9);
        assert!((b.status().actual_position - (450.0 + offset)).abs() < 0.2);
    }
}

/// MC_SetReferenceFlag_BkPlcMc clears and sets the homed status: not homed, an absolute move is
/// refused (16#80F2); homed again, it runs. MC_SetPosition_BkPlcMc leaves it as it is.
#[test]
fn set_reference_flag_sets_and_clears_homed() {
    let cell = cell("hydraulic.toml");
    let mut r = Run::enabled(&cell);
    r.cmd(Command::SetReferenceFlag {
        reference_flag: false,
    });
    assert_eq!(r.try_move_to(200.0, 100.0), Err(ErrorId::NotHomed));
    r.cmd(Command::HydSetPosition {
        position: 10.0,
        relative: false,
    });
    assert_eq!(r.try_move_to(200.0, 100.0), Err(ErrorId::NotHomed));
    r.cmd(Command::SetReferenceFlag {
        reference_flag: true,
    });
    r.try_move_to(60.0, 100.0).unwrap();
    r.until(8000, "landed", |r| r.job().is_none());
    assert!((r.status().actual_position - 60.0).abs() < 0.2);
}

/// MC_ResetAndStop_BkPlcMc during a move: the set velocity ramps down with `Deceleration`
/// (100 mm/s²: 0.1 mm/s a cycle), the axis is Stopping and refuses a move (16#80F0) until the
/// job is Done at rest; then Standstill and a move runs. With `RampTime` only, fRefVelo /
/// RampTime; on a standing axis it is Done at once.
#[test]
fn reset_and_stop_stops_with_its_deceleration_and_is_done_at_rest() {
    let cell = cell("hydraulic.toml");
    for (deceleration, ramp_time, per_cycle) in [(100.0, 0.0, 0.1), (0.0, 4.0, REF_VELO / 4e3)] {
        let mut r = Run::travelling(&cell);
        r.cmd(Command::ResetAndStop {
            deceleration,
            ramp_time,
        });
        assert_eq!(r.job(), Some(Instruction::ResetAndStop));
        r.step();
        assert_eq!(r.state(), AxisState::Stopping);
        assert_eq!(r.try_move_to(300.0, 100.0), Err(ErrorId::AxisLocked));
        let steps = r.ramp_down(5000);
        for d in &steps[..steps.len() - 1] {
            assert!((d - per_cycle).abs() < 1e-9, "{d} per cycle");
        }
        r.step();
        assert_eq!(r.job(), None);
        assert_eq!(r.state(), AxisState::Standstill);
        assert_ne!(r.word(), 0, "the position controller acts");
        r.try_move_to(300.0, 100.0).unwrap();
        r.until(8000, "landed", |r| r.job().is_none());
        r.cmd(Command::ResetAndStop {
            deceleration: 0.0,
            ramp_time: 0.0,
        });
        assert_eq!(r.job(), None);
    }
}

impl Run<'_> {
    fn jog(&mut self, forward: bool, backward: bool, mode: HydJogMode, position: f64) {
        self.cmd(Command::HydMoveJog {
            forward,
            backward,
            mode,
            position,
            dynamics: Dynamics {
                velocity: 60.0,
                acceleration: 0.0,
                deceleration: 0.0,
                jerk: 0.0,
            },
        });
    }
}

/// MC_MoveJog_BkPlcMc's velocity modes: STANDARD_SLOW runs at fJogVeloSlow (a new key, 30 mm/s
/// here), STANDARD_FAST at fJogVeloFast (90 mm/s), CONTINUOUS at the command's 60 mm/s, each
/// while its input is held (an edge of the other input meanwhile is ignored) and stopping to
/// Standstill once it falls.
#[test]
fn jog_velocity_modes_run_at_their_velocity_while_held() {
    let cell = {
        let s = std::fs::read_to_string(root().join("config/hydraulic.toml")).unwrap();
        let s = s.replacen(
            "fEmergencyRamp = 0.1",
            "fEmergencyRamp = 0.1\nfJogVeloSlow = 30.0\nfJogVeloFast = 90.0",
            1,
        );
        tandem_config::parse("hydraulic.toml", &s).unwrap()
    };
    let mut r = Run::enabled(&cell);
    for (mode, forward, v) in [
        (HydJogMode::StandardSlow, true, 30.0),
        (HydJogMode::StandardFast, false, -90.0),
        (HydJogMode::Continuous, true, 60.0),
    ] {
        r.jog(forward, !forward, mode, 0.0);
        assert_eq!(r.job(), Some(Instruction::HydMoveJog));
        for _ in 0..800 {
            r.step();
        }
        assert_eq!(r.status().velocity, v, "{mode:?} {:?}", r.status());
        assert!(
            (r.status().actual_velocity - v).abs() < 0.05 * v.abs(),
            "{mode:?}"
        );
        // The other input's edge is not accepted while moving.
        r.jog(true, true, mode, 0.0);
        r.jog(forward, !forward, mode, 0.0);
        r.step();
        assert_eq!(r.status().velocity, v);
        r.jog(false, false, mode, 0.0);
        r.until(2000, "stopped", |r| r.job().is_none());
        assert_eq!(r.state(), AxisState::Standstill);
        assert_eq!(r.status().velocity, 0.0);
    }
}

/// MC_JOGMODE_INCHING: each rising edge moves exactly `Position` (in the input's direction) on
/// the generator and ends Done in the target window; holding the input does not repeat.
#[test]
fn inching_moves_exactly_position_per_rising_edge() {
    let cell = cell("hydraulic.toml");
    let mut r = Run::enabled(&cell);
    let start = r.status().position;
    for (k, forward) in [true, true, false].into_iter().enumerate() {
        r.jog(forward, !forward, HydJogMode::Inching, 12.5);
        assert_eq!(r.job(), Some(Instruction::HydMoveJog));
        r.until(8000, "step done", |r| r.job().is_none());
        // Held: no new step.
        r.jog(forward, !forward, HydJogMode::Inching, 12.5);
        assert_eq!(r.job(), None);
        r.jog(false, false, HydJogMode::Inching, 12.5);
        let expected = start + 12.5 * [1.0, 2.0, 1.0][k];
        assert_eq!(r.hyd().target, expected);
        assert_eq!(
            r.status().position,
            expected,
            "the set position is the target"
        );
        assert!((r.status().actual_position - expected).abs() < 0.2);
    }
    // Position 0 is refused.
    assert_eq!(
        r.try_cmd(Command::HydMoveJog {
            forward: true,
            backward: false,
            mode: HydJogMode::Inching,
            position: 0.0,
            dynamics: Dynamics::DEFAULT,
        }),
        Err(ErrorId::IllegalDistance)
    );
}

/// fJogVeloSlow / fJogVeloFast must be above 0: the cell is refused naming the key.
#[test]
fn jog_velocities_out_of_range_are_refused_naming_the_key() {
    let s = std::fs::read_to_string(root().join("config/hydraulic.toml")).unwrap();
    for key in ["fJogVeloSlow", "fJogVeloFast"] {
        let bad = s.replacen(
            "fEmergencyRamp = 0.1",
            &format!("fEmergencyRamp = 0.1\n{key} = 0.0"),
            1,
        );
        let e = tandem_config::parse("hydraulic.toml", &bad).unwrap_err();
        assert!(e.to_string().contains(key), "{e}");
    }
}

/// MC_ResetAndStop_BkPlcMc's reset: a following-error alarm (a 1 mm limit, exceeded by the
/// displacement mode's lag in travel) puts the moving axis into ErrorStop with its enable
/// removed (motion refused); MC_ResetAndStop_BkPlcMc acknowledges it (the error word clears, the
/// axis leaves ErrorStop and, MC_Power's Enable still held, asks for its enable again) and is
/// Done at once on the disabled axis.
#[test]
fn reset_and_stop_acknowledges_an_alarm() {
    let s = std::fs::read_to_string(root().join("config/hydraulic.toml")).unwrap();
    let s = s.replacen(
        "enable = false                    # the displacement mode",
        "enable = true\nmin_value = 1.0\nmax_value = 1.0\nmin_velocity = 1.0\n# the displacement mode",
        1,
    );
    let cell = tandem_config::parse("hydraulic.toml", &s).unwrap();
    let mut r = Run::enabled(&cell);
    r.try_move_to(450.0, 200.0).unwrap();
    r.until(3000, "alarm", |r| r.state() == AxisState::ErrorStop);
    assert_ne!(r.status().error_word, 0);
    assert_eq!(r.try_move_to(300.0, 100.0), Err(ErrorId::NotEnabled));
    r.until(3000, "stood", |r| r.status().actual_velocity.abs() < 0.5);
    r.cmd(Command::ResetAndStop {
        deceleration: 0.0,
        ramp_time: 0.0,
    });
    assert_eq!(r.job(), None);
    r.step();
    assert_eq!(r.status().error_word, 0);
    assert_eq!(r.state(), AxisState::Disabled);
}

impl Run<'_> {
    fn joystick(&mut self, execute: bool, joystick: f64) -> Result<Option<u32>, ErrorId> {
        self.try_cmd(Command::MoveJoySticked {
            execute,
            joystick,
            acceleration: 0.0,
            deceleration: 0.0,
        })
    }
}

/// MC_MoveJoySticked_BkPlcMc: the set velocity ramps at fMaxAcc (400 mm/s², 0.4 mm/s a cycle)
/// to JoyStick · fRefVelo, follows a new JoyStick through zero, the ram follows in closed loop,
/// the axis shows SynchronizedMotion; Execute = FALSE stops with fRefVelo / fStopRamp and the
/// job is Done at standstill.
#[test]
fn move_joysticked_ramps_to_the_joystick_velocity_and_stops_with_the_stop_ramp() {
    let cell = cell("hydraulic.toml");
    let mut r = Run::enabled(&cell);
    r.joystick(true, 0.3).unwrap();
    let target = 0.3 * REF_VELO;
    let mut last = 0.0;
    for _ in 0..300 {
        r.step();
        let v = r.status().velocity;
        // The ramp starts the cycle after the command.
        assert!(
            (v - last - 0.4).abs() < 1e-9 || (v - target).abs() < 1e-9 || v == 0.0,
            "{last} -> {v}"
        );
        last = v;
    }
    assert_eq!(last, target);
    assert_eq!(r.state(), AxisState::SynchronizedMotion);
    assert_eq!(r.job(), Some(Instruction::MoveJoySticked));
    for _ in 0..500 {
        r.step();
    }
    let s = r.status();
    assert!((s.actual_velocity - target).abs() < 2.0, "{s:?}");
    // Another JoyStick: down at 0.4 mm/s a cycle through 0 to -0.2 · fRefVelo.
    r.joystick(true, -0.2).unwrap();
    r.until(1000, "reversed", |r| r.status().velocity == -0.2 * REF_VELO);
    assert_eq!(r.job(), Some(Instruction::MoveJoySticked));
    // Execute = FALSE: the stop ramp, 327.06 mm/s² (0.32706 mm/s a cycle), then Done.
    r.joystick(false, 0.0).unwrap();
    let mut last = r.status().velocity;
    while r.job().is_some() {
        r.step();
        let v = r.status().velocity;
        assert!((v - last).abs() <= REF_VELO * 1e-3 + 1e-9, "{last} -> {v}");
        last = v;
    }
    assert_eq!((last, r.state()), (0.0, AxisState::Standstill));
    assert!(r.log().contains("MC_MoveJoySticked_BkPlcMc"), "{}", r.log());
}

/// Towards an active software limit the joystick's velocity is limited by the remaining
/// distance: the set position stops at the limit, no alarm. Bad inputs are refused (an
/// electric axis is refused with the other instructions above).
#[test]
fn move_joysticked_stops_at_the_software_limit_and_refuses_bad_inputs() {
    let src = std::fs::read_to_string(root().join("config/hydraulic.toml")).unwrap();
    let src = format!("{src}\n[axes.ram.sw_limits]\nmin = 50.0\nmax = 180.0\n");
    let cell = tandem_config::parse("hydraulic.toml", &src).unwrap();
    let mut r = Run::enabled(&cell);
    r.joystick(true, 0.5).unwrap();
    for _ in 0..3000 {
        r.step();
        let s = r.status();
        assert!(s.position <= 180.0 && s.error_word == 0, "{s:?}");
    }
    let s = r.status();
    assert!(
        (s.position - 180.0).abs() < 1e-6 && s.velocity.abs() < 1e-3,
        "{s:?}"
    );
    assert_eq!(r.joystick(true, 1.5), Err(ErrorId::IllegalVelocity));
    assert_eq!(
        r.try_cmd(Command::MoveJoySticked {
            execute: true,
            joystick: 0.1,
            acceleration: -1.0,
            deceleration: 0.0,
        }),
        Err(ErrorId::IllegalAcceleration)
    );
}
