//! Independent oracle: profile durations against the `ruckig` package (PyPI, ruckig 0.19.4).
//! Fixtures are produced by `tests/oracle/gen_ruckig_fixtures.py` and committed; see its header
//! for how Siemens acc/dec semantics are mapped onto ruckig's signed limits.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::kinematics::profile::{plan_position, plan_velocity, Limits, State};

const FIXTURE: &str = include_str!("fixtures/ruckig_1dof.csv");

#[test]
fn durations_match_ruckig() {
    let mut n_pos = 0;
    let mut n_vel = 0;
    let mut failures = Vec::new();
    for (line_no, line) in FIXTURE.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 11, "line {}", line_no + 1);
        let num = |i: usize| -> f64 { f[i].parse().unwrap() };
        let start = State {
            p: num(2),
            v: num(3),
            a: num(4),
        };
        let target = num(5);
        let jerk = num(9);
        let lim = Limits {
            vel: num(6),
            acc: num(7),
            dec: num(8),
            jerk: if jerk.is_infinite() { 0.0 } else { jerk },
        };
        let expected = num(10);
        let profile = match f[1] {
            "pos" => {
                n_pos += 1;
                plan_position(start, target, &lim)
            }
            "vel" => {
                n_vel += 1;
                plan_velocity(start, target, &lim)
            }
            other => panic!("unknown kind {other}"),
        }
        .unwrap();
        let ours = profile.duration();
        let allowed = (1e-6f64).max(1e-4 * expected);
        if (ours - expected).abs() > allowed {
            failures.push(format!(
                "id {}: ours {ours} ruckig {expected} ({line})",
                f[0]
            ));
        }
        if f[1] == "pos" {
            let end = profile.at(ours);
            let travel = (target - start.p).abs().max(1e-9);
            assert!(
                (end.p - target).abs() <= 1e-9 * travel.max(1.0),
                "id {} end",
                f[0]
            );
        }
    }
    assert!(
        n_pos >= 1000 && n_vel >= 500,
        "fixture too small: {n_pos} pos, {n_vel} vel"
    );
    assert!(
        failures.is_empty(),
        "{} of {} cases differ:\n{}",
        failures.len(),
        n_pos + n_vel,
        failures.join("\n")
    );
}
