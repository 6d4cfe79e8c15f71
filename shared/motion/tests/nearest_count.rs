//! The count nearest to a position (`Scaling::count`, the drive's `Scaling::drive_increments`,
//! 0x607A) is the nearest by the exact positions of the counts, whatever path computes it: for
//! random mechanics and positions, including those within 1e-6 of a count and of half-way
//! between two counts, the answer is a count whose position is no farther from the position
//! than its neighbours' (ties: either). Guards the fast path of the count search (issue 11's
//! drives bench), which must give the very count the full search gives.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use tandem_motion::plant::mechanics::{EncoderConfig, EncoderKind, Mechanics, Mounting, Scaling};

/// A scaling: `steps` per motor revolution, gear `n : d`, an optional leadscrew `pitch`, the
/// drive's increments per revolution `drive`.
fn scaling((steps, n, d, pitch, drive): (u32, u32, u32, Option<f64>, u32)) -> Scaling {
    let e = EncoderConfig {
        kind: EncoderKind::Incremental,
        steps_per_revolution: steps,
        fine_resolution_bits: 0,
        determinable_revolutions: 1,
        raw_bits: 32,
        inverse: false,
        mounting: Mounting::MotorShaft,
    };
    let m = Mechanics {
        load_gear_numerator: n,
        load_gear_denominator: d,
        leadscrew_pitch: pitch,
        drive_increments_per_revolution: Some(drive),
        ..Mechanics::default()
    };
    Scaling::new(&e, &m).unwrap()
}

/// Whether `c` is a nearest count to `x` among its neighbours, by `pos`.
fn nearest(pos: impl Fn(i64) -> f64, c: i64, x: f64) -> bool {
    let d = |k: i64| (pos(k) - x).abs();
    d(c) <= d(c - 1) && d(c) <= d(c + 1)
}

#[test]
fn the_count_is_the_nearest_on_every_path() {
    let config = Config {
        cases: 4000,
        failure_persistence: None,
        ..Config::default()
    };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[40; 32]);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let mechanics = (
        prop::sample::select(vec![1000u32, 4096, 10_000, 1 << 20, 8_388_608]),
        1u32..50,
        1u32..50,
        prop::option::of(prop::sample::select(vec![5.0, 10.0, 2.54, 0.1])),
        prop::sample::select(vec![1000u32, 4096, 1 << 20, 1 << 23]),
    );
    // A count, and where near it: anywhere, within 1e-6 of it, or within 1e-6 of half-way.
    let at = (
        -(1i64 << 31)..(1i64 << 31),
        prop::sample::select(vec![0u8, 1, 2]),
        -1.0f64..1.0,
    );
    runner
        .run(&(mechanics, at), |(m, (c0, near, f))| {
            let s = scaling(m);
            let frac = match near {
                0 => f,
                1 => f * 1e-6,
                _ => 0.5 + f * 1e-6,
            };
            let x = s.position(c0) + frac * (s.position(c0 + 1) - s.position(c0));
            let c = s.count(x);
            prop_assert!(nearest(|k| s.position(k), c, x), "count {c} for {x}");
            let xd =
                s.drive_position(c0) + frac * (s.drive_position(c0 + 1) - s.drive_position(c0));
            let k = s.drive_increments(xd);
            // The increment count is the nearest, wrapped to 32 bits like 0x607A.
            let near_ok = [-1i64, 0, 1].iter().any(|dk| {
                let cand = i64::from(k) + dk * (1 << 32);
                nearest(|j| s.drive_position(j), cand, xd)
            });
            prop_assert!(near_ok, "increments {k} for {xd}");
            Ok(())
        })
        .unwrap();
}
