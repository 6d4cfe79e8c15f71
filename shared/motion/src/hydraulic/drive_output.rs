//! The drive stage of a hydraulic axis, `MC_AxRtDrive_BkPlcMc` (Beckhoff TwinCAT PLC Hydraulic
//! Positioning library, 4.4.2.1): Finish's normalised output (±1.0 = full scale) as the words
//! and bits of the valve amplifier's process image.
//!
//! The forms (the library chooses a sub-block by `nDrive_Type`, one per terminal; tandem names
//! the form, not the terminal):
//! - [`ValveOutput::Voltage`]: one ±10 V output word (tandem's analog output scaling,
//!   [`output_word`]: 27648 = 10 V), as a 4/3 proportional valve or a servo valve takes it.
//! - [`ValveOutput::TwoCoil`]: two current outputs, one per solenoid (the library's example,
//!   EL2535 2-coil): -100 … 0 … +100 % gives coil A 0 … 0 … 32767 and coil B 32767 … 0 … 0.
//! - [`ValveOutput::OneCoil`]: one current output of a spring-centred single-solenoid valve
//!   (EL2535 1-coil): -100 … 0 … +100 % gives 0 … 16384 … 32767 (50 % is the centre).
//!
//! `bDrive_AbsoluteOutput` (with the voltage form): "control values are always output positively,
//! regardless of the direction"; the direction goes out on the digital outputs `bMovePos` /
//! `bMoveNeg` (a current valve, FAQ #14); they are set with every form, as the library's
//! `ST_TcPlcDeviceOutput` carries them. `bDrive_Reversed`: "the control value output is
//! negated" (before the form; the bits follow the negated value).
//!
//! [`DriveOutputParams::decode`] is what an amplifier wired for the form makes of the words:
//! the simulated valve reads its command through it, so a form that does not match the
//! amplifier's wiring misbehaves in the simulator as it would on the machine.
//!
//! Pure: no IO, no allocation.

use crate::plant::analog_word::{output_word, word_to_normalized};
use std::fmt;

/// A coil's full-scale current word (the library's EL2535 example: 32767).
pub const COIL_FULL_SCALE: i16 = 32767;

/// The centre word of a single-solenoid valve (50 % of [`COIL_FULL_SCALE`]).
pub const ONE_COIL_CENTRE: i16 = 16384;

/// How the valve takes its command (see the module documentation).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum ValveOutput {
    /// One ±10 V output word.
    #[default]
    Voltage,
    /// Two current outputs, one per solenoid.
    TwoCoil,
    /// One current output, the spring centre at half scale.
    OneCoil,
}

/// The drive stage's parameters (members of `ST_TcHydAxParam`).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct DriveOutputParams {
    /// The form of the output.
    pub output: ValveOutput,
    /// `bDrive_AbsoluteOutput`: the magnitude only, the direction on `bMovePos` / `bMoveNeg`
    /// (only with [`ValveOutput::Voltage`]).
    pub absolute: bool,
    /// `bDrive_Reversed`: the output negated.
    pub reversed: bool,
}

/// The valve amplifier's outputs of one cycle.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub struct ValveWords {
    /// The output word: the ±10 V word, coil A's current, or the single coil's.
    pub word: i16,
    /// Coil B's current (two coils only; 0 otherwise).
    pub word_b: i16,
    /// `bMovePos`: the control value is positive.
    pub move_positive: bool,
    /// `bMoveNeg`: the control value is negative.
    pub move_negative: bool,
}

/// Parameters that do not go together (nothing is kept).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct DriveOutputError {
    /// The form given with `bDrive_AbsoluteOutput`.
    pub output: ValveOutput,
}

impl fmt::Display for DriveOutputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "bDrive_AbsoluteOutput is for a ±10 V output, not for {:?} (a coil output carries \
             its direction itself)",
            self.output
        )
    }
}

impl std::error::Error for DriveOutputError {}

/// `u` (normalised) as a coil word 0..=[`COIL_FULL_SCALE`] for 0..=1.
fn coil(u: f64) -> i16 {
    // Within 0..=32767 after the clamp: the conversion is exact.
    (u.clamp(0.0, 1.0) * f64::from(COIL_FULL_SCALE)).round() as i16
}

impl DriveOutputParams {
    /// Refuses `bDrive_AbsoluteOutput` with a coil output.
    pub fn check(&self) -> Result<(), DriveOutputError> {
        if self.absolute && self.output != ValveOutput::Voltage {
            return Err(DriveOutputError {
                output: self.output,
            });
        }
        Ok(())
    }

    /// The words and bits for `normalized` (limited to ±1.0; NaN gives 0).
    pub fn encode(&self, normalized: f64) -> ValveWords {
        let u = if normalized.is_nan() {
            0.0
        } else {
            normalized.clamp(-1.0, 1.0)
        };
        let u = if self.reversed { -u } else { u };
        let (word, word_b) = match (self.output, self.absolute) {
            (ValveOutput::Voltage, false) => (output_word(u), 0),
            (ValveOutput::Voltage, true) => (output_word(u.abs()), 0),
            (ValveOutput::TwoCoil, _) => (coil(u), coil(-u)),
            (ValveOutput::OneCoil, _) => (coil(0.5 + 0.5 * u), 0),
        };
        ValveWords {
            word,
            word_b,
            move_positive: u > 0.0,
            move_negative: u < 0.0,
        }
    }

    /// What an amplifier wired for this form makes of `w` (normalised, reversal not undone: it
    /// is the controller's, not the amplifier's).
    pub fn decode(&self, w: &ValveWords) -> f64 {
        let full = f64::from(COIL_FULL_SCALE);
        match (self.output, self.absolute) {
            (ValveOutput::Voltage, false) => word_to_normalized(w.word),
            (ValveOutput::Voltage, true) => {
                let m = word_to_normalized(w.word).abs();
                match (w.move_positive, w.move_negative) {
                    (true, false) => m,
                    (false, true) => -m,
                    // Neither or both direction valves: no flow path (inferred).
                    _ => 0.0,
                }
            }
            (ValveOutput::TwoCoil, _) => {
                (f64::from(w.word.max(0)) - f64::from(w.word_b.max(0))) / full
            }
            (ValveOutput::OneCoil, _) => {
                (f64::from(w.word.max(0)) - f64::from(ONE_COIL_CENTRE)) / (full / 2.0)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

    use super::*;

    fn form(output: ValveOutput, absolute: bool, reversed: bool) -> DriveOutputParams {
        DriveOutputParams {
            output,
            absolute,
            reversed,
        }
    }

    #[test]
    fn two_coils_take_one_direction_each_as_the_library_shows() {
        let f = form(ValveOutput::TwoCoil, false, false);
        // -100 … 0 … +100 %: coil A 0 … 0 … 32767, coil B 32767 … 0 … 0.
        assert_eq!((f.encode(-1.0).word, f.encode(-1.0).word_b), (0, 32767));
        assert_eq!((f.encode(0.0).word, f.encode(0.0).word_b), (0, 0));
        assert_eq!((f.encode(1.0).word, f.encode(1.0).word_b), (32767, 0));
        assert_eq!((f.encode(0.5).word, f.encode(0.5).word_b), (16384, 0));
        let w = f.encode(-0.25);
        assert!(w.move_negative && !w.move_positive);
    }

    #[test]
    fn one_coil_has_its_centre_at_half_scale() {
        let f = form(ValveOutput::OneCoil, false, false);
        // -100 … 0 … +100 %: 0 … 16384 … 32767.
        assert_eq!(f.encode(-1.0).word, 0);
        assert_eq!(f.encode(0.0).word, 16384);
        assert_eq!(f.encode(1.0).word, 32767);
    }

    #[test]
    fn absolute_output_gives_the_magnitude_and_the_direction_bits() {
        let f = form(ValveOutput::Voltage, true, false);
        let w = f.encode(-0.5);
        assert_eq!(w.word, output_word(0.5));
        assert!(w.move_negative && !w.move_positive);
        let w = f.encode(0.5);
        assert_eq!(w.word, output_word(0.5));
        assert!(w.move_positive && !w.move_negative);
        let w = f.encode(0.0);
        assert!(!w.move_positive && !w.move_negative);
        assert_eq!(
            form(ValveOutput::TwoCoil, true, false).check(),
            Err(DriveOutputError {
                output: ValveOutput::TwoCoil
            })
        );
    }

    #[test]
    fn reversal_negates_the_output_and_its_bits() {
        let plain = form(ValveOutput::Voltage, false, false);
        let rev = form(ValveOutput::Voltage, false, true);
        assert_eq!(rev.encode(0.3).word, -plain.encode(0.3).word);
        assert!(rev.encode(0.3).move_negative);
        let rev = form(ValveOutput::TwoCoil, false, true);
        assert_eq!(rev.encode(1.0).word_b, 32767);
    }

    #[test]
    fn each_form_decodes_what_it_encodes_within_a_word() {
        for output in [
            ValveOutput::Voltage,
            ValveOutput::TwoCoil,
            ValveOutput::OneCoil,
        ] {
            for absolute in [false, true] {
                let f = form(output, absolute, false);
                if f.check().is_err() {
                    continue;
                }
                for k in -100..=100 {
                    let u = f64::from(k) / 100.0;
                    let back = f.decode(&f.encode(u));
                    assert!((back - u).abs() < 1.0 / 16000.0, "{f:?} {u} -> {back}");
                }
                assert_eq!(f.decode(&f.encode(f64::NAN)), 0.0);
                assert_eq!(f.decode(&f.encode(5.0)), f.decode(&f.encode(1.0)));
            }
        }
        // A valve wired for two coils reads a ±10 V word's negative half as nothing.
        let volts = form(ValveOutput::Voltage, false, false).encode(-0.5);
        assert_eq!(form(ValveOutput::TwoCoil, false, false).decode(&volts), 0.0);
    }
}
