//! MC_DigitalCamSwitch_BkPlcMc: properties over random switch sets and motions (fixed seeds).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::objects::digital_cam_switch::{
    CamSwitch, DigitalCamSwitch, McDigitalCamSwitch, SwitchDirection, TrackOptions,
};

fn config(seed: u64) -> ProptestConfig {
    ProptestConfig {
        cases: 256,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(seed),
        ..ProptestConfig::default()
    }
}

fn direction() -> impl Strategy<Value = SwitchDirection> {
    prop_oneof![
        Just(SwitchDirection::Both),
        Just(SwitchDirection::Positive),
        Just(SwitchDirection::Negative),
    ]
}

/// A position switch on one of 4 tracks within -100..100.
fn switch() -> impl Strategy<Value = CamSwitch> {
    (1..=4i32, -100.0..100.0f64, 0.0..60.0f64, direction())
        .prop_map(|(t, f, w, d)| CamSwitch::position(t, f, f + w, d))
}

/// The expected bits at `p` moving in direction `dir`: the OR of the windows that hold `p`.
fn expected(switches: &[CamSwitch], p: f64, dir: i8) -> u32 {
    switches
        .iter()
        .filter(|s| s.first_on_position <= p && p <= s.last_on_position)
        .filter(|s| match s.axis_direction {
            SwitchDirection::Both => true,
            SwitchDirection::Positive => dir > 0,
            SwitchDirection::Negative => dir < 0,
        })
        .fold(0, |b, s| b | 1 << (s.track_number - 1))
}

proptest! {
    #![proptest_config(config(0xDC5_0001))]

    /// Without compensation and hysteresis, a monotone motion's output is at every cycle the
    /// OR of the switches' windows that hold the actual position (direction filtered).
    #[test]
    fn a_monotone_motion_outputs_the_or_of_the_windows(
        switches in prop::collection::vec(switch(), 1..12),
        steps in prop::collection::vec(0.0..3.0f64, 10..200),
        negative in any::<bool>(),
        mask in any::<u32>(),
    ) {
        let mut d = DigitalCamSwitch::new(&switches, &[TrackOptions::NONE; 4]).unwrap();
        d.call(McDigitalCamSwitch { enable: true, enable_mask: mask });
        let (sign, dir) = if negative { (-1.0, -1) } else { (1.0, 1) };
        let mut p = -150.0 * sign;
        for s in steps {
            p += sign * s;
            let bits = d.step(p, sign * 100.0, 0.001);
            prop_assert_eq!(bits, expected(&switches, p, dir) & mask, "p = {}", p);
        }
    }
}

#[test]
fn a_time_switch_trigger_is_projected_and_its_on_time_is_duration_plus_the_compensations() {
    // v = 1000/s, 1 ms cycles: OnCompensation -0.1 s triggers 100 early (at 2900);
    // OffCompensation +0.05 s: on for 1.35 + 0.05 + 0.1 = 1.5 s = 1500 cycles.
    let track = TrackOptions {
        on_compensation: -0.1,
        off_compensation: 0.05,
        hysteresis: 0.0,
    };
    let sw = [CamSwitch::time(1, 3000.0, 1.35, SwitchDirection::Both)];
    let mut d = DigitalCamSwitch::new(&sw, &[track]).unwrap();
    d.call(McDigitalCamSwitch {
        enable: true,
        enable_mask: 1,
    });
    let on: Vec<usize> = (0..4000)
        .filter(|&k| d.step(2000.0 + k as f64, 1000.0, 0.001) == 1)
        .collect();
    assert_eq!((on.first(), on.len()), (Some(&900), 1500));
    assert_eq!(on.last(), Some(&2399));
}
