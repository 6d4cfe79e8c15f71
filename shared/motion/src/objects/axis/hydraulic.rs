//! A hydraulic axis' positionings (`AxisConfig::hydraulic`): the displacement-based generator
//! of the Beckhoff TwinCAT PLC Hydraulic Positioning library (`iTcMc_ProfileCtrlBased`) in
//! place of the jerk-limited profile, and its target window monitoring.
//!
//! The generator is **engaged** by a positioning (MC_MoveAbsolute, MC_MoveRelative,
//! MC_MoveAdditive, a queued one): it then computes the basic setpoint every cycle from the
//! actual position, and it stays engaged through a stop (MC_Halt, MC_Stop, an alarm's stop
//! reaction: its time ramp with the command's deceleration) and at standstill after the move
//! (idle: the set position is the target; automatic repositioning and target clamping act
//! there). Any other motion (velocity, jog, gearing, camming, direct setpoints, a disabled
//! axis) runs on tandem's profiles and disengages it; the next positioning takes the setpoint
//! over without a step. While the generator runs a move, the position controller is off
//! ([`DriveOutputs::position_controlled`] false: the library's displacement mode closes the
//! loop only at standstill); a positioning is Done when the generator is idle and the target
//! window monitoring reports InTargRng and InTarget.
//!
//! `nProfileType` selects the generator: the displacement-based one or the jerk-based one
//! (`iTcMc_ProfileJerkBased`, [`crate::hydraulic::jerk_generator`]), behind one
//! [`Generator`]. With `bTimeBased` the generator runs on its own set position and velocity of
//! the last cycle while it moves (a function of time), and the position controller acts
//! throughout the move.
//!
//! [`DriveOutputs::position_controlled`]: crate::plant::link::DriveOutputs::position_controlled

use super::{Axis, Command, Goal, StartMode, StopMode};
use crate::catalog::error_id::ErrorId;
use crate::hydraulic::auto_zero::{AutoZero, AutoZeroInput, AutoZeroParams, AutoZeroStatus};
use crate::hydraulic::controller::HydControllerParams;
use crate::hydraulic::generator::{HydState, Setpoint};
use crate::hydraulic::jerk_generator::Generator;
use crate::hydraulic::monitor::{TargetMonitor, TargetStatus};
use crate::hydraulic::pressure::{ActualForce, PressureController, PressureOutput, PressureParams};
use crate::hydraulic::pressure_ff::{PctrlParams, PidInputs, PidOutput, PressureFfController};
use crate::hydraulic::profile_core::ProfileGenerator;
use crate::hydraulic::slow_down::{SlowDownParams, SlowDownStatus};
use crate::kinematics::profile::{Profile, State};
use crate::objects::job::{Instruction, JobEventKind, JobId};
use crate::plant::link::HydValveOutputs;

/// The hydraulic part of an axis (boxed in the axis: allocated when it is built).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct HydAxis {
    pub(super) gen: Generator,
    /// `bTimeBased`: the generator runs on the set position and the position controller acts
    /// during the move.
    pub(super) time_based: bool,
    monitor: TargetMonitor,
    /// The generator computes the basic setpoint.
    pub(super) engaged: bool,
    /// The generator's output of the last cycle.
    pub(super) last: Setpoint,
    /// The target window of the last cycle.
    window: TargetStatus,
    /// `fRefVelo` (mm/s): the velocity of a control value of 1.0.
    pub(super) ref_velo: f64,
    /// The pressures and the force of the last sample; `None` without pressure inputs.
    pub(super) actual: Option<ActualForce>,
    /// The running MC_AxCtrlPressure_BkPlcMc job.
    pressure: Option<PressureJob>,
    /// The position controller's and Finish's parameters (AutoZero's basis).
    pub(super) controller: HydControllerParams,
    /// MC_AxCtrlAutoZero_BkPlcMc, once it has been enabled; its `Enable`.
    pub(super) auto_zero: Option<(AutoZero, bool)>,
    /// The library's stop and jog instructions' state (`super::hyd_commands`).
    pub(super) cmds: super::hyd_commands::HydCommands,
    /// MC_AxCtrlSlowDownOnPressureEx_BkPlcMc while enabled, with its last cycle
    /// (`super::hyd_slow_down`).
    pub(super) slow_down: Option<(SlowDownParams, SlowDownStatus)>,
}

/// The controller of a running pressure or force control.
// The PID variant carries its D filter (100 values) inline: the job lives in the axis' boxed
// hydraulic part, and boxing the variant would allocate when the instruction is given.
#[allow(clippy::large_enum_variant)]
#[derive(Copy, Clone, Debug, PartialEq)]
enum PressureLaw {
    /// MC_AxCtrlPressure_BkPlcMc.
    Pi(PressureController),
    /// MC_AxCtrlPressureFF_BkPlcMc with its inputs of the last command, and its last outputs.
    Pid(PressureFfController, PidInputs, PidOutput),
}

/// A running pressure or force control.
#[derive(Copy, Clone, Debug, PartialEq)]
struct PressureJob {
    law: PressureLaw,
    /// `fSetPressure` (`Setpoint`).
    set: f64,
    job: JobId,
    last: PressureOutput,
}

impl PressureJob {
    /// The instruction that runs it.
    fn instruction(&self) -> Instruction {
        Self::instruction_of(&self.law)
    }

    /// The instruction that runs `law`.
    fn instruction_of(law: &PressureLaw) -> Instruction {
        match law {
            PressureLaw::Pi(_) => Instruction::PressureControl,
            PressureLaw::Pid(..) => Instruction::PressureControlFf,
        }
    }

    /// One cycle of `dt` seconds with the actual values.
    fn step(&mut self, actual: &ActualForce, dt: f64) {
        self.last = match &mut self.law {
            PressureLaw::Pi(c) => c.step(true, false, self.set, actual, dt),
            PressureLaw::Pid(c, u, out) => {
                *out = c.step(true, false, u, actual, dt);
                out.control()
            }
        };
    }
}

/// What a hydraulic axis shows besides the axis' status.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HydraulicStatus {
    /// The generator's state (`E_TcHydAxState`; [`HydState::name`] with
    /// [`positive`](Self::positive) gives the library's name).
    pub state: HydState,
    /// The direction of the last motion.
    pub positive: bool,
    /// The generator computes the setpoint (a positioning, its stop, or standstill after it).
    pub engaged: bool,
    /// `fTargetPos`.
    pub target: f64,
    /// `dwTcHydNsDwInTargRng`.
    pub in_target_range: bool,
    /// `dwTcHydNsDwInTarget`.
    pub in_target: bool,
    /// The pressures and the force of the last sample (`fActPressureA`, `fActPressureB`,
    /// `fActPressure`, `fActForce`); `None` without pressure inputs.
    pub actual: Option<ActualForce>,
    /// The pressure or force controller runs (MC_AxCtrlPressure_BkPlcMc or
    /// MC_AxCtrlPressureFF_BkPlcMc), with its set value and its output of the last cycle.
    pub pressure_control: Option<(f64, PressureOutput)>,
    /// MC_AxCtrlPressureFF_BkPlcMc runs: its outputs of the last cycle (`Deviation`,
    /// `Proportional`, `Integrator`, `Differential`, `Response`, `InWindup`).
    pub pressure_ff: Option<PidOutput>,
    /// MC_AxCtrlAutoZero_BkPlcMc's outputs and `fZeroCompensation`, once it has been enabled,
    /// with its `Enable`.
    pub auto_zero: Option<(AutoZeroStatus, bool)>,
    /// MC_AxCtrlSlowDownOnPressureEx_BkPlcMc while enabled: `Busy`, `Active` and the
    /// permissible velocity of the last cycle.
    pub slow_down: Option<SlowDownStatus>,
    /// `fZeroCompensation` in effect (V): the configured one, or as MC_AxCtrlAutoZero_BkPlcMc
    /// or MC_AxUtiOffsetLatch_BkPlcMc set it.
    #[doc(alias = "fZeroCompensation")]
    pub zero_compensation: f64,
}

impl HydAxis {
    /// The hydraulic part of an axis at position `p0`, from its validated configuration.
    pub(super) fn new(cfg: &super::config::HydraulicProfile, p0: f64) -> Option<Box<Self>> {
        let gen = Generator::new(&cfg.profile, cfg.generator, p0).ok()?;
        let monitor = TargetMonitor::new(cfg.monitor).ok()?;
        Some(Box::new(Self {
            gen,
            monitor,
            engaged: false,
            last: Setpoint {
                velocity: 0.0,
                position: p0,
                state: HydState::Idle,
                positive: true,
                clamping_output: 0.0,
                position_control: true,
            },
            window: TargetStatus::default(),
            ref_velo: cfg.generator.ref_velo,
            actual: None,
            pressure: None,
            controller: cfg.controller,
            auto_zero: None,
            cmds: super::hyd_commands::HydCommands::new(cfg.jog_velo),
            slow_down: None,
            time_based: cfg.profile.time_based,
        }))
    }
}

impl Axis {
    /// Plans the current goal on the generator when it takes it: a positioning (engaging it),
    /// or a stop or standstill while it is engaged. Returns whether it did; any other goal
    /// disengages it.
    pub(super) fn hyd_replan(&mut self) -> bool {
        let (basic, actual, ovr) = (self.basic, self.actual_p, self.override_pct / 100.0);
        let Some(h) = self.hyd.as_deref_mut() else {
            return false;
        };
        let taken = match self.goal {
            Goal::Position { target, lim, .. } => {
                h.gen.take_over(basic.p, basic.v);
                if ovr > 0.0 {
                    h.gen
                        .move_with_jerk(target, lim.vel * ovr, (lim.acc, lim.dec, lim.jerk), actual)
                        .is_ok()
                } else {
                    h.gen.stop_with(lim.dec);
                    true
                }
            }
            Goal::Stop { lim } if h.engaged => {
                h.gen.take_over(basic.p, basic.v);
                h.gen.stop_with(lim.dec);
                true
            }
            Goal::Hold if h.engaged => {
                h.gen.take_over(basic.p, basic.v);
                true
            }
            _ => false,
        };
        h.engaged = taken;
        if taken {
            self.basic = State { a: 0.0, ..basic };
            self.prof = Profile::hold(self.basic);
            self.t0 = self.now;
        }
        taken
    }

    /// The generator no longer computes the setpoint (a profile took over the goal).
    pub(super) fn hyd_disengage(&mut self) {
        if let Some(h) = self.hyd.as_deref_mut() {
            h.engaged = false;
        }
    }

    /// One cycle of the engaged generator from the actual position: the basic setpoint and the
    /// target window. Returns whether the generator computed the setpoint.
    pub(super) fn hyd_generate(&mut self) -> bool {
        if self.hyd.is_none() {
            return false;
        }
        if self.hyd_pressure_generate() {
            return true;
        }
        let dt = self.cfg.cycle;
        let (actual, actual_v, v0) = (self.actual_p, self.actual_v, self.basic.v);
        let basic = self.basic;
        let its_goal = matches!(
            self.goal,
            Goal::Position { .. } | Goal::Stop { .. } | Goal::Hold
        );
        let Some(h) = self.hyd.as_deref_mut() else {
            return false;
        };
        // A goal set without planning (synchronous operation, a disabled axis) is not the
        // generator's.
        h.engaged &= its_goal;
        if !h.engaged {
            return false;
        }
        h.slow_down_before();
        // bTimeBased: while it moves the generator runs on its own set position and velocity of
        // the last cycle, so its profile is a function of time (the braking too); idle, on the
        // actual position (the automatic repositioning).
        let (x, xv) = if h.time_based && h.gen.state() != HydState::Idle {
            (basic.p, basic.v)
        } else {
            (actual, actual_v)
        };
        let sp = h.gen.step(dt, x, xv);
        h.slow_down_after();
        h.last = sp;
        h.window = h
            .monitor
            .step(dt, actual, h.gen.target(), sp.state == HydState::Idle);
        self.basic = State {
            p: sp.position,
            v: sp.velocity,
            a: (sp.velocity - v0) / dt,
        };
        true
    }

    /// Whether the engaged generator has ended its motion (idle); `None` when it is not
    /// engaged (the profile's end counts).
    pub(super) fn hyd_finished(&self) -> Option<bool> {
        self.hyd
            .as_deref()
            .filter(|h| h.engaged)
            .map(|h| h.gen.state() == HydState::Idle)
    }

    /// Whether a positioning on the engaged generator is Done (idle, InTargRng, InTarget);
    /// `None` when it is not engaged.
    pub(super) fn hyd_done(&self) -> Option<bool> {
        self.hyd
            .as_deref()
            .filter(|h| h.engaged)
            .map(|h| h.window.done)
    }

    /// Whether the position controller acts: not while the engaged generator runs a move, nor
    /// while the pressure controller gives the control value (it cancels `fLagCtrlOutput`).
    pub(super) fn hyd_position_control(&self) -> bool {
        self.hyd_position_control_with(self.hyd_direct_output())
    }

    /// [`Self::hyd_position_control`] with the direct output of this cycle, `direct`
    /// ([`Self::hyd_direct_output`], looked up once by the caller).
    pub(super) fn hyd_position_control_with(&self, direct: Option<f64>) -> bool {
        match self.hyd.as_deref() {
            Some(h) if h.pressure.is_some() => false,
            // MC_AxRtSetDirectOutput_BkPlcMc: open loop; MC_AxRtFollowUp_BkPlcMc: none.
            Some(_) if direct.is_some() || self.hyd_following_up() => false,
            // bTimeBased: "The position controller is always active" (at the target too,
            // except where target clamping replaces it).
            Some(h) if h.engaged && h.time_based => {
                h.last.position_control || h.last.state != HydState::Idle
            }
            Some(h) if h.engaged => h.last.position_control,
            _ => true,
        }
    }

    /// The feed enables of a hydraulic axis' two directions (MC_Power_BkPlcMc); refused
    /// (16#8002) on an electric axis.
    pub(super) fn hyd_set_feed_enables(
        &mut self,
        positive: bool,
        negative: bool,
    ) -> Result<(), ErrorId> {
        let h = self.hyd.as_deref_mut().ok_or(ErrorId::IllegalObject)?;
        h.gen.set_feed_enables(positive, negative);
        Ok(())
    }

    /// A positioning of a hydraulic axis to `target` needs the feed enable of its direction
    /// (16#80F6 without; the library: dwTcHydErrCdPosFdEna / NegFdEna).
    pub(super) fn hyd_check_feed(&self, target: f64) -> Result<(), ErrorId> {
        match self.hyd.as_deref() {
            Some(h) if target != self.actual_p => {
                if h.gen.feed_enabled(target > self.actual_p) {
                    Ok(())
                } else {
                    Err(ErrorId::NoFeedEnable)
                }
            }
            _ => Ok(()),
        }
    }

    /// The pressures and the force of the sample of this cycle, for a hydraulic axis with
    /// pressure inputs (the edge sets them with the drive inputs, before the step).
    pub fn set_hydraulic_actual(&mut self, actual: &ActualForce) {
        if let Some(h) = self.hyd.as_deref_mut() {
            h.actual = Some(*actual);
        }
    }

    /// `MC_AxCtrlPressure_BkPlcMc`: with `enable` the pressure or force controller takes the
    /// control value (a running one takes the new set value and parameters, its I part
    /// kept); without, a running one ends (Done) and the axis stands in position control at
    /// its actual position. Refused (16#80F5) on an axis that is not hydraulic or has no
    /// pressure inputs, or with a parameter out of its range.
    pub(super) fn cmd_pressure_control(
        &mut self,
        enable: bool,
        set: f64,
        params: PressureParams,
    ) -> Result<JobId, ErrorId> {
        let refused = ErrorId::IllegalControllerParameter;
        let running = self.hyd_pressure_running(Instruction::PressureControl, enable)?;
        if !enable {
            return Ok(self.hyd_pressure_off(running, Instruction::PressureControl));
        }
        self.check_motion_allowed()?;
        if !set.is_finite() {
            return Err(refused);
        }
        let ctrl = PressureController::new(params).map_err(|_| refused)?;
        let law = match running.map(|pj| pj.law) {
            Some(PressureLaw::Pi(c)) => PressureLaw::Pi(c.retuned(params)),
            _ => PressureLaw::Pi(ctrl),
        };
        Ok(self.hyd_pressure_on(running, law, set))
    }

    /// `MC_AxCtrlPressureFF_BkPlcMc`: enabled and not reset, the PID controller takes the
    /// control value (a running one takes the new inputs and parameters, its I part kept);
    /// disabled or reset, a running one ends (Done) and the axis stands in position control at
    /// its actual position. Refused as [`Self::cmd_pressure_control`] (16#80F5), and while the
    /// other pressure instruction runs.
    pub(super) fn cmd_pressure_control_ff(
        &mut self,
        enable: bool,
        reset: bool,
        inputs: PidInputs,
        params: PctrlParams,
    ) -> Result<JobId, ErrorId> {
        let refused = ErrorId::IllegalControllerParameter;
        let running =
            self.hyd_pressure_running(Instruction::PressureControlFf, enable && !reset)?;
        if !enable || reset {
            return Ok(self.hyd_pressure_off(running, Instruction::PressureControlFf));
        }
        self.check_motion_allowed()?;
        let finite = [inputs.setpoint, inputs.feed_velocity, inputs.feed_charge];
        if !finite.iter().all(|x| x.is_finite()) {
            return Err(refused);
        }
        let ctrl = match running.map(|pj| pj.law) {
            Some(PressureLaw::Pid(c, ..)) => c.retuned(params),
            _ => PressureFfController::new(params),
        }
        .map_err(|_| refused)?;
        let last = match running.map(|pj| pj.law) {
            Some(PressureLaw::Pid(_, _, out)) => out,
            _ => PidOutput::default(),
        };
        let law = PressureLaw::Pid(ctrl, inputs, last);
        Ok(self.hyd_pressure_on(running, law, inputs.setpoint))
    }

    /// The pressure job of `instruction` that runs now, if any; refused (16#80F5) on an axis
    /// that is not hydraulic or has no pressure inputs, and, to `enable` it, while the other
    /// pressure instruction runs (inferred: each of the library's two controllers owns the
    /// control value while it runs; one must be disabled before the other takes it). Disabling
    /// an instruction that does not run changes nothing.
    fn hyd_pressure_running(
        &self,
        instruction: Instruction,
        enable: bool,
    ) -> Result<Option<PressureJob>, ErrorId> {
        let refused = ErrorId::IllegalControllerParameter;
        let h = self.hyd.as_deref().ok_or(refused)?;
        if h.actual.is_none() {
            return Err(refused);
        }
        match h.pressure {
            Some(pj) if pj.instruction() != instruction && enable => Err(refused),
            Some(pj) if pj.instruction() != instruction => Ok(None),
            running => Ok(running),
        }
    }

    /// Ends the running pressure job (Done), the axis standing in position control at its
    /// actual position; with none running, a new job that is Done at once.
    fn hyd_pressure_off(
        &mut self,
        running: Option<PressureJob>,
        instruction: Instruction,
    ) -> JobId {
        let Some(pj) = running else {
            let id = self.new_id();
            self.emit(id, instruction, JobEventKind::Done);
            return id;
        };
        self.hyd_pressure_end();
        self.basic = State::rest(self.actual_p);
        self.finish_main(pj.job, instruction);
        pj.job
    }

    /// Starts a pressure job with `law` and set value `set`, or gives a running one (the same
    /// job) its new law and set value.
    fn hyd_pressure_on(
        &mut self,
        running: Option<PressureJob>,
        law: PressureLaw,
        set: f64,
    ) -> JobId {
        if let Some(pj) = running {
            if let Some(p) = self.hyd.as_deref_mut().and_then(|h| h.pressure.as_mut()) {
                *p = PressureJob { law, set, ..*p };
            }
            return pj.job;
        }
        let instruction = PressureJob::instruction_of(&law);
        self.fold_superimposed();
        let v = self.basic.v;
        let lim = self.default_limits();
        let job = self.start_main(
            instruction,
            lim,
            Goal::Direct {
                position: None,
                v,
                a: 0.0,
            },
        );
        if let Some(h) = self.hyd.as_deref_mut() {
            h.pressure = Some(PressureJob {
                law,
                set,
                job,
                last: PressureOutput::default(),
            });
        }
        job
    }

    /// The pressure controller no longer runs.
    fn hyd_pressure_end(&mut self) {
        if let Some(h) = self.hyd.as_deref_mut() {
            h.pressure = None;
        }
    }

    /// One cycle of a running pressure or force control: the control value from the
    /// controller, the set position following the actual one (no position control). Returns
    /// whether it ran; a pressure job that is no longer the axis' job (aborted) ends it.
    fn hyd_pressure_generate(&mut self) -> bool {
        let (dt, actual_p) = (self.cfg.cycle, self.actual_p);
        let main = self.main.map(|m| m.id);
        let Some(h) = self.hyd.as_deref_mut() else {
            return false;
        };
        let Some(pj) = h.pressure.as_mut() else {
            return false;
        };
        if main != Some(pj.job) {
            h.pressure = None;
            return false;
        }
        let actual = h.actual.unwrap_or_default();
        pj.step(&actual, dt);
        self.basic = State {
            p: actual_p,
            v: pj.last.set_speed * h.ref_velo,
            a: 0.0,
        };
        true
    }

    /// The hydraulic axis' generator and target window; `None` for an electric axis.
    pub fn hydraulic_status(&self) -> Option<HydraulicStatus> {
        self.hyd.as_deref().map(|h| HydraulicStatus {
            state: h.last.state,
            positive: h.last.positive,
            engaged: h.engaged,
            target: self.hyd_ext_gen_target().unwrap_or_else(|| h.gen.target()),
            in_target_range: h.window.in_target_range,
            in_target: h.window.in_target,
            actual: h.actual,
            pressure_control: h.pressure.map(|p| (p.set, p.last)),
            pressure_ff: h.pressure.and_then(|p| match p.law {
                PressureLaw::Pid(_, _, out) => Some(out),
                PressureLaw::Pi(_) => None,
            }),
            auto_zero: h.auto_zero.map(|(a, on)| (a.status(), on)),
            slow_down: h.slow_down.map(|(_, s)| s),
            zero_compensation: self.hyd_zero_compensation(),
        })
    }

    /// `MC_AxCtrlAutoZero_BkPlcMc`: with `enable` the zero compensation adjusts
    /// `fZeroCompensation` at standstill (a running one takes the new parameters, its value
    /// kept); without, it stops adjusting and the value stays. Done at once (its outputs are in
    /// [`HydraulicStatus::auto_zero`]). Refused with 16#8002 on an electric axis, with 16#80F5
    /// for a parameter out of its range or a valve with overlap compensation (the library: "may
    /// only be used for zero overlap valves").
    pub(super) fn cmd_auto_zero(
        &mut self,
        enable: bool,
        params: AutoZeroParams,
    ) -> Result<JobId, ErrorId> {
        let h = self.hyd.as_deref_mut().ok_or(ErrorId::IllegalObject)?;
        let refused = ErrorId::IllegalControllerParameter;
        let finish = &h.controller.finish;
        if finish.overlap_comp_p != 0.0 || finish.overlap_comp_m != 0.0 {
            return Err(refused);
        }
        h.auto_zero = match h.auto_zero {
            Some((mut a, _)) => {
                a.retune(params).map_err(|_| refused)?;
                Some((a, enable))
            }
            None => Some((
                AutoZero::new(
                    params,
                    // From the value MC_AxUtiOffsetLatch_BkPlcMc latched, if it did.
                    h.cmds
                        .direct
                        .latched_zero()
                        .unwrap_or(finish.zero_compensation),
                )
                .map_err(|_| refused)?,
                enable,
            )),
        };
        let id = self.new_id();
        self.emit(id, Instruction::AutoZero, JobEventKind::Done);
        Ok(id)
    }

    /// One cycle of MC_AxCtrlAutoZero_BkPlcMc, once it has been enabled: after the setpoint of
    /// this cycle, before the drive's outputs (the library calls it before Finish). Enabled
    /// with the axis enabled and no pressure or force control running; idle when the setpoint
    /// stands with the position controller acting.
    pub(super) fn hyd_auto_zero(&mut self) {
        // Electric axes and hydraulic ones without AutoZero return before any cyclic work.
        if self.hyd.as_deref().is_none_or(|h| h.auto_zero.is_none()) {
            return;
        }
        let (enabled, position_control) = (self.enabled, self.hyd_position_control());
        let total = self.total();
        let (actual_p, actual_v, dt) = (self.actual_p, self.actual_v, self.cfg.cycle);
        let Some(h) = self.hyd.as_deref_mut() else {
            return;
        };
        let Some((a, on)) = h.auto_zero.as_mut() else {
            return;
        };
        let idle =
            position_control && total.v == 0.0 && (!h.engaged || h.last.state == HydState::Idle);
        a.step(&AutoZeroInput {
            enabled: *on && enabled && h.pressure.is_none(),
            idle,
            lag: total.p - actual_p,
            lag_amp: h.controller.lag_amp,
            ref_velo: h.controller.finish.ref_velo,
            window: h.controller.lag_amp_dx,
            actual_velocity: actual_v,
            dt,
        });
    }

    /// What the valve's Finish stage takes from the axis this cycle: the generator's pressing
    /// output at the target (while it computes the setpoint), AutoZero's compensation and the
    /// direct output `direct` ([`Self::hyd_direct_output`], looked up once by the caller).
    pub(super) fn hyd_valve_outputs(&self, direct: Option<f64>) -> HydValveOutputs {
        match self.hyd.as_deref() {
            Some(h) => HydValveOutputs {
                clamping_output: if h.engaged && h.pressure.is_none() {
                    h.last.clamping_output
                } else {
                    0.0
                },
                zero_compensation: h
                    .auto_zero
                    .map(|(a, _)| a.status().compensation)
                    .or(h.cmds.direct.latched_zero()),
                locked: h.cmds.outputs_locked(),
                direct_output: direct,
            },
            None => HydValveOutputs::default(),
        }
    }

    /// MC_Power_BkPlcMc, MC_AxCtrlPressure_BkPlcMc and MC_AxCtrlAutoZero_BkPlcMc (each refuses
    /// an electric axis with its own code); any other command is refused (16#8002).
    pub(super) fn apply_hyd_control(&mut self, cmd: &Command) -> Result<JobId, ErrorId> {
        match *cmd {
            Command::HydPower {
                enable,
                enable_positive,
                enable_negative,
            } => {
                self.hyd_set_feed_enables(enable_positive, enable_negative)?;
                Ok(self.cmd_power(enable, StartMode::PositionControlled, StopMode::Emergency))
            }
            Command::PressureControl {
                enable,
                set_value,
                kp,
                tn,
                preset,
                windup_limit,
                force,
            } => self.cmd_pressure_control(
                enable,
                set_value,
                crate::hydraulic::pressure::PressureParams {
                    kp,
                    tn,
                    preset,
                    windup_limit,
                    reading: if force {
                        crate::hydraulic::pressure::PressureReading::Force
                    } else {
                        crate::hydraulic::pressure::PressureReading::Pressure
                    },
                },
            ),
            Command::PressureControlFf {
                enable,
                reset,
                inputs,
                params,
            } => self.cmd_pressure_control_ff(enable, reset, inputs, params),
            Command::AutoZero { enable, params } => self.cmd_auto_zero(enable, params),
            Command::SlowDownOnPressure { enable, params } => self.cmd_slow_down(enable, params),
            _ => Err(ErrorId::IllegalObject),
        }
    }
}
