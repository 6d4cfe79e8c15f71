//! Benchmarks of the engine's hot paths, with `rsruckig` (a Rust port of ruckig) on the same
//! problems for comparison: one axis cycle, one re-plan to a position or a velocity from a
//! moving state, one evaluation of a planned profile.
//!
//! Every input is fixed: the corpora come from an inline xorshift64* generator with fixed seeds,
//! so runs are comparable. The corpus benches cycle through [`CORPUS`] cases; one sample is one
//! pass over the corpus, so a sample's time per iteration is the corpus mean and the reported
//! median is the median of those means.
//!
//! Run: `cargo bench -p tandem-motion --bench engine`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::sync::OnceLock;

use divan::black_box;
use rsruckig::prelude::*;
use tandem_motion::kinematics::profile::{plan_position, plan_velocity, Limits, Profile, State};

fn main() {
    divan::main();
}

/// Cases in each corpus (one sample = one pass).
const CORPUS: usize = 1000;

/// xorshift64* (as in `tests/vs_rsruckig.rs` and rsruckig's own benches).
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Self(seed | 1)
    }

    /// Uniform in [0, 1).
    fn next(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + self.next() * (hi - lo)
    }

    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + self.next() * (hi.ln() - lo.ln())).exp()
    }
}

/// A moving start state (v, a) within the limits whose released velocity is within them too
/// (both planners then solve the same problem without a recovery phase).
fn feasible_start(fv: f64, fa: f64, lim: &Limits) -> (f64, f64) {
    let mut a = (2.0 * fa - 1.0) * lim.acc.min(lim.dec);
    let mut shift = a * a.abs() / (2.0 * lim.jerk);
    if shift.abs() > 0.999 * lim.vel {
        a = a.signum() * (2.0 * lim.jerk * 0.999 * lim.vel).sqrt();
        shift = a * a.abs() / (2.0 * lim.jerk);
    }
    let lo = (-lim.vel).max(-lim.vel - shift) * 0.999;
    let hi = lim.vel.min(lim.vel - shift) * 0.999;
    (lo + fv * (hi - lo), a)
}

/// Random symmetric limits (acc = dec, so that rsruckig's symmetric `max_acceleration` is the
/// same problem) and a random moving start state within them.
fn random_case(rng: &mut Rng) -> (State, Limits) {
    let vel = rng.log_uniform(1.0, 2000.0);
    let acc = rng.log_uniform(10.0, 20_000.0);
    let jerk = acc * rng.log_uniform(1.0, 200.0);
    let lim = Limits {
        vel,
        acc,
        dec: acc,
        jerk,
    };
    let p = rng.uniform(-1000.0, 1000.0);
    let (v, a) = feasible_start(rng.next(), rng.next(), &lim);
    (State { p, v, a }, lim)
}

fn ruckig_input(start: State, lim: &Limits) -> InputParameter<1> {
    let mut input = InputParameter::new(None);
    input.current_position = daov_stack![start.p];
    input.current_velocity = daov_stack![start.v];
    input.current_acceleration = daov_stack![start.a];
    input.target_velocity = daov_stack![0.0];
    input.target_acceleration = daov_stack![0.0];
    input.max_velocity = daov_stack![lim.vel];
    input.max_acceleration = daov_stack![lim.acc];
    input.max_jerk = daov_stack![lim.jerk];
    input
}

/// One re-planning problem, in both APIs.
struct Case {
    start: State,
    target: f64,
    lim: Limits,
    ruckig: InputParameter<1>,
}

struct Corpora {
    position: Vec<Case>,
    velocity: Vec<Case>,
    /// Planned position profiles and a time inside each, for `at`.
    profiles: Vec<(Profile, f64)>,
    trajectories: Vec<Trajectory<1>>,
}

/// Keeps a case only if both planners solve it with the same duration (they solve the same
/// problem; `tests/vs_rsruckig.rs` checks the agreement in depth).
fn same_duration(ours: f64, theirs: f64) -> bool {
    (ours - theirs).abs() <= (1e-6f64).max(1e-4 * theirs)
}

fn corpora() -> &'static Corpora {
    static C: OnceLock<Corpora> = OnceLock::new();
    C.get_or_init(|| {
        let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
        let mut traj = Trajectory::new(None);

        let mut rng = Rng::new(0x7a6e_d3e0_0b1a_2025);
        let mut position = Vec::with_capacity(CORPUS);
        let mut profiles = Vec::with_capacity(CORPUS);
        let mut trajectories = Vec::with_capacity(CORPUS);
        while position.len() < CORPUS {
            let (start, lim) = random_case(&mut rng);
            let d = rng.log_uniform(0.01, 5000.0);
            let target = start.p + if rng.next() < 0.5 { -d } else { d };
            let t_frac = rng.next();
            let mut input = ruckig_input(start, &lim);
            input.target_position = daov_stack![target];
            let Ok(ours) = plan_position(start, target, &lim) else {
                continue;
            };
            if otg.calculate(&input, &mut traj).is_err()
                || !same_duration(ours.duration(), traj.get_duration())
            {
                continue;
            }
            profiles.push((ours, t_frac * ours.duration()));
            trajectories.push(traj.clone());
            position.push(Case {
                start,
                target,
                lim,
                ruckig: input,
            });
        }

        let mut rng = Rng::new(0x0051_7e10_c174_2025);
        let mut velocity = Vec::with_capacity(CORPUS);
        while velocity.len() < CORPUS {
            let (start, lim) = random_case(&mut rng);
            let target = rng.uniform(-lim.vel, lim.vel);
            let mut input = ruckig_input(start, &lim);
            input.control_interface = ControlInterface::Velocity;
            input.target_velocity = daov_stack![target];
            let Ok(ours) = plan_velocity(start, target, &lim) else {
                continue;
            };
            if otg.calculate(&input, &mut traj).is_err()
                || !same_duration(ours.duration(), traj.get_duration())
            {
                continue;
            }
            velocity.push(Case {
                start,
                target,
                lim,
                ruckig: input,
            });
        }
        Corpora {
            position,
            velocity,
            profiles,
            trajectories,
        }
    })
}

/// Cycles through `n` indices.
struct Cycle {
    i: usize,
    n: usize,
}

impl Cycle {
    fn new(n: usize) -> Self {
        Self { i: 0, n }
    }

    #[inline(always)]
    fn next(&mut self) -> usize {
        let i = self.i;
        self.i = if i + 1 == self.n { 0 } else { i + 1 };
        i
    }
}

/// One `Axis::step` of one axis in motion (simulated drive included, no alarms).
#[divan::bench_group(sample_count = 3000, sample_size = 1000)]
mod axis_step_in_motion {
    use super::*;
    use tandem_motion::kinematics::dynamics::Dynamics;
    use tandem_motion::objects::axis::{
        Axis, AxisConfig, Command, StartMode, StopMode, VelocityDirection,
    };
    use tandem_motion::plant::drive::DriveModel;

    const MS: i64 = 1_000_000;

    #[derive(Copy, Clone)]
    enum Job {
        /// MoveVelocity 100 (cruising forever).
        Velocity,
        /// MoveRelative over 1e8 (cruising for a day: the profile is evaluated in a segment).
        Relative,
    }

    /// An enabled, homed axis that has been running `job` for 1 s; returns it and the next time.
    fn running(drive: Option<DriveModel>, job: Job) -> (Axis, i64) {
        let mut cfg = AxisConfig::example(0.001);
        if let Some(d) = drive {
            cfg.drive = d;
        }
        let mut axis = Axis::new(cfg).unwrap();
        let mut now = 0;
        axis.step(now);
        now += MS;
        axis.command(&Command::Power {
            enable: true,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        })
        .unwrap();
        let cmd = match job {
            Job::Velocity => Command::MoveVelocity {
                dynamics: Dynamics {
                    velocity: 100.0,
                    ..Dynamics::DEFAULT
                },
                direction: VelocityDirection::Positive,
                current: false,
                position_controlled: true,
            },
            Job::Relative => Command::MoveRelative {
                distance: 1e8,
                dynamics: Dynamics::DEFAULT,
            },
        };
        axis.command(&cmd).unwrap();
        for _ in 0..1000 {
            axis.step(now);
            now += MS;
            while axis.pop_event().is_some() {}
        }
        assert!(axis.alarms().next().is_none());
        assert!(axis.status().velocity > 99.0);
        (axis, now)
    }

    fn bench_axis(bencher: divan::Bencher, drive: Option<DriveModel>, job: Job) {
        let (mut axis, mut now) = running(drive, job);
        bencher.bench_local(|| {
            black_box(&mut axis).step(black_box(now));
            now += MS;
        });
        // Still in motion and without alarms after all the timed cycles.
        assert!(axis.alarms().next().is_none(), "an alarm came up");
        assert!(axis.status().velocity > 99.0);
        while axis.pop_event().is_some() {}
    }

    /// Position-loop drive model (the default of `AxisConfig::example`).
    #[divan::bench]
    fn velocity_position_loop(bencher: divan::Bencher) {
        bench_axis(bencher, None, Job::Velocity);
    }

    #[divan::bench]
    fn velocity_delay_2ms(bencher: divan::Bencher) {
        bench_axis(
            bencher,
            Some(DriveModel::Delay { delay: 0.002 }),
            Job::Velocity,
        );
    }

    #[divan::bench]
    fn relative_position_loop(bencher: divan::Bencher) {
        bench_axis(bencher, None, Job::Relative);
    }

    #[divan::bench]
    fn relative_delay_2ms(bencher: divan::Bencher) {
        bench_axis(
            bencher,
            Some(DriveModel::Delay { delay: 0.002 }),
            Job::Relative,
        );
    }

    /// For comparison: rsruckig's steady `update` (input unchanged, so no re-calculation: input
    /// comparison, `at_time`, two `Instant::now` calls) plus `pass_to_input`, 1 DoF, on a long
    /// move. Its counterpart is only the setpoint part of `step` (see `profile_at`).
    #[divan::bench]
    fn rsruckig_update_steady(bencher: divan::Bencher) {
        let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
        let mut output = OutputParameter::new(None);
        let mut input = ruckig_input(
            State::rest(0.0),
            &Limits {
                vel: 100.0,
                acc: 1000.0,
                dec: 1000.0,
                jerk: 20_000.0,
            },
        );
        input.target_position = daov_stack![1e8];
        for _ in 0..1000 {
            otg.update(&input, &mut output).unwrap();
            output.pass_to_input(&mut input);
        }
        bencher.bench_local(|| {
            let r = otg.update(black_box(&input), &mut output);
            output.pass_to_input(&mut input);
            black_box(r)
        });
        assert!(!output.new_calculation);
        assert!((output.new_velocity[0] - 100.0).abs() < 1e-9);
    }
}

/// `Ruckig::<1, ThrowErrorHandler>::calculate` over a corpus, one case per iteration.
fn bench_rsruckig_calculate(bencher: divan::Bencher, cases: &[Case]) {
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
    let mut traj = Trajectory::new(None);
    let mut k = Cycle::new(cases.len());
    bencher.bench_local(|| {
        let c = &cases[k.next()];
        let r = otg.calculate(black_box(&c.ruckig), &mut traj);
        black_box(&traj);
        black_box(r)
    });
}

/// One `plan_position` from a random moving state to a random target (rest), over the corpus.
#[divan::bench_group(sample_count = 1000, sample_size = 1000)]
mod replan_position {
    use super::*;

    #[divan::bench]
    fn tandem(bencher: divan::Bencher) {
        let cases = &corpora().position;
        let mut k = Cycle::new(cases.len());
        bencher.bench_local(|| {
            let c = &cases[k.next()];
            let p = plan_position(black_box(c.start), black_box(c.target), black_box(&c.lim));
            black_box(&p);
        });
    }

    /// `Ruckig::<1, ThrowErrorHandler>::calculate` on the same cases (target v = a = 0).
    #[divan::bench]
    fn rsruckig(bencher: divan::Bencher) {
        bench_rsruckig_calculate(bencher, &corpora().position);
    }
}

/// One `plan_velocity` from a random moving state to a random velocity, over the corpus.
#[divan::bench_group(sample_count = 1000, sample_size = 1000)]
mod replan_velocity {
    use super::*;

    #[divan::bench]
    fn tandem(bencher: divan::Bencher) {
        let cases = &corpora().velocity;
        let mut k = Cycle::new(cases.len());
        bencher.bench_local(|| {
            let c = &cases[k.next()];
            let p = plan_velocity(black_box(c.start), black_box(c.target), black_box(&c.lim));
            black_box(&p);
        });
    }

    /// rsruckig with `ControlInterface::Velocity` on the same cases (target a = 0).
    #[divan::bench]
    fn rsruckig(bencher: divan::Bencher) {
        bench_rsruckig_calculate(bencher, &corpora().velocity);
    }
}

/// One evaluation of a planned profile: `corpus_*` at a random time of each profile of the
/// position corpus in turn; `single_*` on one long profile at 1 ms steps (the cyclic use).
#[divan::bench_group(sample_count = 3000, sample_size = 1000)]
mod profile_at {
    use super::*;

    #[divan::bench]
    fn corpus_tandem(bencher: divan::Bencher) {
        let profiles = &corpora().profiles;
        let mut k = Cycle::new(profiles.len());
        bencher.bench_local(|| {
            let (p, t) = &profiles[k.next()];
            black_box(p).at(black_box(*t))
        });
    }

    #[divan::bench]
    fn corpus_rsruckig(bencher: divan::Bencher) {
        let c = corpora();
        let mut k = Cycle::new(c.trajectories.len());
        let mut pos = DataArrayOrVec::<f64, 1>::new(None, 0.0);
        let mut vel = DataArrayOrVec::<f64, 1>::new(None, 0.0);
        let mut acc = DataArrayOrVec::<f64, 1>::new(None, 0.0);
        bencher.bench_local(|| {
            let i = k.next();
            let traj = &c.trajectories[i];
            let t = c.profiles[i].1;
            let mut section = Some(0);
            black_box(traj).at_time(
                black_box(t),
                &mut Some(&mut pos),
                &mut Some(&mut vel),
                &mut Some(&mut acc),
                &mut None,
                &mut section,
            );
            black_box((pos[0], vel[0], acc[0]))
        });
    }

    /// A 10 s move (0.2 s ramps, cruise), sampled every 1 ms and wrapped around.
    fn long_move() -> (State, f64, Limits) {
        let lim = Limits {
            vel: 100.0,
            acc: 1000.0,
            dec: 1000.0,
            jerk: 20_000.0,
        };
        (State::rest(0.0), 1000.0, lim)
    }

    #[divan::bench]
    fn single_tandem(bencher: divan::Bencher) {
        let (start, target, lim) = long_move();
        let p = plan_position(start, target, &lim).unwrap();
        let n = (p.duration() / 0.001) as usize;
        let mut k = Cycle::new(n);
        bencher.bench_local(|| black_box(&p).at(black_box(k.next() as f64 * 0.001)));
    }

    #[divan::bench]
    fn single_rsruckig(bencher: divan::Bencher) {
        let (start, target, lim) = long_move();
        let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 0.001);
        let mut traj = Trajectory::new(None);
        let mut input = ruckig_input(start, &lim);
        input.target_position = daov_stack![target];
        otg.calculate(&input, &mut traj).unwrap();
        let n = (traj.get_duration() / 0.001) as usize;
        let mut k = Cycle::new(n);
        let mut pos = DataArrayOrVec::<f64, 1>::new(None, 0.0);
        let mut vel = DataArrayOrVec::<f64, 1>::new(None, 0.0);
        let mut acc = DataArrayOrVec::<f64, 1>::new(None, 0.0);
        bencher.bench_local(|| {
            let mut section = Some(0);
            black_box(&traj).at_time(
                black_box(k.next() as f64 * 0.001),
                &mut Some(&mut pos),
                &mut Some(&mut vel),
                &mut Some(&mut acc),
                &mut None,
                &mut section,
            );
            black_box((pos[0], vel[0], acc[0]))
        });
    }
}

/// One cycle of a following axis in synchronous operation (the leading value is computed, not
/// stepped, so only the follower is timed).
#[divan::bench_group(sample_count = 3000, sample_size = 1000)]
mod follower_step {
    use super::*;
    use tandem_motion::kinematics::dynamics::Dynamics;
    use tandem_motion::objects::axis::{Axis, AxisConfig, AxisKind, Command, StartMode, StopMode};
    use tandem_motion::objects::job::JobEventKind;
    use tandem_motion::objects::leading::LeadingValue;

    const MS: i64 = 1_000_000;

    fn lv(k: i64) -> LeadingValue {
        LeadingValue {
            p: 100.0 * k as f64 * 1e-3,
            v: 100.0,
            a: 0.0,
            modulo: None,
        }
    }

    /// A follower geared 3:2 to a leader at 100/s, in sync.
    fn geared() -> (Axis, i64) {
        let mut cfg = AxisConfig::example(0.001);
        cfg.kind = AxisKind::Synchronous;
        cfg.following_error.enable = false;
        let mut axis = Axis::new(cfg).unwrap();
        axis.step(0);
        axis.command(&Command::Power {
            enable: true,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        })
        .unwrap();
        let id = axis
            .command(&Command::GearIn {
                master: 1,
                ratio_numerator: 3,
                ratio_denominator: 2,
                dynamics: Dynamics::DEFAULT,
            })
            .unwrap();
        let mut k = 1;
        let mut in_gear = false;
        while k < 5000 {
            axis.set_leading_value(1, Some(lv(k)));
            axis.step(k * MS);
            while let Some(e) = axis.pop_event() {
                in_gear |= e.job == id && e.kind == JobEventKind::InGear;
            }
            k += 1;
        }
        assert!(in_gear);
        (axis, k)
    }

    #[divan::bench]
    fn gear_in_synchronous(bencher: divan::Bencher) {
        let (mut axis, mut k) = geared();
        bencher.bench_local(|| {
            let a = black_box(&mut axis);
            a.set_leading_value(1, Some(lv(k)));
            a.step(black_box(k * MS));
            k += 1;
        });
        assert!(axis.alarms().next().is_none());
        assert!((axis.status().velocity - 150.0).abs() < 1e-9);
    }

    use std::sync::Arc;
    use tandem_motion::cam::Cam;
    use tandem_motion::catalog::alarm::status_bit;
    use tandem_motion::objects::axis::{
        ApplicationMode, AxisState, SyncDirection, SyncProfileReference,
    };

    /// A follower in MC_CamIn (cyclic, direct: synchronous at once) on `cam`, its leader at
    /// constant velocity `v` from 0; returns the follower, the next cycle and the follower
    /// position at the sync point.
    fn cammed(cam: Cam, v: f64) -> (Axis, i64, f64) {
        let mut cfg = AxisConfig::example(0.001);
        cfg.kind = AxisKind::Synchronous;
        cfg.following_error.enable = false;
        cfg.limits.max_velocity = 5000.0;
        let mut axis = Axis::new(cfg).unwrap();
        axis.step(0);
        axis.command(&Command::Power {
            enable: true,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        })
        .unwrap();
        axis.provide_cam(1, Arc::new(cam));
        let id = axis
            .command(&Command::CamIn {
                master: 1,
                cam: 1,
                master_offset: 0.0,
                slave_offset: 0.0,
                master_scaling: 1.0,
                slave_scaling: 1.0,
                master_sync_position: 0.0,
                sync_profile_reference: SyncProfileReference::Direct,
                master_start_distance: 1.0,
                dynamics: Dynamics::DEFAULT,
                application_mode: ApplicationMode::Cyclic,
                sync_direction: SyncDirection::Shortest,
            })
            .unwrap();
        let y0 = axis.status().position_unwrapped;
        let mut k = 1;
        let mut in_sync = false;
        while k < 5000 {
            axis.set_leading_value(1, Some(lv_at(v, k)));
            axis.step(k * MS);
            while let Some(e) = axis.pop_event() {
                in_sync |= e.job == id && e.kind == JobEventKind::InSync;
            }
            k += 1;
        }
        assert!(in_sync);
        (axis, k, y0)
    }

    fn lv_at(v: f64, k: i64) -> LeadingValue {
        LeadingValue {
            p: v * k as f64 * 1e-3,
            v,
            a: 0.0,
            modulo: None,
        }
    }

    fn bench_cam(bencher: divan::Bencher, cam: Cam, v: f64) {
        let f = cam.clone();
        let (mut axis, mut k, y0) = cammed(cam, v);
        bencher.bench_local(|| {
            let a = black_box(&mut axis);
            a.set_leading_value(1, Some(lv_at(v, k)));
            a.step(black_box(k * MS));
            k += 1;
        });
        // Still synchronous, without alarms, and on the cam: the sync point was the cam start
        // with the leader at `v` ms, so the follower is at f(x mod range) - f(start) + y0.
        assert!(axis.alarms().next().is_none(), "an alarm came up");
        let s = axis.status();
        assert_eq!(s.state, AxisState::SynchronizedMotion);
        assert!(s.has(status_bit::SYNCHRONOUS));
        assert_eq!(s.sync_function, 3);
        let (c0, c1) = f.leading_range();
        let x = lv_at(v, k - 1).p - lv_at(v, 1).p;
        let expect = f.following(c0 + x.rem_euclid(c1 - c0)).unwrap().value - f.start().value + y0;
        assert!(
            (s.position_unwrapped - expect).abs() < 1e-6,
            "{} vs {expect}",
            s.position_unwrapped
        );
    }

    /// MC_CamIn cyclic on a 1,000-point cubic-spline cam (range 0..999), leader at 500/s
    /// (a cam cycle every 2 s, half a spline piece per cycle).
    #[divan::bench]
    fn cam_spline_1000(bencher: divan::Bencher) {
        bench_cam(bencher, spline_1000_cam(), 500.0);
    }

    /// MC_CamIn cyclic on a 16-segment polynomial cam (degree 7, range 0..360), leader at
    /// 90/s (a cam cycle every 4 s).
    #[divan::bench]
    fn cam_poly_16(bencher: divan::Bencher) {
        bench_cam(bencher, poly_16_cam(), 90.0);
    }
}

/// A cyclic cam through 1,000 points `x = 0, 1, …, 999` with `y` a smooth periodic function
/// (`y(0) = y(999)`), cubic spline with equal first derivatives at the ends. Not monotonic.
fn spline_1000_cam() -> tandem_motion::cam::Cam {
    use tandem_motion::cam::{BoundaryCondition, Cam, CamDefinition, Interpolation};
    let points = (0..1000)
        .map(|i| {
            let x = f64::from(i);
            let w = std::f64::consts::TAU * x / 999.0;
            (
                x,
                40.0 * w.sin() + 15.0 * (3.0 * w).sin() + 5.0 * (7.0 * w).cos(),
            )
        })
        .collect();
    let cam = Cam::interpolate(&CamDefinition {
        points,
        segments: vec![],
        interpolation: Interpolation::CubicSpline,
        boundary: BoundaryCondition::EqualFirstDerivative,
    })
    .unwrap();
    assert_eq!(cam.piece_count(), 999);
    cam
}

/// A cyclic cam of 16 explicit degree-7 polynomial segments of 22.5 over 0..360: alternating
/// rises 0 -> h and returns h -> 0 (the 4-5-6-7 law, joined C3 at rest), h = 10, 14, …, 38.
fn poly_16_cam() -> tandem_motion::cam::Cam {
    use tandem_motion::cam::{Cam, CamDefinition, Interpolation, SegmentDef};
    let segments = (0..16)
        .map(|i| {
            let h = 10.0 + 4.0 * f64::from(i / 2);
            let (x0, x1) = (22.5 * f64::from(i), 22.5 * f64::from(i + 1));
            let coeffs = if i % 2 == 0 {
                [0.0, 0.0, 0.0, 0.0, 35.0 * h, -84.0 * h, 70.0 * h, -20.0 * h]
            } else {
                [h, 0.0, 0.0, 0.0, -35.0 * h, 84.0 * h, -70.0 * h, 20.0 * h]
            };
            SegmentDef::Polynomial { x0, x1, coeffs }
        })
        .collect();
    let cam = Cam::interpolate(&CamDefinition {
        points: vec![],
        segments,
        interpolation: Interpolation::CubicSpline,
        boundary: Default::default(),
    })
    .unwrap();
    assert_eq!(cam.piece_count(), 16);
    assert_eq!(cam.continuity(), tandem_motion::cam::Continuity::C2);
    cam
}

/// The cams of the cam benches and their fixed corpora: `(y, approach)` for `leading`, `x` for
/// `following`, uniform over the cam's ranges.
struct CamCorpora {
    spline: tandem_motion::cam::Cam,
    poly: tandem_motion::cam::Cam,
    spline_leading: Vec<(f64, f64)>,
    poly_leading: Vec<(f64, f64)>,
    spline_following: Vec<f64>,
}

fn cam_corpora() -> &'static CamCorpora {
    static C: OnceLock<CamCorpora> = OnceLock::new();
    C.get_or_init(|| {
        let leading = |cam: &tandem_motion::cam::Cam, seed: u64| {
            let mut rng = Rng::new(seed);
            let (x0, x1) = cam.leading_range();
            let (y0, y1) = cam.following_range();
            (0..CORPUS)
                .map(|_| {
                    let y = rng.uniform(y0, y1);
                    let approach = rng.uniform(x0, x1);
                    // Every case has a solution (y is inside the range of a continuous cam).
                    cam.leading(y, approach).unwrap();
                    (y, approach)
                })
                .collect::<Vec<_>>()
        };
        let spline = spline_1000_cam();
        let poly = poly_16_cam();
        let spline_leading = leading(&spline, 0x1ead_0001_cafe_2025);
        let poly_leading = leading(&poly, 0x1ead_0002_cafe_2025);
        let mut rng = Rng::new(0xf011_0001_cafe_2025);
        let (x0, x1) = spline.leading_range();
        let spline_following = (0..CORPUS).map(|_| rng.uniform(x0, x1)).collect();
        CamCorpora {
            spline,
            poly,
            spline_leading,
            poly_leading,
            spline_following,
        }
    })
}

/// One `Cam::leading` (MC_GetCamLeadingValue) for a random `y` with a random approach value,
/// over the corpus. Both cams are non-monotonic, so every monotonic run is considered.
#[divan::bench_group(sample_count = 1000, sample_size = 1000)]
mod cam_leading_value {
    use super::*;

    #[divan::bench]
    fn spline_1000(bencher: divan::Bencher) {
        let c = cam_corpora();
        let mut k = Cycle::new(c.spline_leading.len());
        bencher.bench_local(|| {
            let (y, approach) = c.spline_leading[k.next()];
            black_box(&c.spline).leading(black_box(y), black_box(approach))
        });
    }

    #[divan::bench]
    fn poly_16(bencher: divan::Bencher) {
        let c = cam_corpora();
        let mut k = Cycle::new(c.poly_leading.len());
        bencher.bench_local(|| {
            let (y, approach) = c.poly_leading[k.next()];
            black_box(&c.poly).leading(black_box(y), black_box(approach))
        });
    }
}

/// One `Cam::following` (MC_GetCamFollowingValue, no hint: binary search over the pieces) at a
/// random `x`, over the corpus.
#[divan::bench_group(sample_count = 1000, sample_size = 1000)]
mod cam_following_value {
    use super::*;

    #[divan::bench]
    fn spline_1000(bencher: divan::Bencher) {
        let c = cam_corpora();
        let mut k = Cycle::new(c.spline_following.len());
        bencher.bench_local(|| {
            let x = c.spline_following[k.next()];
            black_box(&c.spline).following(black_box(x))
        });
    }
}

/// One cycle (1 ms) of the position-based objects on a modulo axis (360): the axis' motion of
/// the cycle is built (`AxisMotion`, p/v/a at both cycle ends) and the object stepped with it.
/// The figure includes building the motion. Targets (issue 4): at most 150 ns each.
#[divan::bench_group(sample_count = 3000, sample_size = 1000)]
mod cams_and_measuring {
    use super::*;
    use tandem_motion::kinematics::cycle_motion::AxisMotion;
    use tandem_motion::kinematics::modulo::Modulo;
    use tandem_motion::objects::cam_track::{
        CamTrack, CamTrackConfig, CamTrackData, CamTrackMode, CamTrackType, McCamTrack, TrackCam,
    };
    use tandem_motion::objects::measuring::{
        CyclicMode, MeasuringContext, MeasuringInput, MeasuringInputConfig,
    };
    use tandem_motion::objects::output_cam::CamEdges;
    use tandem_motion::plant::sensor::InputEdge;

    const MS: i64 = 1_000_000;
    const MODULO: Option<Modulo> = Some(Modulo {
        start: 0.0,
        length: 360.0,
    });

    /// Cycles in one period of the velocity swing (4 Hz at 1 ms).
    const PERIOD: usize = 250;

    /// Velocity 1000/s plus `swing` * sin(2π·4 Hz·t): the exact p, v, a over one swing period
    /// (`PERIOD + 1` cycle boundaries; a later period is the same shifted by 250 in p), so
    /// that the timed loop reads a table instead of evaluating sin and cos.
    fn table(swing: f64) -> Vec<State> {
        let w = 2.0 * std::f64::consts::PI * 4.0;
        (0..=PERIOD)
            .map(|k| {
                let t = k as f64 * 1e-3;
                State {
                    p: 1000.0 * t + swing / w * (1.0 - (w * t).cos()),
                    v: 1000.0 + swing * (w * t).sin(),
                    a: swing * w * (w * t).cos(),
                }
            })
            .collect()
    }

    fn motion(tab: &[State], k: usize) -> AxisMotion {
        let (q, r) = (k / PERIOD, k % PERIOD);
        let shift = |s: State| State {
            p: s.p + (q * PERIOD) as f64,
            ..s
        };
        let t0 = (k as i64) * MS;
        AxisMotion::new(t0, t0 + MS, shift(tab[r]), shift(tab[r + 1])).with_modulo(MODULO)
    }

    /// 32 distance cams (0.9 wide, every 1.4) on a track of length 45 from 5, with hysteresis
    /// and on/off compensation: at 1000/s about 1.4 track edges per cycle.
    fn track() -> CamTrack {
        let mut data = CamTrackData::new(5.0, 45.0);
        for i in 0..32 {
            let on = i as f64 * 1.4;
            data = data.with_cam(i, TrackCam::distance(on, on + 0.9));
        }
        data.parameters.hysteresis = 0.05;
        data.parameters.on_compensation = 0.3e-3;
        data.parameters.off_compensation = 0.1e-3;
        CamTrack::new(CamTrackConfig::new(CamTrackType::Distance), data).unwrap()
    }

    fn bench_track(bencher: divan::Bencher, swing: f64) {
        let tab = table(swing);
        let mut track = track();
        let mut edges = CamEdges::default();
        let enable = McCamTrack::enabled(CamTrackMode::EndOfCycle);
        let mut k = 0;
        let mut n = 0usize;
        bencher.bench_local(|| {
            let m = motion(&tab, black_box(k));
            track.call(1, &enable);
            track.step(&m, &mut edges);
            n += edges.len();
            k += 1;
        });
        // About 64 edges per 45 of travel: the track really switched.
        assert!(
            n as f64 > 0.9 * 64.0 / 45.0 * k as f64,
            "{n} edges in {k} cycles"
        );
        assert_eq!(edges.dropped(), 0);
    }

    /// MC_CamTrack, 32 cams, constant velocity.
    #[divan::bench]
    fn cam_track_32_constant_velocity(bencher: divan::Bencher) {
        bench_track(bencher, 0.0);
    }

    /// MC_CamTrack, 32 cams, velocity swinging 1000 ± 600/s (acceleration in every cycle).
    #[divan::bench]
    fn cam_track_32_varying_velocity(bencher: divan::Bencher) {
        bench_track(bencher, 600.0);
    }

    /// MC_MeasuringInputCyclic (Mode 2, both edges) with two edges in every cycle: the measured
    /// position of each is interpolated at its time, with a correction time.
    #[divan::bench]
    fn measuring_cyclic_two_edges(bencher: divan::Bencher) {
        let mut mi = MeasuringInput::new(MeasuringInputConfig {
            apply_activation_time: false,
            correction_time: 0.2e-3,
            ..MeasuringInputConfig::timer_di(MS)
        })
        .unwrap();
        let job = mi
            .measuring_input_cyclic(CyclicMode::Both, None, MeasuringContext::OK)
            .unwrap();
        let tab = table(600.0);
        let mut k = 0;
        bencher.bench_local(|| {
            let m = motion(&tab, black_box(k));
            let t0 = k as i64 * MS;
            let two = [
                InputEdge {
                    time_ns: t0 + 200_000,
                    rising: true,
                    latched: None,
                },
                InputEdge {
                    time_ns: t0 + 700_000,
                    rising: false,
                    latched: None,
                },
            ];
            mi.step(&m, black_box(&two));
            k += 1;
        });
        let s = mi.job_status(job).unwrap();
        assert_eq!(s.counter1 as usize, k);
        assert_eq!(s.counter2 as usize, k);
        assert_eq!(s.lost_edge_counter1, 0);
    }
}

/// The leading-value buffer (see the leading values between nodes, docs/processes.md 'Leading
/// values') of a leader sampled every 1 ms, 256 samples buffered: a follower's lookup inside the
/// last two sample intervals (the common case: delay of one or two cycles), a lookup deep in the
/// buffer (binary search), and one cycle of the runtime (push the new sample, then look the leader
/// up at a delay of 1.5 ms). The lookup times are a corpus of random offsets.
#[divan::bench_group(sample_count = 3000, sample_size = 1000)]
mod leading_value_buffer {
    use super::*;
    use tandem_motion::objects::leading::{LeadingSample, LeadingValueBuffer, Lookup};

    const MS: i64 = 1_000_000;
    const N: usize = 256;

    /// Sample `k` of a leader whose acceleration swings ±600/s² around 1000/s.
    fn sample(k: i64) -> LeadingSample {
        let t = k as f64 * 1e-3;
        let w = 2.0 * std::f64::consts::PI;
        let (s, c) = (w * t).sin_cos();
        LeadingSample {
            t_ns: k * MS,
            seq: k as u64,
            p: 1000.0 * t - 600.0 / (w * w) * s,
            v: 1000.0 - 600.0 / w * c,
            a: 600.0 * s,
            modulo: None,
            valid: true,
        }
    }

    fn full() -> LeadingValueBuffer<N> {
        let mut b = LeadingValueBuffer::new();
        for k in 0..N as i64 {
            b.push(sample(k)).unwrap();
        }
        b
    }

    /// `CORPUS` offsets in `[lo, hi)` ns.
    fn offsets(seed: u64, lo: i64, hi: i64) -> Vec<i64> {
        let mut rng = Rng::new(seed);
        (0..CORPUS)
            .map(|_| rng.uniform(lo as f64, hi as f64) as i64)
            .collect()
    }

    fn value(l: Lookup) -> f64 {
        l.value().map_or(f64::NAN, |v| v.p)
    }

    /// `at` for a time inside the last two sample intervals of the full buffer.
    #[divan::bench]
    fn at_last_two_samples(bencher: divan::Bencher) {
        let b = full();
        let newest = b.newest().unwrap().t_ns;
        let times: Vec<i64> = offsets(0x1ead_0001, -2 * MS, 0)
            .into_iter()
            .map(|o| newest + o)
            .collect();
        assert!(times.iter().all(|&t| b.at(t, 0).value().is_some()));
        let mut k = Cycle::new(times.len());
        bencher.bench_local(|| value(black_box(&b).at(black_box(times[k.next()]), MS)));
    }

    /// `at` for a time anywhere in the older 250 intervals of the full buffer (binary search).
    #[divan::bench]
    fn at_deep(bencher: divan::Bencher) {
        let b = full();
        let newest = b.newest().unwrap().t_ns;
        let times: Vec<i64> = offsets(0x1ead_0002, -(N as i64 - 1) * MS, -5 * MS)
            .into_iter()
            .map(|o| newest + o)
            .collect();
        assert!(times.iter().all(|&t| b.at(t, 0).value().is_some()));
        let mut k = Cycle::new(times.len());
        bencher.bench_local(|| value(black_box(&b).at(black_box(times[k.next()]), MS)));
    }

    /// One cycle: push the leader's new sample into the full buffer, then look the leader up
    /// at a delay of 1.5 ms (interpolated between the two newest samples). The samples come
    /// from a table of one period of the leader's motion (1 s), shifted by whole periods.
    #[divan::bench]
    fn push_and_at(bencher: divan::Bencher) {
        const PERIOD: i64 = 1000;
        let mut b = full();
        let table: Vec<LeadingSample> = (0..PERIOD).map(sample).collect();
        let mut k = N as i64;
        bencher.bench_local(|| {
            let (n, i) = (k / PERIOD, k % PERIOD);
            let base = table[i as usize];
            let s = LeadingSample {
                t_ns: k * MS,
                seq: k as u64,
                p: base.p + 1000.0 * n as f64,
                ..base
            };
            k += 1;
            // The timed work is the push; a refused sample is part of what is measured.
            let _ = b.push(black_box(s));
            value(b.at(black_box(s.t_ns - 3 * MS / 2), MS))
        });
        assert_eq!((b.rejected(), b.lost()), (0, 0));
        let newest = b.newest().unwrap().t_ns;
        assert!(b.at(newest - 3 * MS / 2, 0).value().is_some());
        assert_eq!(b.len(), N);
    }
}
