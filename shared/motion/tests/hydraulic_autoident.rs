//! The automatic identification `MC_AxUtiAutoIdent_BkPlcMc` (docs/hydraulics.md, "Automatic
//! identification") run open loop at 1 ms against the simulated valve and cylinder, whose
//! overlap, offset, bend and unequal edges are known: the issue's check "auto-identification
//! recovers the model's overlap, offset and area ratio within 5 % and a curve whose inverse
//! linearises the model within 5 % of full scale", and the end stops within 0.5 mm; once without
//! friction, once with 300 N of Coulomb friction.
//!
//! The model's values are derived independently of the identification: the overlap and offset
//! from its parameters (the spool follows the output plus the offset; no edge opens within the
//! overlap, so the thresholds are `±overlap - offset`), the area ratio and the full-scale
//! velocity by stepping the cylinder open loop at constant outputs from a fresh start.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::hydraulic::autoident::{AutoIdent, AutoIdentParams};
use tandem_motion::plant::hydraulic::{CylinderParams, SimCylinder};
use tandem_testkit::counting::measure;

tandem_testkit::counting_allocator!();

const DT: f64 = 1e-3;

/// 10 % overlap, a zero offset of 3 % (0.3 V), a bend (25 % of the flow at 40 % of the
/// opening), edges of B passing 60 % of A's flow.
fn cylinder() -> CylinderParams {
    CylinderParams {
        overlap: 0.1,
        offset: 0.03,
        bend_opening: 0.4,
        bend_flow: 0.25,
        flow_ratio_b: 0.6,
        ..CylinderParams::example()
    }
}

fn params() -> AutoIdentParams {
    AutoIdentParams {
        end_of_travel_negativ_limit: 10.0,
        end_of_travel_positiv_limit: 10.0,
        tbl_count: 21,
        low_end: 150.0,
        high_end: 350.0,
        ramp: 0.5,
        settling: 0.2,
        recovery: 0.3,
        min_cycle: 50.0,
        ..AutoIdentParams::default()
    }
}

/// The steady velocity (mm/s) at constant output `u` from `x`: the mean over 0.3..0.6 s (the
/// oil column rings after the start).
fn steady_velocity(m: CylinderParams, u: f64, x: f64) -> f64 {
    let mut c = SimCylinder::new(m, x).unwrap();
    let mut x1 = 0.0;
    for i in 1..=600 {
        let s = c.step(u, DT);
        if i == 300 {
            x1 = s.position;
        }
    }
    (c.state().position - x1) / 0.3
}

/// A steady velocity from the end of travel that gives room in its direction.
fn model_velocity(m: CylinderParams, u: f64) -> f64 {
    let v = steady_velocity(m, u, 250.0);
    steady_velocity(m, u, if v >= 0.0 { 20.0 } else { 480.0 })
}

/// Runs the identification to its end; returns it and the simulated seconds it took. From
/// `Execute` to the finished table nothing is allocated (counted).
fn identify(m: CylinderParams) -> (AutoIdent, f64) {
    let mut id = AutoIdent::new(params()).unwrap();
    let mut cyl = SimCylinder::new(m, 250.0).unwrap();
    let mut t = 0.0;
    let mut steps_seen = 0;
    let mut last_step = -1;
    let counts = measure(|| run_to_end(&mut id, &mut cyl, &mut t, &mut steps_seen, &mut last_step));
    assert_eq!(
        counts.allocations, 0,
        "allocations during the identification"
    );
    assert!(steps_seen > 50, "{steps_seen} steps");
    assert_eq!(id.error(), None);
    assert!(id.done());
    (id, t)
}

fn run_to_end(
    id: &mut AutoIdent,
    cyl: &mut SimCylinder,
    t: &mut f64,
    steps_seen: &mut u32,
    last_step: &mut i16,
) {
    id.execute();
    while id.busy() {
        let s = *cyl.state();
        let u = id.step(DT, s.position, s.velocity);
        assert!(u.abs() <= 1.0 + 1e-12, "output {u}");
        cyl.step(u, DT);
        if id.step_number() != *last_step {
            *last_step = id.step_number();
            *steps_seen += 1;
        }
        *t += DT;
        assert!(*t < 2000.0, "still busy");
    }
}

#[test]
fn auto_identification_recovers_the_models_parameters_and_linearises_it() {
    check_identification(cylinder());
}

/// The same with 300 N of Coulomb friction (stick-slip at breakaway): the pressure must build
/// before the axis moves.
#[test]
fn with_coulomb_friction_too() {
    check_identification(CylinderParams {
        coulomb: 300.0,
        ..cylinder()
    });
}

fn check_identification(m: CylinderParams) {
    let (id, t) = identify(m);
    let r = *id.result();
    eprintln!("identified in {t:.1} s (simulated): {r:#?}");

    // End of travel: the stops at 0 and the stroke.
    assert!(r.end_of_travel_negativ_done && r.end_of_travel_positiv_done);
    assert!(
        r.end_of_travel_negativ.abs() <= 0.5,
        "{}",
        r.end_of_travel_negativ
    );
    assert!(
        (r.end_of_travel_positiv - m.stroke).abs() <= 0.5,
        "{}",
        r.end_of_travel_positiv
    );

    // Overlap and offset: the thresholds ±overlap - offset.
    let within = |got: f64, want: f64, what: &str| {
        let rel = (got - want).abs() / want.abs();
        eprintln!(
            "{what}: identified {got:.5}, model {want:.5}, {:.2} %",
            rel * 100.0
        );
        assert!(rel <= 0.05, "{what}: {got} against {want}");
    };
    within(r.overlap_comp_p, m.overlap, "overlap");
    within(r.overlap_comp_m, m.overlap, "overlap M");
    // fZeroCompensation cancels the valve's offset: -offset · 10 V.
    within(
        r.zero_compensation,
        -m.offset * 10.0,
        "fZeroCompensation (V)",
    );

    // Area ratio: the model's steady velocities at ±1 V beyond the true overlap and offset.
    let v_p = model_velocity(m, 0.1 + m.overlap - m.offset);
    let v_m = model_velocity(m, -0.1 - m.overlap - m.offset);
    eprintln!("model at ±1 V: {v_p:.3} / {v_m:.3} mm/s");
    within(r.area_ratio, v_m.abs() / v_p.abs(), "fAreaRatio");

    // The curve: its output for a target velocity, plus fZeroCompensation, as Finish's
    // characteristic-curve linearisation forms it, applied open loop.
    let table = id.table().expect("a table");
    assert_eq!(table.len(), 21);
    let full = model_velocity(m, 1.0 - m.offset)
        .abs()
        .max(model_velocity(m, -1.0 - m.offset).abs());
    eprintln!(
        "fRefVelo identified {:.2}, model full scale {full:.2} mm/s",
        r.ref_velo
    );
    within(r.ref_velo, full, "fRefVelo");
    // The targets across the range each direction reaches (the retracting one is the slower:
    // the table's first point, at output -1.0).
    let (v_min, _) = table.points().next().unwrap();
    let (v_max, _) = table.points().last().unwrap();
    eprintln!("table velocities {v_min:.4} .. {v_max:.4}");
    assert!(v_min < -0.5 && v_max == 1.0, "{v_min} {v_max}");
    let mut worst: f64 = 0.0;
    let mut count = 0;
    for i in -20..=20 {
        let target = f64::from(i) * 0.05;
        if target < v_min {
            continue;
        }
        count += 1;
        let u = table.output(target, 0.0) + r.zero_compensation / 10.0;
        let v = model_velocity(m, u);
        let err = (v - target * r.ref_velo).abs() / full;
        worst = worst.max(err);
        assert!(
            err <= 0.05,
            "target {target}: output {u:.4}, velocity {v:.2} mm/s against {:.2} ({:.2} % of full scale)",
            target * r.ref_velo,
            err * 100.0
        );
    }
    assert!(count >= 34, "{count} targets");
    eprintln!(
        "linearised: worst deviation {:.2} % of full scale over {count} targets",
        worst * 100.0
    );
}

#[test]
fn without_the_curve_the_identification_stops_after_the_area_ratio() {
    let mut id = AutoIdent::new(AutoIdentParams {
        enable_valve_characteristic: false,
        ..params()
    })
    .unwrap();
    let mut cyl = SimCylinder::new(cylinder(), 100.0).unwrap();
    id.execute();
    let mut t = 0.0;
    while id.busy() && t < 600.0 {
        let s = *cyl.state();
        let u = id.step(DT, s.position, s.velocity);
        cyl.step(u, DT);
        t += DT;
    }
    assert!(id.done(), "{:?}", id.error());
    assert!(id.table().is_none());
    assert!(id.result().area_ratio > 0.0);
    assert_eq!(id.result().measured_points, 0);
}

#[test]
fn a_valve_that_does_not_open_within_the_limit_fails_with_not_moving() {
    // 40 % overlap, 3 V limits: the search reaches the limit without motion.
    let mut id = AutoIdent::new(AutoIdentParams {
        enable_end_of_travel: false,
        end_of_travel_negativ: 0.0,
        end_of_travel_positiv: 500.0,
        end_of_travel_negativ_limit: 3.0,
        end_of_travel_positiv_limit: 3.0,
        ..params()
    })
    .unwrap();
    let mut cyl = SimCylinder::new(
        CylinderParams {
            overlap: 0.4,
            ..cylinder()
        },
        250.0,
    )
    .unwrap();
    id.execute();
    let mut t = 0.0;
    while id.busy() && t < 600.0 {
        let s = *cyl.state();
        let u = id.step(DT, s.position, s.velocity);
        cyl.step(u, DT);
        t += DT;
    }
    let e = id.error().expect("an error");
    assert_eq!(e.code().0, 0x435D, "{e}");
    assert!(!id.done());
    assert_eq!(id.step(DT, 250.0, 0.0), 0.0);
}
