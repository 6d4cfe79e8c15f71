//! `[cell] watchdog_ms` and `watchdog_restart_ms` (`tandem up`'s watchdog): defaults 500 ms and
//! 2 s; each range-checked before it becomes nanoseconds, the error naming the key and line.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::parse;

const CELL: &str = "[cell]
name = \"c\"

[[nodes]]
name = \"n1\"
cycle_us = 1000

[axes.master]
node = \"n1\"
virtual = true

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

fn with(keys: &str) -> String {
    CELL.replacen("name = \"c\"\n", &format!("name = \"c\"\n{keys}"), 1)
}

#[test]
fn the_watchdog_defaults_to_half_a_second_and_restarts_after_two() {
    let c = parse("cell.toml", CELL).unwrap();
    assert_eq!(
        (c.watchdog_ns, c.watchdog_restart_ns),
        (500_000_000, 2_000_000_000)
    );
    let c = parse(
        "cell.toml",
        &with("watchdog_ms = 250\nwatchdog_restart_ms = 250\n"),
    )
    .unwrap();
    assert_eq!(
        (c.watchdog_ns, c.watchdog_restart_ns),
        (250_000_000, 250_000_000)
    );
}

#[test]
fn watchdog_times_out_of_range_are_refused_naming_the_key() {
    for (keys, key) in [
        ("watchdog_ms = 0\n", "cell.watchdog_ms"),
        ("watchdog_ms = 9\n", "cell.watchdog_ms"),
        ("watchdog_ms = 3600001\n", "cell.watchdog_ms"),
        (
            "watchdog_ms = 9223372036854775807\nwatchdog_restart_ms = 9223372036854775807\n",
            "cell.watchdog_ms",
        ),
        (
            "watchdog_ms = 600\nwatchdog_restart_ms = 500\n",
            "cell.watchdog_restart_ms",
        ),
        (
            "watchdog_restart_ms = 3600001\n",
            "cell.watchdog_restart_ms",
        ),
    ] {
        let text = with(keys);
        let e = parse("cell.toml", &text).unwrap_err();
        assert_eq!(e.key, key, "{keys}");
        let short = key.trim_start_matches("cell.");
        let line = text
            .lines()
            .position(|l| l.starts_with(&format!("{short} ")));
        assert_eq!(e.line, line.map(|l| l + 1), "{keys}: {e}");
        assert!(e.line >= Some(3), "{e}");
    }
}
