//! MC_AxRtSetDirectOutput_BkPlcMc and MC_AxRtSetExtGenValues_BkPlcMc on the simulated valve and
//! cylinder of `config/hydraulic.toml`, through the executive: the direct output's control value
//! slews at full scale per RampTime and reaches the valve word to the bit through Finish and the
//! drive stage's output form, the cylinder moves open loop, Enable = FALSE ramps it to 0 before
//! the job is Done, another motion aborts it; external set values are the axis' set values each
//! cycle with the position controller's lag bounded, and their falling edge stops the axis with
//! fStopRamp in Standstill; bad inputs are refused and change nothing.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod hyd_rig;
use hyd_rig::Run;

use tandem_config::Cell;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::hydraulic::drive_output::{DriveOutputParams, ValveOutput};
use tandem_motion::hydraulic::generator::HydState;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{AxisState, Command, StartMode, StopMode};
use tandem_motion::objects::job::Instruction;
use tandem_motion::plant::analog::output_word;
use tandem_runtime::exec::Executive;
use tandem_testkit::workspace::root;

tandem_testkit::counting_allocator!();

/// fRefVelo of config/hydraulic.toml (mm/s).
const REF_VELO: f64 = 327.06;
/// Its fLagAmp (mm/s per mm).
const LAG_AMP: f64 = 50.0;
/// Its fStopRamp (s from fRefVelo to 0).
const STOP_RAMP: f64 = 1.0;
/// The cycle (s).
const DT: f64 = 0.001;

/// config/hydraulic.toml with `edits` (each `from` must occur).
fn cell(edits: &[(&str, &str)]) -> Cell {
    let mut s = std::fs::read_to_string(root().join("config/hydraulic.toml")).unwrap();
    for (from, to) in edits {
        assert!(s.contains(from), "{from}");
        s = s.replacen(from, to, 1);
    }
    tandem_config::parse("hydraulic.toml", &s).unwrap()
}

/// Finish of config/hydraulic.toml for the control value `u`, by hand (docs/hydraulics.md,
/// sectional linearisation): fAreaRatio 0.6947 (< 1) divides a negative value; no bend; the
/// overlap compensation fValve_OverlapCompP 0.05 ramped in over 0…fCreepSpeedP (5 mm/s of
/// 327.06); fZeroCompensation -0.1 V (-0.01 of full scale); limited to ±1.
fn finish(u: f64) -> f64 {
    let v = if u < 0.0 { u / 0.6947 } else { u };
    let ramp = if u == 0.0 {
        0.0
    } else {
        (u.abs() / (5.0 / REF_VELO)).min(1.0)
    };
    (v + (0.05 * ramp).copysign(u) - 0.01).clamp(-1.0, 1.0)
}

impl Run<'_> {
    fn direct(&mut self, enable: bool, out_value: f64, ramp_time: f64) -> Result<u32, ErrorId> {
        self.try_cmd(Command::SetDirectOutput {
            enable,
            out_value,
            ramp_time,
        })
        .map(|j| j.unwrap_or(0))
    }

    fn ext(
        &mut self,
        enable: bool,
        position: f64,
        velocity: f64,
        target: f64,
    ) -> Result<u32, ErrorId> {
        self.try_cmd(Command::SetExtGenValues {
            enable,
            position,
            velocity,
            target_position: target,
        })
        .map(|j| j.unwrap_or(0))
    }

    fn job(&self) -> Option<Instruction> {
        self.status().motion_job.map(|(_, i)| i)
    }
}

/// OutValue 0.2 with RampTime 0.5 s: the control value rises 0.002 a cycle (full scale in
/// 500 cycles of 1 ms) to 0.2 in exactly 100 cycles; each cycle the set velocity is the value
/// times fRefVelo and the ±10 V word is Finish's output of it to the bit. The ram runs out
/// open loop (the set position follows the actual one), the axis shows ContinuousMotion.
/// Enable = FALSE: down 0.002 a cycle, 100 cycles, the job Done only at 0; then Standstill,
/// holding in position control.
#[test]
fn direct_output_slews_to_the_valve_word_and_ramps_to_zero_on_release() {
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    let start = r.status().actual_position;
    let job = r.direct(true, 0.2, 0.5).unwrap();
    assert!(job > 0);
    for n in 1..=1000 {
        r.step();
        let u = (f64::from(n) * 0.002).min(0.2);
        let s = r.status();
        assert!((s.velocity - u * REF_VELO).abs() < 1e-9, "cycle {n}: {s:?}");
        assert_eq!(r.word(), output_word(finish(u)), "cycle {n}: u {u}");
        assert_eq!(s.position, s.actual_position, "cycle {n}");
        assert_eq!(s.state, AxisState::ContinuousMotion);
        assert_eq!(r.job(), Some(Instruction::SetDirectOutput));
    }
    // 0.2 of fRefVelo is 65 mm/s; the ram ran out open loop for most of a second.
    let s = r.status();
    let moved = s.actual_position - start;
    assert!(moved > 40.0 && s.actual_velocity > 40.0, "{s:?}");
    assert_eq!(r.direct(false, 0.0, 0.5), Ok(job));
    for n in 1..=100 {
        r.step();
        let u = (0.2 - f64::from(n) * 0.002).max(0.0);
        assert!(
            (r.status().velocity - u * REF_VELO).abs() < 1e-9,
            "cycle {n}: {:?}",
            r.status()
        );
        assert_eq!(r.word(), output_word(finish(u)), "cycle {n}: u {u}");
        if n < 100 {
            assert_eq!(r.job(), Some(Instruction::SetDirectOutput), "cycle {n}");
        }
    }
    assert_eq!(r.job(), None);
    assert!(
        r.log()
            .contains(&format!("MC_AxRtSetDirectOutput_BkPlcMc job {job}: Done")),
        "{}",
        r.log()
    );
    for _ in 0..1000 {
        r.step();
    }
    let s = r.status();
    assert_eq!(s.state, AxisState::Standstill);
    assert!(
        s.actual_velocity.abs() < 0.5 && (s.position - s.actual_position).abs() < 0.1,
        "{s:?}"
    );
}

/// Negative values on a two-coil valve: RampTime 0 gives the value at once; the words are the
/// drive stage's two-coil form of Finish's output (-0.3 / fAreaRatio, the overlap, the offset),
/// and the ram retracts. With bDrive_Reversed the words swap.
#[test]
fn direct_output_goes_through_the_valve_output_form() {
    for reversed in [false, true] {
        let axis = if reversed {
            "valve_output = \"two_coil\"\nbDrive_Reversed = true"
        } else {
            "valve_output = \"two_coil\""
        };
        let cell = cell(&[
            ("fLagAmp = 50.0", &format!("fLagAmp = 50.0\n{axis}")),
            ("load = 0.0 ", "valve_input = \"two_coil\"\nload = 0.0 "),
        ]);
        let mut r = Run::enabled(&cell);
        let start = r.status().actual_position;
        r.direct(true, -0.3, 0.0).unwrap();
        let form = DriveOutputParams {
            output: ValveOutput::TwoCoil,
            absolute: false,
            reversed,
        };
        let want = form.encode(finish(-0.3));
        for _ in 0..300 {
            r.step();
            let link = r.exec.analog_drive(0).unwrap().link;
            assert_eq!(link.word, want.word, "reversed {reversed}");
        }
        let c = r.exec.analog_drive(0).unwrap().latched;
        assert_eq!((c.words.word, c.words.word_b), (want.word, want.word_b));
        assert!(
            if reversed {
                c.words.word > 0
            } else {
                c.words.word_b > 0
            },
            "{c:?}"
        );
        let moved = r.status().actual_position - start;
        if reversed {
            // Reversal on a valve not wired reversed: it runs the other way, as on the machine.
            assert!(moved > 5.0, "{moved}");
        } else {
            assert!(moved < -5.0, "{moved}");
        }
    }
}

/// Another motion takes the axis over: the direct output is CommandAborted and the positioning
/// runs from where the ram stands, in closed loop.
#[test]
fn direct_output_is_aborted_by_another_motion() {
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    let job = r.direct(true, 0.1, 0.2).unwrap();
    for _ in 0..300 {
        r.step();
    }
    r.move_to(150.0, 100.0);
    r.step();
    assert_eq!(r.job(), Some(Instruction::MoveAbsolute));
    assert!(
        r.log().contains(&format!(
            "MC_AxRtSetDirectOutput_BkPlcMc job {job}: CommandAborted"
        )),
        "{}",
        r.log()
    );
    // The old job's Enable = FALSE no longer finds it.
    assert_eq!(r.direct(false, 0.0, 0.0), Ok(0));
    r.until(8000, "in target", |r| {
        r.job().is_none() && r.hyd().in_target
    });
    assert!((r.status().actual_position - 150.0).abs() < 0.2);
}

/// Refusals, each changing nothing: OutValue beyond full scale or not a number (16#8003),
/// RampTime below 0 (16#8004), external values not finite (16#8009 positions, 16#8003
/// velocity); a running direct output keeps its value; a disabled axis refuses (16#800F); an
/// electric axis refuses both instructions (16#8002).
#[test]
fn refusals_change_nothing() {
    let cell_h = cell(&[]);
    let mut r = Run::enabled(&cell_h);
    assert_eq!(r.direct(true, 1.5, 0.0), Err(ErrorId::IllegalVelocity));
    assert_eq!(r.direct(true, f64::NAN, 0.0), Err(ErrorId::IllegalVelocity));
    assert_eq!(r.direct(true, 0.5, -1.0), Err(ErrorId::IllegalAcceleration));
    assert_eq!(
        r.direct(true, 0.5, f64::INFINITY),
        Err(ErrorId::IllegalAcceleration)
    );
    assert_eq!(
        r.ext(true, f64::NAN, 0.0, 0.0),
        Err(ErrorId::IllegalPosition)
    );
    assert_eq!(
        r.ext(true, 100.0, 0.0, f64::INFINITY),
        Err(ErrorId::IllegalPosition)
    );
    assert_eq!(
        r.ext(true, 100.0, f64::NAN, 100.0),
        Err(ErrorId::IllegalVelocity)
    );
    let word = r.word();
    r.step();
    assert_eq!((r.job(), r.state()), (None, AxisState::Standstill));
    assert_eq!(r.word(), word);
    // A running direct output: a refused update keeps it as it was.
    r.direct(true, 0.1, 0.0).unwrap();
    r.step();
    assert_eq!(r.direct(true, -2.0, 0.0), Err(ErrorId::IllegalVelocity));
    r.step();
    assert!((r.status().velocity - 0.1 * REF_VELO).abs() < 1e-9);
    r.direct(false, 0.0, 0.0).unwrap();
    r.step();
    r.cmd(Command::Power {
        enable: false,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    });
    r.until(1000, "disabled", |r| r.state() == AxisState::Disabled);
    assert_eq!(r.direct(true, 0.1, 0.0), Err(ErrorId::NotEnabled));
    assert_eq!(r.ext(true, 100.0, 0.0, 100.0), Err(ErrorId::NotEnabled));
    let cell_e = {
        let s = std::fs::read_to_string(root().join("config/analog.toml")).unwrap();
        tandem_config::parse("analog.toml", &s).unwrap()
    };
    let mut exec = Executive::new(&cell_e, None).unwrap();
    let mut log = Vec::new();
    exec.step(0, &mut log).unwrap();
    for c in [
        Command::SetDirectOutput {
            enable: true,
            out_value: 0.1,
            ramp_time: 0.0,
        },
        Command::SetExtGenValues {
            enable: true,
            position: 0.0,
            velocity: 0.0,
            target_position: 0.0,
        },
    ] {
        let out = exec
            .apply_at(0, 0, "slide", "test", Action::Command(c), &mut log)
            .unwrap();
        assert_eq!(out, Err(ErrorId::IllegalObject), "{c:?}");
    }
}

/// The external leading values of one cycle `k` (from the command on): a ramp from 100 mm
/// accelerating at 400 mm/s² to 50 mm/s, then constant.
fn leading(k: usize) -> (f64, f64) {
    let t = k as f64 * DT;
    let (a, v) = (400.0, 50.0);
    let t1 = v / a;
    if t <= t1 {
        (100.0 + 0.5 * a * t * t, a * t)
    } else {
        (100.0 + 0.5 * a * t1 * t1 + v * (t - t1), v)
    }
}

/// MC_AxRtSetExtGenValues_BkPlcMc fed a ramp each cycle: the values are the axis' set position
/// and set velocity of that cycle exactly, TargetPosition is the target shown, the axis shows
/// SynchronizedMotion, and the position controller closes the loop: once the ramp runs at its
/// 50 mm/s, the lag stays below 5 % of v / fLagAmp (1 mm: the lag at which the P part alone
/// would give the velocity; the feed forward gives nearly all of it, 4 µm measured). Enable = FALSE: Standstill
/// at once, the set velocity ramps down with fRefVelo / fStopRamp (0.32706 mm/s a cycle) on the
/// generator, which then holds in position control.
#[test]
fn external_set_values_are_followed_and_the_falling_edge_stops_with_the_stop_ramp() {
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    let (p, v) = leading(0);
    let job = r.ext(true, p, v, 400.0).unwrap();
    assert!(job > 0);
    let bound = 0.05 * 50.0 / LAG_AMP;
    let mut worst = 0.0_f64;
    for k in 0..2000 {
        let (p, v) = leading(k);
        assert_eq!(r.ext(true, p, v, 400.0), Ok(job));
        r.step();
        let s = r.status();
        assert!(
            (s.position - p).abs() < 1e-9 && s.velocity == v,
            "cycle {k}: {s:?}"
        );
        assert_eq!(s.state, AxisState::SynchronizedMotion);
        assert_eq!(r.hyd().target, 400.0);
        if k >= 500 {
            worst = worst.max((s.position - s.actual_position).abs());
        }
    }
    assert!(worst < bound, "lag {worst} mm, bound {bound} mm");
    let before = r.status().velocity;
    assert_eq!(before, 50.0);
    assert_eq!(r.ext(false, 0.0, 0.0, 0.0), Ok(job));
    assert_eq!(r.job(), None);
    let step = REF_VELO / STOP_RAMP * DT;
    let mut last = before;
    let mut cycles = 0;
    while r.status().velocity != 0.0 || cycles == 0 {
        r.step();
        cycles += 1;
        let s = r.status();
        assert_eq!(s.state, AxisState::Standstill, "cycle {cycles}");
        let dv = last - s.velocity;
        assert!(
            (dv - step).abs() < 1e-9 || (s.velocity == 0.0 && dv <= step + 1e-9),
            "cycle {cycles}: {last} -> {}",
            s.velocity
        );
        last = s.velocity;
        assert!(cycles < 1000, "no standstill");
    }
    assert!(
        r.log()
            .contains(&format!("MC_AxRtSetExtGenValues_BkPlcMc job {job}: Done")),
        "{}",
        r.log()
    );
    // 50 mm/s at 0.32706 mm/s a cycle: 153 cycles (152 full steps and a last partial one).
    assert_eq!(cycles, 153);
    r.until(3000, "idle", |r| r.hyd().state == HydState::Idle);
    for _ in 0..1000 {
        r.step();
    }
    let s = r.status();
    assert_eq!(s.state, AxisState::Standstill);
    assert!((s.position - s.actual_position).abs() < 0.05, "{s:?}");
}

/// A falling edge at standstill: Done, nothing moves; a refused update of a running job keeps
/// its last values; another motion aborts it (CommandAborted).
#[test]
fn external_set_values_at_rest_refused_updates_and_abort() {
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    let p0 = r.status().position;
    let job = r.ext(true, p0 + 0.5, 0.0, p0 + 0.5).unwrap();
    for _ in 0..500 {
        r.step();
    }
    // Within fMonTargetRange (0.2 mm): the P controller stands short by the friction.
    assert!((r.status().actual_position - (p0 + 0.5)).abs() < 0.2);
    assert_eq!(
        r.ext(true, f64::NAN, 0.0, 0.0),
        Err(ErrorId::IllegalPosition)
    );
    r.step();
    assert_eq!(r.status().position, p0 + 0.5);
    assert_eq!(r.ext(false, 0.0, 0.0, 0.0), Ok(job));
    assert_eq!((r.job(), r.state()), (None, AxisState::Standstill));
    r.step();
    assert_eq!(r.status().position, p0 + 0.5);
    let job = r.ext(true, p0 + 0.5, 0.0, p0 + 0.5).unwrap();
    r.step();
    r.move_to(150.0, 100.0);
    r.step();
    assert_eq!(r.job(), Some(Instruction::MoveAbsolute));
    assert!(
        r.log().contains(&format!(
            "MC_AxRtSetExtGenValues_BkPlcMc job {job}: CommandAborted"
        )),
        "{}",
        r.log()
    );
    assert_eq!(r.ext(false, 0.0, 0.0, 0.0), Ok(0));
}

/// config/hydraulic.toml with a zero-lapped valve whose 1 % offset is not compensated: without
/// position control it drifts out at about 1 % of fRefVelo.
fn drifting() -> Cell {
    cell(&[
        ("overlap = 0.05 ", "overlap = 0.0 "),
        ("fValve_OverlapCompP = 0.05", "fValve_OverlapCompP = 0.0"),
        ("fZeroCompensation = -0.1", "fZeroCompensation = 0.0"),
    ])
}

impl Run<'_> {
    fn follow_up(&mut self, enable: bool) {
        self.cmd(Command::FollowUp { enable });
    }
}

/// MC_AxRtFollowUp_BkPlcMc: while enabled, every cycle the set position and the target are the
/// actual position, the set velocity 0 and the valve word Finish's output of nothing (0 with no
/// offset compensation): the ram drifts on its valve's offset; motion is refused (16#80F0).
/// The falling edge closes the loop at the actual position of that moment: the set position
/// stays there and the ram stops within the offset's standing lag (0.01 · fRefVelo / fLagAmp
/// = 0.065 mm, and a count of the scale).
#[test]
fn follow_up_copies_the_actual_position_and_position_control_resumes_there() {
    let cell = drifting();
    let mut r = Run::enabled(&cell);
    for _ in 0..500 {
        r.step();
    }
    let start = r.status().actual_position;
    assert!((start - 100.0).abs() < 0.2, "held at {start}");
    r.follow_up(true);
    for k in 0..1000 {
        r.step();
        let s = r.status();
        assert_eq!(s.position, s.actual_position, "cycle {k}");
        assert_eq!(
            (s.velocity, s.state),
            (0.0, AxisState::Standstill),
            "cycle {k}"
        );
        assert_eq!(r.hyd().target, s.actual_position, "cycle {k}");
        assert_eq!(r.word(), output_word(0.0), "cycle {k}");
    }
    let drift = r.status().actual_position - start;
    assert!(drift > 1.0, "drifted {drift} mm");
    assert_eq!(r.try_move_to(150.0, 100.0), Err(ErrorId::AxisLocked));
    r.follow_up(false);
    let held = r.status().actual_position;
    for _ in 0..1000 {
        r.step();
        assert_eq!(r.status().position, held);
    }
    let s = r.status();
    assert!(
        (s.actual_position - held).abs() < 0.07 && s.actual_velocity.abs() < 0.5,
        "{s:?}"
    );
    // 3.09 mm drifted, 0.045 mm from the held position measured.
    // Motion again.
    r.move_to(150.0, 100.0);
    assert_eq!(r.job(), Some(Instruction::MoveAbsolute));
}

/// Enabled during a positioning, the follow-up aborts it (CommandAborted); on an electric axis
/// it is refused (16#8002).
#[test]
fn follow_up_aborts_a_running_motion() {
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    r.move_to(300.0, 100.0);
    for _ in 0..200 {
        r.step();
    }
    let (job, _) = r.status().motion_job.unwrap();
    r.follow_up(true);
    r.step();
    assert_eq!(r.job(), None);
    assert!(
        r.log()
            .contains(&format!("MC_MoveAbsolute job {job}: CommandAborted")),
        "{}",
        r.log()
    );
    assert_eq!(r.status().position, r.status().actual_position);
    r.follow_up(false);
    let cell_e = {
        let s = std::fs::read_to_string(root().join("config/analog.toml")).unwrap();
        tandem_config::parse("analog.toml", &s).unwrap()
    };
    let mut exec = Executive::new(&cell_e, None).unwrap();
    let mut log = Vec::new();
    exec.step(0, &mut log).unwrap();
    let c = Command::FollowUp { enable: true };
    let out = exec
        .apply_at(0, 0, "slide", "test", Action::Command(c), &mut log)
        .unwrap();
    assert_eq!(out, Err(ErrorId::IllegalObject));
}

impl Run<'_> {
    fn offset_latch(&mut self, offset_limit: f64) -> Result<u32, ErrorId> {
        self.try_cmd(Command::OffsetLatch {
            execute: true,
            offset_limit,
        })
        .map(|j| j.unwrap_or(0))
    }
}

/// The ±10 V word of the drifting cell's Finish for the controller output `u` and the
/// compensation `zc` (V): fAreaRatio 0.6947 divides a negative value, no overlap compensation.
fn drifting_word(u: f64, zc: f64) -> i16 {
    let v = if u < 0.0 { u / 0.6947 } else { u };
    output_word((v + zc / 10.0).clamp(-1.0, 1.0))
}

/// MC_AxUtiOffsetLatch_BkPlcMc on the drifting valve held in position control: its standing
/// lag's controller output, fLagAmp · lag / fRefVelo · 10 V, becomes fZeroCompensation (to
/// 1e-12); the set position is the actual one at once, and the next words are Finish's of the
/// new compensation and that cycle's P part to the bit; the standing lag falls to under a
/// third of what it was.
#[test]
fn offset_latch_takes_the_controller_output_into_the_compensation() {
    let cell = drifting();
    let mut r = Run::enabled(&cell);
    for _ in 0..1000 {
        r.step();
    }
    let s = r.status();
    let lag = s.position - s.actual_position;
    assert!(lag.abs() > 0.02, "standing lag {lag}");
    assert_eq!(r.hyd().zero_compensation, 0.0);
    assert_eq!(r.word(), drifting_word(LAG_AMP * lag / REF_VELO, 0.0));
    let expected = LAG_AMP * lag / REF_VELO * 10.0;
    let job = r.offset_latch(0.5).unwrap();
    assert!(job > 0);
    let zc = r.hyd().zero_compensation;
    assert!((zc - expected).abs() < 1e-12, "{zc} for {expected}");
    assert_eq!(r.status().position, s.actual_position);
    for k in 0..1000 {
        r.step();
        let s = r.status();
        let u = LAG_AMP * (s.position - s.actual_position) / REF_VELO;
        assert_eq!(r.word(), drifting_word(u, zc), "cycle {k}");
    }
    let s = r.status();
    // 0.054 mm before, 0.013 mm after (measured): the friction held part of the offset.
    assert!(
        (s.position - s.actual_position).abs() < lag.abs() / 3.0,
        "lag after the latch: {s:?}, before {lag}"
    );
    assert!(
        r.log()
            .contains(&format!("MC_AxUtiOffsetLatch_BkPlcMc job {job}: Done")),
        "{}",
        r.log()
    );
}

/// The latch's refusals change nothing: an output beyond ±OffsetLimit and an OffsetLimit below
/// 0 (16#80F5), a motion (16#80F0), a disabled axis (16#800F), an I part configured (16#80F5).
#[test]
fn offset_latch_refusals_change_nothing() {
    let cell = drifting();
    let mut r = Run::enabled(&cell);
    for _ in 0..1000 {
        r.step();
    }
    let position = r.status().position;
    assert_eq!(
        r.offset_latch(0.01),
        Err(ErrorId::IllegalControllerParameter)
    );
    assert_eq!(
        r.offset_latch(-1.0),
        Err(ErrorId::IllegalControllerParameter)
    );
    assert_eq!(r.hyd().zero_compensation, 0.0);
    assert_eq!(r.status().position, position);
    r.move_to(150.0, 100.0);
    r.step();
    assert_eq!(r.offset_latch(0.5), Err(ErrorId::AxisLocked));
    r.follow_up(true);
    assert_eq!(r.offset_latch(0.5), Err(ErrorId::AxisLocked));
    r.follow_up(false);
    r.cmd(Command::Power {
        enable: false,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    });
    r.until(1000, "disabled", |r| r.state() == AxisState::Disabled);
    assert_eq!(r.offset_latch(0.5), Err(ErrorId::NotEnabled));
    assert_eq!(r.hyd().zero_compensation, 0.0);
    let with_i = cell_with_i();
    let mut r = Run::enabled(&with_i);
    r.step();
    assert_eq!(
        r.offset_latch(0.5),
        Err(ErrorId::IllegalControllerParameter)
    );
}

/// The drifting cell with the position controller's I part.
fn cell_with_i() -> Cell {
    cell(&[
        ("overlap = 0.05 ", "overlap = 0.0 "),
        ("fValve_OverlapCompP = 0.05", "fValve_OverlapCompP = 0.0"),
        ("fZeroCompensation = -0.1", "fZeroCompensation = 0.0"),
        ("fLagAmp = 50.0", "fLagAmp = 50.0\nfLagAmpTi = 10.0"),
    ])
}

/// The node's command path (`tandem_config::script::parse_command`, what a node does with a
/// command line from the network): leading values sent as text each cycle with their own
/// parameter names are the axis' set values of that cycle, exactly as the command built in
/// code; `enable false` ends it. Also MC_AxRtSetDirectOutput_BkPlcMc and
/// MC_AxRtFollowUp_BkPlcMc / MC_AxUtiOffsetLatch_BkPlcMc by name.
#[test]
fn leading_values_arrive_each_cycle_through_the_nodes_command_path() {
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    let send = |r: &mut Run<'_>, instruction: &str, params: &[(&str, String)]| {
        let params: Vec<(String, String)> = params
            .iter()
            .map(|(k, v)| ((*k).to_string(), v.clone()))
            .collect();
        let e = tandem_config::script::parse_command(&cell, "ram", instruction, &params).unwrap();
        let t = r.k * hyd_rig::MS;
        r.exec
            .apply_at(t, t, &e.axis, e.instruction, e.action, &mut r.log)
            .unwrap()
    };
    for k in 0..300 {
        let (p, v) = leading(k);
        let out = send(
            &mut r,
            "MC_AxRtSetExtGenValues_BkPlcMc",
            &[
                ("position", p.to_string()),
                ("velocity", v.to_string()),
                ("target_position", "400".into()),
            ],
        );
        assert!(out.is_ok(), "{out:?}");
        r.step();
        let s = r.status();
        assert!(
            (s.position - p).abs() < 1e-9 && s.velocity == v,
            "{k}: {s:?}"
        );
        assert_eq!(s.state, AxisState::SynchronizedMotion);
    }
    send(
        &mut r,
        "MC_AxRtSetExtGenValues_BkPlcMc",
        &[("enable", "false".into())],
    )
    .unwrap();
    r.step();
    assert_eq!((r.job(), r.state()), (None, AxisState::Standstill));
    r.until(3000, "idle", |r| r.hyd().state == HydState::Idle);
    send(
        &mut r,
        "MC_AxRtSetDirectOutput_BkPlcMc",
        &[("out_value", "-0.1".into()), ("ramp_time", "0".into())],
    )
    .unwrap();
    r.step();
    assert!((r.status().velocity + 0.1 * REF_VELO).abs() < 1e-9);
    assert_eq!(r.job(), Some(Instruction::SetDirectOutput));
    send(
        &mut r,
        "MC_AxRtSetDirectOutput_BkPlcMc",
        &[("enable", "false".into())],
    )
    .unwrap();
    r.step();
    assert_eq!(r.job(), None);
    send(&mut r, "MC_AxRtFollowUp_BkPlcMc", &[]).unwrap();
    assert_eq!(r.try_move_to(150.0, 100.0), Err(ErrorId::AxisLocked));
    send(
        &mut r,
        "MC_AxRtFollowUp_BkPlcMc",
        &[("enable", "false".into())],
    )
    .unwrap();
    for _ in 0..500 {
        r.step();
    }
    let out = send(
        &mut r,
        "MC_AxUtiOffsetLatch_BkPlcMc",
        &[("offset_limit", "-1".into())],
    );
    assert_eq!(out, Err(ErrorId::IllegalControllerParameter));
    assert!(send(&mut r, "MC_AxUtiOffsetLatch_BkPlcMc", &[]).is_ok());
}

/// The cyclic path does not allocate with these instructions running: 1,000 cycles of leading
/// values applied and stepped, a direct output slewing out and released to its Done, a
/// follow-up: 0 allocations (counted on this thread, the log's buffer reserved before).
#[test]
fn the_instructions_run_without_allocating() {
    use tandem_testkit::counting::{arm, disarm};
    let cell = cell(&[]);
    let mut r = Run::enabled(&cell);
    r.log.reserve(1 << 16);
    let (p, v) = leading(0);
    r.ext(true, p, v, 400.0).unwrap();
    r.step();
    let mut accepted = true;
    arm();
    for k in 1..1000 {
        let (p, v) = leading(k);
        accepted &= r.ext(true, p, v, 400.0).is_ok();
        r.step();
    }
    let (ext_allocs, _) = disarm();
    assert!(accepted);
    r.ext(false, 0.0, 0.0, 0.0).unwrap();
    r.until(3000, "idle", |r| r.hyd().state == HydState::Idle);
    r.direct(true, 0.1, 0.2).unwrap();
    arm();
    for _ in 0..300 {
        r.step();
    }
    // Checked after the armed section.
    let released = r.direct(false, 0.0, 0.2);
    for _ in 0..300 {
        r.step();
    }
    let (direct_allocs, _) = disarm();
    assert!(released.is_ok() && r.job().is_none(), "{released:?}");
    r.follow_up(true);
    arm();
    for _ in 0..300 {
        r.step();
    }
    let (follow_allocs, _) = disarm();
    assert_eq!((ext_allocs, direct_allocs, follow_allocs), (0, 0, 0));
}
