//! The absolute encoder adjustment as the axis keeps it for the runtime to retain (S7-1500T
//! Motion Control V4.0 function manual, 'Direct homing and absolute adjustment', 'When Homed is
//! lost', 'Technology DB and restart'): MC_Home 6 and 7 change it (and count the change), 0 and
//! 1 do not; a restored adjustment makes the axis homed at the retained offset, a missing or
//! void one leaves it not homed, across MC_Reset restarts too; a restore is refused on an
//! incremental encoder, an enabled axis and a non-finite offset, changing nothing.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::catalog::alarm::status_bit;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_motion::objects::axis::{
    AbsoluteOffset, Axis, AxisConfig, Command, EncoderType, RestoreOffsetError, StartMode, StopMode,
};
use tandem_motion::plant::drive::Actual;
use tandem_motion::plant::link::{DriveInputs, DriveState};

const MS: i64 = 1_000_000;
/// Where the drive stands (physical position).
const PHYS: f64 = 12.5;

/// An axis with encoder `encoder` on a connected drive standing at [`PHYS`].
struct Bench {
    axis: Axis,
    k: i64,
    inputs: DriveInputs,
}

impl Bench {
    fn new(encoder: EncoderType) -> Self {
        let mut cfg = AxisConfig::example(0.001);
        cfg.encoder = encoder;
        let mut axis = Axis::new(cfg).unwrap();
        axis.connect_drive();
        let inputs = DriveInputs {
            actual: Actual {
                p: PHYS,
                v: 0.0,
                balanced: PHYS,
            },
            state: DriveState::Operational,
            ..DriveInputs::default()
        };
        // The drive's first sample, as the runtime sets it before the axis steps.
        axis.set_drive_inputs(&inputs);
        Self { axis, k: 0, inputs }
    }

    fn step(&mut self, n: usize) {
        for _ in 0..n {
            self.axis.set_drive_inputs(&self.inputs);
            self.axis.step(self.k * MS);
            self.k += 1;
        }
    }

    fn homed(&self) -> bool {
        self.axis.status().status_word & status_bit::HOMING_DONE != 0
    }

    fn actual(&self) -> f64 {
        self.axis.status().actual_position
    }

    fn power(&mut self, enable: bool) {
        self.axis
            .command(&Command::Power {
                enable,
                start_mode: StartMode::PositionControlled,
                stop_mode: StopMode::Emergency,
            })
            .unwrap();
        self.step(5);
        assert_eq!(
            self.axis.status().status_word & status_bit::ENABLE != 0,
            enable
        );
    }

    fn home(&mut self, mode: u8, position: f64) -> Result<u32, ErrorId> {
        let r = self.axis.command(&Command::Home { mode, position });
        self.step(1);
        r
    }

    fn restart(&mut self) {
        self.axis
            .command(&Command::Reset { restart: true })
            .unwrap();
        self.step(1);
    }
}

#[test]
fn a_restored_adjustment_homes_the_axis_at_the_retained_offset() {
    let mut b = Bench::new(EncoderType::Absolute);
    let before = b.axis.absolute_offset();
    b.axis.restore_absolute_offset(Some(100.0)).unwrap();
    let after = b.axis.absolute_offset();
    assert_eq!(
        after,
        AbsoluteOffset {
            offset: 100.0,
            adjusted: true,
            changes: before.changes.wrapping_add(1),
        }
    );
    // Shown at once (the status between cycles) and from the first cycle on.
    assert!(b.homed());
    assert_eq!(b.actual(), PHYS + 100.0);
    b.step(3);
    assert!(b.homed());
    assert_eq!(b.actual(), PHYS + 100.0);
    assert_eq!(
        b.axis.status().position,
        PHYS + 100.0,
        "the setpoint follows"
    );
    // A restart keeps a retained adjustment (S7: Homed of an absolute encoder survives it).
    b.restart();
    assert!(b.homed());
    assert_eq!(b.actual(), PHYS + 100.0);
    assert_eq!(b.axis.absolute_offset(), after, "a restart changes nothing");
}

#[test]
fn nothing_retained_leaves_the_axis_not_homed_across_restarts() {
    let mut b = Bench::new(EncoderType::Absolute);
    assert!(
        b.homed(),
        "without a runtime, an absolute encoder counts as adjusted at 0"
    );
    b.axis.restore_absolute_offset(None).unwrap();
    let a = b.axis.absolute_offset();
    assert!(!a.adjusted && a.offset == 0.0 && a.changes == 1, "{a:?}");
    b.step(2);
    assert!(!b.homed());
    assert_eq!(b.actual(), PHYS);
    b.restart();
    assert!(
        !b.homed(),
        "a restart does not make an unadjusted encoder homed"
    );
    // MC_Home 0 homes the axis but is not an adjustment: not retained, lost at a restart.
    b.power(true);
    b.home(0, 3.0).unwrap();
    assert!(b.homed());
    assert_eq!(b.actual(), 3.0);
    assert_eq!(b.axis.absolute_offset(), a, "mode 0 is not retained");
    b.power(false);
    b.restart();
    assert!(!b.homed());
    assert_eq!(b.actual(), PHYS);
}

#[test]
fn mc_home_6_and_7_change_the_adjustment_and_count_each_change() {
    let mut b = Bench::new(EncoderType::Absolute);
    b.axis.restore_absolute_offset(None).unwrap();
    b.step(1);
    // Modes 6 and 7 need the axis enabled and position-controlled.
    assert_eq!(b.home(7, 40.0), Err(ErrorId::NotPositionControlled));
    assert_eq!(b.axis.absolute_offset().changes, 1);
    b.power(true);
    b.home(7, 40.0).unwrap();
    let a = b.axis.absolute_offset();
    // Known answer: the drive stands at 12.5, the axis is to read 40.
    assert_eq!((a.offset, a.adjusted, a.changes), (27.5, true, 2));
    assert!(b.homed());
    assert_eq!(b.actual(), 40.0);
    b.home(6, -2.5).unwrap();
    let a = b.axis.absolute_offset();
    assert_eq!((a.offset, a.adjusted, a.changes), (25.0, true, 3));
    assert_eq!(b.actual(), 37.5);
    // Modes 0 and 1 shift the axis but leave the adjustment (and its counter) alone.
    b.home(0, 1.0).unwrap();
    b.home(1, 1.0).unwrap();
    assert_eq!(b.actual(), 2.0);
    assert_eq!(b.axis.absolute_offset(), a);
    // The same position again is still a change (the runtime stores it again).
    b.home(7, 37.5).unwrap();
    assert_eq!(b.axis.absolute_offset().changes, 4);
    assert_eq!(b.axis.absolute_offset().offset, 25.0);
    // After a restart the axis is back on its adjustment, not on mode 0's shift.
    b.power(false);
    b.restart();
    assert!(b.homed());
    assert_eq!(b.actual(), 37.5);
}

#[test]
fn a_restore_is_refused_and_changes_nothing_when_it_cannot_apply() {
    let mut inc = Bench::new(EncoderType::Incremental);
    let a = inc.axis.absolute_offset();
    assert!(!a.adjusted);
    assert_eq!(
        inc.axis.restore_absolute_offset(Some(1.0)),
        Err(RestoreOffsetError::Incremental)
    );
    assert_eq!(inc.axis.absolute_offset(), a);
    assert!(!inc.homed());

    let mut b = Bench::new(EncoderType::Absolute);
    b.axis.restore_absolute_offset(Some(5.0)).unwrap();
    let a = b.axis.absolute_offset();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(
            b.axis.restore_absolute_offset(Some(bad)),
            Err(RestoreOffsetError::NotFinite)
        );
    }
    b.power(true);
    assert_eq!(
        b.axis.restore_absolute_offset(None),
        Err(RestoreOffsetError::Enabled)
    );
    assert_eq!(b.axis.absolute_offset(), a);
    assert!(b.homed());
    assert_eq!(b.actual(), PHYS + 5.0);
    for e in [
        RestoreOffsetError::Incremental,
        RestoreOffsetError::Enabled,
        RestoreOffsetError::NotFinite,
    ] {
        assert!(!e.to_string().is_empty());
    }
}
