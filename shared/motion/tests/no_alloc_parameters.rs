//! MC_WriteParameter and MC_ReadParameter do not allocate, nor does any cycle after a write: a
//! counting global allocator, armed only on the test thread, counts every allocation while an
//! axis moves and every writable tag is written (and read back, and one invalid value refused)
//! mid-motion, each followed by 50 cycles.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::axis::{
    Axis, AxisConfig, Command, Direction, StartMode, StopMode, AXIS_PARAMETERS,
};
use tandem_motion::objects::parameter::ParamType;
use tandem_testkit::counting::{arm, disarm};

tandem_testkit::counting_allocator!();

const MS: i64 = 1_000_000;

#[test]
fn writes_reads_and_the_cycles_after_them_do_not_allocate() {
    let mut axis = Axis::new(AxisConfig::example(0.001)).unwrap();
    let mut k = 0i64;
    axis.step(0);
    axis.command(&Command::Power {
        enable: true,
        start_mode: StartMode::PositionControlled,
        stop_mode: StopMode::Emergency,
    })
    .unwrap();
    axis.command(&Command::Home {
        mode: 0,
        position: 0.0,
    })
    .unwrap();
    axis.command(&Command::MoveAbsolute {
        position: 2000.0,
        dynamics: Dynamics {
            velocity: 300.0,
            acceleration: 1000.0,
            deceleration: 1000.0,
            jerk: 20_000.0,
        },
        direction: Direction::Shortest,
    })
    .unwrap();
    let (mut accepted, mut refused) = (0u32, 0u32);
    arm();
    for (i, e) in AXIS_PARAMETERS.iter().enumerate() {
        let n = u16::try_from(i + 1).unwrap_or(0);
        let old = axis.read_parameter(n).unwrap_or(0.0);
        let new = match e.ty {
            ParamType::Bool => 1.0 - old,
            ParamType::Real if old != 0.0 => old * 0.95,
            ParamType::Real => 1.0,
        };
        let ok = axis
            .command(&Command::WriteParameter {
                parameter: n,
                value: new,
            })
            .is_ok();
        accepted += u32::from(ok);
        refused += u32::from(
            axis.command(&Command::WriteParameter {
                parameter: n,
                value: f64::NAN,
            })
            .is_err(),
        );
        // The read is checked by axis_parameters.rs; here only that it does not allocate.
        let _read = axis.command(&Command::ReadParameter { parameter: n });
        for _ in 0..50 {
            k += 1;
            axis.step(k * MS);
            while axis.pop_event().is_some() {}
        }
    }
    let (allocs, _) = disarm();
    assert_eq!(allocs, 0, "allocations while writing parameters mid-motion");
    assert_eq!(accepted, 28, "every writable tag");
    assert_eq!(refused, 32);
}
