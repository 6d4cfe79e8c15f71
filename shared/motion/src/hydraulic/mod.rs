//! Hydraulic axes as the Beckhoff TwinCAT PLC Hydraulic Positioning library (`*_BkPlcMc`)
//! runs them: per cycle, actual values → enables → commands → generator → position controller →
//! extra controllers → Finish → drive output (the library's 'Cyclic organisation').
//!
//! The stages, pure and allocation-free (a `kind = "hydraulic"` axis runs them through
//! `objects::axis` and the analog connection, docs/hydraulics.md):
//! - [`generator`]: the displacement-based set value generator `iTcMc_ProfileCtrlBased` (start
//!   ramp, travel, square-root braking ramp to creep speed, creep, idle; stops);
//! - [`profile_core`]: what both generators share (the set values, the feed enables, the
//!   stops) and [`profile_core::ProfileGenerator`], the interface the axis runs either through;
//! - [`time_ramp`]: the time-ramp generator `iTcMc_ProfileTimeRamp` for an axis without an
//!   encoder, on four digital position cams;
//! - [`monitor`]: the target window monitoring (InTargRng, InTarget with its filter time, Done);
//! - [`finish`]: the Finish stage, `MC_AxRtFinish_BkPlcMc` (sectional linearisation: feed
//!   forward, area ratio, bend point, ramped overlap compensation, clamping output, offset) and
//!   `MC_AxRtFinishLinear_BkPlcMc` (a characteristic curve);
//! - [`valve_table`]: the characteristic curve of a valve and cylinder, read from the library's
//!   table file format and checked;
//! - [`controller`]: the position controller (`fLagAmp`, the I part) and Finish as one stage;
//! - [`controller_ex`]: the extended controller's D part and condition feedback
//!   (`MC_AxRtPosPiControllerEx_BkPlcMc`), a discrete linear system the controller adds;
//! - [`auto_zero`]: the automatic zero compensation `MC_AxCtrlAutoZero_BkPlcMc`;
//! - [`drive_output`]: the drive stage `MC_AxRtDrive_BkPlcMc` (±10 V, two coils, one coil,
//!   absolute output with direction bits, reversal);
//! - [`pressure`]: the pressures and force from two inputs (`MC_AxRtReadForceDiff_BkPlcMc`) and
//!   the pressure or force controller (`MC_AxCtrlPressure_BkPlcMc`);
//! - [`pressure_ff`]: the PID pressure or force controller with feed-forward
//!   (`MC_AxCtrlPressureFF_BkPlcMc`, `ST_TcPctrlParam`);
//! - [`slow_down`]: slowing down on pressure, `MC_AxCtrlSlowDownOnPressureEx_BkPlcMc` (a
//!   permissible velocity from the margin to a set pressure or force);
//! - [`autoident`]: the automatic identification `MC_AxUtiAutoIdent_BkPlcMc` (end of travel,
//!   overlap and offset, area ratio, characteristic curve).

pub mod auto_zero;
pub mod autoident;
pub mod controller;
pub mod controller_ex;
pub mod drive_output;
pub mod finish;
pub mod generator;
pub mod jerk_generator;
pub mod monitor;
pub mod pressure;
pub mod pressure_ff;
pub mod profile_core;
pub mod slow_down;
pub mod time_ramp;
pub mod valve_table;
