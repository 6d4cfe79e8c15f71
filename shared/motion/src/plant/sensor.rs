//! Timestamped input edges and a simulated mark sensor that produces them from the motion of
//! one cycle (what a measuring input is stepped with).

use crate::kinematics::crossing::RangeSet;
use crate::kinematics::cycle_motion::AxisMotion;
use crate::kinematics::timed_list::{Timed, TimedList};

/// One timestamped edge of a digital input.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct InputEdge {
    /// Time of the edge (ns, cell clock).
    pub time_ns: i64,
    /// Rising (`true`) or falling edge.
    pub rising: bool,
    /// The axis position the hardware latched at the edge (a drive's touch probe), in the
    /// axis's coordinate; `None`: the measuring input takes the position at `time_ns` from the
    /// axis's motion.
    pub latched: Option<f64>,
}

/// Capacity of an [`InputEdges`] buffer.
pub const INPUT_EDGE_CAPACITY: usize = 32;

/// A fixed-capacity list of input edges (what a [`SimulatedSensor`] produces in one cycle).
pub type InputEdges = TimedList<InputEdge, INPUT_EDGE_CAPACITY>;

impl Timed for InputEdge {
    fn time_ns(&self) -> i64 {
        self.time_ns
    }
}

/// Which motion direction a [`SimulatedSensor`] reacts to.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SensorDirection {
    /// Only while the axis moves in the positive direction.
    Positive,
    /// Only while the axis moves in the negative direction.
    Negative,
    /// Both directions.
    Both,
}

/// A simulated sensor: a mark of `width` at `position` (reduced into the modulo range on modulo
/// axes, so it repeats every revolution). The signal is high while the axis is on the mark: the
/// axis entering the mark gives a rising edge, leaving it a falling edge (moving up, rising at
/// `position` and falling at `position + width`). Each edge is reported `dead_time` after the
/// crossing, plus a deterministic jitter uniform in `[-jitter_ns, jitter_ns]` (xorshift64*,
/// seeded).
#[derive(Copy, Clone, Debug)]
pub struct SimulatedSensor {
    /// Start of the mark.
    pub position: f64,
    /// Width of the mark (> 0).
    pub width: f64,
    /// Delay from the crossing to the edge (s).
    pub dead_time: f64,
    /// Jitter amplitude (ns, >= 0).
    pub jitter_ns: i64,
    /// Direction the sensor reacts to.
    pub direction: SensorDirection,
    rng: u64,
    pending: InputEdges,
}

impl SimulatedSensor {
    /// A sensor with the given mark, dead time, jitter and seed.
    pub fn new(
        position: f64,
        width: f64,
        dead_time: f64,
        jitter_ns: i64,
        seed: u64,
        direction: SensorDirection,
    ) -> Self {
        Self {
            position,
            width,
            dead_time,
            jitter_ns: jitter_ns.max(0),
            direction,
            rng: seed | 1,
            pending: InputEdges::default(),
        }
    }

    fn next_jitter(&mut self) -> i64 {
        // xorshift64*
        let mut x = self.rng;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.rng = x;
        if self.jitter_ns == 0 {
            return 0;
        }
        let r = x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11; // 53 bits
        let u = r as f64 / (1u64 << 53) as f64; // [0, 1)
        ((2.0 * u - 1.0) * self.jitter_ns as f64).round() as i64
    }

    /// Appends to `out` the edges that the axis motion of this cycle produces and whose time is
    /// not after `t1_ns` (later ones are kept for the next cycle), in time order.
    pub fn step(&mut self, motion: &AxisMotion, out: &mut InputEdges) {
        let set = RangeSet::from_bounds(
            self.position,
            self.position + self.width,
            motion.modulo,
            false,
            RangeSet::Empty,
        );
        let set = match (set, motion.modulo) {
            // A mark at least one revolution wide covers everything.
            (RangeSet::Empty, Some(_)) if self.width > 0.0 => RangeSet::Full,
            (s, _) => s,
        };
        let mut crossings = InputEdges::default();
        motion.for_each_run(|run| {
            let d = run.dir();
            let ok = match self.direction {
                SensorDirection::Both => d != 0,
                SensorDirection::Positive => d > 0,
                SensorDirection::Negative => d < 0,
            };
            if !ok {
                return;
            }
            set.crossings(run.xa, run.xb, |c, entering| {
                let t = run.time_of(c) + self.dead_time;
                crossings.push(InputEdge {
                    time_ns: motion.ns(t),
                    rising: entering,
                    latched: None,
                });
                true
            });
        });
        for e in crossings.as_slice() {
            let j = self.next_jitter();
            self.pending.push(InputEdge {
                time_ns: e.time_ns + j,
                rising: e.rising,
                latched: None,
            });
        }
        self.pending.sort();
        let mut keep = InputEdges::default();
        for e in self.pending.as_slice() {
            if e.time_ns <= motion.t1_ns {
                out.push(*e);
            } else {
                keep.push(*e);
            }
        }
        keep.dropped = self.pending.dropped;
        self.pending = keep;
    }
}
