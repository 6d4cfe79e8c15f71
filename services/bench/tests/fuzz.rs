//! The fuzzer in CI: 10^5 generated inputs from a fixed seed over every decoder of outside
//! input (docs/fuzzing.md), none of which may panic or be answered wrongly. Times are not
//! asserted (no wall-clock assertions); `cargo bench -p tandem-bench --bench fuzz` runs 10^7
//! and reports the slowest input.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_bench::fuzz::{self, Fixture, Plan, Target, Watch};

#[test]
fn a_hundred_thousand_inputs_make_no_decoder_panic() {
    let fixture = Fixture::new();
    // Every bundled cell without files beside it parses, so the script target has cells.
    assert!(fixture.cells() >= 9, "{} cells parsed", fixture.cells());
    let plan = Plan {
        seed: 0x7a4d_3e11,
        inputs: 100_000,
        targets: Target::ALL.to_vec(),
    };
    let mut failures = Vec::new();
    let reports = fuzz::run(&fixture, &plan, &Watch::default(), |f| {
        eprintln!("{f}");
        failures.push(f.to_string());
    });
    for r in &reports {
        eprintln!(
            "{}: {} inputs, {} accepted, {} failures, slowest {} µs",
            r.target,
            r.inputs,
            r.accepted,
            r.failures,
            r.slowest_ns / 1000
        );
    }
    assert_eq!(reports.iter().map(|r| r.inputs).sum::<u64>(), 100_000);
    // The generator reaches past the first error: some mutated inputs are still accepted, and
    // most are refused.
    for r in &reports {
        assert!(r.accepted > 0, "{}: nothing accepted", r.target);
        assert!(r.accepted < r.inputs, "{}: nothing refused", r.target);
    }
    assert!(
        failures.is_empty(),
        "{} failures: {failures:#?}",
        failures.len()
    );
}

#[test]
fn an_input_is_a_function_of_seed_target_and_index() {
    let fixture = Fixture::new();
    for t in Target::ALL {
        for i in [0, 1, 99_999] {
            assert_eq!(
                fuzz::generate(&fixture, 5, t, i),
                fuzz::generate(&fixture, 5, t, i)
            );
        }
        assert_ne!(
            (0..20)
                .map(|i| fuzz::generate(&fixture, 5, t, i))
                .collect::<Vec<_>>(),
            (0..20)
                .map(|i| fuzz::generate(&fixture, 6, t, i))
                .collect::<Vec<_>>()
        );
        assert!((0..2000).all(|i| fuzz::generate(&fixture, 5, t, i).len() <= fuzz::MAX_INPUT));
    }
}

#[test]
fn the_seeds_are_accepted_unmutated() {
    // A decoder that refused everything would pass the fuzzer: the real inputs it starts from
    // must be accepted as they are.
    let fixture = Fixture::new();
    let accepted = |t: Target, bytes: &[u8]| fuzz::feed(&fixture, t, 0, bytes).unwrap();
    assert!(accepted(
        Target::Text,
        b"units/cyan MC_GearIn --master=shaft/master --ratio-numerator=3 --ratio-denominator=5"
    ));
    assert!(accepted(
        Target::Json,
        br#"{"instruction": "MC_MoveVelocity", "params": {"velocity": 100}}"#
    ));
    assert!(accepted(Target::Cam, b"x,y\n0,0\n90,10\n180,0\n"));
    assert!(accepted(
        Target::Cell,
        include_bytes!("../../../config/press.toml")
    ));
    assert!(!accepted(Target::Cam, b"x,y\n0,NaN\n"));
    assert!(!accepted(Target::Wire, &[0u8; 63]));
}

#[test]
fn the_cells_with_cam_points_parse() {
    // The cell target reaches Cam::interpolate with points through these.
    let fixture = Fixture::new();
    assert_eq!(fixture.points_cells().len(), 3);
    for (i, c) in fixture.points_cells().iter().enumerate() {
        assert!(c.contains("points = [[0.0, 0.0]"), "{i}");
        let cell = tandem_config::parse("points.toml", c).unwrap();
        assert_eq!(cell.cams.len(), 1);
    }
}
