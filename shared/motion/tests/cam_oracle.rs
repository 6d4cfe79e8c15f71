//! Independent oracle: motion laws against the `pyplcopen` package (PyPI, pyplcopen 0.21.0).
//! Fixtures are produced by `tests/oracle/gen_cam_fixtures.py` and committed; see its header
//! for how the law names were found.
//!
//! pyplcopen 0.21.0 provides three laws: `cycloidal` (our `Cycloid`), `modified_sine`
//! (`ModifiedSine`) and `poly345` (`Poly5`). Its modified sine is the VDI 2143 form (factor
//! `1/(4+π)`, quarter waves on `[0, ⅛]` and `[⅞, 1]`), the same as ours: no disagreement.
//!
//! Each sample is compared with a cam made of one law segment on `[0, master_span] ×
//! [0, rise]`, evaluated by `Cam::following`, so the box mapping is checked too.
//!
//! Tolerance: `|ours − theirs| ≤ 1e-12 · max(1, |rise|)`. Both sides evaluate the same closed
//! forms in f64 and differ only in the order of operations (≈1e-15 relative observed);
//! 1e-12 leaves a margin of three orders and is still ten orders below the difference between
//! law variants (the other common modified sine differs by ~1e-2).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::BTreeMap;

use tandem_motion::cam::{Cam, CamDefinition, Interpolation, MotionLaw, SegmentDef};

const FIXTURE: &str = include_str!("fixtures/cam_laws.csv");

fn law_for(name: &str) -> MotionLaw {
    match name {
        "cycloidal" => MotionLaw::Cycloid,
        "modified_sine" => MotionLaw::ModifiedSine,
        "poly345" => MotionLaw::Poly5,
        other => panic!("unknown pyplcopen law {other}"),
    }
}

#[test]
fn laws_match_pyplcopen() {
    let mut cams: BTreeMap<(String, u64, u64), Cam> = BTreeMap::new();
    let mut rows_per_law: BTreeMap<String, usize> = BTreeMap::new();
    let mut worst = 0.0f64;
    let mut failures = Vec::new();
    let mut lines = FIXTURE.lines();
    assert_eq!(lines.next(), Some("law,master_span,rise,points,i,x,y"));
    for (n, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 7, "line {}", n + 2);
        let num = |i: usize| -> f64 { f[i].parse().unwrap() };
        let (span, rise, points, i, x, y) = (
            num(1),
            num(2),
            f[3].parse::<usize>().unwrap(),
            f[4].parse::<usize>().unwrap(),
            num(5),
            num(6),
        );
        let law = law_for(f[0]);
        let key = (f[0].to_string(), span.to_bits(), rise.to_bits());
        let cam = cams.entry(key).or_insert_with(|| {
            Cam::interpolate(&CamDefinition {
                segments: vec![SegmentDef::Law {
                    law,
                    x0: 0.0,
                    x1: span,
                    y0: 0.0,
                    y1: rise,
                }],
                interpolation: Interpolation::Linear,
                ..CamDefinition::default()
            })
            .unwrap()
        });
        // pyplcopen samples x_i = span · i/(points − 1).
        let u = i as f64 / (points - 1) as f64;
        assert!((x - span * u).abs() <= 1e-12 * span, "line {}", n + 2);
        let ours = cam.following(x).unwrap().value;
        let err = (ours - y).abs() / rise.abs().max(1.0);
        worst = worst.max(err);
        if err > 1e-12 {
            failures.push(format!(
                "line {}: ours {ours} pyplcopen {y} ({line})",
                n + 2
            ));
        }
        // The normalized law itself at the same u.
        let direct = rise * law.s(u);
        assert!((direct - y).abs() <= 1e-12 * rise.abs().max(1.0));
        *rows_per_law.entry(f[0].to_string()).or_default() += 1;
    }
    println!("worst deviation {worst:e} (relative to max(1, |rise|)), rows {rows_per_law:?}");
    assert_eq!(rows_per_law.len(), 3, "{rows_per_law:?}");
    assert!(rows_per_law.values().all(|&n| n >= 300), "{rows_per_law:?}");
    assert!(
        failures.is_empty(),
        "{} samples differ (worst {worst:e}):\n{}",
        failures.len(),
        failures.join("\n")
    );
}
