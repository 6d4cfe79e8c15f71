//! A simulated hydraulic axis: a proportional 4/3 valve and a differential cylinder with a mass,
//! friction and end stops, to commission a hydraulic axis against before the machine exists
//! (what the Beckhoff TwinCAT PLC Hydraulic Positioning library's commissioning chapter (5.8)
//! and its valve and cylinder notes (5.3, 5.4) say a real one does, as a physical model).
//!
//! The valve takes the normalised output of the Finish stage (±1.0 = ±10 V). Its spool follows
//! the command plus the valve's **zero offset** (the hydraulic zero is not the electrical one)
//! through a first-order lag (the valve's response time). A spool within the **overlap** opens
//! no edge; beyond it the opening grows linearly to full, bent at the **bend point** of the
//! valve's flow curve (flatter below). Each control edge passes the flow of an orifice,
//! `Q = Q_N · opening · sqrt(Δp / Δp_N)` (the data sheet's nominal flow at the nominal pressure
//! drop per edge): a positive spool connects the supply P to chamber A and chamber B to the tank
//! T, a negative one P to B and A to T. So the velocity depends on the load and the supply
//! pressure, and on the direction: A is the full piston area, B the annulus. With equal flows
//! into the active chamber (`v = Q/A`) the extending (positive) direction would be the slower
//! one, as the library's valve notes put it (5.3); through the orifices of a symmetric valve at no
//! load the throttled outflow of the full-area chamber makes retracting the slower one instead
//! (the closed form in the tests), which is why valves for differential cylinders have edges
//! of unequal flow ([`CylinderParams::flow_ratio_b`]; the library's example 11:6).
//!
//! Each chamber's pressure follows from its oil's compressibility, `dp/dt = β / V · (Q - A·v)`,
//! with `V` the dead volume plus the swept one; the piston, with the moving mass, from
//! `m·a = p_A·A_A - p_B·A_B - viscous·v - Coulomb friction - load`. The oil column makes the
//! axis a weakly damped oscillator of hydraulic natural frequency `ω = sqrt(β·(A_A²/V_A +
//! A_B²/V_B) / m)` (49 Hz at mid-stroke for [`CylinderParams::example`], below 20 Hz for
//! long strokes and heavy loads: the limit of `Kv`). At the end stops the
//! piston stands, and the pressure builds up to the supply: the force a pressing axis has.
//!
//! Units: mm, mm/s, mm², bar, kg, N (1 bar = 0.1 N/mm²); flows in l/min at the interface and
//! mm³/s inside. Integrated with [`SUBSTEPS`] semi-implicit Euler steps per call (the oil spring
//! is stiff). Pure: no IO, no clock (the cycle time is an input), no allocation.

use super::analog::{Amplifier, AnalogCommand, AnalogFeedback};
pub use super::cylinder_error::CylinderError;
use super::mechanics::Scaling;
/// Integration steps per [`SimCylinder::step`] call, at least (more when the call is long: no
/// sub-step exceeds [`MAX_SUBSTEP`]).
pub const SUBSTEPS: u32 = 20;

/// The longest sub-step (s): well below the period of the oil spring of any sensible axis.
pub const MAX_SUBSTEP: f64 = 50e-6;

/// 1 l/min in mm³/s.
const L_PER_MIN: f64 = 1e6 / 60.0;

/// 1 bar·mm² in N.
const BAR_MM2: f64 = 0.1;

/// The valve and cylinder (see the module documentation). Defaults: [`CylinderParams::example`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CylinderParams {
    /// Piston area, chamber A (mm², > 0).
    pub area_a: f64,
    /// Annulus area, chamber B (mm², > 0).
    pub area_b: f64,
    /// Stroke (mm, > 0): the piston moves between 0 and the stroke.
    pub stroke: f64,
    /// Dead volume of each chamber with its line (mm³, > 0).
    pub dead_volume: f64,
    /// Moving mass (kg, > 0).
    pub mass: f64,
    /// Bulk modulus of the oil (bar, > 0; mineral oil with some air: 10,000 to 14,000).
    pub bulk_modulus: f64,
    /// Viscous friction (N per mm/s, >= 0).
    pub viscous: f64,
    /// Coulomb friction (N, >= 0): the force needed to break away and to keep moving.
    pub coulomb: f64,
    /// Supply pressure (bar, > 0).
    pub supply: f64,
    /// Tank pressure (bar, >= 0, below the supply).
    pub tank: f64,
    /// Nominal flow of one control edge of chamber A (P→A, A→T) at full opening (l/min, > 0).
    pub nominal_flow: f64,
    /// The nominal flow of chamber B's edges (P→B, B→T) relative to A's (> 0): 1 for a
    /// symmetric valve; below 1 for a valve matched to a differential cylinder (the library's
    /// example 11:6; `area_b / area_a` makes the edges' flows proportional to the areas).
    pub flow_ratio_b: f64,
    /// Pressure drop per edge at which the nominal flow is given (bar, > 0; data sheets: 35).
    pub nominal_drop: f64,
    /// Overlap: the spool travel (normalised, 0..1) before an edge opens.
    pub overlap: f64,
    /// Zero offset of the spool (normalised, within ±0.2): the command that holds it centred
    /// is its negative.
    pub offset: f64,
    /// The flow curve's bend: the opening (0..1) at which the flow is [`Self::bend_flow`] of
    /// nominal; 0 and 0: a straight curve.
    pub bend_opening: f64,
    /// The flow (0..1 of nominal) at the bend.
    pub bend_flow: f64,
    /// Response time of the spool (s, >= 0): the time constant of its first-order lag.
    pub response_time: f64,
}

impl CylinderParams {
    /// A 63/45 mm cylinder of 500 mm stroke with 200 kg on a 40 l/min valve at 100 bar: areas
    /// 3,117 and 1,527 mm² (ratio 2.04), dead volumes 100 cm³, oil 12,000 bar, a zero-lapped
    /// valve (no overlap, offset, bend) with a 5 ms spool.
    pub fn example() -> Self {
        let piston = core::f64::consts::PI / 4.0 * 63.0 * 63.0;
        let rod = core::f64::consts::PI / 4.0 * 45.0 * 45.0;
        Self {
            area_a: piston,
            area_b: piston - rod,
            stroke: 500.0,
            dead_volume: 100_000.0,
            mass: 200.0,
            bulk_modulus: 12_000.0,
            viscous: 2.0,
            coulomb: 0.0,
            supply: 100.0,
            tank: 0.0,
            nominal_flow: 40.0,
            flow_ratio_b: 1.0,
            nominal_drop: 35.0,
            overlap: 0.0,
            offset: 0.0,
            bend_opening: 0.0,
            bend_flow: 0.0,
            response_time: 0.005,
        }
    }

    /// Checks every parameter; the first one out of its range is named.
    pub fn check(&self) -> Result<(), CylinderError> {
        let pos = [
            ("area_a", self.area_a),
            ("area_b", self.area_b),
            ("stroke", self.stroke),
            ("dead_volume", self.dead_volume),
            ("mass", self.mass),
            ("bulk_modulus", self.bulk_modulus),
            ("supply", self.supply),
            ("nominal_flow", self.nominal_flow),
            ("flow_ratio_b", self.flow_ratio_b),
            ("nominal_drop", self.nominal_drop),
        ];
        for (name, value) in pos {
            if !(value.is_finite() && value > 0.0) {
                return Err(CylinderError { name, value });
            }
        }
        let ranges = [
            ("viscous", self.viscous, 0.0, f64::MAX),
            ("coulomb", self.coulomb, 0.0, f64::MAX),
            ("tank", self.tank, 0.0, self.supply),
            ("overlap", self.overlap, 0.0, 0.9),
            ("offset", self.offset, -0.2, 0.2),
            ("bend_opening", self.bend_opening, 0.0, 1.0),
            ("bend_flow", self.bend_flow, 0.0, 1.0),
            ("response_time", self.response_time, 0.0, 1.0),
        ];
        for (name, value, min, max) in ranges {
            if !(value.is_finite() && (min..=max).contains(&value)) {
                return Err(CylinderError { name, value });
            }
        }
        let (bo, bf) = (self.bend_opening, self.bend_flow);
        let inside = |x: f64| x > 0.0 && x < 1.0;
        if !(bo == 0.0 && bf == 0.0 || inside(bo) && inside(bf)) {
            return Err(CylinderError {
                name: "bend_opening",
                value: bo,
            });
        }
        Ok(())
    }

    /// The hydraulic natural frequency at position `x` (Hz):
    /// `sqrt(β·(A_A²/V_A + A_B²/V_B) / m) / 2π`.
    pub fn natural_frequency(&self, x: f64) -> f64 {
        let (va, vb) = self.volumes(x);
        let stiffness = self.bulk_modulus
            * BAR_MM2
            * (self.area_a * self.area_a / va + self.area_b * self.area_b / vb);
        // N/mm over kg: 1 N/mm = 1000 N/m.
        (stiffness * 1000.0 / self.mass).sqrt() / (2.0 * core::f64::consts::PI)
    }

    /// The volumes of chambers A and B at position `x` (mm³).
    fn volumes(&self, x: f64) -> (f64, f64) {
        let x = x.clamp(0.0, self.stroke);
        (
            self.dead_volume + self.area_a * x,
            self.dead_volume + self.area_b * (self.stroke - x),
        )
    }

    /// The opening of one edge (0..1) for spool position `s` (normalised, its magnitude).
    fn opening(&self, s: f64) -> f64 {
        let travel = ((s.abs() - self.overlap) / (1.0 - self.overlap)).clamp(0.0, 1.0);
        let (bo, bf) = (self.bend_opening, self.bend_flow);
        if bo == 0.0 {
            travel
        } else if travel <= bo {
            travel * bf / bo
        } else {
            bf + (travel - bo) * (1.0 - bf) / (1.0 - bo)
        }
    }
}

/// What the simulated axis shows after a step.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct CylinderState {
    /// Piston position (mm, 0 ..= stroke).
    pub position: f64,
    /// Piston velocity (mm/s).
    pub velocity: f64,
    /// Pressure in chamber A (bar).
    pub pressure_a: f64,
    /// Pressure in chamber B (bar).
    pub pressure_b: f64,
    /// The force of the oil on the piston, `p_A·A_A - p_B·A_B` (N).
    pub force: f64,
    /// Spool position (normalised).
    pub spool: f64,
    /// Oil flow into chamber A (l/min; out of it: negative).
    pub flow_a: f64,
    /// Oil flow into chamber B (l/min).
    pub flow_b: f64,
}

/// The simulated valve and cylinder (see the module documentation).
#[doc(alias = "iTcMc_EncoderSim")]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SimCylinder {
    p: CylinderParams,
    s: CylinderState,
    /// External load force (N, against positive motion).
    load: f64,
}

impl SimCylinder {
    /// The cylinder with parameters `p` at rest at position `x`, both chambers at the pressure
    /// that balances the piston (the mean of supply and tank in chamber B).
    pub fn new(p: CylinderParams, x: f64) -> Result<Self, CylinderError> {
        p.check()?;
        if !(x.is_finite() && (0.0..=p.stroke).contains(&x)) {
            return Err(CylinderError {
                name: "position",
                value: x,
            });
        }
        let pb = 0.5 * (p.supply + p.tank);
        let s = CylinderState {
            position: x,
            pressure_a: pb * p.area_b / p.area_a,
            pressure_b: pb,
            ..CylinderState::default()
        };
        let mut c = Self { p, s, load: 0.0 };
        c.s.force = c.force();
        Ok(c)
    }

    /// The parameters.
    pub fn params(&self) -> &CylinderParams {
        &self.p
    }

    /// The state after the last step.
    pub fn state(&self) -> &CylinderState {
        &self.s
    }

    /// Sets the external load force (N, against positive motion; a weight on a rising
    /// cylinder).
    pub fn set_load(&mut self, newtons: f64) {
        if newtons.is_finite() {
            self.load = newtons;
        }
    }

    /// The force of the oil on the piston (N).
    fn force(&self) -> f64 {
        (self.s.pressure_a * self.p.area_a - self.s.pressure_b * self.p.area_b) * BAR_MM2
    }

    /// Advances the axis by `dt` seconds with valve command `u` (normalised, clamped to ±1;
    /// NaN counts as 0). Returns the state.
    pub fn step(&mut self, u: f64, dt: f64) -> &CylinderState {
        if !(dt.is_finite() && dt > 0.0) {
            return &self.s;
        }
        let u = if u.is_nan() { 0.0 } else { u.clamp(-1.0, 1.0) };
        let n = (dt / MAX_SUBSTEP).ceil().max(f64::from(SUBSTEPS)).min(1e6);
        let h = dt / n;
        for _ in 0..n as u32 {
            self.substep(u, h);
        }
        self.s.force = self.force();
        &self.s
    }

    /// The flows into A and B (mm³/s) at spool position `spool`.
    fn flows(&self, spool: f64) -> (f64, f64) {
        let p = &self.p;
        let k = p.nominal_flow * L_PER_MIN * self.p.opening(spool);
        let orifice = |k: f64, from: f64, to: f64| {
            let d = from - to;
            k * (d.abs() / p.nominal_drop).sqrt() * d.signum()
        };
        let (ka, kb) = (k, k * p.flow_ratio_b);
        let (pa, pb) = (self.s.pressure_a, self.s.pressure_b);
        if spool > 0.0 {
            (orifice(ka, p.supply, pa), -orifice(kb, pb, p.tank))
        } else if spool < 0.0 {
            (-orifice(ka, pa, p.tank), orifice(kb, p.supply, pb))
        } else {
            (0.0, 0.0)
        }
    }

    /// One integration step of `h` seconds.
    fn substep(&mut self, u: f64, h: f64) {
        let p = self.p;
        // The spool: first-order lag to the command plus the offset.
        let target = (u + p.offset).clamp(-1.0, 1.0);
        self.s.spool = if p.response_time > 0.0 {
            self.s.spool + (target - self.s.spool) * (h / p.response_time).min(1.0)
        } else {
            target
        };
        let (qa, qb) = self.flows(self.s.spool);
        // The piston (semi-implicit: velocity first, then position).
        let drive = self.force() - self.load;
        let v = self.s.velocity;
        let mut force = drive - p.viscous * v;
        if v != 0.0 {
            force -= p.coulomb.copysign(v);
        } else if force.abs() <= p.coulomb {
            force = 0.0;
        } else {
            force -= p.coulomb.copysign(force);
        }
        // a in mm/s²: N / kg = m/s² = 1000 mm/s².
        let mut v_new = v + force / p.mass * 1000.0 * h;
        if v != 0.0 && v_new * v < 0.0 && (drive - p.viscous * v_new).abs() <= p.coulomb {
            v_new = 0.0; // friction holds it where it stops
        }
        let mut x = self.s.position + v_new * h;
        if x <= 0.0 && v_new <= 0.0 || x >= p.stroke && v_new >= 0.0 {
            x = x.clamp(0.0, p.stroke);
            v_new = 0.0;
        }
        self.s.position = x;
        self.s.velocity = v_new;
        // The chambers.
        let (va, vb) = p.volumes(x);
        let beta = p.bulk_modulus;
        let dpa = beta / va * (qa - p.area_a * v_new) * h;
        let dpb = beta / vb * (qb + p.area_b * v_new) * h;
        // Cavitation and relief bound the pressures (inferred: a simple clamp).
        self.s.pressure_a = (self.s.pressure_a + dpa).clamp(0.0, p.supply);
        self.s.pressure_b = (self.s.pressure_b + dpb).clamp(0.0, p.supply);
        self.s.flow_a = qa / L_PER_MIN;
        self.s.flow_b = qb / L_PER_MIN;
    }
}

/// The parameters of a simulated valve and cylinder on an analog output
/// (`[devices.<name>] kind = "sim_valve_cylinder"`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SimValveCylinderParams {
    /// The valve and cylinder.
    pub cylinder: CylinderParams,
    /// The valve amplifier's ready output follows its enable input after this time (s, >= 0).
    pub ready_delay: f64,
    /// A constant external load force (N, against positive motion).
    pub load: f64,
    /// The pressure sensors' range (bar at 10 V, the input word 27648; > 0): each chamber's
    /// pressure is read through a 16-bit analog input.
    pub pressure_range: f64,
    /// How the amplifier takes its command: ±10 V (default), two coils, one coil, or a current
    /// valve (the magnitude with direction valves: `absolute`). `reversed` must be false: a
    /// valve's wiring has no reversal (the axis' `bDrive_Reversed` is the controller's).
    pub input: crate::hydraulic::drive_output::DriveOutputParams,
}

/// A proportional valve with its amplifier on an analog output (enable DO and output word
/// out, ready DI in) and the cylinder it drives, with a linear encoder on the piston (the raw
/// word the axis' [`Scaling`] reads): the device of the process image a hydraulic axis' analog
/// connection drives. While the amplifier is not enabled or in fault, the spool is commanded
/// to 0 (it rests at the valve's zero offset). Nothing allocates.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SimValveCylinder {
    cylinder: SimCylinder,
    scaling: Scaling,
    /// The latched command, the ready output and the fault latch.
    amplifier: Amplifier,
    /// The pressure inputs' words per bar.
    words_per_bar: f64,
    /// How the amplifier takes its command.
    input: crate::hydraulic::drive_output::DriveOutputParams,
}

impl SimValveCylinderParams {
    /// Checks every parameter (the cylinder's, then `ready_delay` >= 0, `load` finite,
    /// `pressure_range` > 0); the first one out of its range is named.
    pub fn check(&self) -> Result<(), CylinderError> {
        self.cylinder.check()?;
        let ok = [
            ("ready_delay", self.ready_delay, self.ready_delay >= 0.0),
            ("load", self.load, true),
            (
                "pressure_range",
                self.pressure_range,
                self.pressure_range > 0.0,
            ),
        ];
        if let Some((name, value, _)) = ok.into_iter().find(|(_, v, ok)| !(v.is_finite() && *ok)) {
            return Err(CylinderError { name, value });
        }
        if self.input.reversed || self.input.check().is_err() {
            return Err(CylinderError {
                name: "valve_input",
                value: f64::NAN,
            });
        }
        Ok(())
    }
}

impl SimValveCylinder {
    /// The valve and cylinder at rest at position `x` (mm), the encoder read through
    /// `scaling`. Refuses parameters out of range, naming the first.
    pub fn new(p: SimValveCylinderParams, scaling: Scaling, x: f64) -> Result<Self, CylinderError> {
        p.check()?;
        let mut cylinder = SimCylinder::new(p.cylinder, x)?;
        cylinder.set_load(p.load);
        Ok(Self {
            cylinder,
            scaling,
            amplifier: Amplifier::new(p.ready_delay),
            input: p.input,
            words_per_bar: f64::from(super::analog::NOMINAL_WORD) / p.pressure_range,
        })
    }

    /// Latches the command of the boundary (its effect starts now).
    pub fn exchange(&mut self, command: &AnalogCommand) {
        self.amplifier.exchange(command);
    }

    /// Runs `dt_ns` with the latched command.
    pub fn advance(&mut self, dt_ns: i64) {
        let dt = dt_ns.max(0) as f64 * 1e-9;
        let u = if self.amplifier.on() {
            self.input.decode(&self.amplifier.command().words)
        } else {
            0.0
        };
        self.cylinder.step(u, dt);
        self.amplifier.advance(dt);
    }

    /// The process image inputs now: the amplifier's ready output and the encoder's raw word.
    pub fn feedback(&self) -> AnalogFeedback {
        AnalogFeedback {
            ready: self.amplifier.ready(),
            // The low 32 bits; the counter masks them to `raw_bits`.
            encoder_raw: self.scaling.count(self.cylinder.state().position) as u32,
            pressure_a: self.word(self.cylinder.state().pressure_a),
            pressure_b: self.word(self.cylinder.state().pressure_b),
        }
    }

    /// A pressure's analog input word (rounded, saturated).
    fn word(&self, bar: f64) -> i16 {
        (bar * self.words_per_bar).round().clamp(-32768.0, 32767.0) as i16
    }

    /// The cylinder's state (position, velocity, pressures, force, spool, flows).
    pub fn state(&self) -> &CylinderState {
        self.cylinder.state()
    }

    /// The latched command, the ready output and the fault latch (a fault of the valve
    /// amplifier commands the spool to 0).
    pub fn amplifier(&self) -> &Amplifier {
        &self.amplifier
    }

    /// The same, to inject or clear a fault.
    pub fn amplifier_mut(&mut self) -> &mut Amplifier {
        &mut self.amplifier
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    /// Runs `c` for `seconds` at command `u` in 1 ms cycles.
    fn run(c: &mut SimCylinder, u: f64, seconds: f64) {
        for _ in 0..(seconds * 1000.0).round() as u32 {
            c.step(u, 1e-3);
        }
    }

    /// The steady velocity of an unloaded, frictionless cylinder, from the orifice equations
    /// and the force balance (an independent closed form), with `K_A`, `K_B` the edges' flow
    /// per sqrt(bar): extending, `A_A·v = K_A·sqrt(ps - pA)`, `A_B·v = K_B·sqrt(pB)`,
    /// `pA·A_A = pB·A_B` give `v = sqrt(ps / (A_A²/K_A² + A_B³/(A_A·K_B²)))`; retracting,
    /// `v = sqrt(ps / (A_B²/K_B² + A_A³/(A_B·K_A²)))`.
    fn steady(p: &CylinderParams, u: f64) -> f64 {
        let ka = p.nominal_flow * L_PER_MIN * p.opening(u) / p.nominal_drop.sqrt();
        let kb = ka * p.flow_ratio_b;
        let (a, b) = (p.area_a, p.area_b);
        let denominator = if u > 0.0 {
            a * a / (ka * ka) + b * b * b / (a * kb * kb)
        } else {
            b * b / (kb * kb) + a * a * a / (b * ka * ka)
        };
        (p.supply / denominator).sqrt() * u.signum()
    }

    fn frictionless() -> CylinderParams {
        CylinderParams {
            viscous: 0.0,
            ..CylinderParams::example()
        }
    }

    #[test]
    fn the_steady_velocity_is_the_orifice_equations_in_both_directions() {
        let symmetric = frictionless();
        let matched = CylinderParams {
            flow_ratio_b: symmetric.area_b / symmetric.area_a,
            ..symmetric
        };
        for p in [symmetric, matched] {
            for u in [0.2, 0.5, -0.2, -0.5] {
                // 2 s to settle (small openings damp the oil column little), from the end the
                // piston moves away from.
                let mut c = SimCylinder::new(p, if u > 0.0 { 50.0 } else { 450.0 }).unwrap();
                run(&mut c, u, 2.0);
                let v = c.state().velocity;
                let want = steady(&p, u);
                assert!(
                    ((v - want) / want).abs() < 1e-3,
                    "u {u}, B/A {}: velocity {v}, closed form {want}",
                    p.flow_ratio_b
                );
            }
        }
        // On a symmetric valve retracting is the slower direction (by sqrt(2) for areas 2:1).
        assert!(steady(&symmetric, 0.5) > -steady(&symmetric, -0.5));
    }

    #[test]
    fn within_the_overlap_nothing_moves_and_an_offset_drifts() {
        let p = CylinderParams {
            overlap: 0.1,
            ..frictionless()
        };
        let mut c = SimCylinder::new(p, 250.0).unwrap();
        run(&mut c, 0.08, 0.5);
        assert!((c.state().position - 250.0).abs() < 1e-3, "{:?}", c.state());
        // Beyond the overlap it moves, with the opening of the remaining travel (a small
        // opening damps the oil column little: it settles within 2 s).
        run(&mut c, 0.2, 2.0);
        let want = steady(&p, 0.2);
        let v = c.state().velocity;
        assert!(
            ((v - want) / want).abs() < 1e-3,
            "{v} {want} {:?}",
            c.state()
        );
        // A zero offset makes the axis creep at command 0; its negative holds it.
        let p = CylinderParams {
            offset: 0.03,
            ..frictionless()
        };
        let mut c = SimCylinder::new(p, 250.0).unwrap();
        run(&mut c, 0.0, 0.5);
        assert!(c.state().velocity > 1.0, "{:?}", c.state());
        let mut c = SimCylinder::new(p, 250.0).unwrap();
        run(&mut c, -0.03, 0.5);
        assert!(c.state().velocity.abs() < 1e-6, "{:?}", c.state());
    }

    #[test]
    fn at_the_end_stop_the_pressure_builds_up_to_the_pressing_force() {
        let p = frictionless();
        let mut c = SimCylinder::new(p, 490.0).unwrap();
        run(&mut c, 0.5, 1.0);
        let s = *c.state();
        assert_eq!(s.position, p.stroke);
        assert_eq!(s.velocity, 0.0);
        // Chamber A at supply, B at tank: the force is ps·A_A.
        assert!((s.pressure_a - p.supply).abs() < 0.5, "{s:?}");
        assert!(s.pressure_b < 0.5, "{s:?}");
        assert!((s.force - p.supply * p.area_a * 0.1).abs() / (p.supply * p.area_a * 0.1) < 0.01);
    }

    #[test]
    fn the_oil_column_rings_at_the_hydraulic_natural_frequency() {
        // A closed valve, a load step: the piston oscillates on its oil spring. Count the
        // period from the zero crossings of the velocity.
        let p = CylinderParams {
            viscous: 0.0,
            response_time: 0.0,
            ..CylinderParams::example()
        };
        let mut c = SimCylinder::new(p, 250.0).unwrap();
        c.set_load(2000.0);
        let (mut crossings, mut last, mut t) = (Vec::new(), 0.0, 0.0);
        let dt = 1e-4;
        while t < 0.5 {
            let v = c.step(0.0, dt).velocity;
            t += dt;
            if last < 0.0 && v >= 0.0 {
                crossings.push(t);
            }
            last = v;
        }
        assert!(crossings.len() >= 4, "{crossings:?}");
        let periods: Vec<f64> = crossings.windows(2).map(|w| w[1] - w[0]).collect();
        let f = 1.0 / (periods.iter().sum::<f64>() / periods.len() as f64);
        let want = p.natural_frequency(250.0);
        assert!(
            (f - want).abs() / want < 0.03,
            "rings at {f} Hz, formula {want} Hz"
        );
    }

    #[test]
    fn coulomb_friction_holds_the_piston_until_the_force_exceeds_it() {
        let p = CylinderParams {
            coulomb: 3000.0,
            ..frictionless()
        };
        let mut c = SimCylinder::new(p, 250.0).unwrap();
        // A load below the friction: nothing moves.
        c.set_load(2500.0);
        run(&mut c, 0.0, 0.3);
        assert_eq!(c.state().position, 250.0);
        // Driven hard enough: it moves.
        c.set_load(0.0);
        run(&mut c, 0.5, 0.3);
        assert!(c.state().position > 260.0, "{:?}", c.state());
    }

    #[test]
    fn bad_parameters_and_inputs_are_refused_or_ignored() {
        let bad = |p: CylinderParams| SimCylinder::new(p, 0.0).unwrap_err();
        let e = CylinderParams::example();
        assert_eq!(
            bad(CylinderParams { area_b: 0.0, ..e }),
            CylinderError {
                name: "area_b",
                value: 0.0
            }
        );
        assert_eq!(
            bad(CylinderParams { area_b: 0.0, ..e }).code().name(),
            "dwTcHydErrIllegalAreas"
        );
        assert_eq!(bad(CylinderParams { overlap: 0.95, ..e }).name, "overlap");
        assert_eq!(
            bad(CylinderParams {
                bend_opening: 0.4,
                ..e
            })
            .name,
            "bend_opening"
        );
        assert_eq!(SimCylinder::new(e, 600.0).unwrap_err().name, "position");
        let mut c = SimCylinder::new(e, 100.0).unwrap();
        let before = *c.state();
        c.step(0.5, f64::NAN);
        c.step(0.5, -1.0);
        assert_eq!(*c.state(), before);
        run(&mut c, f64::NAN, 0.1);
        assert!(c.state().position.is_finite());
    }
}
