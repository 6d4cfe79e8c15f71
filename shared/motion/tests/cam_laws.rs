//! Motion laws against their closed forms and known answers; continuity per interpolation type
//! on random point sets (seeded proptest); the leading-value inverse; the approach/tie rule;
//! binary search on a 1,000-point spline.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
// The allocation check needs `unsafe impl GlobalAlloc`; it only forwards to `System`.
#![allow(unsafe_code)]

use std::f64::consts::PI;

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::cam::{
    parse_csv, BoundaryCondition, Cam, CamDefinition, CamError, Continuity, Interpolation,
    Monotonicity, MotionLaw, PieceSource, SegmentDef,
};

const ALL_LAWS: [MotionLaw; 14] = [
    MotionLaw::StraightLine,
    MotionLaw::QuadraticParabola,
    MotionLaw::Poly5,
    MotionLaw::SimpleSine,
    MotionLaw::Cycloid,
    MotionLaw::ModifiedSine,
    MotionLaw::ModifiedTrapezoid,
    MotionLaw::ModifiedAccelerationTrapezoid { lambda: 0.5 },
    MotionLaw::ModifiedAccelerationTrapezoid { lambda: 0.3 },
    MotionLaw::ModifiedAccelerationTrapezoid { lambda: 0.8 },
    MotionLaw::InclinedSine { velocity: 0.0 },
    MotionLaw::InclinedSine { velocity: 0.5 },
    MotionLaw::InclinedSine { velocity: 1.7 },
    MotionLaw::Poly7,
];

/// Grid of `n + 1` points on [0, 1]; `n` is a multiple of 40, so 1/8, 0.3, 0.5 and 0.8 are on it.
fn grid(n: usize) -> impl Iterator<Item = f64> {
    (0..=n).map(move |i| i as f64 / n as f64)
}

/// Independent textbook forms `(s, s', s'')` (written from VDI 2143 / the literature, not from
/// the implementation). `None` for the laws checked by integration only.
fn textbook(law: MotionLaw, u: f64) -> Option<(f64, f64, f64)> {
    let (s, c) = (2.0 * PI * u).sin_cos();
    Some(match law {
        MotionLaw::StraightLine => (u, 1.0, 0.0),
        MotionLaw::QuadraticParabola if u < 0.5 => (2.0 * u * u, 4.0 * u, 4.0),
        MotionLaw::QuadraticParabola => (-1.0 + 4.0 * u - 2.0 * u * u, 4.0 - 4.0 * u, -4.0),
        MotionLaw::Poly5 => (
            10.0 * u.powi(3) - 15.0 * u.powi(4) + 6.0 * u.powi(5),
            30.0 * u.powi(2) - 60.0 * u.powi(3) + 30.0 * u.powi(4),
            60.0 * u - 180.0 * u.powi(2) + 120.0 * u.powi(3),
        ),
        MotionLaw::Poly7 => (
            35.0 * u.powi(4) - 84.0 * u.powi(5) + 70.0 * u.powi(6) - 20.0 * u.powi(7),
            140.0 * u.powi(3) - 420.0 * u.powi(4) + 420.0 * u.powi(5) - 140.0 * u.powi(6),
            420.0 * u.powi(2) - 1680.0 * u.powi(3) + 2100.0 * u.powi(4) - 840.0 * u.powi(5),
        ),
        MotionLaw::SimpleSine => (
            (1.0 - (PI * u).cos()) / 2.0,
            PI / 2.0 * (PI * u).sin(),
            PI * PI / 2.0 * (PI * u).cos(),
        ),
        MotionLaw::Cycloid => (u - s / (2.0 * PI), 1.0 - c, 2.0 * PI * s),
        MotionLaw::InclinedSine { velocity: v } => (
            v * u + (1.0 - v) * (u - s / (2.0 * PI)),
            v + (1.0 - v) * (1.0 - c),
            (1.0 - v) * 2.0 * PI * s,
        ),
        MotionLaw::ModifiedSine => {
            let k = 1.0 / (4.0 + PI);
            let pos = if u <= 0.125 {
                k * (PI * u - 0.25 * (4.0 * PI * u).sin())
            } else if u <= 0.875 {
                k * (2.0 + PI * u - 9.0 / 4.0 * (PI / 3.0 + 4.0 * PI * u / 3.0).sin())
            } else {
                k * (4.0 + PI * u - 0.25 * (4.0 * PI * u).sin())
            };
            // Velocity and acceleration are checked by integration below.
            (pos, f64::NAN, f64::NAN)
        }
        _ => return None,
    })
}

/// The classic modified trapezoid acceleration (Neklutin), written piecewise.
fn modified_trapezoid_acceleration(u: f64) -> f64 {
    let a = 8.0 * PI / (PI + 2.0);
    if u <= 0.125 {
        a * (4.0 * PI * u).sin()
    } else if u <= 0.375 {
        a
    } else if u <= 0.625 {
        a * (4.0 * PI * (u - 0.375)).cos()
    } else if u <= 0.875 {
        -a
    } else {
        -a * (4.0 * PI * (u - 0.875)).cos()
    }
}

#[test]
fn laws_match_their_textbook_closed_forms() {
    for law in ALL_LAWS {
        for u in grid(4000) {
            let Some((s, v, a)) = textbook(law, u) else {
                continue;
            };
            let e = law.eval(u);
            assert!((e.value - s).abs() < 1e-13, "{law:?} s({u})");
            if !v.is_nan() {
                assert!((e.first_derivative - v).abs() < 1e-12, "{law:?} s'({u})");
                assert!((e.second_derivative - a).abs() < 1e-10, "{law:?} s''({u})");
            }
        }
    }
}

/// Integrates `s''` and `s'` of the implementation with Simpson's rule (steps aligned with
/// every breakpoint) and compares with `s'` and `s`: the three closed forms are consistent.
#[test]
fn derivatives_integrate_to_the_law() {
    let n = 24_000;
    let h = 1.0 / n as f64;
    for law in ALL_LAWS {
        let e0 = law.eval(0.0);
        let (mut v, mut s) = (e0.first_derivative, 0.0);
        for i in 0..n {
            let (u0, um, u1) = (i as f64 * h, (i as f64 + 0.5) * h, (i + 1) as f64 * h);
            // Evaluate just inside the step so that a jump of s'' (parabola) is not straddled.
            let inside = |u: f64| u.clamp(u0 + 1e-15, u1 - 1e-15);
            let (a0, am, a1) = (
                law.eval(inside(u0)).second_derivative,
                law.eval(um).second_derivative,
                law.eval(inside(u1)).second_derivative,
            );
            let (v0, vm, v1) = (
                law.eval(u0).first_derivative,
                law.eval(um).first_derivative,
                law.eval(u1).first_derivative,
            );
            v += h * (a0 + 4.0 * am + a1) / 6.0;
            s += h * (v0 + 4.0 * vm + v1) / 6.0;
            if (i + 1) % 600 == 0 {
                let e = law.eval(u1);
                assert!((e.first_derivative - v).abs() < 1e-9, "{law:?} s' at {u1}");
                assert!((e.value - s).abs() < 1e-10, "{law:?} s at {u1}");
            }
        }
        assert!((s - 1.0).abs() < 1e-10, "{law:?} s(1)");
    }
    // The modified trapezoid against its classic piecewise acceleration.
    for u in grid(4000) {
        let a = MotionLaw::ModifiedTrapezoid.eval(u).second_derivative;
        assert!(
            (a - modified_trapezoid_acceleration(u)).abs() < 1e-11,
            "MT a({u})"
        );
    }
}

#[test]
fn boundary_values() {
    let h2 = PI * PI / 2.0;
    // (law, s'(0), s''(0), s'(1), s''(1))
    let table = [
        (MotionLaw::StraightLine, 1.0, 0.0, 1.0, 0.0),
        (MotionLaw::QuadraticParabola, 0.0, 4.0, 0.0, -4.0),
        (MotionLaw::Poly5, 0.0, 0.0, 0.0, 0.0),
        (MotionLaw::SimpleSine, 0.0, h2, 0.0, -h2),
        (MotionLaw::Cycloid, 0.0, 0.0, 0.0, 0.0),
        (MotionLaw::ModifiedSine, 0.0, 0.0, 0.0, 0.0),
        (MotionLaw::ModifiedTrapezoid, 0.0, 0.0, 0.0, 0.0),
        (
            MotionLaw::ModifiedAccelerationTrapezoid { lambda: 0.3 },
            0.0,
            0.0,
            0.0,
            0.0,
        ),
        (
            MotionLaw::InclinedSine { velocity: 0.5 },
            0.5,
            0.0,
            0.5,
            0.0,
        ),
        (
            MotionLaw::InclinedSine { velocity: 1.7 },
            1.7,
            0.0,
            1.7,
            0.0,
        ),
        (MotionLaw::Poly7, 0.0, 0.0, 0.0, 0.0),
    ];
    for (law, v0, a0, v1, a1) in table {
        let (e0, e1) = (law.eval(0.0), law.eval(1.0));
        assert_eq!(e0.value, 0.0, "{law:?}");
        assert!(
            (e1.value - 1.0).abs() < 1e-15,
            "{law:?} s(1) = {}",
            e1.value
        );
        assert!((e0.first_derivative - v0).abs() < 1e-12, "{law:?}");
        assert!((e0.second_derivative - a0).abs() < 1e-12, "{law:?}");
        assert!((e1.first_derivative - v1).abs() < 1e-12, "{law:?}");
        assert!((e1.second_derivative - a1).abs() < 1e-12, "{law:?}");
    }
    // Poly7 also starts and ends without jerk: s'' ~ u² near the ends.
    let a = MotionLaw::Poly7.eval(1e-4).second_derivative;
    assert!(a.abs() < 420.0 * 1e-8 * 1.01);
    // Outside [0, 1] the argument is clamped.
    assert_eq!(MotionLaw::Poly5.eval(-1.0), MotionLaw::Poly5.eval(0.0));
    assert_eq!(MotionLaw::Poly5.eval(2.0), MotionLaw::Poly5.eval(1.0));
}

#[test]
fn known_answers() {
    let p5 = MotionLaw::Poly5;
    assert!((p5.s(0.5) - 0.5).abs() < 1e-15);
    assert!((p5.eval(0.5).first_derivative - 1.875).abs() < 1e-14);
    assert_eq!(p5.peak_velocity(), 1.875);
    assert!((p5.peak_acceleration() - 5.773_502_691_896_258).abs() < 1e-12);
    let u_a = 0.5 - 3f64.sqrt() / 6.0;
    assert!((p5.eval(u_a).second_derivative - 10.0 / 3f64.sqrt()).abs() < 1e-12);

    let cy = MotionLaw::Cycloid;
    assert!((cy.eval(0.5).first_derivative - 2.0).abs() < 1e-15);
    assert!((cy.eval(0.25).second_derivative - 2.0 * PI).abs() < 1e-14);
    assert_eq!(
        (cy.peak_velocity(), cy.peak_acceleration()),
        (2.0, 2.0 * PI)
    );

    let hs = MotionLaw::SimpleSine;
    assert!((hs.eval(0.5).first_derivative - PI / 2.0).abs() < 1e-15);
    assert_eq!(hs.peak_velocity(), PI / 2.0);
    assert!((hs.peak_acceleration() - 4.934_802_200_544_679).abs() < 1e-12);

    let ms = MotionLaw::ModifiedSine;
    assert!((ms.peak_velocity() - 1.759_6).abs() < 1e-4);
    assert!((ms.peak_acceleration() - 5.528_0).abs() < 1e-4);
    assert!((ms.eval(0.5).first_derivative - ms.peak_velocity()).abs() < 1e-14);
    assert!((ms.eval(0.125).second_derivative - ms.peak_acceleration()).abs() < 1e-12);

    let mt = MotionLaw::ModifiedTrapezoid;
    assert_eq!(mt.peak_velocity(), 2.0);
    assert!((mt.peak_acceleration() - 4.888_1).abs() < 1e-4);
    assert!((mt.eval(0.25).second_derivative - mt.peak_acceleration()).abs() < 1e-12);
    assert!((mt.eval(0.5).first_derivative - 2.0).abs() < 1e-14);

    let mat = MotionLaw::ModifiedAccelerationTrapezoid { lambda: 0.3 };
    assert!((mat.s(0.3) - 0.3).abs() < 1e-15, "s(λ) = λ");
    assert!((mat.eval(0.3).first_derivative - 2.0).abs() < 1e-14);
    assert!((mat.peak_acceleration() - 4.888_1 * 0.5 / 0.3).abs() < 1e-3);

    let p7 = MotionLaw::Poly7;
    assert!((p7.s(0.5) - 0.5).abs() < 1e-15);
    assert_eq!(p7.peak_velocity(), 2.1875);
    assert!((p7.peak_acceleration() - 7.513_2).abs() < 1e-4);

    let qp = MotionLaw::QuadraticParabola;
    assert_eq!((qp.peak_velocity(), qp.peak_acceleration()), (2.0, 4.0));
    assert_eq!(qp.s(0.5), 0.5);

    let is = MotionLaw::InclinedSine { velocity: 0.5 };
    assert!((is.eval(0.5).first_derivative - 1.5).abs() < 1e-15);
    assert_eq!(is.peak_velocity(), 1.5);
    assert_eq!(is.peak_acceleration(), PI);
    assert_eq!(MotionLaw::StraightLine.peak_velocity(), 1.0);
}

#[test]
fn peak_values_match_dense_sampling() {
    for law in ALL_LAWS {
        let (mut cv, mut ca) = (0.0f64, 0.0f64);
        for u in grid(200_000) {
            let e = law.eval(u);
            cv = cv.max(e.first_derivative.abs());
            ca = ca.max(e.second_derivative.abs());
        }
        let (pv, pa) = (law.peak_velocity(), law.peak_acceleration());
        assert!(
            cv <= pv * (1.0 + 1e-12) && cv >= pv * (1.0 - 1e-6),
            "{law:?} Cv"
        );
        assert!(ca <= pa * (1.0 + 1e-12) + 1e-12, "{law:?} Ca {ca} > {pa}");
        assert!(ca >= pa * (1.0 - 1e-6), "{law:?} Ca {ca} < {pa}");
    }
}

#[test]
fn symmetric_laws_are_point_symmetric() {
    for law in ALL_LAWS {
        let symmetric = match law {
            MotionLaw::ModifiedAccelerationTrapezoid { lambda } => lambda == 0.5,
            MotionLaw::InclinedSine { .. } | MotionLaw::StraightLine => true,
            _ => true,
        };
        if !symmetric {
            // The asymmetric trapezoid mirrors into the one with 1 − λ.
            let MotionLaw::ModifiedAccelerationTrapezoid { lambda } = law else {
                unreachable!()
            };
            let mirror = MotionLaw::ModifiedAccelerationTrapezoid {
                lambda: 1.0 - lambda,
            };
            for u in grid(400) {
                assert!(
                    (law.s(1.0 - u) - (1.0 - mirror.s(u))).abs() < 1e-14,
                    "{law:?}"
                );
            }
            continue;
        }
        for u in grid(400) {
            let (a, b) = (law.eval(u), law.eval(1.0 - u));
            assert!(
                (b.value - (1.0 - a.value)).abs() < 1e-14,
                "{law:?} s at {u}"
            );
            assert!(
                (b.first_derivative - a.first_derivative).abs() < 1e-12,
                "{law:?}"
            );
            if law != MotionLaw::QuadraticParabola || u != 0.5 {
                assert!(
                    (b.second_derivative + a.second_derivative).abs() < 1e-10,
                    "{law:?} s'' at {u}"
                );
            }
        }
    }
}

#[test]
fn laws_are_smooth_across_their_internal_breakpoints() {
    let mut laws = ALL_LAWS.to_vec();
    laws.push(MotionLaw::ModifiedAccelerationTrapezoid { lambda: 0.3 });
    for law in laws {
        let mut points = law.breakpoints().to_vec();
        if let MotionLaw::ModifiedAccelerationTrapezoid { lambda } = law {
            let mu = 1.0 - lambda;
            points = vec![
                lambda / 4.0,
                3.0 * lambda / 4.0,
                lambda,
                lambda + mu / 4.0,
                lambda + 3.0 * mu / 4.0,
            ];
        }
        for b in points {
            let (l, r) = (law.eval(b - 1e-9), law.eval(b + 1e-9));
            assert!((l.value - r.value).abs() < 1e-8, "{law:?} at {b}");
            assert!((l.first_derivative - r.first_derivative).abs() < 1e-7);
            if law == MotionLaw::QuadraticParabola {
                assert_eq!(r.second_derivative - l.second_derivative, -8.0, "C1 only");
            } else {
                assert!(
                    (l.second_derivative - r.second_derivative).abs() < 1e-6,
                    "{law:?} s'' at {b}"
                );
            }
        }
    }
}

#[test]
fn monotonic_laws_never_fall() {
    for law in ALL_LAWS {
        if law == (MotionLaw::InclinedSine { velocity: 1.7 }) {
            continue; // monotonic too (0 ≤ v ≤ 2), checked below with v = 2.5
        }
        for u in grid(10_000) {
            assert!(law.eval(u).first_derivative >= -1e-12, "{law:?} at {u}");
        }
    }
    let over = MotionLaw::InclinedSine { velocity: 2.5 };
    assert!(over.eval(0.5).first_derivative < 0.0, "v > 2 overshoots");
}

#[test]
fn a_law_segment_maps_onto_its_box() {
    for law in ALL_LAWS {
        let (x0, x1, y0, y1) = (2.0, 5.0, 1.0, -3.0);
        let cam = Cam::interpolate(&CamDefinition {
            segments: vec![SegmentDef::Law {
                law,
                x0,
                x1,
                y0,
                y1,
            }],
            ..CamDefinition::default()
        })
        .unwrap();
        assert_eq!(cam.leading_range(), (2.0, 5.0));
        assert!((cam.rise() - (y1 - y0)).abs() < 1e-14);
        for u in grid(200) {
            let s = law.eval(u);
            let v = cam.following(x0 + u * (x1 - x0)).unwrap();
            let dy = y1 - y0;
            let h = x1 - x0;
            assert!((v.value - (y0 + dy * s.value)).abs() < 1e-13, "{law:?}");
            assert!((v.first_derivative - dy / h * s.first_derivative).abs() < 1e-12);
            if law != MotionLaw::QuadraticParabola || u != 0.5 {
                assert!(
                    (v.second_derivative - dy / (h * h) * s.second_derivative).abs() < 1e-11,
                    "{law:?} at {u}"
                );
            }
        }
    }
}

// --- Continuity per interpolation type on random point sets ---------------------------------

/// Sorted, distinct random points: spacing 0.05..2, y in -10..10.
fn point_set(max: usize) -> impl Strategy<Value = Vec<(f64, f64)>> {
    (
        -100.0f64..100.0,
        prop::collection::vec((0.05f64..2.0, -10.0f64..10.0), 2..max),
    )
        .prop_map(|(x0, steps)| {
            let mut x = x0;
            steps
                .into_iter()
                .map(|(dx, y)| {
                    x += dx;
                    (x, y)
                })
                .collect()
        })
}

/// Strictly increasing random points: spacing 0.05..2, rise 0.1..5 per step.
fn increasing_set(max: usize) -> impl Strategy<Value = Vec<(f64, f64)>> {
    (
        -100.0f64..100.0,
        -50.0f64..50.0,
        prop::collection::vec((0.05f64..2.0, 0.1f64..5.0), 2..max),
    )
        .prop_map(|(x0, y0, steps)| {
            let (mut x, mut y) = (x0, y0);
            steps
                .into_iter()
                .map(|(dx, dy)| {
                    x += dx;
                    y += dy;
                    (x, y)
                })
                .collect()
        })
}

const INTERPOLATIONS: [Interpolation; 3] = [
    Interpolation::Linear,
    Interpolation::CubicSpline,
    Interpolation::Bezier,
];

fn build(points: &[(f64, f64)], interpolation: Interpolation, boundary: BoundaryCondition) -> Cam {
    Cam::interpolate(&CamDefinition {
        points: points.to_vec(),
        segments: Vec::new(),
        interpolation,
        boundary,
    })
    .unwrap()
}

/// The class every junction of a points-only cam has at least.
fn guaranteed(interpolation: Interpolation) -> Continuity {
    match interpolation {
        Interpolation::Linear => Continuity::C0,
        Interpolation::CubicSpline => Continuity::C2,
        Interpolation::Bezier => Continuity::C1,
    }
}

/// Checks the continuity at junction `j` independently of its reported class: the left limit
/// is extrapolated from `x − δ` with the left piece's own derivatives, `δ` a millionth of the
/// narrower neighbouring piece (so the change of `y''` over `δ` is ~1e-6 of its size).
fn check_junction_numerically(cam: &Cam, j: usize, class: Continuity) {
    let pieces: Vec<_> = cam.pieces().collect();
    let (a, b) = (pieces[j], pieces[j + 1]);
    let x = b.x_start;
    let d = 1e-6 * (a.x_end - a.x_start).min(b.x_end - b.x_start);
    let l = cam.following(x - d).unwrap();
    let r = cam.following(x).unwrap();
    let l_val = l.value + d * l.first_derivative + 0.5 * d * d * l.second_derivative;
    let l_der = l.first_derivative + d * l.second_derivative;
    let scale = 1.0 + r.value.abs() + r.first_derivative.abs();
    assert!((l_val - r.value).abs() < 1e-9 * scale, "value at {x}");
    if class >= Continuity::C1 {
        let tol = 1e-5 * (1.0 + r.first_derivative.abs() + r.second_derivative.abs());
        assert!((l_der - r.first_derivative).abs() < tol, "slope at {x}");
    }
    if class >= Continuity::C2 {
        // Extrapolate y'' with the jerk from a second sample.
        let l2 = cam.following(x - 2.0 * d).unwrap();
        let l_curv = 2.0 * l.second_derivative - l2.second_derivative;
        let tol = 1e-4 * (1.0 + r.second_derivative.abs() + l.second_derivative.abs());
        assert!(
            (l_curv - r.second_derivative).abs() < tol,
            "curvature at {x}: {l:?} {r:?} d {d}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 300,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0xCA4_2143),
        ..ProptestConfig::default()
    })]

    #[test]
    fn continuity_per_interpolation_type(pts in point_set(40), equal in prop::bool::ANY) {
        let boundary = if equal {
            BoundaryCondition::EqualFirstDerivative
        } else {
            BoundaryCondition::None
        };
        let (ymin, ymax) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.1), b.max(p.1)));
        for interpolation in INTERPOLATIONS {
            let cam = build(&pts, interpolation, boundary);
            prop_assert_eq!(cam.piece_count(), pts.len() - 1);
            // Through the points.
            for &(x, y) in &pts {
                let v = cam.following(x).unwrap().value;
                prop_assert!((v - y).abs() <= 1e-9 * (1.0 + y.abs()), "{:?} {} {}", interpolation, v, y);
            }
            // Classes as documented, reported and numerically.
            let class = guaranteed(interpolation);
            for (k, j) in cam.junctions().iter().enumerate() {
                prop_assert!(j.continuity >= class, "{:?} {:?}", interpolation, j);
                check_junction_numerically(&cam, k, class);
            }
            prop_assert!(cam.continuity() >= class);
            // Range: Bézier and linear stay inside the points' y range.
            if interpolation != Interpolation::CubicSpline {
                let (lo, hi) = cam.following_range();
                prop_assert!(lo >= ymin - 1e-9 && hi <= ymax + 1e-9, "{:?} {} {}", interpolation, lo, hi);
                let (x0, x1) = cam.leading_range();
                for k in 0..=2000 {
                    let y = cam.following(x0 + (x1 - x0) * k as f64 / 2000.0).unwrap().value;
                    prop_assert!(y >= ymin - 1e-9 && y <= ymax + 1e-9);
                }
            }
            if equal && interpolation != Interpolation::Linear {
                let (s, e) = (cam.start(), cam.end());
                let tol = 1e-9 * (1.0 + s.first_derivative.abs());
                prop_assert!((s.first_derivative - e.first_derivative).abs() <= tol);
                if interpolation == Interpolation::CubicSpline {
                    let tol = 1e-7 * (1.0 + s.second_derivative.abs());
                    prop_assert!((s.second_derivative - e.second_derivative).abs() <= tol);
                }
            }
            if !equal && interpolation == Interpolation::CubicSpline {
                prop_assert!(cam.start().second_derivative.abs() < 1e-8, "natural end");
                prop_assert!(cam.end().second_derivative.abs() < 1e-8, "natural end");
            }
        }
    }

    #[test]
    fn monotone_points_give_monotone_bezier_and_an_exact_inverse(
        pts in increasing_set(40),
        approach in -1000.0f64..1000.0,
    ) {
        for interpolation in [Interpolation::Bezier, Interpolation::Linear] {
            let cam = build(&pts, interpolation, BoundaryCondition::None);
            prop_assert_eq!(cam.monotonicity(), Monotonicity::NonDecreasing);
            let (x0, x1) = cam.leading_range();
            let mut prev = f64::NEG_INFINITY;
            for k in 0..=1000 {
                let x = x0 + (x1 - x0) * k as f64 / 1000.0;
                let v = cam.following(x).unwrap();
                prop_assert!(v.value >= prev - 1e-12);
                prev = v.value;
                let back = cam.leading(v.value, approach).unwrap();
                if v.first_derivative > 1e-3 {
                    prop_assert!((back - x).abs() <= 1e-9, "{:?} x {} back {}", interpolation, x, back);
                } else {
                    let again = cam.following(back).unwrap().value;
                    prop_assert!((again - v.value).abs() <= 1e-12 * (1.0 + v.value.abs()));
                }
            }
        }
    }

    #[test]
    fn segments_points_and_gaps(
        layout in prop::collection::vec(
            (prop::bool::ANY, 0usize..14, 0.3f64..3.0, -5.0f64..5.0, -5.0f64..5.0, 0.001f64..1.0),
            1..8,
        ),
    ) {
        // Blocks left to right: a law segment or a few points, separated by gaps > 1e-4.
        let mut x = 0.0;
        let mut segments = Vec::new();
        let mut points = Vec::new();
        for (is_segment, law, width, ya, yb, gap) in layout {
            if is_segment {
                segments.push(SegmentDef::Law { law: ALL_LAWS[law], x0: x, x1: x + width, y0: ya, y1: yb });
            } else {
                points.push((x, ya));
                points.push((x + 0.5 * width, yb));
                points.push((x + width, 0.5 * (ya + yb)));
            }
            x += width + gap;
        }
        for interpolation in INTERPOLATIONS {
            let def = CamDefinition {
                points: points.clone(),
                segments: segments.clone(),
                interpolation,
                boundary: BoundaryCondition::None,
            };
            let Ok(cam) = Cam::interpolate(&def) else {
                prop_assert!(segments.is_empty() && points.len() < 2);
                continue;
            };
            // Segments are evaluated exactly as defined.
            for s in &segments {
                let SegmentDef::Law { law, x0, x1, y0, y1 } = *s else { unreachable!() };
                for k in 0..=20 {
                    let u = k as f64 / 20.0;
                    let want = y0 + (y1 - y0) * law.s(u);
                    let got = cam.following(x0 + u * (x1 - x0)).unwrap().value;
                    prop_assert!((got - want).abs() < 1e-12, "{:?}", law);
                }
            }
            for &(px, py) in &points {
                prop_assert!((cam.following(px).unwrap().value - py).abs() < 1e-9);
            }
            let pieces: Vec<_> = cam.pieces().collect();
            for (j, junction) in cam.junctions().iter().enumerate() {
                let both_interpolated = pieces[j].source == PieceSource::Interpolated
                    && pieces[j + 1].source == PieceSource::Interpolated;
                // A transition piece with segments on both sides is the quintic one.
                let quintic = |i: usize| {
                    pieces[i].source == PieceSource::Interpolated
                        && i > 0
                        && i + 1 < pieces.len()
                        && pieces[i - 1].source != PieceSource::Interpolated
                        && pieces[i + 1].source != PieceSource::Interpolated
                };
                let class = match interpolation {
                    Interpolation::Linear => Continuity::C0,
                    Interpolation::Bezier if both_interpolated => Continuity::C1,
                    Interpolation::Bezier => Continuity::C0,
                    Interpolation::CubicSpline if both_interpolated => Continuity::C2,
                    Interpolation::CubicSpline if quintic(j) || quintic(j + 1) => Continuity::C2,
                    // A segment next to a spline chain through points: clamped slope, C1.
                    Interpolation::CubicSpline => Continuity::C1,
                };
                prop_assert!(junction.continuity >= class, "{:?} {:?}", interpolation, junction);
                check_junction_numerically(&cam, j, class);
            }
        }
    }
}

// --- Leading value ----------------------------------------------------------------------------

/// A chain of laws: rise, dwell, rise, fall is not allowed here (monotonic).
fn monotonic_law_cam() -> Cam {
    let seg = |law, x0: f64, x1: f64, y0: f64, y1: f64| SegmentDef::Law {
        law,
        x0,
        x1,
        y0,
        y1,
    };
    Cam::interpolate(&CamDefinition {
        segments: vec![
            seg(MotionLaw::Poly5, 0.0, 90.0, 0.0, 40.0),
            seg(MotionLaw::StraightLine, 90.0, 120.0, 40.0, 40.0),
            seg(MotionLaw::ModifiedSine, 120.0, 200.0, 40.0, 100.0),
            seg(MotionLaw::Cycloid, 200.0, 260.0, 100.0, 130.0),
            seg(
                MotionLaw::ModifiedAccelerationTrapezoid { lambda: 0.3 },
                260.0,
                300.0,
                130.0,
                150.0,
            ),
            seg(MotionLaw::Poly7, 300.0, 360.0, 150.0, 155.0),
        ],
        interpolation: Interpolation::CubicSpline,
        ..CamDefinition::default()
    })
    .unwrap()
}

#[test]
fn leading_value_inverts_the_following_value_on_monotonic_cams() {
    let cam = monotonic_law_cam();
    assert_eq!(cam.monotonicity(), Monotonicity::NonDecreasing);
    assert_eq!(cam.following_range(), (0.0, 155.0));
    let mut checked = 0;
    for k in 0..=36_000 {
        let x = k as f64 * 0.01;
        let v = cam.following(x).unwrap();
        for approach in [-500.0, x, 1000.0] {
            let back = cam.leading(v.value, approach).unwrap();
            if v.first_derivative > 1e-3 {
                assert!((back - x).abs() <= 1e-9, "x {x} back {back}");
                checked += 1;
            } else {
                // Dwell or a dwell end: any x with the same value is a solution.
                let again = cam.following(back).unwrap().value;
                assert!(
                    (again - v.value).abs() <= 1e-12 * 155.0,
                    "x {x} back {back}"
                );
            }
        }
    }
    assert!(checked > 90_000);
    // The dwell [90, 120] at 40: nearest point of the interval.
    assert_eq!(cam.leading(40.0, 100.0), Ok(100.0));
    assert_eq!(cam.leading(40.0, 0.0), Ok(90.0));
    assert_eq!(cam.leading(40.0, 500.0), Ok(120.0));
    assert_eq!(cam.leading(155.5, 0.0), Err(CamError::NoLeadingValue));
    assert_eq!(CamError::NoLeadingValue.error_id().code(), 0x8063);
}

/// The example of S7-Technology V4.1 function manual, 3.5 '"Cam disk" technology object'
/// (MC_GetCamPoint Mode 1): master 0..10, the following value 4 is reached once below and once
/// above 5.
#[test]
fn approach_value_and_tie_rule() {
    let cam = Cam::interpolate(&CamDefinition {
        segments: vec![
            SegmentDef::Law {
                law: MotionLaw::Poly5,
                x0: 0.0,
                x1: 5.0,
                y0: 0.0,
                y1: 8.0,
            },
            SegmentDef::Law {
                law: MotionLaw::Poly5,
                x0: 5.0,
                x1: 10.0,
                y0: 8.0,
                y1: 0.0,
            },
        ],
        ..CamDefinition::default()
    })
    .unwrap();
    assert_eq!(cam.monotonicity(), Monotonicity::None);
    let near = |got: f64, want: f64| (got - want).abs() < 1e-12;
    assert!(near(cam.leading(4.0, 4.9).unwrap(), 2.5));
    assert!(near(cam.leading(4.0, 5.1).unwrap(), 7.5));
    assert!(
        near(cam.leading(4.0, 5.0).unwrap(), 2.5),
        "tie: the lower one"
    );
    assert!(near(cam.leading(4.0, -10.0).unwrap(), 2.5));
    assert!(near(cam.leading(4.0, 100.0).unwrap(), 7.5));
    assert!(near(cam.leading(4.0, 7.5).unwrap(), 7.5));
    assert!(near(cam.leading(8.0, 0.0).unwrap(), 5.0));
    assert_eq!(cam.leading(0.0, 5.0), Ok(0.0), "tie between 0 and 10");
    assert_eq!(cam.leading(0.0, 5.5), Ok(10.0));
    assert_eq!(cam.leading(8.5, 5.0), Err(CamError::NoLeadingValue));
    assert_eq!(
        cam.leading(4.0, f64::NAN),
        Err(CamError::IllegalApproachLeadingValue)
    );
}

/// Non-monotonic spline: the answer equals a brute-force search over all crossings.
#[test]
fn leading_value_on_a_wavy_spline_matches_brute_force() {
    let pts: Vec<(f64, f64)> = (0..=40)
        .map(|i| {
            let x = i as f64 * 0.5;
            (x, (0.9 * x).sin() * (1.0 + 0.05 * x))
        })
        .collect();
    let cam = build(&pts, Interpolation::CubicSpline, BoundaryCondition::None);
    let (x0, x1) = cam.leading_range();
    let n = 200_000;
    let f = |x: f64| cam.following(x).unwrap().value;
    for (k, y) in [-0.7, -0.2, 0.0, 0.33, 0.8, 1.4].into_iter().enumerate() {
        // All crossings on a fine grid, refined by bisection.
        let mut roots = Vec::new();
        let mut xa = x0;
        let mut fa = f(xa) - y;
        for i in 1..=n {
            let xb = x0 + (x1 - x0) * i as f64 / n as f64;
            let fb = f(xb) - y;
            if fa == 0.0 {
                roots.push(xa);
            } else if fa * fb < 0.0 {
                let (mut lo, mut hi) = (xa, xb);
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if (f(mid) - y) * fa > 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                roots.push(0.5 * (lo + hi));
            }
            xa = xb;
            fa = fb;
        }
        assert!(roots.len() >= 2, "y {y}: {roots:?}");
        for j in 0..=60 {
            let approach = -2.0 + j as f64 * 0.4 + 0.01 * k as f64;
            let want = roots
                .iter()
                .copied()
                .min_by(|a, b| (a - approach).abs().total_cmp(&(b - approach).abs()))
                .unwrap();
            let got = cam.leading(y, approach).unwrap();
            assert!(
                (got - want).abs() < 1e-9,
                "y {y} approach {approach}: {got} vs {want}"
            );
            assert!((f(got) - y).abs() < 1e-12);
        }
    }
}

// --- O(log n) ------------------------------------------------------------------------------

#[test]
fn thousand_point_spline_uses_binary_search() {
    let pts: Vec<(f64, f64)> = (0..1000)
        .map(|i| {
            let x = i as f64 * 0.36 + 0.05 * ((i * 7919) % 13) as f64;
            (x, 50.0 * (x * 0.02).sin() + x)
        })
        .collect();
    let cam = build(&pts, Interpolation::CubicSpline, BoundaryCondition::None);
    assert_eq!(cam.piece_count(), 999);
    let pieces: Vec<_> = cam.pieces().collect();
    let (x0, x1) = cam.leading_range();
    let mut hint = 0;
    for k in 0..=20_000 {
        let x = x0 + (x1 - x0) * k as f64 / 20_000.0;
        // The piece by linear scan…
        let want = pieces.iter().rposition(|p| p.x_start <= x).unwrap();
        // …equals the binary search (`partition_point` over the piece starts) and the hint.
        assert_eq!(cam.piece_index(x), Some(want), "x {x}");
        assert_eq!(
            cam.following_with_hint(x, &mut hint).unwrap(),
            cam.following(x).unwrap()
        );
        assert_eq!(hint, want);
    }
    for j in cam.junctions() {
        assert_eq!(j.continuity, Continuity::C2);
    }
}

#[test]
fn csv_to_cam() {
    let text = "# degrees, mm\nleading,following\n0,0\n90,10\n180,10\n270,0\n360,0\n";
    let points = parse_csv(text).unwrap();
    assert_eq!(points.len(), 5);
    let mut def = CamDefinition::from_points(points, Interpolation::CubicSpline);
    def.boundary = BoundaryCondition::EqualFirstDerivative;
    let cam = Cam::interpolate(&def).unwrap();
    assert_eq!(cam.leading_range(), (0.0, 360.0));
    assert_eq!(cam.rise(), 0.0);
    let (s, e) = (cam.start(), cam.end());
    assert!((s.first_derivative - e.first_derivative).abs() < 1e-12);
    assert!((s.second_derivative - e.second_derivative).abs() < 1e-12);
    let bad = parse_csv("0,0\n1,x\n").unwrap_err();
    assert_eq!(bad.line, 2);
}

// --- No allocation on the query path ----------------------------------------------------------

use tandem_testkit::counting::{arm, disarm};

tandem_testkit::counting_allocator!();

#[test]
fn queries_do_not_allocate() {
    let monotonic = monotonic_law_cam();
    let pts: Vec<(f64, f64)> = (0..=200)
        .map(|i| (i as f64 * 0.1, (i as f64 * 0.1).sin()))
        .collect();
    let wavy = build(&pts, Interpolation::Bezier, BoundaryCondition::None);
    arm();
    let mut sum = 0.0;
    let mut hint = 0;
    for k in 0..=10_000 {
        let x = k as f64 * 0.036;
        let v = monotonic.following(x).unwrap();
        sum += v.value + monotonic.following_with_hint(x, &mut hint).unwrap().value;
        sum += monotonic.leading(v.value, x).unwrap();
        let xw = k as f64 * 0.002;
        let w = wavy.following(xw).unwrap();
        sum += wavy.leading(w.value, xw).unwrap();
        sum += wavy.following(1e9).map_or(0.0, |v| v.value);
    }
    let (allocs, _) = disarm();
    assert!(sum.is_finite());
    assert_eq!(allocs, 0, "allocations on the query path");
}
