//! The retained data of an axis on a simulated CiA 402 servo (`config/servo.toml` with an
//! absolute or cyclic absolute encoder), in the executive (S7-1500T Motion Control V4.0 function
//! manual, 'Drive and encoder connection' (actual value types), 'Direct homing and absolute
//! adjustment', 'When Homed is lost'): the adjustment of MC_Home 7 is handed over once, restored
//! by a new executive with the axis homed at the same position; an adjustment made under another
//! encoder or mechanics configuration is void (the axis is not homed, the cleared adjustment is
//! handed over); a cyclic absolute encoder's count of traversed ranges is handed over every
//! quarter range (without allocating) and resumed after a restart.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use tandem_config::{AxisIndex, Cell, DriveConnection};
use tandem_motion::catalog::alarm::status_bit;
use tandem_motion::kinematics::dynamics::Dynamics;
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{AxisState, Command, RestoreOffsetError, StartMode, StopMode};
use tandem_motion::plant::mechanics::{AbsoluteAdjustment, Scaling};
use tandem_runtime::exec::{AdjustmentChange, Executive, RestoreError, Restored};
use tandem_testkit::counting::{arm, disarm};
use tandem_testkit::workspace::root;

tandem_testkit::counting_allocator!();

const MS: i64 = 1_000_000;
const AXIS: AxisIndex = AxisIndex(0);

/// `config/servo.toml` with its encoder line replaced by `encoder` and then `edit` applied.
fn servo_cell(encoder: &str, edit: impl Fn(String) -> String) -> Cell {
    let src = std::fs::read_to_string(root().join("config/servo.toml")).unwrap();
    let line = "encoder = \"incremental\"           # the drive's motor encoder (its 0x6064)";
    assert!(src.contains(line));
    let src = edit(src.replace(line, encoder));
    tandem_config::parse("servo.toml", &src).unwrap()
}

/// A cyclic absolute encoder of one motor revolution: 2^20 increments, the servo's.
const CYCLIC_TABLE: &str = "[axes.slide.encoder]\ntype = \"cyclic_absolute\"\nraw_bits = 20";

fn absolute() -> Cell {
    servo_cell("encoder = \"absolute\"", |s| s)
}

fn scaling(cell: &Cell) -> Scaling {
    match &cell.axes[0].drive {
        DriveConnection::Cia402(c) => c.scaling,
        other => panic!("not on a drive: {other:?}"),
    }
}

/// An executive of the whole cell, stepped cycle by cycle.
struct Run<'c> {
    exec: Executive<'c>,
    k: i64,
    log: Vec<u8>,
}

impl<'c> Run<'c> {
    fn new(cell: &'c Cell) -> Self {
        Self {
            exec: Executive::new(cell, None).unwrap(),
            k: 0,
            // Room for every line of a test: writing one does not allocate.
            log: Vec::with_capacity(1 << 16),
        }
    }

    fn cmd(&mut self, c: Command) {
        let t = self.k * MS;
        let r = self
            .exec
            .apply_at(t, t, "slide", "test", Action::Command(c), &mut self.log)
            .unwrap();
        assert!(r.is_ok(), "{r:?}\n{}", self.log());
    }

    fn step(&mut self) {
        self.exec.step(self.k * MS, &mut self.log).unwrap();
        self.k += 1;
    }

    fn log(&self) -> String {
        String::from_utf8_lossy(&self.log).into_owned()
    }

    fn homed(&mut self) -> bool {
        self.exec.status()[0].status_word & status_bit::HOMING_DONE != 0
    }

    fn actual(&mut self) -> f64 {
        self.exec.status()[0].actual_position
    }

    /// Every change handed over now.
    fn take(&mut self) -> Vec<AdjustmentChange> {
        let mut v = Vec::new();
        self.exec.take_adjustments(|c| {
            v.push(c);
            true
        });
        v
    }

    fn enable(&mut self) {
        self.cmd(Command::Power {
            enable: true,
            start_mode: StartMode::PositionControlled,
            stop_mode: StopMode::Emergency,
        });
        for _ in 0..50 {
            if self.exec.status()[0].state == AxisState::Standstill {
                return;
            }
            self.step();
        }
        panic!("not enabled\n{}", self.log());
    }

    /// Enables the axis and adjusts it with MC_Home 7 to `position`; returns the one change
    /// handed over.
    fn adjust(&mut self, position: f64) -> AbsoluteAdjustment {
        self.enable();
        assert!(self.take().is_empty(), "nothing before the adjustment");
        self.cmd(Command::Home { mode: 7, position });
        self.step();
        let taken = self.take();
        assert_eq!(taken.len(), 1, "{taken:?}");
        let c = taken[0];
        assert_eq!(c.axis, AXIS);
        assert!(!c.count_only);
        assert!(self.take().is_empty(), "handed over once");
        c.adjustment.unwrap()
    }
}

/// MC_Home 7 to a known position; a new executive (the node restarted) restores it: the axis
/// is homed from its first cycle at exactly that position, and nothing is handed over again.
#[test]
fn an_adjustment_is_handed_over_once_and_restored_by_a_new_executive() {
    let cell = absolute();
    let mut r = Run::new(&cell);
    assert_eq!(r.exec.retained_axes().collect::<Vec<_>>(), [AXIS]);
    assert_eq!(
        r.exec.restore_adjustment(AXIS, None),
        Ok(Restored::NotAdjusted)
    );
    assert!(!r.homed(), "nothing retained: not homed");
    assert!(r.take().is_empty(), "nothing to retain yet");
    r.step();
    let p = 123.456_789;
    let adj = r.adjust(p);
    assert!(r.homed());
    assert_eq!(r.actual(), p);
    let s = scaling(&cell);
    assert_eq!(adj.fingerprint, link_fingerprint(&cell));
    assert!(
        adj.fingerprint != s.fingerprint(),
        "the drive's mapping is in it too"
    );
    // The servo holds still at the increments it started at (0): the offset is the position.
    assert_eq!(adj.count, 0);
    assert!((adj.offset - p).abs() < 1e-12, "{adj:?}");
    // A change not taken is offered again, as it is then.
    r.cmd(Command::Home {
        mode: 7,
        position: 7.0,
    });
    r.step();
    let mut offered = Vec::new();
    r.exec.take_adjustments(|c| {
        offered.push(c);
        false
    });
    assert_eq!(offered.len(), 1);
    let again = r.take();
    assert_eq!(again, offered);
    assert_eq!(again[0].adjustment.unwrap().offset, 7.0);
    let adj = again[0].adjustment.unwrap();
    // The node restarted: the drive is where it was, the adjustment comes back from the file.
    let mut r2 = Run::new(&cell);
    assert!(
        r2.homed(),
        "before the restore, the simulation's convention"
    );
    assert_eq!(
        r2.exec.restore_adjustment(AXIS, Some(adj)),
        Ok(Restored::Adjusted)
    );
    assert!(
        r2.take().is_empty(),
        "what was restored is not stored again"
    );
    r2.step();
    assert!(r2.homed());
    assert_eq!(r2.actual(), 7.0);
    assert_eq!(r2.exec.status()[0].state, AxisState::Disabled);
    for _ in 0..20 {
        r2.step();
    }
    assert_eq!(r2.actual(), 7.0);
    assert!(r2.take().is_empty());
}

/// The fingerprint the executive of `cell` makes adjustments under, read off a void restore
/// of a record made under fingerprint 0.
fn link_fingerprint(cell: &Cell) -> u64 {
    let mut probe = Run::new(cell);
    let wrong = AbsoluteAdjustment {
        offset: 0.0,
        count: 0,
        fingerprint: 0,
    };
    match probe.exec.restore_adjustment(AXIS, Some(wrong)).unwrap() {
        Restored::Void { now, made_under } => {
            assert_eq!(made_under, 0);
            now
        }
        other => panic!("{other:?}"),
    }
}

/// An edit of the cell's source.
type Edit = fn(String) -> String;

/// An adjustment made under another configuration is void: the axis is not homed, the
/// cleared adjustment is handed over once (so the void one is never used again); the same
/// configuration takes it.
#[test]
fn an_adjustment_of_another_configuration_is_void() {
    let cell = absolute();
    let mut r = Run::new(&cell);
    r.exec.restore_adjustment(AXIS, None).unwrap();
    r.step();
    let adj = r.adjust(50.0);
    let edits: [(&str, Edit); 5] = [
        ("leadscrew pitch", |s| {
            s.replace("leadscrew_pitch = 10.0", "leadscrew_pitch = 5.0")
        }),
        ("load gear", |s| {
            s.replace("load_gear = [3, 1]", "load_gear = [4, 1]")
        }),
        ("drive inversion", |s| {
            s.replace("inverse_drive = false", "inverse_drive = true")
        }),
        ("drive increments", |s| {
            s.replace(
                "increments_per_revolution = 1048576",
                "increments_per_revolution = 524288",
            )
        }),
        ("encoder type", |s| {
            s.replace("encoder = \"absolute\"", CYCLIC_TABLE)
        }),
    ];
    for (what, edit) in edits {
        let other = servo_cell("encoder = \"absolute\"", edit);
        assert_ne!(other, cell, "{what}: the edit applies");
        let mut r2 = Run::new(&other);
        let restored = r2.exec.restore_adjustment(AXIS, Some(adj)).unwrap();
        let Restored::Void { made_under, now } = restored else {
            panic!("{what}: {restored:?}");
        };
        assert_eq!(made_under, adj.fingerprint);
        assert_ne!(now, adj.fingerprint);
        r2.step();
        assert!(
            !r2.homed(),
            "{what}: a void adjustment leaves the axis not homed"
        );
        let taken = r2.take();
        assert_eq!(taken.len(), 1, "{what}: {taken:?}");
        assert_eq!(taken[0].adjustment, None, "{what}: cleared");
        assert!(r2.take().is_empty(), "{what}");
        r2.step();
        assert!(!r2.homed());
    }
    // The same configuration (another initial position, which is no part of it) takes it.
    let same = servo_cell("encoder = \"absolute\"", |s| {
        s.replace(
            "kind = \"positioning\"",
            "kind = \"positioning\"\ninitial_position = 0.0",
        )
    });
    let mut r3 = Run::new(&same);
    assert_eq!(
        r3.exec.restore_adjustment(AXIS, Some(adj)),
        Ok(Restored::Adjusted)
    );
    r3.step();
    assert!(r3.homed());
    assert_eq!(r3.actual(), 50.0);
}

/// Refusals: an incremental encoder retains nothing, a restore after the first step and an
/// unknown axis are refused; a non-finite offset is refused by the axis. Nothing changes.
#[test]
fn a_restore_that_cannot_apply_is_refused() {
    let inc = servo_cell("encoder = \"incremental\"", |s| s);
    let mut r = Run::new(&inc);
    assert_eq!(r.exec.retained_axes().count(), 0);
    let any = AbsoluteAdjustment {
        offset: 1.0,
        count: 0,
        fingerprint: 0,
    };
    assert_eq!(
        r.exec.restore_adjustment(AXIS, Some(any)),
        Err(RestoreError::NotRetained { axis: AXIS })
    );
    assert_eq!(
        r.exec.restore_adjustment(AxisIndex(5), None),
        Err(RestoreError::NotRetained { axis: AxisIndex(5) })
    );
    let cell = absolute();
    let mut r = Run::new(&cell);
    let fingerprint = link_fingerprint(&cell);
    let nan = AbsoluteAdjustment {
        offset: f64::NAN,
        count: 0,
        fingerprint,
    };
    assert_eq!(
        r.exec.restore_adjustment(AXIS, Some(nan)),
        Err(RestoreError::Axis {
            axis: AXIS,
            reason: RestoreOffsetError::NotFinite
        })
    );
    assert!(r.take().is_empty(), "a refused restore changes nothing");
    r.step();
    assert_eq!(
        r.exec.restore_adjustment(AXIS, None),
        Err(RestoreError::Started { axis: AXIS })
    );
    assert!(r.homed(), "unchanged");
    for e in [
        RestoreError::NotRetained { axis: AXIS },
        RestoreError::Started { axis: AXIS },
    ] {
        assert!(e.to_string().starts_with("axis 0: "), "{e}");
    }
}

/// A cyclic absolute encoder of one motor revolution (20 bits): while the axis moves, its count
/// is handed over each time it is a quarter range (2^18 counts) from the one handed over last;
/// after a restart with the drive where it stopped, the count resumes from the retained one
/// and the axis is at the same position; without the retained count it would be whole
/// revolutions off.
#[test]
fn a_cyclic_absolute_encoder_retains_its_count_of_ranges() {
    let cyclic = |initial: f64| {
        servo_cell(CYCLIC_TABLE, move |s| {
            s.replace(
                "kind = \"positioning\"",
                &format!("kind = \"positioning\"\ninitial_position = {initial:?}"),
            )
        })
    };
    let cell = cyclic(0.0);
    let mut r = Run::new(&cell);
    r.exec.restore_adjustment(AXIS, None).unwrap();
    r.step();
    let adj = r.adjust(0.0);
    r.cmd(Command::MoveAbsolute {
        position: 50.0,
        dynamics: Dynamics {
            velocity: 200.0,
            acceleration: 2000.0,
            deceleration: 2000.0,
            jerk: 40000.0,
        },
        direction: tandem_motion::objects::axis::Direction::Shortest,
    });
    let quarter = 1i64 << 18;
    let mut last = adj.count;
    let mut changes = Vec::with_capacity(100);
    let mut allocations = 0;
    for _ in 0..1500 {
        // The step and the take of the cyclic path, counted: no allocation.
        let mut taken = [None; 2];
        let mut n = 0;
        arm();
        r.step();
        r.exec.take_adjustments(|c| {
            if let Some(slot) = taken.get_mut(n) {
                *slot = Some(c);
            }
            n += 1;
            true
        });
        allocations += disarm().0;
        assert!(n <= 1, "one change per cycle at most");
        for c in taken.into_iter().flatten() {
            let a = c.adjustment.unwrap();
            assert!(c.count_only, "{c:?}");
            assert_eq!(a.offset, adj.offset, "the offset does not move");
            assert!(a.count - last >= quarter, "{} after {last}", a.count);
            // The axis moves at most 0.2 mm, 0.24 of a quarter range, per cycle.
            assert!(a.count - last < quarter * 5 / 4, "{} after {last}", a.count);
            last = a.count;
            changes.push(a);
        }
    }
    assert_eq!(allocations, 0, "allocations on the cyclic path");
    assert!(r.log().contains("MC_MoveAbsolute job"), "{}", r.log());
    // 50 mm is 15 motor revolutions (3:1 gear, 10 mm pitch): 60 quarter ranges, handed over
    // in steps of 1 to 1.24 quarters; the last within a quarter of where the axis stopped.
    assert!((48..=60).contains(&changes.len()), "{}", changes.len());
    let retained = *changes.last().unwrap();
    let stopped = r.exec.drive_feedback(0).unwrap().position_actual;
    assert!((i64::from(stopped) - retained.count).abs() < quarter);
    assert!((i64::from(stopped) - (15 << 20)).abs() < 1000, "{stopped}");
    let before = r.actual();
    assert!((before - 50.0).abs() < 0.01, "{before}");
    // The restart: the simulated servo starts at the configured initial position; put it
    // where the axis stopped (the encoder did not move while the node was off).
    let s = scaling(&cell);
    let at = s.drive_position(i64::from(stopped));
    let cell2 = cyclic(at);
    let mut r2 = Run::new(&cell2);
    assert_eq!(
        r2.exec.restore_adjustment(AXIS, Some(retained)),
        Ok(Restored::Adjusted)
    );
    r2.step();
    let count = i64::from(r2.exec.drive_feedback(0).unwrap().position_actual);
    assert_eq!(
        count,
        i64::from(stopped),
        "the servo starts where it stopped"
    );
    assert!(r2.homed());
    let want = s.drive_position(count) + retained.offset;
    assert!((r2.actual() - want).abs() < 1e-9, "{} {want}", r2.actual());
    assert!(
        (r2.actual() - before).abs() < 1e-6,
        "{} {before}",
        r2.actual()
    );
    // The same record with the count of the first range: the raw value alone puts the axis
    // 15 revolutions (50 mm) off; the retained count is what makes it right.
    let mut r3 = Run::new(&cell2);
    let first_range = AbsoluteAdjustment {
        count: 0,
        ..retained
    };
    r3.exec.restore_adjustment(AXIS, Some(first_range)).unwrap();
    r3.step();
    assert!(
        (r3.actual() - (before - 50.0)).abs() < 1e-6,
        "{}",
        r3.actual()
    );
}
