//! Strategies shared by the property tests of the cam and measuring objects.

use proptest::prelude::*;
use tandem_motion::kinematics::profile::Limits;

/// Jerk-limited dynamics of a machine axis: velocity 50..400/s, acceleration and deceleration
/// 500..5000/s², jerk 5,000..200,000/s³.
pub fn limits() -> impl Strategy<Value = Limits> {
    (
        50.0f64..400.0,
        500.0f64..5000.0,
        500.0f64..5000.0,
        5_000.0f64..200_000.0,
    )
        .prop_map(|(vel, acc, dec, jerk)| Limits {
            vel,
            acc,
            dec,
            jerk,
        })
}
