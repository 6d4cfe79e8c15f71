//! `MC_InterpolateCam`: from a [`CamDefinition`] to the pieces of a [`Cam`] (allocating, off
//! the cyclic path).
//!
//! Steps (S7-1500T Motion Control V4.0 function manual, 3.10 'Cam technology object', S7-Technology
//! V4.1 function manual, 3.5 '"Cam disk" technology object'):
//! 1. validate (finite, `|v| ≤ 1e12`, `x0 < x1`, law parameters);
//! 2. segments in definition order: a later segment is used in full, an earlier one keeps only
//!    what lies outside it, however narrow;
//! 3. points sorted by x; among equal x (within [`POINT_RESOLUTION`]) the last one wins; points on a segment or within
//!    [`GAP_THRESHOLD`] of one are dropped (the segment wins);
//! 4. gaps between segments not wider than [`GAP_THRESHOLD`] are closed by pulling both ends to
//!    the middle (each segment is stretched, its shape kept);
//! 5. every remaining gap, with the points in it, becomes a chain that is interpolated.

use super::piece::{
    bezier_end_slope, bezier_slopes, clip_slope, spline_end_curvature, spline_slopes,
    spline_start_curvature, End, Formula, Piece, PieceSource,
};
use super::{
    BoundaryCondition, Cam, CamDefinition, CamError, CamValue, Interpolation, SegmentDef,
    GAP_THRESHOLD, POINT_RESOLUTION, VALUE_LIMIT,
};

/// The part `[a, b]` of segment `seg` that survives, with its source parameters at `a` and `b`.
#[derive(Copy, Clone, Debug)]
struct Frag {
    a: f64,
    b: f64,
    seg: usize,
    ta: f64,
    tb: f64,
}

/// Knots to interpolate between two segments (or a cam edge), with the segment values at the
/// bounded ends.
#[derive(Clone, Debug)]
struct Chain {
    xs: Vec<f64>,
    ys: Vec<f64>,
    left: Option<CamValue>,
    right: Option<CamValue>,
}

fn ok_value(v: f64) -> bool {
    v.is_finite() && v.abs() <= VALUE_LIMIT
}

fn validate(def: &CamDefinition) -> Result<(), CamError> {
    for (index, &(x, y)) in def.points.iter().enumerate() {
        if !ok_value(x) || !ok_value(y) {
            return Err(CamError::InvalidPoint { index });
        }
    }
    for (index, seg) in def.segments.iter().enumerate() {
        let (x0, x1) = seg.span();
        let ok = ok_value(x0)
            && ok_value(x1)
            && x0 < x1
            && match *seg {
                SegmentDef::Polynomial { coeffs, .. } => coeffs.iter().all(|c| c.is_finite()),
                SegmentDef::Law { law, y0, y1, .. } => {
                    law.is_valid() && ok_value(y0) && ok_value(y1)
                }
                SegmentDef::S7Polynomial {
                    a,
                    sine_amplitude,
                    sine_period,
                    sine_phase,
                    ..
                } => {
                    a.iter().all(|c| c.is_finite())
                        && sine_amplitude.is_finite()
                        && sine_period.is_finite()
                        && sine_phase.is_finite()
                        && (sine_amplitude == 0.0 || sine_period != 0.0)
                }
            };
        if !ok {
            return Err(CamError::InvalidSegment { index });
        }
    }
    Ok(())
}

/// The source parameter of a segment at `x`.
fn param(seg: &SegmentDef, x: f64) -> f64 {
    match *seg {
        SegmentDef::Polynomial { x0, x1, .. } | SegmentDef::Law { x0, x1, .. } => {
            (x - x0) / (x1 - x0)
        }
        SegmentDef::S7Polynomial { .. } => x,
    }
}

/// Overlap resolution: each new segment is used in full; earlier ones keep their parts outside.
fn resolve_segments(segs: &[SegmentDef]) -> Vec<Frag> {
    let mut frags: Vec<Frag> = Vec::new();
    for (i, seg) in segs.iter().enumerate() {
        let (x0, x1) = seg.span();
        let mut next = Vec::with_capacity(frags.len() + 2);
        for f in &frags {
            if f.b <= x0 || f.a >= x1 {
                next.push(*f);
                continue;
            }
            let old = &segs[f.seg];
            if x0 > f.a {
                next.push(Frag {
                    b: x0,
                    tb: param(old, x0),
                    ..*f
                });
            }
            if f.b > x1 {
                next.push(Frag {
                    a: x1,
                    ta: param(old, x1),
                    ..*f
                });
            }
        }
        next.push(Frag {
            a: x0,
            b: x1,
            seg: i,
            ta: param(seg, x0),
            tb: param(seg, x1),
        });
        next.sort_by(|p, q| p.a.total_cmp(&q.a));
        frags = next;
    }
    frags
}

/// Points sorted by x, the last of equal x (within [`POINT_RESOLUTION`]) kept, those on or
/// near a segment dropped.
fn resolve_points(points: &[(f64, f64)], frags: &[Frag]) -> Vec<(f64, f64)> {
    // `+ 0.0` turns -0.0 into 0.0, so that both sort as the same x.
    let pts: Vec<(f64, f64)> = points.iter().map(|&(x, y)| (x + 0.0, y)).collect();
    let mut order: Vec<usize> = (0..pts.len()).collect();
    order.sort_by(|&i, &j| pts[i].0.total_cmp(&pts[j].0).then(i.cmp(&j)));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(pts.len());
    for i in order {
        let p = pts[i];
        match out.last_mut() {
            Some(last) if p.0 - last.0 <= POINT_RESOLUTION * last.0.abs().max(1.0) => *last = p,
            _ => out.push(p),
        }
    }
    out.retain(|&(x, _)| {
        let i = frags.partition_point(|f| f.b + GAP_THRESHOLD < x);
        !(i < frags.len() && frags[i].a - GAP_THRESHOLD <= x)
    });
    out
}

/// Refuses a segment whose value or derivatives are not finite on its span, sampled at nine
/// evenly spaced leading values: finite coefficients can still overflow (a polynomial
/// coefficient of `1e308`, a span of `1e-300`), and the axis that follows the cam takes these
/// values as setpoints. Inferred: the manuals name the `±1.0E12` range of points and segment
/// ends, not of derived values; a segment that cannot be evaluated is invalid
/// ([`CamError::InvalidSegment`]).
fn finite_segments(frags: &[Frag], pieces: &[Piece]) -> Result<(), CamError> {
    for (f, p) in frags.iter().zip(pieces) {
        let finite = (0..=8).all(|k| {
            let x = p.xa + (p.xb - p.xa) * f64::from(k) / 8.0;
            let v = p.eval(x);
            v.value.is_finite() && v.first_derivative.is_finite() && v.second_derivative.is_finite()
        });
        if !finite {
            return Err(CamError::InvalidSegment { index: f.seg });
        }
    }
    Ok(())
}

fn frag_piece(f: &Frag, seg: &SegmentDef) -> Piece {
    let formula = match *seg {
        SegmentDef::Polynomial { coeffs, .. } => Formula::Poly(coeffs),
        SegmentDef::Law { law, y0, y1, .. } => Formula::Law {
            law,
            y0,
            dy: y1 - y0,
        },
        SegmentDef::S7Polynomial {
            a,
            sine_amplitude,
            sine_period,
            sine_phase,
            ..
        } => Piece::s7_formula(a, sine_amplitude, sine_period, sine_phase),
    };
    Piece {
        xa: f.a,
        xb: f.b,
        t0: f.ta,
        k: (f.tb - f.ta) / (f.b - f.a),
        formula,
        source: PieceSource::Segment(f.seg),
    }
}

/// The gaps between segment pieces (and the cam edges) with the points inside them.
fn make_chains(points: &[(f64, f64)], segs: &[Piece]) -> Vec<Chain> {
    let mut chains = Vec::new();
    let mut p = 0;
    for j in 0..=segs.len() {
        let left = j.checked_sub(1).and_then(|i| segs.get(i));
        let right = segs.get(j);
        let upper = right.map_or(f64::INFINITY, |r| r.xa);
        let start = p;
        while p < points.len() && points[p].0 < upper {
            p += 1;
        }
        let mut xs = Vec::with_capacity(p - start + 2);
        let mut ys = Vec::with_capacity(p - start + 2);
        let lv = left.map(|l| {
            let v = l.eval(l.xb);
            xs.push(l.xb);
            ys.push(v.value);
            v
        });
        for &(x, y) in &points[start..p] {
            xs.push(x);
            ys.push(y);
        }
        let rv = right.map(|r| {
            let v = r.eval(r.xa);
            xs.push(r.xa);
            ys.push(v.value);
            v
        });
        if xs.len() >= 2 && xs[xs.len() - 1] > xs[0] {
            chains.push(Chain {
                xs,
                ys,
                left: lv,
                right: rv,
            });
        }
    }
    chains
}

fn secant(xs: &[f64], ys: &[f64], i: usize) -> f64 {
    (ys[i + 1] - ys[i]) / (xs[i + 1] - xs[i])
}

/// Builds the cam (see the module documentation).
pub(super) fn build(def: &CamDefinition) -> Result<Cam, CamError> {
    if def.points.is_empty() && def.segments.is_empty() {
        return Err(CamError::Empty);
    }
    validate(def)?;
    let mut frags = resolve_segments(&def.segments);
    let points = resolve_points(&def.points, &frags);
    if frags.is_empty() && points.len() < 2 {
        return Err(CamError::TooFewPoints);
    }
    for i in 1..frags.len() {
        let gap = frags[i].a - frags[i - 1].b;
        if gap > 0.0 && gap <= GAP_THRESHOLD {
            let mid = 0.5 * (frags[i].a + frags[i - 1].b);
            frags[i - 1].b = mid;
            frags[i].a = mid;
        }
    }
    let seg_pieces: Vec<Piece> = frags
        .iter()
        .map(|f| frag_piece(f, &def.segments[f.seg]))
        .collect();
    finite_segments(&frags, &seg_pieces)?;
    let chains = make_chains(&points, &seg_pieces);

    let outer_left = chains.first().is_some_and(|c| c.left.is_none());
    let outer_right = chains.last().is_some_and(|c| c.right.is_none());
    let equal = def.boundary == BoundaryCondition::EqualFirstDerivative;
    // Slopes of segments at the cam edges (for a chain at the other edge).
    let start_slope = (!outer_left)
        .then(|| seg_pieces.first().map(|p| p.eval(p.xa).first_derivative))
        .flatten();
    let end_slope = (!outer_right)
        .then(|| seg_pieces.last().map(|p| p.eval(p.xb).first_derivative))
        .flatten();

    let mut pieces = seg_pieces.clone();
    match def.interpolation {
        Interpolation::Linear => {
            for c in &chains {
                for i in 0..c.xs.len() - 1 {
                    pieces.push(Piece::line(c.xs[i], c.ys[i], c.xs[i + 1], c.ys[i + 1]));
                }
            }
        }
        Interpolation::CubicSpline => {
            let (ol, or) = if !equal {
                (End::Natural, End::Natural)
            } else {
                match (outer_left, outer_right) {
                    (true, true) => {
                        let p = equal_slope_spline(&chains);
                        (End::Slope(p), End::Slope(p))
                    }
                    (true, false) => (end_slope.map_or(End::Natural, End::Slope), End::Natural),
                    (false, true) => (End::Natural, start_slope.map_or(End::Natural, End::Slope)),
                    (false, false) => (End::Natural, End::Natural),
                }
            };
            for c in &chains {
                if let (Some(l), Some(r), 2) = (c.left, c.right, c.xs.len()) {
                    pieces.push(Piece::hermite5(c.xs[0], l, c.xs[1], r));
                    continue;
                }
                let le = c.left.map_or(ol, |v| End::Slope(v.first_derivative));
                let re = c.right.map_or(or, |v| End::Slope(v.first_derivative));
                let m = spline_slopes(&c.xs, &c.ys, le, re);
                push_hermite(&mut pieces, &c.xs, &c.ys, &m);
            }
        }
        Interpolation::Bezier => {
            let (ol, or) = if !equal {
                (None, None)
            } else {
                match (outer_left, outer_right) {
                    (true, true) => {
                        let p = equal_slope_bezier(&chains);
                        (Some(p), Some(p))
                    }
                    (true, false) => (end_slope, None),
                    (false, true) => (None, start_slope),
                    (false, false) => (None, None),
                }
            };
            for c in &chains {
                let le = c.left.map(|v| v.first_derivative).or(ol);
                let re = c.right.map(|v| v.first_derivative).or(or);
                let m = bezier_slopes(&c.xs, &c.ys, le, re);
                push_hermite(&mut pieces, &c.xs, &c.ys, &m);
            }
        }
    }
    pieces.sort_by(|p, q| p.xa.total_cmp(&q.xa));
    Ok(Cam::assemble(pieces, def.interpolation))
}

fn push_hermite(pieces: &mut Vec<Piece>, xs: &[f64], ys: &[f64], m: &[f64]) {
    for i in 0..xs.len() - 1 {
        pieces.push(Piece::hermite3(
            xs[i],
            ys[i],
            m[i],
            xs[i + 1],
            ys[i + 1],
            m[i + 1],
        ));
    }
}

/// The common edge slope `p` of a spline whose both edges are interpolated such that the second
/// derivatives at the edges are equal too. Both edge curvatures are affine in `p` (the spline
/// is linear in its end conditions), so two solves determine it.
fn equal_slope_spline(chains: &[Chain]) -> f64 {
    let (Some(first), Some(last)) = (chains.first(), chains.last()) else {
        return 0.0;
    };
    let single = chains.len() == 1;
    let curvatures = |p: f64| -> (f64, f64) {
        let fr = if single {
            End::Slope(p)
        } else {
            first
                .right
                .map_or(End::Natural, |v| End::Slope(v.first_derivative))
        };
        let mf = spline_slopes(&first.xs, &first.ys, End::Slope(p), fr);
        let start = spline_start_curvature(&first.xs, &first.ys, &mf);
        let end = if single {
            spline_end_curvature(&first.xs, &first.ys, &mf)
        } else {
            let ll = last
                .left
                .map_or(End::Natural, |v| End::Slope(v.first_derivative));
            let ml = spline_slopes(&last.xs, &last.ys, ll, End::Slope(p));
            spline_end_curvature(&last.xs, &last.ys, &ml)
        };
        (start, end)
    };
    let (s0, e0) = curvatures(0.0);
    let (s1, e1) = curvatures(1.0);
    let d0 = s0 - e0;
    let dd = (s1 - e1) - d0;
    let p = -d0 / dd;
    if p.is_finite() {
        p
    } else {
        0.0
    }
}

/// The common edge slope of a Bézier chain with both edges interpolated: the mean of the two
/// one-sided estimates, clipped so that both edge spans stay inside their y range.
fn equal_slope_bezier(chains: &[Chain]) -> f64 {
    let (Some(first), Some(last)) = (chains.first(), chains.last()) else {
        return 0.0;
    };
    let (fx, fy) = (&first.xs, &first.ys);
    let (lx, ly) = (&last.xs, &last.ys);
    let d_first = secant(fx, fy, 0);
    let n = lx.len();
    let d_last = secant(lx, ly, n - 2);
    let left = bezier_end_slope(
        fx[1] - fx[0],
        d_first,
        (fx.len() > 2).then(|| (fx[2] - fx[1], secant(fx, fy, 1))),
    );
    let right = bezier_end_slope(
        lx[n - 1] - lx[n - 2],
        d_last,
        (n > 2).then(|| (lx[n - 2] - lx[n - 3], secant(lx, ly, n - 3))),
    );
    clip_slope(clip_slope(0.5 * (left + right), d_first), d_last)
}
