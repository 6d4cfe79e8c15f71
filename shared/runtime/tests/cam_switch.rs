//! MC_DigitalCamSwitch_BkPlcMc through the executive, on the bundled example
//! (config/hydraulic-cam-switch.toml): each track's digital output follows its bit of
//! `OutputBits` one boundary later, and the bits switch where the library's example puts them
//! (scaled to the ram), compensation projected with the actual velocity.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;
use tandem_config::AxisIndex;
use tandem_runtime::exec::Executive;

const T: i64 = 1_000_000;

#[test]
fn the_outputs_follow_the_track_bits_and_switch_where_the_example_says() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cell = tandem_config::load(&root.join("config/hydraulic-cam-switch.toml")).unwrap();
    let src =
        std::fs::read_to_string(root.join("config/hydraulic-cam-switch-script.toml")).unwrap();
    let script = tandem_config::script::parse_cell("script.toml", &src, &cell).unwrap();
    let cam1 = cell.signal("cam1").unwrap();
    let cam2 = cell.signal("cam2").unwrap();
    let mut exec = Executive::new(&cell, None).unwrap();
    let mut log = Vec::new();
    let (mut next, mut t) = (0, 0);
    let mut prev_bits = 0u32;
    // (step, bit, on, actual position, actual velocity) of every bit change.
    let mut changes = Vec::new();
    let mut followed = 0;
    while t <= script.duration_ns {
        while let Some(e) = script.entries.get(next).filter(|e| e.t_ns <= t) {
            next += 1;
            let r = exec.apply_at(t, e.t_ns, &e.axis, e.instruction, e.action, &mut log);
            assert!(r.unwrap().is_ok(), "{}", String::from_utf8_lossy(&log));
        }
        exec.step(t, &mut log).unwrap();
        // The outputs now show the bits of the step before (written at this boundary).
        let levels = (
            exec.signal_level(cam1).unwrap(),
            exec.signal_level(cam2).unwrap(),
        );
        assert_eq!(levels, (prev_bits & 1 != 0, prev_bits & 2 != 0), "t = {t}");
        followed += 1;
        let row = exec.objects_row().to_string();
        // The last two columns: cams.outputs, cams.in_operation.
        let fields: Vec<&str> = row.rsplit(',').take(2).collect();
        let bits: u32 = fields[1].parse().unwrap();
        let s = *exec.axis_status(AxisIndex(0)).unwrap();
        for bit in 0..2 {
            if (bits ^ prev_bits) & (1 << bit) != 0 {
                let on = bits & (1 << bit) != 0;
                changes.push((t, bit, on, s.actual_position, s.actual_velocity));
            }
        }
        prev_bits = bits;
        t += T;
    }
    assert!(followed > 12_000);
    // Track 1 (bit 0), v = ±100 mm/s, OnCompensation −0.125 s (12.5 mm early), Off +0.25 s
    // (25 mm late); one cycle moves 0.1 mm.
    let at = |bit: u32, on: bool, v_sign: f64| -> Vec<f64> {
        changes
            .iter()
            .filter(|c| c.1 == bit && c.2 == on && c.4 * v_sign > 50.0)
            .map(|c| c.3)
            .collect()
    };
    let close = |got: &[f64], want: &[f64]| {
        got.len() == want.len() && got.iter().zip(want).all(|(g, w)| (g - w).abs() < 0.3)
    };
    let (on_up, off_up) = (at(0, true, 1.0), at(0, false, 1.0));
    assert!(close(&on_up, &[187.5]), "{on_up:?} {changes:?}");
    assert!(close(&off_up, &[125.0, 325.0]), "{off_up:?}");
    let (on_down, off_down) = (at(0, true, -1.0), at(0, false, -1.0));
    assert!(close(&on_down, &[312.5, 112.5]), "{on_down:?}");
    assert!(close(&off_down, &[225.0]), "{off_down:?}");
    // Track 2 (bit 1): on at 300 in both directions, for 1.35 s = 1350 cycles.
    let t2: Vec<_> = changes.iter().filter(|c| c.1 == 1).collect();
    assert_eq!(t2.len(), 4, "{t2:?}");
    assert!(
        (t2[0].3 - 300.0).abs() < 0.3 && (t2[2].3 - 300.0).abs() < 0.3,
        "{t2:?}"
    );
    assert_eq!((t2[1].0 - t2[0].0, t2[3].0 - t2[2].0), (1350 * T, 1350 * T));
    // EnableMask 0b10 at 12 s masks track 1 (on since 9.3 s); Enable FALSE at 12.5 s.
    let last = changes.last().unwrap();
    assert_eq!((last.0, last.1, last.2), (12_000 * T, 0, false));
}
