//! The `*_us` keys (cycles, leading-value delay and tolerance, link budgets) are checked for
//! range before they become nanoseconds: a value near 2^63 (TOML's largest integer) used to
//! wrap when multiplied by 1000 and pass `tandem check`; now anything over one hour is refused,
//! naming the key. (Beyond 2^63 - 1 the TOML reader refuses the number itself.)
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{parse, Problem};

const CELL: &str = "[cell]
name = \"c\"

[[nodes]]
name = \"n1\"
cycle_us = 1000

[axes.master]
node = \"n1\"
virtual = true

[axes.master.leading_value]
delay_us = 3000
tolerance_us = 4000

[axes.master.dynamics]
max_velocity = 2000.0
max_acceleration = 4000.0
max_deceleration = 4000.0
max_jerk = 40000.0
velocity = 800.0
acceleration = 3000.0
deceleration = 3000.0
jerk = 30000.0
emergency_deceleration = 8000.0
";

/// The error of `CELL` with `from` replaced by `to`: its line and key.
fn refused(from: &str, to: &str) -> (Option<usize>, String, Problem) {
    assert!(CELL.contains(from), "{from}");
    let e = parse("cell.toml", &CELL.replacen(from, to, 1)).unwrap_err();
    (e.line, e.key.clone(), *e.problem)
}

#[test]
fn the_cell_parses_with_sane_values() {
    let cell = parse("cell.toml", CELL).unwrap();
    let lv = cell.axes[0].leading;
    assert_eq!((lv.delay_ns, lv.tolerance_ns), (3_000_000, 4_000_000));
}

#[test]
fn a_delay_or_tolerance_near_2_pow_63_is_refused_naming_the_key() {
    for (from, to, line, key) in [
        (
            "delay_us = 3000",
            "delay_us = 9223372036854775807",
            13,
            "axes.master.leading_value.delay_us",
        ),
        (
            "tolerance_us = 4000",
            "tolerance_us = 9223372036854775000",
            14,
            "axes.master.leading_value.tolerance_us",
        ),
        (
            "delay_us = 3000",
            "delay_us = 3600000001",
            13,
            "axes.master.leading_value.delay_us",
        ),
    ] {
        let (l, k, p) = refused(from, to);
        assert_eq!((l, k.as_str()), (Some(line), key), "{to}");
        assert!(matches!(p, Problem::Invalid(_)), "{to}: {p}");
    }
}

#[test]
fn a_budget_near_2_pow_63_is_refused_naming_the_key() {
    // (A huge `base_tick_us` is refused by the nodes' cycle check first: no cycle is a
    // multiple of it; `a_huge_base_tick_is_refused_by_the_cycle_check`.)
    for key in ["ipc_budget_us", "network_budget_us"] {
        let src = CELL.replacen(
            "name = \"c\"\n",
            &format!("name = \"c\"\n{key} = 9223372036854775807\n"),
            1,
        );
        let e = parse("cell.toml", &src).unwrap_err();
        assert_eq!(
            (e.line, e.key.as_str()),
            (Some(3), format!("cell.{key}").as_str()),
            "{e}"
        );
    }
}

#[test]
fn a_cycle_over_an_hour_is_refused() {
    let (_, k, _) = refused("cycle_us = 1000", "cycle_us = 9223372036854775000");
    assert_eq!(k, "nodes");
}

#[test]
fn a_huge_base_tick_is_refused_by_the_cycle_check() {
    let src = CELL.replacen(
        "name = \"c\"\n",
        "name = \"c\"\nbase_tick_us = 9223372036854775807\n",
        1,
    );
    let e = parse("cell.toml", &src).unwrap_err();
    assert_eq!(e.key, "nodes", "{e}");
    assert!(matches!(*e.problem, Problem::Cycle { .. }), "{e}");
}
