//! Definition rules, errors and queries of the cam (the laws and the property tests are in
//! `tests/cam_laws.rs`).

use super::*;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

fn def(
    points: &[(f64, f64)],
    segments: &[SegmentDef],
    interpolation: Interpolation,
) -> CamDefinition {
    CamDefinition {
        points: points.to_vec(),
        segments: segments.to_vec(),
        interpolation,
        boundary: BoundaryCondition::None,
    }
}

fn y(cam: &Cam, x: f64) -> f64 {
    cam.following(x).unwrap().value
}

#[test]
fn cam_is_shareable() {
    fn send_sync<T: Send + Sync + Clone>() {}
    send_sync::<Cam>();
    send_sync::<CamDefinition>();
}

#[test]
fn errors_map_to_the_reference_error_ids() {
    assert_eq!(CamError::Empty.error_id().code(), 0x80AA);
    assert_eq!(CamError::InUse.error_id().code(), 0x80AB);
    assert_eq!(CamError::TooFewPoints.error_id().code(), 0x80AC);
    assert_eq!(
        CamError::InvalidPoint { index: 3 }.error_id().code(),
        0x80AC
    );
    assert_eq!(
        CamError::InvalidSegment { index: 0 }.error_id().code(),
        0x80AC
    );
    assert_eq!(CamError::NoLeadingValue.error_id().code(), 0x8063);
    assert_eq!(CamError::NoFollowingValue.error_id().code(), 0x8064);
    assert_eq!(
        CamError::IllegalApproachLeadingValue.error_id().code(),
        0x8062
    );
    assert_eq!(
        CamError::InvalidSegment { index: 2 }.to_string(),
        "16#80AC CamInvalidPoints: segment 2 is invalid"
    );
    assert_eq!(CamError::Empty.to_string(), "16#80AA CamEmpty");
}

#[test]
fn bad_definitions_are_refused() {
    let lin = Interpolation::Linear;
    let interp = |d: CamDefinition| Cam::interpolate(&d).unwrap_err();
    assert_eq!(interp(CamDefinition::default()), CamError::Empty);
    assert_eq!(interp(def(&[(1.0, 2.0)], &[], lin)), CamError::TooFewPoints);
    assert_eq!(
        interp(def(&[(1.0, 2.0), (1.0, 3.0)], &[], lin)),
        CamError::TooFewPoints,
        "equal x: the last wins, one point remains"
    );
    assert_eq!(
        interp(def(&[(0.0, 0.0), (1.0, f64::NAN)], &[], lin)),
        CamError::InvalidPoint { index: 1 }
    );
    assert_eq!(
        interp(def(&[(0.0, 0.0), (2e12, 1.0)], &[], lin)),
        CamError::InvalidPoint { index: 1 }
    );
    let good = SegmentDef::line(0.0, 0.0, 1.0, 1.0);
    for bad in [
        SegmentDef::line(1.0, 0.0, 1.0, 1.0),
        SegmentDef::line(2.0, 0.0, 1.0, 1.0),
        SegmentDef::Law {
            law: MotionLaw::ModifiedAccelerationTrapezoid { lambda: 0.0 },
            x0: 0.0,
            x1: 1.0,
            y0: 0.0,
            y1: 1.0,
        },
        SegmentDef::polynomial(0.0, 1.0, &[0.0, f64::INFINITY]),
        SegmentDef::S7Polynomial {
            xmin: 0.0,
            xmax: 1.0,
            a: [0.0; 7],
            sine_amplitude: 1.0,
            sine_period: 0.0,
            sine_phase: 0.0,
        },
    ] {
        assert_eq!(
            interp(def(&[], &[good, bad], lin)),
            CamError::InvalidSegment { index: 1 },
            "{bad:?}"
        );
    }
    // A single segment is a cam.
    let cam = Cam::interpolate(&def(&[], &[good], lin)).unwrap();
    assert_eq!(cam.leading_range(), (0.0, 1.0));
    assert_eq!(cam.piece_count(), 1);
}

#[test]
fn points_in_any_order_and_the_last_of_equal_x_wins() {
    let cam = Cam::interpolate(&def(
        &[(2.0, 5.0), (0.0, 0.0), (1.0, 9.0), (1.0, 1.0), (-0.0, 7.0)],
        &[],
        Interpolation::Linear,
    ))
    .unwrap();
    assert_eq!(cam.leading_range(), (0.0, 2.0));
    assert_eq!(y(&cam, 0.0), 7.0, "-0.0 equals 0.0 and comes later");
    assert_eq!(y(&cam, 1.0), 1.0);
    assert_eq!(y(&cam, 1.5), 3.0);
}

#[test]
fn a_later_segment_is_used_in_full_and_the_earlier_continues_after_it() {
    let a = SegmentDef::line(0.0, 0.0, 10.0, 10.0);
    let b = SegmentDef::Law {
        law: MotionLaw::StraightLine,
        x0: 4.0,
        x1: 6.0,
        y0: 100.0,
        y1: 100.0,
    };
    let cam = Cam::interpolate(&def(&[], &[a, b], Interpolation::CubicSpline)).unwrap();
    let pieces: Vec<PieceInfo> = cam.pieces().collect();
    assert_eq!(pieces.len(), 3);
    assert_eq!(
        (pieces[0].x_start, pieces[0].x_end, pieces[0].source),
        (0.0, 4.0, PieceSource::Segment(0))
    );
    assert_eq!(
        (pieces[1].x_start, pieces[1].x_end, pieces[1].source),
        (4.0, 6.0, PieceSource::Segment(1))
    );
    assert_eq!(
        (pieces[2].x_start, pieces[2].x_end, pieces[2].source),
        (6.0, 10.0, PieceSource::Segment(0))
    );
    assert!(close(y(&cam, 3.0), 3.0, 1e-12));
    assert_eq!(y(&cam, 4.0), 100.0, "right-hand value at the jump");
    assert!(
        close(y(&cam, 8.0), 8.0, 1e-12),
        "the earlier shape continues"
    );
    assert!(cam
        .junctions()
        .iter()
        .all(|j| j.continuity == Continuity::Discontinuous));
    assert_eq!(cam.continuity(), Continuity::Discontinuous);
    // In the other order the long line wins everywhere.
    let cam = Cam::interpolate(&def(&[], &[b, a], Interpolation::CubicSpline)).unwrap();
    assert_eq!(cam.piece_count(), 1);
    assert!(close(y(&cam, 5.0), 5.0, 1e-12));
}

#[test]
fn a_segment_wins_over_points_on_it_or_next_to_it() {
    let seg = SegmentDef::line(1.0, 1.0, 2.0, 2.0);
    let cam = Cam::interpolate(&def(
        &[
            (0.0, 0.0),
            (1.5, 99.0),
            (2.0 + 0.5 * GAP_THRESHOLD, 50.0),
            (3.0, 3.0),
        ],
        &[seg],
        Interpolation::Linear,
    ))
    .unwrap();
    assert!(close(y(&cam, 1.5), 1.5, 1e-12));
    assert!(
        close(y(&cam, 2.5), 2.5, 1e-12),
        "the point at 2.00005 is gone"
    );
    assert_eq!(cam.piece_count(), 3);
    assert!(cam
        .junctions()
        .iter()
        .all(|j| j.continuity == Continuity::C2));
}

#[test]
fn small_gaps_are_pulled_together_larger_ones_get_a_transition() {
    let a = SegmentDef::line(0.0, 0.0, 1.0, 1.0);
    let b = SegmentDef::line(1.0 + 0.5 * GAP_THRESHOLD, 1.0, 2.0, 2.0);
    let cam = Cam::interpolate(&def(&[], &[a, b], Interpolation::Linear)).unwrap();
    assert_eq!(cam.piece_count(), 2);
    let j = cam.junctions()[0];
    assert!(close(j.x, 1.0 + 0.25 * GAP_THRESHOLD, 1e-15));
    assert!(close(j.left.value, 1.0, 1e-12) && close(j.right.value, 1.0, 1e-12));
    assert!(close(
        y(&cam, 0.5),
        0.5 / (1.0 + 0.25 * GAP_THRESHOLD),
        1e-12
    ));

    // 3e-4 is beyond the threshold: an interpolated transition.
    let b = SegmentDef::Law {
        law: MotionLaw::Poly5,
        x0: 1.5,
        x1: 2.5,
        y0: 3.0,
        y1: 5.0,
    };
    for (interp, class) in [
        (Interpolation::Linear, Continuity::C0),
        (Interpolation::CubicSpline, Continuity::C2),
        (Interpolation::Bezier, Continuity::C0),
    ] {
        let cam = Cam::interpolate(&def(&[], &[a, b], interp)).unwrap();
        let pieces: Vec<PieceInfo> = cam.pieces().collect();
        assert_eq!(pieces.len(), 3);
        assert_eq!(pieces[1].source, PieceSource::Interpolated);
        assert_eq!((pieces[1].x_start, pieces[1].x_end), (1.0, 1.5));
        for j in cam.junctions() {
            assert!(j.continuity >= class, "{interp:?} {j:?}");
        }
        let (lo, hi) = cam.following_range();
        assert_eq!(lo, 0.0);
        if interp == Interpolation::Bezier {
            assert!(hi <= 5.0 + 1e-12, "Bézier stays inside the y range");
        }
    }
}

#[test]
fn bezier_takes_over_segment_slopes_inside_the_range_rule() {
    // The line's slope 1 is inside the cone of the span (secant 1.5): C1.
    let a = SegmentDef::line(0.0, 0.0, 1.0, 1.0);
    let cam =
        Cam::interpolate(&def(&[(2.0, 2.5), (3.0, 3.0)], &[a], Interpolation::Bezier)).unwrap();
    assert!(cam.junctions()[0].continuity >= Continuity::C1);
    // A slope of 10 would leave the range: clipped to 3·secant, C0 only.
    let a = SegmentDef::line(0.0, -9.0, 1.0, 1.0);
    let cam =
        Cam::interpolate(&def(&[(2.0, 1.5), (3.0, 3.0)], &[a], Interpolation::Bezier)).unwrap();
    assert_eq!(cam.junctions()[0].continuity, Continuity::C0);
    assert!(cam.following_range().1 <= 3.0 + 1e-12);
}

#[test]
fn spline_with_segments_is_c1_at_the_segments_and_c2_between_points() {
    let seg = SegmentDef::Law {
        law: MotionLaw::Cycloid,
        x0: 0.0,
        x1: 1.0,
        y0: 0.0,
        y1: 1.0,
    };
    let cam = Cam::interpolate(&def(
        &[(1.5, 1.2), (2.0, 2.0), (2.7, 1.0), (3.0, 0.5)],
        &[seg],
        Interpolation::CubicSpline,
    ))
    .unwrap();
    let j = cam.junctions();
    assert_eq!(j.len(), 4);
    assert!(j[0].continuity >= Continuity::C1);
    for k in &j[1..] {
        assert_eq!(k.continuity, Continuity::C2, "{k:?}");
    }
}

#[test]
fn equal_first_derivative_boundary() {
    let pts = [(0.0, 0.0), (1.0, 2.0), (2.5, 1.0), (4.0, 3.0)];
    for interp in [Interpolation::CubicSpline, Interpolation::Bezier] {
        let mut d = def(&pts, &[], interp);
        d.boundary = BoundaryCondition::EqualFirstDerivative;
        let cam = Cam::interpolate(&d).unwrap();
        let (s, e) = (cam.start(), cam.end());
        assert!(
            close(s.first_derivative, e.first_derivative, 1e-9),
            "{interp:?}"
        );
        if interp == Interpolation::CubicSpline {
            assert!(close(s.second_derivative, e.second_derivative, 1e-9));
        }
        assert_eq!(cam.rise(), 3.0);
    }
    // A segment at the start: the interpolated end takes its slope.
    let seg = SegmentDef::Law {
        law: MotionLaw::InclinedSine { velocity: 0.5 },
        x0: 0.0,
        x1: 1.0,
        y0: 0.0,
        y1: 1.0,
    };
    for interp in [Interpolation::CubicSpline, Interpolation::Bezier] {
        let mut d = def(&[(2.0, 2.0), (3.0, 3.0)], &[seg], interp);
        d.boundary = BoundaryCondition::EqualFirstDerivative;
        let cam = Cam::interpolate(&d).unwrap();
        assert!(close(cam.start().first_derivative, 0.5, 1e-12));
        assert!(close(cam.end().first_derivative, 0.5, 1e-12), "{interp:?}");
    }
    // Interpolated edges on both sides of a segment: two chains, one common slope.
    let mid = SegmentDef::Law {
        law: MotionLaw::Poly5,
        x0: 2.0,
        x1: 3.0,
        y0: 1.0,
        y1: 4.0,
    };
    for interp in [Interpolation::CubicSpline, Interpolation::Bezier] {
        let mut d = def(
            &[(0.0, 0.0), (1.0, 0.5), (4.0, 4.5), (5.0, 6.0)],
            &[mid],
            interp,
        );
        d.boundary = BoundaryCondition::EqualFirstDerivative;
        let cam = Cam::interpolate(&d).unwrap();
        let (s, e) = (cam.start(), cam.end());
        assert!(
            close(s.first_derivative, e.first_derivative, 1e-9),
            "{interp:?}"
        );
        assert!(s.first_derivative > 0.0);
        if interp == Interpolation::CubicSpline {
            assert!(close(s.second_derivative, e.second_derivative, 1e-9));
        }
    }
    // Without the condition the natural spline end has y'' = 0.
    let cam = Cam::interpolate(&def(&pts, &[], Interpolation::CubicSpline)).unwrap();
    assert!(close(cam.start().second_derivative, 0.0, 1e-9));
    assert!(close(cam.end().second_derivative, 0.0, 1e-9));
}

#[test]
fn s7_polynomial_uses_absolute_x_and_the_period_length() {
    let seg = SegmentDef::S7Polynomial {
        xmin: 10.0,
        xmax: 12.0,
        a: [1.0, 2.0, 0.5, 0.0, 0.0, 0.0, 0.0],
        sine_amplitude: 0.25,
        sine_period: 4.0,
        sine_phase: 0.1,
    };
    let cam = Cam::interpolate(&def(&[], &[seg], Interpolation::Linear)).unwrap();
    let x: f64 = 11.0;
    let w = 2.0 * core::f64::consts::PI / 4.0;
    let v = cam.following(x).unwrap();
    assert!(close(
        v.value,
        1.0 + 2.0 * x + 0.5 * x * x + 0.25 * (w * x + 0.1).sin(),
        1e-12
    ));
    assert!(close(
        v.first_derivative,
        2.0 + x + 0.25 * w * (w * x + 0.1).cos(),
        1e-12
    ));
    assert!(close(
        v.second_derivative,
        1.0 - 0.25 * w * w * (w * x + 0.1).sin(),
        1e-12
    ));
}

#[test]
fn following_range_checks() {
    let cam =
        Cam::interpolate(&def(&[(1.0, 1.0), (3.0, 2.0)], &[], Interpolation::Linear)).unwrap();
    assert_eq!(cam.following(0.5), Err(CamError::NoFollowingValue));
    assert_eq!(cam.following(3.1), Err(CamError::NoFollowingValue));
    assert_eq!(cam.following(f64::NAN), Err(CamError::NoFollowingValue));
    assert_eq!(y(&cam, 3.0), 2.0);
    assert_eq!(y(&cam, 3.0 + 1e-13), 2.0, "within the tolerance: clamped");
    assert_eq!(cam.piece_index(3.0), Some(0));
    assert_eq!(cam.piece_index(0.0), None);
}

#[test]
fn hinted_evaluation_equals_the_binary_search() {
    let pts: Vec<(f64, f64)> = (0..50)
        .map(|i| (i as f64 * 0.7, (i as f64 * 0.3).sin()))
        .collect();
    let cam =
        Cam::interpolate(&CamDefinition::from_points(pts, Interpolation::CubicSpline)).unwrap();
    let mut hint = usize::MAX;
    for k in 0..2000 {
        let x = (k as f64 * 0.017) % 34.3;
        assert_eq!(
            cam.following_with_hint(x, &mut hint).unwrap(),
            cam.following(x).unwrap()
        );
        assert_eq!(Some(hint), cam.piece_index(x));
    }
    assert_eq!(
        cam.following_with_hint(-1.0, &mut hint),
        Err(CamError::NoFollowingValue)
    );
}

#[test]
fn leading_value_errors_and_flat_parts() {
    // Dwell at y = 1 on [1, 2], a jump from 2 to 3 at x = 3.
    let cam = Cam::interpolate(&def(
        &[(0.0, 0.0), (1.0, 1.0), (2.0, 1.0)],
        &[
            SegmentDef::line(2.0, 1.0, 3.0, 2.0),
            SegmentDef::line(3.0, 3.0, 4.0, 4.0),
        ],
        Interpolation::Linear,
    ))
    .unwrap();
    assert_eq!(cam.monotonicity(), Monotonicity::NonDecreasing);
    assert_eq!(cam.leading(1.0, 1.5), Ok(1.5));
    assert_eq!(cam.leading(1.0, 5.0), Ok(2.0));
    assert_eq!(cam.leading(1.0, -3.0), Ok(1.0));
    assert_eq!(cam.leading(2.5, 0.0), Err(CamError::NoLeadingValue));
    assert_eq!(cam.leading(4.5, 0.0), Err(CamError::NoLeadingValue));
    assert_eq!(cam.leading(f64::NAN, 0.0), Err(CamError::NoLeadingValue));
    assert_eq!(
        cam.leading(1.0, f64::INFINITY),
        Err(CamError::IllegalApproachLeadingValue)
    );
    assert!(close(cam.leading(3.5, 0.0).unwrap(), 3.5, 1e-12));
    assert!(close(cam.leading(0.25, 9.0).unwrap(), 0.25, 1e-12));
    assert_eq!(cam.following_range(), (0.0, 4.0));
    // A constant cam.
    let cam = Cam::interpolate(&def(
        &[(0.0, 1.0), (2.0, 1.0)],
        &[],
        Interpolation::CubicSpline,
    ))
    .unwrap();
    assert_eq!(cam.monotonicity(), Monotonicity::Constant);
    assert_eq!(cam.leading(1.0, 0.5), Ok(0.5));
    assert_eq!(cam.leading(1.1, 0.5), Err(CamError::NoLeadingValue));
}

#[test]
fn leading_value_on_a_falling_cam() {
    let cam = Cam::interpolate(&def(
        &[],
        &[SegmentDef::Law {
            law: MotionLaw::ModifiedSine,
            x0: 2.0,
            x1: 6.0,
            y0: 10.0,
            y1: -2.0,
        }],
        Interpolation::Linear,
    ))
    .unwrap();
    assert_eq!(cam.monotonicity(), Monotonicity::NonIncreasing);
    for k in 1..40 {
        let x = 2.0 + 4.0 * k as f64 / 40.0;
        let yv = y(&cam, x);
        assert!(close(cam.leading(yv, 0.0).unwrap(), x, 1e-9), "{x}");
    }
    assert_eq!(cam.leading(10.0, 100.0), Ok(2.0));
    assert_eq!(cam.leading(-2.0, -100.0), Ok(6.0));
}
