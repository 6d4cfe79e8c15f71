//! `MC_AxCtrlSlowDownOnPressureEx_BkPlcMc` on a hydraulic axis (Beckhoff TwinCAT PLC Hydraulic
//! Positioning library, 4.4.1.5): while enabled, each cycle before the displacement generator's
//! step the permissible velocity from the margin of the actual pressure or force to its set value
//! ([`crate::hydraulic::slow_down`]) limits the generator's set velocity; `Active` while it cuts
//! it. The axis stops where the set value is reached, short of its target if need be (the
//! positioning stays Busy, as in the library: "the axis should come to a standstill now at the
//! latest"), and backs off with `EnableRelief`.

use super::hydraulic::HydAxis;
use super::Axis;
use crate::catalog::error_id::ErrorId;
use crate::hydraulic::jerk_generator::ProfileType;
use crate::hydraulic::profile_core::ProfileGenerator;
use crate::hydraulic::slow_down::{SlowDownParams, SlowDownStatus};
use crate::objects::job::{Instruction, JobEventKind, JobId};

impl HydAxis {
    /// The limiter's cycle, before the generator steps: the permissible velocity from the
    /// sample of this cycle handed to the generator (none without the limiter).
    pub(super) fn slow_down_before(&mut self) {
        let limit = match (&mut self.slow_down, self.actual) {
            (Some((p, status)), Some(a)) => {
                *status = p.step(self.last.velocity.abs(), &a);
                status.permissible
            }
            _ => f64::INFINITY,
        };
        self.gen.limit_velocity(limit);
    }

    /// After the generator's step: `Active` when it cut the set velocity.
    pub(super) fn slow_down_after(&mut self) {
        if let Some((_, status)) = &mut self.slow_down {
            status.active = self.gen.limited();
        }
    }
}

impl Axis {
    /// `MC_AxCtrlSlowDownOnPressureEx_BkPlcMc`: with `enable` the limiter runs with `params`
    /// (a running one takes them); without, it ends. Refused (16#80F5) on an axis without
    /// pressure inputs, a time-based one or one on the jerk-based generator, and with inputs
    /// the library refuses (`kP` not above 0, `|Setpoint| ·
    /// kP` below the creep velocity), 16#8002 on an axis that is not hydraulic; nothing
    /// changes then. Done at once: the limiter's `Busy` and `Active` are in
    /// [`super::HydraulicStatus::slow_down`].
    pub(super) fn cmd_slow_down(
        &mut self,
        enable: bool,
        params: SlowDownParams,
    ) -> Result<JobId, ErrorId> {
        let h = self.hyd.as_deref_mut().ok_or(ErrorId::IllegalObject)?;
        if enable {
            let refused = ErrorId::IllegalControllerParameter;
            // The library's prerequisites: pressure inputs, a displacement-controlled axis
            // (not time-based); the limit is built for the displacement generator only.
            let ctrl_based = h.gen.profile_type() == ProfileType::CtrlBased;
            if h.actual.is_none() || h.time_based || !ctrl_based {
                return Err(refused);
            }
            let g = h.gen.params();
            let creep = g.approach_p.creep_speed.min(g.approach_m.creep_speed);
            params.check(creep).map_err(|_| refused)?;
            let status = h.slow_down.map_or(SlowDownStatus::default(), |(_, s)| s);
            h.slow_down = Some((params, status));
        } else {
            h.slow_down = None;
            h.gen.limit_velocity(f64::INFINITY);
        }
        let id = self.new_id();
        self.emit(id, Instruction::SlowDownOnPressure, JobEventKind::Done);
        Ok(id)
    }
}
