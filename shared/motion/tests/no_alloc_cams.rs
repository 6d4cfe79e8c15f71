//! The cyclic path of the cam and measuring objects does not allocate: a counting global
//! allocator, armed only on the test thread, counts every allocation while a 32-cam track (with
//! hysteresis, compensations, a Timer DQ cap and Mode 1 data changes), an output cam, a
//! simulated sensor and two cyclic measuring inputs (one with two edges in every cycle) run
//! 10,000 cycles of 1 ms on a modulo axis moving back and forth.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_motion::kinematics::cycle_motion::AxisMotion;
use tandem_motion::kinematics::modulo::Modulo;
use tandem_motion::kinematics::profile::{plan_position, Limits, Profile, State};
use tandem_motion::objects::cam_track::{
    CamTrack, CamTrackConfig, CamTrackData, CamTrackMode, CamTrackType, McCamTrack, TrackCam,
    TrackOutputInterface,
};
use tandem_motion::objects::measuring::{
    CyclicMode, MeasuringContext, MeasuringInput, MeasuringInputConfig,
};
use tandem_motion::objects::output_cam::{
    CamDirection, CamEdges, McOutputCam, OutputCam, OutputCamConfig, OutputCamType,
};
use tandem_motion::plant::sensor::{InputEdge, InputEdges, SensorDirection, SimulatedSensor};
use tandem_testkit::counting::{arm, disarm};

tandem_testkit::counting_allocator!();

const MS: i64 = 1_000_000;
const CYCLES: i64 = 10_000;

#[test]
fn ten_thousand_cycles_without_allocation() {
    let lim = Limits {
        vel: 300.0,
        acc: 3000.0,
        dec: 3000.0,
        jerk: 60_000.0,
    };
    // Moves there and back, each starting at a cycle boundary.
    let mut moves: Vec<(i64, Profile)> = Vec::new();
    let mut t = 0;
    let mut p = 0.0;
    let mut k = 0;
    while t < CYCLES * MS {
        let target = if k % 2 == 0 { p + 700.0 } else { p - 450.0 };
        let prof = plan_position(State::rest(p), target, &lim).unwrap();
        moves.push((t, prof));
        t += ((prof.duration() * 1e3) as i64 + 5) * MS;
        p = target;
        k += 1;
    }
    let modulo = Some(Modulo {
        start: 0.0,
        length: 360.0,
    });

    let mut data = CamTrackData::new(5.0, 45.0);
    for i in 0..32 {
        let on = i as f64 * 1.4;
        data = data.with_cam(i, TrackCam::distance(on, on + 0.9));
    }
    data.parameters.hysteresis = 0.05;
    data.parameters.on_compensation = 0.3e-3;
    data.parameters.off_compensation = 0.1e-3;
    let cfg = CamTrackConfig {
        interface: TrackOutputInterface::TimerDq,
        ..CamTrackConfig::new(CamTrackType::Distance)
    };
    let mut track = CamTrack::new(cfg, data).unwrap();
    let other = {
        let mut d = data;
        d.cams[3] = TrackCam::distance(4.0, 8.0);
        d.masking = 0x7FFF_FFFF;
        d
    };

    let mut cam = OutputCam::new(OutputCamConfig::new(OutputCamType::Distance)).unwrap();
    let cam_in = McOutputCam::distance(80.0, 220.0).with_direction(CamDirection::Both);

    let mut mi = MeasuringInput::new(MeasuringInputConfig {
        apply_activation_time: false,
        ..MeasuringInputConfig::timer_di(MS)
    })
    .unwrap();
    let job = mi
        .measuring_input_cyclic(CyclicMode::Rising, None, MeasuringContext::OK)
        .unwrap();
    let mut mi2 = MeasuringInput::new(MeasuringInputConfig {
        apply_activation_time: false,
        correction_time: 0.4e-3,
        ..MeasuringInputConfig::timer_di(MS)
    })
    .unwrap();
    let job2 = mi2
        .measuring_input_cyclic(CyclicMode::Both, None, MeasuringContext::OK)
        .unwrap();
    let mut sensor = SimulatedSensor::new(100.0, 20.0, 0.4e-3, 20_000, 7, SensorDirection::Both);

    let mut track_edges = CamEdges::default();
    let mut cam_edges = CamEdges::default();
    let mut sensor_edges = InputEdges::default();
    let mut n_track = 0usize;
    let mut n_cam = 0usize;
    let mut n_sensor = 0usize;
    let mut seg = 0usize;

    arm();
    for k in 0..CYCLES {
        let (t0, t1) = (k * MS, (k + 1) * MS);
        while seg + 1 < moves.len() && moves[seg + 1].0 <= t0 {
            seg += 1;
        }
        let (ts, prof) = &moves[seg];
        let motion = AxisMotion::from_profile(prof, *ts, t0, t1).with_modulo(modulo);

        if k == 3000 {
            track.set_data(other);
        }
        if k == 6000 {
            track.set_data(data);
        }
        track.call(1, &McCamTrack::enabled(CamTrackMode::EndOfCycle));
        track.step(&motion, &mut track_edges);
        n_track += track_edges.len();

        cam.call(1, &cam_in);
        cam.step(&motion, &mut cam_edges);
        n_cam += cam_edges.len();

        let two = [
            InputEdge {
                time_ns: t0 + 200_000,
                rising: true,
                latched: None,
            },
            InputEdge {
                time_ns: t0 + 700_000,
                rising: true,
                latched: None,
            },
        ];
        mi.step(&motion, &two);

        sensor_edges.clear();
        sensor.step(&motion, &mut sensor_edges);
        n_sensor += sensor_edges.len();
        mi2.step(&motion, sensor_edges.as_slice());
    }
    let (allocs, _) = disarm();
    assert_eq!(allocs, 0, "{allocs} allocations in {CYCLES} cycles");

    // The run did something.
    let s = mi.job_status(job).unwrap();
    assert_eq!((s.counter1, s.counter2), (CYCLES as u32, CYCLES as u32));
    assert!(n_track > 1000, "track edges {n_track}");
    assert!(n_cam > 5, "cam edges {n_cam}");
    assert!(n_sensor >= 8, "sensor edges {n_sensor}");
    assert!(mi2.job_status(job2).unwrap().counter1 >= 4);
}
