//! Proptest strategies shared by the property tests of the cam and measuring objects.
//!
//! ```
//! use proptest::prelude::*;
//! use proptest::strategy::ValueTree;
//! use proptest::test_runner::TestRunner;
//!
//! let mut runner = TestRunner::deterministic();
//! let l = tandem_testkit::strategies::limits()
//!     .new_tree(&mut runner)
//!     .unwrap()
//!     .current();
//! assert!((50.0..400.0).contains(&l.vel) && (5_000.0..200_000.0).contains(&l.jerk));
//! ```

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
