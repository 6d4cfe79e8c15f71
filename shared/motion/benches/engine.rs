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
use tandem_motion::profile::{plan_position, plan_velocity, Limits, Profile, State};

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
    use tandem_motion::axis::{Axis, AxisConfig, Command, StartMode, StopMode, VelocityDirection};
    use tandem_motion::drive::DriveModel;
    use tandem_motion::dynamics::Dynamics;

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
        let cases = &corpora().position;
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
        let cases = &corpora().velocity;
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
    use tandem_motion::axis::{Axis, AxisConfig, AxisKind, Command, StartMode, StopMode};
    use tandem_motion::dynamics::Dynamics;
    use tandem_motion::job::JobEventKind;
    use tandem_motion::leading::LeadingValue;

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
}
