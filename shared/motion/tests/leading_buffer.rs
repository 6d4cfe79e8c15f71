//! Leading-value buffer (see the leading values between nodes, docs/processes.md 'Leading values'):
//! property tests of the interpolation between the buffered samples of a leader, the extrapolation
//! past the newest, the ring, the refused pushes and the invalid samples; and that the cyclic path
//! does not allocate.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::objects::leading::{
    LeadingSample, LeadingValue, LeadingValueBuffer, Lookup, Missing, Rejected,
};
use tandem_testkit::counting::{arm, disarm};

tandem_testkit::counting_allocator!();

const MS: i64 = 1_000_000;

/// A polynomial of degree <= 5 in the time (s) since `t0_ns`.
#[derive(Copy, Clone, Debug)]
struct Poly {
    t0_ns: i64,
    c: [f64; 6],
}

impl Poly {
    /// (p, v, a) at `t_ns`.
    fn eval(&self, t_ns: i64) -> (f64, f64, f64) {
        let x = (t_ns - self.t0_ns) as f64 * 1e-9;
        let c = &self.c;
        let p = c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * (c[4] + x * c[5]))));
        let v = c[1] + x * (2.0 * c[2] + x * (3.0 * c[3] + x * (4.0 * c[4] + x * 5.0 * c[5])));
        let a = 2.0 * c[2] + x * (6.0 * c[3] + x * (12.0 * c[4] + x * 20.0 * c[5]));
        (p, v, a)
    }

    fn sample(&self, t_ns: i64, seq: u64) -> LeadingSample {
        let (p, v, a) = self.eval(t_ns);
        LeadingSample {
            t_ns,
            seq,
            p,
            v,
            a,
            modulo: None,
            valid: true,
        }
    }
}

/// A random polynomial over a window of `window_s` seconds: every term contributes up to
/// `scale` over the window, on top of an offset of up to 1e4 (a leader far from 0).
fn poly(window_s: f64) -> impl Strategy<Value = Poly> {
    (
        -1e15 as i64..1e15 as i64,
        -1e4f64..1e4,
        prop::array::uniform5(-1.0f64..1.0),
        -3.0f64..3.0,
    )
        .prop_map(move |(t0_ns, offset, r, log_scale)| {
            let scale = 10f64.powf(log_scale);
            let mut c = [offset, 0.0, 0.0, 0.0, 0.0, 0.0];
            for (k, rk) in r.iter().enumerate() {
                c[k + 1] = rk * scale / window_s.powi(k as i32 + 1);
            }
            Poly { t0_ns, c }
        })
}

/// The rounding floor of the comparisons: positions are stored in f64, so a sample's position
/// carries an error of `eps * |p|`; the interpolant turns it into errors of order
/// `eps * M / h^k` in the k-th derivative (`M = |p| + |v| h + |a| h²`, `h` the period).
const FLOOR: f64 = 1e3 * f64::EPSILON;

/// The normalised magnitude `M` of a set of samples with period `h` (s).
fn magnitude(samples: &[LeadingSample], h: f64) -> f64 {
    samples
        .iter()
        .map(|s| s.p.abs() + s.v.abs() * h + s.a.abs() * h * h)
        .fold(0.0, f64::max)
}

/// `got` equals `want` within 1e-9 relative, or within the rounding floor of derivative `k`.
fn close(got: f64, want: f64, k: i32, m: f64, h: f64) -> bool {
    (got - want).abs() <= 1e-9 * want.abs() + FLOOR * m / h.powi(k)
}

fn assert_close(got: LeadingValue, want: (f64, f64, f64), m: f64, h: f64, what: &str) {
    assert!(
        close(got.p, want.0, 0, m, h)
            && close(got.v, want.1, 1, m, h)
            && close(got.a, want.2, 2, m, h),
        "{what}: got ({}, {}, {}), want {want:?} (M {m}, h {h})",
        got.p,
        got.v,
        got.a
    );
}

fn interpolated(l: Lookup) -> LeadingValue {
    match l {
        Lookup::Interpolated(v) => v,
        other => panic!("expected an interpolated value, got {other:?}"),
    }
}

/// Offsets into an interval of `period_ns` at which the tests look the leader up.
fn offsets(period_ns: i64, fractions: &[f64]) -> Vec<i64> {
    let mut o = vec![
        1,
        2,
        period_ns / 3,
        period_ns / 2,
        period_ns - 2,
        period_ns - 1,
    ];
    o.extend(
        fractions
            .iter()
            .map(|f| ((f * period_ns as f64) as i64).clamp(1, period_ns - 1)),
    );
    o
}

/// The one-sided limits at `t` of the value around it, estimated from `t ∓ 1 ns` and `t ∓ 2 ns`
/// (linear extrapolation: the error is the second derivative times 1 ns², far below the
/// tolerances).
fn limit(b: &LeadingValueBuffer<64>, t: i64, dir: i64, tol: i64) -> (f64, f64, f64) {
    let x1 = b.at(t + dir, tol).value().unwrap();
    let x2 = b.at(t + 2 * dir, tol).value().unwrap();
    (2.0 * x1.p - x2.p, 2.0 * x1.v - x2.v, 2.0 * x1.a - x2.a)
}

fn triple(v: LeadingValue) -> (f64, f64, f64) {
    (v.p, v.v, v.a)
}

const SAMPLES: usize = 12;

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x1ead_0004),
        ..ProptestConfig::default()
    })]

    /// Samples of a random polynomial of degree <= 5 at a fixed period (0.25..4 ms): the value
    /// anywhere between them (and on them) equals the polynomial's p, v, a within 1e-9 relative
    /// or the f64 rounding floor of the samples ([`FLOOR`]).
    #[test]
    fn interpolation_is_exact_for_quintics(
        period_ns in 250_000i64..4 * MS,
        p in poly(SAMPLES as f64 * 4e-3),
        fractions in prop::collection::vec(0.0f64..1.0, 8),
    ) {
        let mut b = LeadingValueBuffer::<64>::new();
        let samples: Vec<_> = (0..SAMPLES)
            .map(|i| p.sample(p.t0_ns + i as i64 * period_ns, i as u64))
            .collect();
        for s in &samples {
            b.push(*s).unwrap();
        }
        prop_assert_eq!(b.len(), SAMPLES);
        prop_assert_eq!(b.lost(), 0);
        let h = period_ns as f64 * 1e-9;
        let m = magnitude(&samples, h);
        for s in &samples {
            prop_assert_eq!(b.at(s.t_ns, 0), Lookup::Interpolated(s.value()));
        }
        for s in &samples[..SAMPLES - 1] {
            for o in offsets(period_ns, &fractions) {
                let t = s.t_ns + o;
                let got = interpolated(b.at(t, 0));
                assert_close(got, p.eval(t), m, h, &format!("t = t_i + {o} ns"));
            }
        }
    }

    /// Samples of a jerk-limited-looking motion (piecewise constant jerk, with random errors
    /// added to p, v and a of every sample, so the interpolant is a genuine quintic): p, v and a
    /// are continuous across every sample time (the left and right limits equal the sample).
    #[test]
    fn interpolation_is_continuous_across_samples(
        period_ns in 250_000i64..4 * MS,
        start in (-1e4f64..1e4, -1e3f64..1e3, -1e4f64..1e4),
        jerks in prop::collection::vec(-1e6f64..1e6, SAMPLES),
        noise in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0), SAMPLES),
        noise_scale in 0.0f64..1e-2,
        t0_ns in -1e15 as i64..1e15 as i64,
    ) {
        let h = period_ns as f64 * 1e-9;
        let (mut p, mut v, mut a) = start;
        let mut samples = Vec::new();
        for (i, (j, e)) in jerks.iter().zip(&noise).enumerate() {
            samples.push(LeadingSample {
                t_ns: t0_ns + i as i64 * period_ns,
                seq: i as u64,
                p: p + e.0 * noise_scale,
                v: v + e.1 * noise_scale / h,
                a: a + e.2 * noise_scale / (h * h),
                modulo: Some(Modulo { start: 0.0, length: 360.0 }),
                valid: true,
            });
            p += h * (v + h * (a / 2.0 + h * j / 6.0));
            v += h * (a + h * j / 2.0);
            a += h * j;
        }
        let mut b = LeadingValueBuffer::<64>::new();
        for s in &samples {
            b.push(*s).unwrap();
        }
        let m = magnitude(&samples, h);
        for s in &samples[1..SAMPLES - 1] {
            let at = interpolated(b.at(s.t_ns, 0));
            prop_assert_eq!(at, s.value());
            assert_close(at, limit(&b, s.t_ns, -1, 0), m, h, "left limit");
            assert_close(at, limit(&b, s.t_ns, 1, 0), m, h, "right limit");
        }
    }

    /// A leader with constant acceleration: extrapolated exactly up to the tolerance, missing
    /// (late) 1 ns beyond; the extrapolation continues the interpolation across the newest
    /// sample; and when the late sample arrives, the value at the time bridged does not jump.
    #[test]
    fn extrapolation_bridges_late_samples(
        period_ns in 250_000i64..4 * MS,
        (p0, v0, acc) in (-1e4f64..1e4, -1e3f64..1e3, -1e4f64..1e4),
        tol_periods in 0.0f64..5.0,
        t0_ns in -1e15 as i64..1e15 as i64,
    ) {
        let tol = (tol_periods * period_ns as f64) as i64 + 2;
        let p = Poly { t0_ns, c: [p0, v0, 0.5 * acc, 0.0, 0.0, 0.0] };
        let samples: Vec<_> = (0..SAMPLES as u64)
            .map(|i| p.sample(t0_ns + i as i64 * period_ns, i))
            .collect();
        let mut b = LeadingValueBuffer::<64>::new();
        for s in &samples {
            b.push(*s).unwrap();
        }
        let newest = *b.newest().unwrap();
        prop_assert_eq!(newest, samples[SAMPLES - 1]);
        let h = period_ns as f64 * 1e-9;
        // The span bridged counts as a period for the rounding floor.
        let hx = h.max(tol as f64 * 1e-9);
        let m = magnitude(&samples, hx).max(magnitude(&[p.sample(newest.t_ns + tol, 0)], hx));
        for dt in [1, 2, tol / 3 + 1, tol - 1, tol] {
            match b.at(newest.t_ns + dt, tol) {
                Lookup::Extrapolated { value, age_ns } => {
                    prop_assert_eq!(age_ns, dt);
                    assert_close(value, p.eval(newest.t_ns + dt), m, h, &format!("dt {dt}"));
                }
                other => panic!("dt {dt}: {other:?}"),
            }
        }
        prop_assert_eq!(
            b.at(newest.t_ns + tol + 1, tol),
            Lookup::Missing(Missing::Late { newest_ns: newest.t_ns })
        );
        prop_assert_eq!(b.at(newest.t_ns + 1, 0), Lookup::Missing(Missing::Late { newest_ns: newest.t_ns }));
        prop_assert_eq!(b.at(newest.t_ns, 0), Lookup::Interpolated(newest.value()));
        // Continuous across the newest sample: interpolated on the left, extrapolated on the
        // right.
        let at = interpolated(b.at(newest.t_ns, tol));
        assert_close(at, limit(&b, newest.t_ns, -1, tol), m, h, "left of the newest");
        assert_close(at, limit(&b, newest.t_ns, 1, tol), m, h, "right of the newest");
        // The late sample arrives: the value at the time bridged stays.
        let bridged = b.at(newest.t_ns + tol, tol).value().unwrap();
        let late = p.sample(newest.t_ns + period_ns, SAMPLES as u64);
        b.push(late).unwrap();
        let now = b.at(newest.t_ns + tol, tol).value().unwrap();
        assert_close(now, triple(bridged), m, hx, "after the late sample");
    }

    /// More than `N` samples pushed: the buffer holds the newest `N`, the older ones are
    /// `TooOld`, and lookups within the newest `N` stay exact.
    #[test]
    fn ring_keeps_the_newest_n(
        period_ns in 250_000i64..4 * MS,
        p in poly(0.1),
        extra in 1usize..200,
        fractions in prop::collection::vec(0.0f64..1.0, 3),
    ) {
        ring_case::<1>(p, period_ns, extra, &fractions);
        ring_case::<2>(p, period_ns, extra, &fractions);
        ring_case::<7>(p, period_ns, extra, &fractions);
        ring_case::<64>(p, period_ns, extra, &fractions);
    }

    /// Random pushes, some out of order, duplicate or not finite, with random sequence gaps:
    /// every refused push changes no lookup and is counted; the buffer answers exactly as one
    /// fed only the accepted samples; gaps in the accepted sequence are counted in `lost`.
    #[test]
    fn refused_pushes_change_nothing(
        script in prop::collection::vec(
            (-2i64..6, 0u64..4, 0u8..12),
            1..80,
        ),
    ) {
        let p = Poly { t0_ns: 0, c: [1.0, 20.0, -3.0, 0.5, 0.0, 0.0] };
        let mut b = LeadingValueBuffer::<16>::new();
        let mut reference = LeadingValueBuffer::<16>::new();
        let (mut t, mut seq) = (0i64, 0u64);
        let (mut rejected, mut lost) = (0u64, 0u64);
        let mut last_accepted: Option<u64> = None;
        for &(dt, dseq, bad) in &script {
            t += dt * 100_000;
            seq += dseq;
            let mut s = p.sample(t, seq);
            match bad {
                0 => s.p = f64::NAN,
                1 => s.v = f64::INFINITY,
                2 => s.a = f64::NEG_INFINITY,
                _ => {}
            }
            let probes: Vec<i64> = (-3..12).map(|k| t + k * 37_000).collect();
            let before: Vec<Lookup> = probes.iter().map(|&x| b.at(x, 300_000)).collect();
            let newest = b.newest().copied();
            let expect = if bad < 3 {
                Err(Rejected::NotFinite)
            } else if let Some(n) = newest.filter(|n| t <= n.t_ns) {
                Err(Rejected::OutOfOrder { newest_ns: n.t_ns })
            } else {
                Ok(())
            };
            prop_assert_eq!(b.push(s), expect);
            if expect.is_ok() {
                if last_accepted.is_some_and(|q| seq != q + 1) {
                    lost += 1;
                }
                last_accepted = Some(seq);
                reference.push(s).unwrap();
            } else {
                rejected += 1;
                let after: Vec<Lookup> = probes.iter().map(|&x| b.at(x, 300_000)).collect();
                prop_assert_eq!(&before, &after);
                prop_assert_eq!(b.newest().copied(), newest);
            }
            prop_assert_eq!((b.rejected(), b.lost()), (rejected, lost));
            prop_assert_eq!(b.len(), reference.len());
            for x in probes {
                prop_assert_eq!(b.at(x, 300_000), reference.at(x, 300_000));
            }
        }
    }

    /// Random samples marked invalid: a lookup that uses an invalid sample (the sample itself,
    /// either end of the interval, or the newest for an extrapolation) is `Missing(Invalid)`;
    /// every other lookup is the same as with all samples valid; late stays late.
    #[test]
    fn invalid_samples_are_missing(
        valid in prop::collection::vec(prop::bool::weighted(0.7), 2..20),
        period_ns in 250_000i64..4 * MS,
    ) {
        let p = Poly { t0_ns: 0, c: [5.0, -40.0, 100.0, 0.0, 0.0, 0.0] };
        let n = valid.len();
        let mut b = LeadingValueBuffer::<32>::new();
        let mut all_valid = LeadingValueBuffer::<32>::new();
        for (i, &ok) in valid.iter().enumerate() {
            let s = p.sample(i as i64 * period_ns, i as u64);
            all_valid.push(s).unwrap();
            b.push(LeadingSample { valid: ok, ..s }).unwrap();
        }
        let tol = period_ns;
        let check = |t: i64, used: &[usize]| -> Result<(), TestCaseError> {
            let want = if used.iter().any(|&i| !valid[i]) {
                Lookup::Missing(Missing::Invalid)
            } else {
                all_valid.at(t, tol)
            };
            prop_assert_eq!(b.at(t, tol), want, "t {}, samples {:?}", t, used);
            Ok(())
        };
        for i in 0..n {
            let t = i as i64 * period_ns;
            check(t, &[i])?;
            if i + 1 < n {
                check(t + 1, &[i, i + 1])?;
                check(t + period_ns / 2, &[i, i + 1])?;
                check(t + period_ns - 1, &[i, i + 1])?;
            }
        }
        let newest = (n - 1) as i64 * period_ns;
        check(newest + 1, &[n - 1])?;
        check(newest + tol, &[n - 1])?;
        prop_assert_eq!(b.at(newest + tol + 1, tol), Lookup::Missing(Missing::Late { newest_ns: newest }));
        prop_assert_eq!(b.at(-1, tol), Lookup::Missing(Missing::TooOld { oldest_ns: 0 }));
    }
}

/// Pushes `N + extra` samples of `p` into a buffer of `N` and checks what it holds.
fn ring_case<const N: usize>(p: Poly, period_ns: i64, extra: usize, fractions: &[f64]) {
    let mut b = LeadingValueBuffer::<N>::new();
    let total = N + extra;
    let samples: Vec<_> = (0..total as u64)
        .map(|i| p.sample(p.t0_ns + i as i64 * period_ns, i))
        .collect();
    for (i, s) in samples.iter().enumerate() {
        b.push(*s).unwrap();
        assert_eq!(b.len(), (i + 1).min(N));
        assert_eq!(b.newest(), Some(s));
    }
    assert_eq!((b.rejected(), b.lost()), (0, 0));
    let kept = &samples[total - N..];
    let oldest_ns = kept[0].t_ns;
    for s in &samples[..total - N] {
        assert_eq!(
            b.at(s.t_ns, 0),
            Lookup::Missing(Missing::TooOld { oldest_ns }),
            "N {N}"
        );
    }
    assert_eq!(
        b.at(oldest_ns - 1, 0),
        Lookup::Missing(Missing::TooOld { oldest_ns })
    );
    let h = period_ns as f64 * 1e-9;
    let m = magnitude(kept, h);
    for s in kept {
        assert_eq!(b.at(s.t_ns, 0), Lookup::Interpolated(s.value()), "N {N}");
    }
    for s in &kept[..N - 1] {
        for o in offsets(period_ns, fractions) {
            let t = s.t_ns + o;
            assert_close(
                interpolated(b.at(t, 0)),
                p.eval(t),
                m,
                h,
                &format!("N {N}, t_i + {o}"),
            );
        }
    }
}

fn linear_sample(k: i64, seq: u64) -> LeadingSample {
    LeadingSample {
        t_ns: k * MS,
        seq,
        p: 0.1 * k as f64,
        v: 100.0,
        a: 0.0,
        modulo: None,
        valid: true,
    }
}

/// The missing cases of an empty, a one-sample and a cleared buffer; `Lookup::value`.
#[test]
fn empty_single_and_cleared() {
    let mut b = LeadingValueBuffer::<4>::default();
    assert!(b.is_empty());
    assert_eq!(b.newest(), None);
    assert_eq!(b.at(0, MS), Lookup::Missing(Missing::Empty));
    assert_eq!(b.at(0, MS).value(), None);
    b.push(linear_sample(3, 10)).unwrap();
    assert_eq!(b.len(), 1);
    assert_eq!(
        b.at(3 * MS - 1, MS),
        Lookup::Missing(Missing::TooOld { oldest_ns: 3 * MS })
    );
    assert_eq!(b.at(3 * MS, MS).value(), Some(linear_sample(3, 10).value()));
    let Lookup::Extrapolated { value, age_ns } = b.at(3 * MS + MS / 2, MS) else {
        panic!("not extrapolated");
    };
    assert_eq!(age_ns, MS / 2);
    assert!((value.p - 0.35).abs() < 1e-12 && value.v == 100.0 && value.a == 0.0);
    assert_eq!(
        b.at(4 * MS + 1, MS),
        Lookup::Missing(Missing::Late { newest_ns: 3 * MS })
    );
    // A negative tolerance: the newest sample itself only.
    assert_eq!(
        b.at(3 * MS + 1, -5),
        Lookup::Missing(Missing::Late { newest_ns: 3 * MS })
    );
    assert!(b.at(3 * MS, -5).value().is_some());
    // Extreme times do not overflow.
    assert_eq!(
        b.at(i64::MAX, i64::MAX - 3 * MS - 1),
        Lookup::Missing(Missing::Late { newest_ns: 3 * MS })
    );
    assert!(matches!(
        b.at(i64::MAX, i64::MAX),
        Lookup::Extrapolated { age_ns, .. } if age_ns == i64::MAX - 3 * MS
    ));
    assert_eq!(
        b.at(i64::MIN, 0),
        Lookup::Missing(Missing::TooOld { oldest_ns: 3 * MS })
    );
    // Cleared: empty again, counters kept, any time and sequence number accepted next.
    b.push(linear_sample(3, 11)).unwrap_err();
    b.clear();
    assert!(b.is_empty());
    assert_eq!(b.at(3 * MS, MS), Lookup::Missing(Missing::Empty));
    assert_eq!(b.rejected(), 1);
    b.push(linear_sample(1, 0)).unwrap();
    assert_eq!((b.rejected(), b.lost()), (1, 0));
    assert!(format!("{b:?}").contains("len: 1"));
}

/// Refusals by example: a duplicate time, an earlier time, NaN (which wins over the time), and
/// sequence gaps (a jump by more than one, a restart) counted once each.
#[test]
fn refusals_and_gaps_by_example() {
    let mut b = LeadingValueBuffer::<8>::new();
    b.push(linear_sample(0, 0)).unwrap();
    b.push(linear_sample(1, 1)).unwrap();
    let before = b.at(MS / 2, 0);
    assert_eq!(
        b.push(linear_sample(1, 2)),
        Err(Rejected::OutOfOrder { newest_ns: MS })
    );
    assert_eq!(
        b.push(linear_sample(0, 2)),
        Err(Rejected::OutOfOrder { newest_ns: MS })
    );
    let nan = LeadingSample {
        p: f64::NAN,
        ..linear_sample(0, 2)
    };
    assert_eq!(b.push(nan), Err(Rejected::NotFinite));
    assert_eq!(b.at(MS / 2, 0), before);
    assert_eq!((b.len(), b.rejected(), b.lost()), (2, 3, 0));
    b.push(linear_sample(2, 2)).unwrap();
    b.push(linear_sample(3, 5)).unwrap(); // 3 and 4 lost: one gap
    b.push(linear_sample(4, 6)).unwrap();
    b.push(linear_sample(5, 0)).unwrap(); // sender restarted: one gap
    b.push(linear_sample(6, 1)).unwrap();
    assert_eq!((b.len(), b.rejected(), b.lost()), (7, 3, 2));
}

/// Modulo settings of the result: those of the later sample used.
#[test]
fn modulo_comes_from_the_later_sample() {
    let m1 = Some(Modulo {
        start: 0.0,
        length: 360.0,
    });
    let m2 = Some(Modulo {
        start: -180.0,
        length: 360.0,
    });
    let mut b = LeadingValueBuffer::<4>::new();
    b.push(LeadingSample {
        modulo: m1,
        ..linear_sample(0, 0)
    })
    .unwrap();
    b.push(LeadingSample {
        modulo: m2,
        ..linear_sample(1, 1)
    })
    .unwrap();
    assert_eq!(b.at(0, 0).value().unwrap().modulo, m1);
    assert_eq!(b.at(1, 0).value().unwrap().modulo, m2);
    assert_eq!(b.at(MS, 0).value().unwrap().modulo, m2);
    assert_eq!(b.at(MS + 1, MS).value().unwrap().modulo, m2);
}

/// No allocation: building a buffer of 1024 samples, then 20,000 cycles of push, lookups at a
/// delay (interpolated, extrapolated, too old), refused pushes and a clear.
#[test]
fn cyclic_path_does_not_allocate() {
    arm();
    let mut b = LeadingValueBuffer::<1024>::new();
    let mut sum = 0.0;
    let mut missing = 0u32;
    for k in 0..20_000i64 {
        if k == 10_000 {
            b.clear();
        }
        // Every 7th sample is lost (late and never arrives).
        if k % 7 != 3 {
            b.push(linear_sample(k, k as u64)).unwrap();
        }
        if k % 100 == 0 {
            b.push(linear_sample(k - 1, k as u64)).unwrap_err();
        }
        for delay in [0, MS / 3, 5 * MS / 2, 2000 * MS] {
            match b.at(k * MS + MS / 4 - delay, MS) {
                Lookup::Interpolated(v) | Lookup::Extrapolated { value: v, .. } => sum += v.p,
                Lookup::Missing(_) => missing += 1,
            }
        }
    }
    let (allocs, _) = disarm();
    assert!(sum.is_finite() && missing > 0);
    assert!(b.lost() > 0 && b.rejected() == 200);
    assert_eq!(allocs, 0, "{allocs} allocations on the cyclic path");
}

/// A gap in the samples (a leader restarted) is bridged no further than a late sample: beyond
/// the tolerance after the sample before the gap the value is missing, and the samples after
/// the gap are exact again.
#[test]
fn a_gap_is_missing_beyond_the_tolerance() {
    let mut b = LeadingValueBuffer::<16>::new();
    b.set_max_gap(3_000_000);
    let s = |t_ns: i64, seq: u64| LeadingSample {
        t_ns,
        seq,
        p: t_ns as f64 * 1e-6,
        v: 1000.0,
        a: 0.0,
        modulo: None,
        valid: true,
    };
    for k in 0..4 {
        assert!(b.push(s(k * 1_000_000, k as u64)).is_ok());
    }
    // The leader is gone for 2 s, then publishes again.
    assert!(b.push(s(2_003_000_000, 0)).is_ok());
    let tol = 2_000_000;
    assert!(matches!(
        b.at(3_000_000 + tol, tol),
        Lookup::Interpolated(_)
    ));
    assert_eq!(
        b.at(3_000_000 + tol + 1, tol),
        Lookup::Missing(Missing::Late {
            newest_ns: 3_000_000
        })
    );
    assert_eq!(
        b.at(1_000_000_000, tol),
        Lookup::Missing(Missing::Late {
            newest_ns: 3_000_000
        })
    );
    assert_eq!(
        b.at(2_003_000_000, tol).value(),
        Some(s(2_003_000_000, 0).value())
    );
}
