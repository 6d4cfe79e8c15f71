//! Encoder values and mechanics (S7-1500T Motion Control V4.0 function manual, 'Drive and encoder
//! connection' and 'Mechanics'): known answers for each mechanics combination, the refused
//! configurations, the raw counter over 10^6 random wraps (property test), the round trip
//! count -> position -> count up to 2^52, the drive's 32-bit wrapping increments, the absolute
//! encoder adjustment's byte layout, and that the cyclic methods do not allocate.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tandem_motion::plant::mechanics::{
    AbsoluteAdjustment, AdjustmentError, EncoderConfig, EncoderKind, Mechanics, MechanicsError,
    MechanicsField, MechanicsRule, Mounting, RawCounter, Scaling, ADJUSTMENT_LEN,
};
use tandem_testkit::counting::{arm, disarm};

tandem_testkit::counting_allocator!();

const TWO_20: i64 = 1 << 20;

/// An incremental encoder of `steps` per revolution on the motor shaft, raw word 32 bits.
fn encoder(steps: u32) -> EncoderConfig {
    EncoderConfig {
        kind: EncoderKind::Incremental,
        steps_per_revolution: steps,
        fine_resolution_bits: 0,
        determinable_revolutions: 1,
        raw_bits: 32,
        inverse: false,
        mounting: Mounting::MotorShaft,
    }
}

/// Mechanics with gear `numerator : denominator`.
fn gear(numerator: u32, denominator: u32) -> Mechanics {
    Mechanics {
        load_gear_numerator: numerator,
        load_gear_denominator: denominator,
        ..Mechanics::default()
    }
}

fn scaling(e: EncoderConfig, m: Mechanics) -> Scaling {
    Scaling::new(&e, &m).unwrap()
}

/// Rotary axis, 2^20 increments per motor revolution on the motor shaft, load gear 3:1 (three
/// motor revolutions per load revolution): one motor revolution is 120 °.
#[test]
fn rotary_motor_shaft_gear_3_to_1() {
    let s = scaling(encoder(1 << 20), gear(3, 1));
    assert_eq!(s.counts_per_revolution(), 1 << 20);
    assert_eq!(s.position(TWO_20), 120.0);
    assert_eq!(s.position(3 * TWO_20), 360.0);
    assert_eq!(s.position(-TWO_20), -120.0);
    assert_eq!(s.position(TWO_20 / 2), 60.0);
    assert_eq!(s.position(1), 120.0 / TWO_20 as f64);
    assert_eq!(s.count(120.0), TWO_20);
    assert_eq!(s.count(-240.0), -2 * TWO_20);
    assert_eq!(s.velocity(TWO_20 as f64), 120.0);
    assert_eq!(s.counts_per_second(360.0), 3.0 * TWO_20 as f64);
    assert_eq!(s.drive_increments(360.0), 3 << 20);
    // No drift: after 10^6 load revolutions the position is exactly 360e6 °, and one count
    // further exactly one count's angle more.
    let n = 3 * TWO_20 * 1_000_000;
    assert_eq!(s.position(n), 360e6);
    assert_eq!(s.position(n + 1) - 360e6, 120.0 / TWO_20 as f64);
    assert_eq!(s.count(360e6), n);
}

/// Gear 2:3 (two motor revolutions per three load revolutions): one motor revolution is 540 °.
#[test]
fn rotary_motor_shaft_gear_2_to_3() {
    let s = scaling(encoder(1000), gear(2, 3));
    assert_eq!(s.position(1000), 540.0);
    assert_eq!(s.position(2000), 1080.0);
    assert_eq!(s.position(500), 270.0);
    assert_eq!(s.count(540.0), 1000);
    assert_eq!(s.count(0.54), 1);
    assert_eq!(
        s.count(0.26),
        0,
        "0.26 ° is nearer 0 than one count (0.54 °)"
    );
    assert_eq!(s.count(0.28), 1);
}

/// A load-side encoder of 4096 steps: the gear does not apply to the actual value, but to the
/// drive's increments (4096 per motor revolution, the encoder's resolution by default).
#[test]
fn rotary_load_side() {
    let e = EncoderConfig {
        steps_per_revolution: 4096,
        mounting: Mounting::LoadSide,
        ..encoder(4096)
    };
    let s = scaling(e, gear(3, 1));
    assert_eq!(s.position(1024), 90.0);
    assert_eq!(s.position(4096), 360.0);
    assert_eq!(s.count(90.0), 1024);
    // 90 ° of load are 0.75 motor revolutions.
    assert_eq!(s.drive_increments(90.0), 3072);
    assert_eq!(s.drive_position(3072), 90.0);
    // A drive with its own 10000 increments per motor revolution.
    let m = Mechanics {
        drive_increments_per_revolution: Some(10_000),
        ..gear(3, 1)
    };
    let s = scaling(e, m);
    assert_eq!(s.drive_increments(120.0), 10_000);
    assert_eq!(s.drive_increments_per_second(360.0), 30_000.0);
}

/// An external measuring wheel of 100 mm per revolution, 2500 steps: neither gear nor
/// leadscrew applies.
#[test]
fn external_distance_per_revolution() {
    let e = EncoderConfig {
        steps_per_revolution: 2500,
        mounting: Mounting::External {
            distance_per_revolution: 100.0,
        },
        ..encoder(2500)
    };
    let m = Mechanics {
        leadscrew_pitch: Some(5.0),
        ..gear(7, 2)
    };
    let s = scaling(e, m);
    assert_eq!(s.position(1250), 50.0);
    assert_eq!(s.position(2500), 100.0);
    assert_eq!(s.position(1), 0.04);
    assert_eq!(s.count(50.0), 1250);
    assert_eq!(s.velocity(2500.0), 100.0);
}

/// A linear axis: leadscrew pitch 5 mm, gear 2:1, 10000 increments per motor revolution on the
/// motor shaft: one motor revolution is 2.5 mm.
#[test]
fn linear_leadscrew_5_mm() {
    let m = Mechanics {
        leadscrew_pitch: Some(5.0),
        ..gear(2, 1)
    };
    let s = scaling(encoder(10_000), m);
    assert_eq!(s.position(10_000), 2.5);
    assert_eq!(s.position(40_000), 10.0);
    assert_eq!(s.position(1), 2.5e-4);
    assert_eq!(s.position(-4_000_000_000), -1e6);
    assert_eq!(s.count(2.5), 10_000);
    assert_eq!(s.count(-1e6), -4_000_000_000);
    assert_eq!(s.velocity(10_000.0), 2.5);
    assert_eq!(s.counts_per_second(100.0), 400_000.0);
    assert_eq!(s.drive_increments(2.5), 10_000);
}

/// Inversion of the actual value (`Sensor[n].InverseDirection`) and of the setpoint
/// (`Actor.InverseDirection`).
#[test]
fn inversion_of_encoder_and_drive() {
    let e = EncoderConfig {
        inverse: true,
        ..encoder(1 << 20)
    };
    let s = scaling(e, gear(3, 1));
    assert_eq!(s.position(TWO_20), -120.0);
    assert_eq!(s.count(-120.0), TWO_20);
    assert_eq!(s.velocity(TWO_20 as f64), -120.0);
    assert_eq!(s.counts_per_second(-120.0), TWO_20 as f64);
    assert_eq!(
        s.drive_increments(120.0),
        1 << 20,
        "the drive is not inverted"
    );
    assert!(s.torque_factor() > 0.0);

    let m = Mechanics {
        inverse_drive: true,
        ..gear(3, 1)
    };
    let s = scaling(encoder(1 << 20), m);
    assert_eq!(s.position(TWO_20), 120.0, "the encoder is not inverted");
    assert_eq!(s.drive_increments(120.0), -(1 << 20));
    assert_eq!(s.drive_position(-TWO_20), 120.0);
    assert_eq!(s.drive_increments_per_second(120.0), -(TWO_20 as f64));
    assert_eq!(s.load_torque(1.0), -3.0);

    // Both inverted (the drive's own motor encoder): a setpoint equal to the actual position is
    // the actual increment count.
    let s = scaling(e, m);
    for c in [-5 * TWO_20 - 7, -1, 0, 1, 12_345_678] {
        assert_eq!(i64::from(s.drive_increments(s.position(c))), c);
    }
}

/// Fine resolution of 11 bits (`FineResolutionXist1`): a 2048-step encoder counts 2^22 per
/// revolution, one step is 2^11 counts.
#[test]
fn fine_resolution_11_bits() {
    let e = EncoderConfig {
        steps_per_revolution: 2048,
        fine_resolution_bits: 11,
        mounting: Mounting::LoadSide,
        ..encoder(2048)
    };
    let s = scaling(e, Mechanics::default());
    assert_eq!(s.counts_per_revolution(), 1 << 22);
    assert_eq!(s.position(1 << 11), 360.0 / 2048.0);
    assert_eq!(s.position(1 << 11), 0.17578125);
    assert_eq!(s.position(1 << 22), 360.0);
    assert_eq!(s.position(1), 360.0 / (1 << 22) as f64);
    assert_eq!(s.count(0.17578125), 1 << 11);
}

/// A 25-bit SSI encoder (13-bit single turn, 12-bit multiturn; the EL5001 counter value), load
/// side: the raw word wraps at 2^25 and the count goes on.
#[test]
fn ssi_25_bit_raw_word() {
    let e = EncoderConfig {
        kind: EncoderKind::CyclicAbsolute,
        steps_per_revolution: 8192,
        determinable_revolutions: 4096,
        raw_bits: 25,
        mounting: Mounting::LoadSide,
        ..encoder(8192)
    };
    let s = scaling(e, Mechanics::default());
    let top = (1u32 << 25) - 10;
    let mut c = s.raw_counter(top);
    assert_eq!(c.count(), i64::from(top));
    assert_eq!(c.ranges(), 0);
    // +15 counts crosses the wrap; bits above the 25 are ignored.
    assert_eq!(c.update(5 | 0xFE00_0000), (1 << 25) + 5);
    assert_eq!(c.ranges(), 1);
    assert_eq!(c.raw(), 5);
    assert_eq!(s.position(c.count()), 4096.0 * 360.0 + 5.0 * 360.0 / 8192.0);
    // And back.
    assert_eq!(c.update(top), i64::from(top));
    assert_eq!(c.ranges(), 0);

    // An absolute encoder whose range does not fit 25 bits, and a cyclic absolute one whose
    // range does not fill them, are refused.
    let too_big = EncoderConfig {
        kind: EncoderKind::Absolute,
        determinable_revolutions: 8192,
        ..e
    };
    assert_eq!(
        Scaling::new(&too_big, &Mechanics::default()),
        Err(MechanicsError {
            field: MechanicsField::DeterminableRevolutions,
            rule: MechanicsRule::RangeExceedsRawWord {
                range: 1 << 26,
                raw_bits: 25
            }
        })
    );
    let absolute_half = EncoderConfig {
        kind: EncoderKind::Absolute,
        determinable_revolutions: 2048,
        ..e
    };
    assert!(Scaling::new(&absolute_half, &Mechanics::default()).is_ok());
    let cyclic_half = EncoderConfig {
        kind: EncoderKind::CyclicAbsolute,
        ..absolute_half
    };
    let err = Scaling::new(&cyclic_half, &Mechanics::default()).unwrap_err();
    assert_eq!(
        err.rule,
        MechanicsRule::RangeNotRawWord {
            range: 1 << 24,
            raw_bits: 25
        }
    );
    assert!(err.to_string().contains("DeterminableRevolutions"), "{err}");
}

/// Torque and force: gear, leadscrew and efficiency (`Actor.Efficiency`).
#[test]
fn torque_conversion() {
    let m = Mechanics {
        efficiency: 0.9,
        ..gear(3, 1)
    };
    let s = scaling(encoder(1 << 20), m);
    assert!((s.load_torque(2.0) - 5.4).abs() < 1e-12);
    assert!((s.motor_torque(5.4) - 2.0).abs() < 1e-12);
    // Leadscrew 5 mm, 1:1: F = 2 pi T / pitch; 1 N·m gives 1.2566 N·m/mm = 1256.6 N.
    let m = Mechanics {
        leadscrew_pitch: Some(5.0),
        ..Mechanics::default()
    };
    let s = scaling(encoder(1 << 20), m);
    assert!((s.load_torque(1.0) - 1.256_637_061_435_917_2).abs() < 1e-15);
    assert!((s.load_torque(1.0) * 1000.0 - 1_256.637_061_435_917).abs() < 1e-9);
    assert!((s.motor_torque(s.load_torque(0.3)) - 0.3).abs() < 1e-15);
}

/// Each field outside its range is refused, naming it and the rule.
#[test]
fn refused_configurations_name_field_and_rule() {
    let e = encoder(1 << 20);
    let m = Mechanics::default();
    let refused = |e: EncoderConfig, m: Mechanics| Scaling::new(&e, &m).unwrap_err();
    let range = |found, min, max| MechanicsRule::OutOfRange { found, min, max };
    let cases = [
        (
            refused(
                EncoderConfig {
                    steps_per_revolution: 0,
                    ..e
                },
                m,
            ),
            MechanicsField::StepsPerRevolution,
            range(0, 1, 8_388_608),
        ),
        (
            refused(
                EncoderConfig {
                    steps_per_revolution: 8_388_609,
                    ..e
                },
                m,
            ),
            MechanicsField::StepsPerRevolution,
            range(8_388_609, 1, 8_388_608),
        ),
        (
            refused(
                EncoderConfig {
                    fine_resolution_bits: 32,
                    ..e
                },
                m,
            ),
            MechanicsField::FineResolutionBits,
            range(32, 0, 31),
        ),
        (
            refused(EncoderConfig { raw_bits: 0, ..e }, m),
            MechanicsField::RawBits,
            range(0, 1, 32),
        ),
        (
            refused(EncoderConfig { raw_bits: 33, ..e }, m),
            MechanicsField::RawBits,
            range(33, 1, 32),
        ),
        (
            refused(
                EncoderConfig {
                    kind: EncoderKind::Absolute,
                    determinable_revolutions: 0,
                    ..e
                },
                m,
            ),
            MechanicsField::DeterminableRevolutions,
            range(0, 1, u64::from(u32::MAX)),
        ),
        (
            refused(
                EncoderConfig {
                    mounting: Mounting::External {
                        distance_per_revolution: 0.0,
                    },
                    ..e
                },
                m,
            ),
            MechanicsField::DistancePerRevolution,
            MechanicsRule::LengthOutOfRange,
        ),
        (
            refused(e, gear(0, 1)),
            MechanicsField::LoadGearNumerator,
            range(0, 1, u64::from(u32::MAX)),
        ),
        (
            refused(e, gear(1, 0)),
            MechanicsField::LoadGearDenominator,
            range(0, 1, u64::from(u32::MAX)),
        ),
        (
            refused(
                e,
                Mechanics {
                    leadscrew_pitch: Some(f64::NAN),
                    ..m
                },
            ),
            MechanicsField::LeadscrewPitch,
            MechanicsRule::LengthOutOfRange,
        ),
        (
            refused(
                e,
                Mechanics {
                    leadscrew_pitch: Some(-5.0),
                    ..m
                },
            ),
            MechanicsField::LeadscrewPitch,
            MechanicsRule::LengthOutOfRange,
        ),
        (
            refused(
                e,
                Mechanics {
                    efficiency: 0.0,
                    ..m
                },
            ),
            MechanicsField::Efficiency,
            MechanicsRule::NotFraction,
        ),
        (
            refused(
                e,
                Mechanics {
                    efficiency: 1.01,
                    ..m
                },
            ),
            MechanicsField::Efficiency,
            MechanicsRule::NotFraction,
        ),
        (
            refused(
                e,
                Mechanics {
                    drive_increments_per_revolution: Some(0),
                    ..m
                },
            ),
            MechanicsField::DriveIncrementsPerRevolution,
            range(0, 1, u64::from(u32::MAX)),
        ),
    ];
    for (err, field, rule) in cases {
        assert_eq!(err, MechanicsError { field, rule });
        assert!(!err.to_string().is_empty());
    }
    let err = refused(
        EncoderConfig {
            steps_per_revolution: 0,
            ..e
        },
        m,
    );
    assert_eq!(
        err.to_string(),
        "steps_per_revolution (Sensor[n].Parameter.StepsPerRevolution): is 0, must be in \
         1..=8388608"
    );
    // The extremes are accepted: 2^23 steps with 31 bits of fine resolution, 32-bit gears, and
    // the incremental encoder ignores the multiturn range.
    let widest = EncoderConfig {
        steps_per_revolution: 8_388_608,
        fine_resolution_bits: 31,
        determinable_revolutions: 0,
        ..e
    };
    let s = scaling(widest, gear(u32::MAX, u32::MAX));
    assert_eq!(s.counts_per_revolution(), 1 << 54);
    assert_eq!(s.position(1 << 52), 90.0);
    assert_eq!(s.position(-(1 << 52)), -90.0);
    assert_eq!(s.count(-90.0), -(1 << 52));
}

#[test]
fn raw_counter_basics() {
    assert_eq!(
        RawCounter::new(0, 0),
        Err(MechanicsError {
            field: MechanicsField::RawBits,
            rule: MechanicsRule::OutOfRange {
                found: 0,
                min: 1,
                max: 32
            }
        })
    );
    assert!(RawCounter::new(33, 0).is_err());
    // A CiA 402 0x6064 (INT32) of -5.
    let mut c = RawCounter::new_signed(32, (-5i32) as u32).unwrap();
    assert_eq!(c.count(), -5);
    assert_eq!(c.ranges(), -1);
    assert_eq!(c.update(3), 3);
    // The same word read unsigned.
    assert_eq!(
        RawCounter::new(32, (-5i32) as u32).unwrap().count(),
        4_294_967_291
    );
    // 16 bits: exactly half a range backwards is read as backwards, just below half forwards.
    let mut c = RawCounter::new(16, 0).unwrap();
    assert_eq!(c.update(0x8000), -0x8000);
    assert_eq!(c.update(0xFFFF), -0x8000 + 0x7FFF);
    // A touch-probe value near the present position, across the wrap, without taking it.
    let c = RawCounter::new_signed(32, 0x7FFF_FFF0).unwrap();
    assert_eq!(c.nearest(0x8000_0005), 0x8000_0005);
    assert_eq!(c.count(), 0x7FFF_FFF0);
    // Rebase by whole ranges keeps the raw relation; overflow is refused.
    let mut c = RawCounter::new(8, 200).unwrap();
    assert_eq!(c.rebase(512), Some(200 - 512));
    // From raw 200 to raw 10 is +66 modulo 256.
    assert_eq!(c.update(10), 200 - 512 + 66);
    assert_eq!(c.rebase(i64::MAX), None);
    assert_eq!(c.count(), 200 - 512 + 66);
}

/// A cyclic absolute encoder retains its count; after a restart the count moves from the
/// retained one by the shortest path to the new raw value (S7: up to half a range of motion
/// while off is allowed).
#[test]
fn cyclic_absolute_resume() {
    let range: i64 = 1 << 25;
    let retained = 3 * range + range - 100;
    // Moved +200 while off, across the wrap.
    let c = RawCounter::resume(25, retained, 100).unwrap();
    assert_eq!(c.count(), retained + 200);
    assert_eq!(c.ranges(), 4);
    // Moved -300 while off.
    let c = RawCounter::resume(25, retained, (range - 400) as u32).unwrap();
    assert_eq!(c.count(), retained - 300);
    // Negative counts.
    let c = RawCounter::resume(25, -5, (range - 7) as u32).unwrap();
    assert_eq!(c.count(), -7);
    // When to retain: a quarter range away from the last retained count.
    let mut c = RawCounter::resume(25, retained, (retained % range) as u32).unwrap();
    assert_eq!(c.count(), retained);
    assert!(!c.retain_due(retained));
    let quarter = range / 4;
    c.update(((retained + quarter - 1) % range) as u32);
    assert!(!c.retain_due(retained));
    c.update(((retained + quarter) % range) as u32);
    assert!(c.retain_due(retained));
    c.update(((retained - quarter) % range) as u32);
    assert!(c.retain_due(retained));
}

/// MC_Home 7 sets the actual position; MC_Home 6 shifts it; the adjustment survives its bytes
/// exactly and refuses wrong lengths, versions and offsets.
#[test]
fn absolute_adjustment() {
    let e = EncoderConfig {
        kind: EncoderKind::Absolute,
        steps_per_revolution: 1 << 20,
        determinable_revolutions: 4096,
        ..encoder(1 << 20)
    };
    let s = scaling(e, gear(3, 1));
    let count = 5 * TWO_20 + 12_345;
    let a = AbsoluteAdjustment::absolute(&s, count, 10.0);
    assert_eq!(a.position(&s, count), 10.0);
    assert_eq!(a.position(&s, count + TWO_20), 130.0);
    let b = a.relative(&s, count + 3, 2.5);
    assert_eq!(b.offset, a.offset + 2.5);
    assert!((b.position(&s, count) - 12.5).abs() < 1e-12);
    assert!(b.matches(&s));
    let other = scaling(e, gear(4, 1));
    assert!(!b.matches(&other), "a gear change voids the adjustment");
    let inverted = scaling(EncoderConfig { inverse: true, ..e }, gear(3, 1));
    assert!(!b.matches(&inverted));
    assert!(b.matches(&scaling(
        e,
        Mechanics {
            efficiency: 0.5,
            ..gear(3, 1)
        }
    )));

    let bytes = b.to_bytes();
    assert_eq!(bytes.len(), ADJUSTMENT_LEN);
    assert_eq!(bytes[0], 1);
    assert_eq!(&bytes[1..9], &b.offset.to_le_bytes());
    let back = AbsoluteAdjustment::from_bytes(&bytes).unwrap();
    assert_eq!(back.offset.to_bits(), b.offset.to_bits());
    assert_eq!(back, b);
    assert_eq!(
        AbsoluteAdjustment::from_bytes(&bytes[..24]),
        Err(AdjustmentError::Length {
            expected: 25,
            found: 24
        })
    );
    let mut wrong = bytes;
    wrong[0] = 2;
    assert_eq!(
        AbsoluteAdjustment::from_bytes(&wrong),
        Err(AdjustmentError::Version {
            expected: 1,
            found: 2
        })
    );
    let mut nan = bytes;
    nan[1..9].copy_from_slice(&f64::NAN.to_le_bytes());
    assert_eq!(
        AbsoluteAdjustment::from_bytes(&nan),
        Err(AdjustmentError::NotFinite)
    );
}

/// The drive's target wraps like its 32-bit counter.
#[test]
fn drive_increments_wrap_like_i32() {
    let s = scaling(encoder(1 << 20), Mechanics::default());
    let c = (1i64 << 31) + 5;
    assert_eq!(s.drive_increments(s.position(c)), i32::MIN + 5);
    assert_eq!(s.drive_increments(s.position(-c)), i32::MAX - 4);
    assert_eq!(s.drive_increments(s.position(1 << 32)), 0);
    assert_eq!(s.drive_increments(s.position(-(1 << 32) - 1)), -1);
    // Non-finite setpoints saturate (then wrap): they never panic.
    assert_eq!(s.drive_increments(f64::NAN), 0);
    assert_eq!(s.drive_increments(f64::INFINITY), -1);
    assert_eq!(s.count(f64::NEG_INFINITY), i64::MIN);
    assert_eq!(s.count(1e300), i64::MAX);
    assert_eq!(s.count(-1e300), i64::MIN);
    assert_eq!(s.count(f64::NAN), 0);
}

/// The cyclic methods do not allocate.
#[test]
fn cyclic_methods_do_not_allocate() {
    let s = scaling(encoder(1 << 20), gear(3, 1));
    let mut c = s.raw_counter(0);
    arm();
    let mut sum = 0.0;
    for k in 0..1000u32 {
        let n = c.update(k.wrapping_mul(1_000_003));
        sum += s.position(n) + s.velocity(1.0) + s.load_torque(1.0);
        sum += f64::from(s.drive_increments(sum)) + s.count(sum) as f64;
    }
    let (allocs, _) = disarm();
    assert_eq!(allocs, 0);
    assert!(sum.is_finite());
}

/// A deterministic 64-bit generator (SplitMix64) for the random walks.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A step in `[-half, half)`, where the raw counter is exact, from the exact count `at`:
    /// uniform most of the time, now and then an extreme, a small step, or a step onto the raw
    /// values 0, `2^bits - 1` or `half` (the wrap and the sign change of the word).
    fn step(&mut self, half: i64, at: i64) -> i64 {
        let modulus = 2 * half;
        // The step onto raw value `target` of the nearest range, in [-half, half).
        let onto = |target: i64| (target - at + half).rem_euclid(modulus) - half;
        let r = self.next();
        match r % 32 {
            0 | 1 => -half,
            2 | 3 => half - 1,
            4 | 5 => (r >> 32) as i64 % 8 - 4,
            6 => onto(0),
            7 => onto(modulus - 1),
            8 => onto(half),
            _ => ((r >> 8) % modulus as u64) as i64 - half,
        }
    }
}

/// Steps per raw width per case, and cases: 12 cases x 3 widths x 120 000 steps; a uniform step
/// crosses the wrap with probability about 1/4, so the cases cross it about 1.17 x 10^6 times
/// (each case asserts at least 90 000, so together at least 1.08 x 10^6).
const WALK_STEPS: usize = 120_000;
const WALK_CASES: u32 = 12;
const WRAPS_PER_CASE: u64 = 90_000;

proptest! {
    #![proptest_config(ProptestConfig {
        cases: WALK_CASES,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x0E5C_0DE5),
        ..ProptestConfig::default()
    })]

    /// A random walk of steps below half the raw range, for raw words of 16, 25 and 32 bits,
    /// from a random start and with a random drift: the counter equals the exact sum of the
    /// steps after every step, and the walk wraps the raw word at least [`WRAPS_PER_CASE`]
    /// times (at least 10^6 wraps over the cases).
    #[test]
    fn raw_counter_is_exact_over_random_wraps(
        seed in any::<u64>(),
        start in any::<u32>(),
        drift_every in 0u64..4,
    ) {
        let mut rng = SplitMix(seed);
        let mut wraps = 0u64;
        for raw_bits in [16u8, 25, 32] {
            let modulus = 1i64 << raw_bits;
            let half = modulus / 2;
            let mut c = RawCounter::new(raw_bits, start).unwrap();
            let mut exact = i64::from(start) & (modulus - 1);
            prop_assert_eq!(c.count(), exact);
            for k in 0..WALK_STEPS {
                let mut step = rng.step(half, exact);
                // A drift: every few steps only forward, so the count runs far from 0.
                if drift_every > 0 && k as u64 % (drift_every + 1) == 0 {
                    step = step.rem_euclid(half);
                }
                let before = exact.div_euclid(modulus);
                exact += step;
                wraps += (exact.div_euclid(modulus) - before).unsigned_abs();
                let raw = exact.rem_euclid(modulus) as u32;
                prop_assert_eq!(c.update(raw), exact, "raw_bits {} step {}", raw_bits, k);
            }
            prop_assert_eq!(c.ranges(), exact.div_euclid(modulus));
        }
        prop_assert!(wraps >= WRAPS_PER_CASE, "only {} wraps", wraps);
    }
}

/// A random but valid configuration: any steps, fine resolution, gear, mounting, pitch and
/// inversion.
fn any_scaling() -> impl Strategy<Value = Scaling> {
    let pitch = prop_oneof![
        Just(None),
        Just(Some(5.0)),
        Just(Some(2.54)),
        Just(Some(0.1)),
        (1e-3f64..1e3).prop_map(Some)
    ];
    let mounting = prop_oneof![
        Just(Mounting::MotorShaft),
        Just(Mounting::LoadSide),
        (1e-3f64..1e4).prop_map(|d| Mounting::External {
            distance_per_revolution: d
        })
    ];
    let gear = prop_oneof![(1u32..=16, 1u32..=16), (1u32..=u32::MAX, 1u32..=u32::MAX)];
    (
        1u32..=8_388_608,
        0u8..=31,
        gear,
        pitch,
        mounting,
        any::<(bool, bool)>(),
        prop::option::of(1u32..=u32::MAX),
    )
        .prop_map(
            |(steps, fine, (n, d), pitch, mounting, (inv_e, inv_d), drive)| {
                let e = EncoderConfig {
                    steps_per_revolution: steps,
                    fine_resolution_bits: fine,
                    inverse: inv_e,
                    mounting,
                    ..encoder(steps)
                };
                let m = Mechanics {
                    load_gear_numerator: n,
                    load_gear_denominator: d,
                    leadscrew_pitch: pitch,
                    inverse_drive: inv_d,
                    efficiency: 1.0,
                    drive_increments_per_revolution: drive,
                };
                scaling(e, m)
            },
        )
}

/// A count anywhere up to 2^52 in magnitude, with the small ones and the extremes often.
fn any_count() -> impl Strategy<Value = i64> {
    const MAX: i64 = 1 << 52;
    prop_oneof![
        -MAX..=MAX,
        -1_000_000i64..=1_000_000,
        (MAX - 1000)..=MAX,
        -MAX..=(1000 - MAX),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 20_000,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(0x0E5C_0DE6),
        ..ProptestConfig::default()
    })]

    /// count -> position -> count is the identity for |count| <= 2^52, for the encoder and for
    /// the drive's increments; and positions are monotone in the count.
    #[test]
    fn count_position_round_trip(s in any_scaling(), c in any_count()) {
        let p = s.position(c);
        prop_assert_eq!(s.count(p), c, "position {:e} of {:?}", p, s);
        let q = s.drive_position(c);
        prop_assert_eq!(i64::from(s.drive_increments(q)), i64::from(c as i32));
        let sign = if s.encoder().inverse { -1.0 } else { 1.0 };
        prop_assert!(sign * (s.position(c + 1) - p) > 0.0);
    }

    /// The drive's increments wrap like an i32 however far the position: when the drive works
    /// in the encoder's increments (both on the motor shaft, inverted alike), the setpoint of an
    /// actual position is that position's count modulo 2^32.
    #[test]
    fn drive_increments_wrap(
        steps in 1u32..=8_388_608,
        fine in 0u8..=12,
        (n, d) in (1u32..=100, 1u32..=100),
        inverse in any::<bool>(),
        c in any_count(),
    ) {
        let e = EncoderConfig { fine_resolution_bits: fine, inverse, ..encoder(steps) };
        let m = Mechanics { inverse_drive: inverse, ..gear(n, d) };
        let s = scaling(e, m);
        prop_assert_eq!(s.drive_increments(s.position(c)), c as i32);
    }
}
