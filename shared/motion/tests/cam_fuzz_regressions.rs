//! Inputs the fuzzer (`cargo bench -p tandem-bench --bench fuzz`, docs/fuzzing.md) found, each
//! fed exactly: a cam that is built answers finite values over its whole leading range.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::cam::{
    parse_csv, BoundaryCondition, Cam, CamDefinition, CamError, Interpolation, SegmentDef,
    POINT_RESOLUTION,
};

/// Every interpolation and boundary condition of the points of `csv`: built, and finite at
/// both ends and in the middle (or refused).
fn finite_everywhere(csv: &[u8]) {
    let points = parse_csv(std::str::from_utf8(csv).unwrap()).unwrap();
    for interpolation in [
        Interpolation::Linear,
        Interpolation::CubicSpline,
        Interpolation::Bezier,
    ] {
        for boundary in [
            BoundaryCondition::None,
            BoundaryCondition::EqualFirstDerivative,
        ] {
            let def = CamDefinition {
                boundary,
                ..CamDefinition::from_points(points.clone(), interpolation)
            };
            let Ok(cam) = Cam::interpolate(&def) else {
                continue;
            };
            let (x0, x1) = cam.leading_range();
            for x in [x0, x1, 0.5 * (x0 + x1)] {
                let v = cam.following(x).unwrap();
                assert!(
                    v.value.is_finite()
                        && v.first_derivative.is_finite()
                        && v.second_derivative.is_finite(),
                    "{interpolation:?}/{boundary:?} at {x}: {v:?}"
                );
            }
        }
    }
}

#[test]
fn two_points_a_subnormal_apart_are_one_point() {
    // cam seed 2051882513 index 12682: `0,1` and `1e-320,1`. The span between them had an
    // infinite 1/dx and answered NaN at x = 0; now they are one x, the later point wins, and a
    // cam of one point is refused.
    let csv = hex("302c310a31652d3332302c310a");
    assert_eq!(csv, b"0,1\n1e-320,1\n");
    finite_everywhere(&csv);
    let points = parse_csv("0,1\n1e-320,1\n").unwrap();
    let def = CamDefinition::from_points(points, Interpolation::Linear);
    assert!(Cam::interpolate(&def).is_err());
}

#[test]
fn a_subnormal_point_among_others_is_merged_with_its_neighbour() {
    // cam seed 2051882513 index 14781 (cubic spline NaN at x = -5) and 12983 (linear NaN at 0).
    for h in [
        "302c350a2d352c300a31652d3332302c2d350a352c300a31302c2d350a31302c2d340a",
        "2d31302c2d350a31652d3332302c300a302c350a352c300a31302c2d350a31302c2d340a",
        "23206c6966740d0a6c656164696e672c666f6c6c6f77696e670d0a302e302c20302e300d0a34302e31652d3332302c20322e30202320746f700d0a0d0a38302e302c302e300d0a",
    ] {
        finite_everywhere(&hex(h));
    }
    // The later of two points closer than the resolution wins.
    let def = CamDefinition::from_points(
        vec![(0.0, 0.0), (1.0, 1.0), (1.0 + 0.5 * POINT_RESOLUTION, 3.0)],
        Interpolation::Linear,
    );
    let cam = Cam::interpolate(&def).unwrap();
    assert_eq!(cam.piece_count(), 1);
    assert_eq!(cam.end().value, 3.0);
    // Points further apart than the resolution stay apart.
    let def = CamDefinition::from_points(
        vec![(0.0, 0.0), (1.0, 1.0), (1.0 + 4.0 * POINT_RESOLUTION, 1.0)],
        Interpolation::Linear,
    );
    assert_eq!(Cam::interpolate(&def).unwrap().piece_count(), 2);
}

#[test]
fn a_segment_whose_derivatives_overflow_is_refused() {
    // cell seed 2051882513 index 11080: config/cross-cutter.toml's cam `cut` with the
    // transition's u^5 coefficient replaced by 1e308. Every coefficient is finite, so the cell
    // was accepted, and MC_GetCamFollowingValue answered a second derivative of +inf at x = 250.
    let poly = |x0: f64, x1: f64, c: &[f64]| {
        let mut coeffs = [0.0; 8];
        coeffs[..c.len()].copy_from_slice(c);
        SegmentDef::Polynomial { x0, x1, coeffs }
    };
    let mut def = CamDefinition::from_points(Vec::new(), Interpolation::CubicSpline);
    def.segments = vec![
        poly(0.0, 50.0, &[0.0, 45.0]),
        poly(
            50.0,
            450.0,
            &[45.0, 360.0, 0.0, 0.0, -3150.0, 1e308, -6300.0, 1800.0],
        ),
        poly(450.0, 500.0, &[315.0, 45.0]),
    ];
    assert_eq!(
        Cam::interpolate(&def).unwrap_err(),
        CamError::InvalidSegment { index: 1 }
    );
    // The file's own coefficient (7560) builds a cam, finite everywhere.
    if let Some(SegmentDef::Polynomial { coeffs, .. }) = def.segments.get_mut(1) {
        coeffs[5] = 7560.0;
    }
    let cam = Cam::interpolate(&def).unwrap();
    for k in 0..=100 {
        let v = cam.following(5.0 * f64::from(k)).unwrap();
        assert!(v.second_derivative.is_finite(), "{k}: {v:?}");
    }
    // A span so narrow that 1/w² overflows.
    def.segments = vec![poly(0.0, 1e-200, &[0.0, 1.0, 1.0])];
    assert_eq!(
        Cam::interpolate(&def).unwrap_err(),
        CamError::InvalidSegment { index: 0 }
    );
}

fn hex(h: &str) -> Vec<u8> {
    (0..h.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&h[i..i + 2], 16).unwrap())
        .collect()
}
