//! Modulo axes: a position range `[start, start + length)` that repeats (S7-1500T Motion Control
//! V4.0 function manual, 3.2.3 'Modulo setting').
//!
//! Axes keep a continuous (unwrapped) position internally, so a wrap is never a jump; every
//! absolute input is reduced into the range (S7-Technology V4.1 function manual, 6.9.4 'Absolute
//! positions of modulo axes': 400 -> 40, -20 -> 340 on 0..360).

/// Modulo settings of an axis or encoder.
#[derive(Copy, Clone, Debug, PartialEq)]
#[doc(alias = "Modulo.Length")]
pub struct Modulo {
    /// `Modulo.StartValue`.
    pub start: f64,
    /// `Modulo.Length`, > 0.
    pub length: f64,
}

impl Modulo {
    /// Reduces `p` into `[start, start + length)`.
    #[inline]
    pub fn wrap(&self, p: f64) -> f64 {
        let r = (p - self.start).rem_euclid(self.length);
        // rem_euclid can return `length` itself for tiny negative inputs.
        if r >= self.length {
            self.start
        } else {
            self.start + r
        }
    }

    /// Distance from `from` to the position `to` (any representation), in `(-L/2, L/2]`.
    #[inline]
    pub fn shortest(&self, from: f64, to: f64) -> f64 {
        let d = (to - from).rem_euclid(self.length);
        if d > 0.5 * self.length {
            d - self.length
        } else {
            d
        }
    }

    /// Distance from `from` to `to` going in the positive direction, in `[0, L)`.
    #[inline]
    pub fn forward(&self, from: f64, to: f64) -> f64 {
        let d = (to - from).rem_euclid(self.length);
        if d >= self.length {
            0.0
        } else {
            d
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reduces_absolute_inputs_as_the_references_show() {
        let m = Modulo {
            start: 0.0,
            length: 360.0,
        };
        assert_eq!(m.wrap(400.0), 40.0);
        assert_eq!(m.wrap(-20.0), 340.0);
        assert_eq!(m.wrap(730.0), 10.0);
        assert_eq!(m.wrap(360.0), 0.0);
        assert_eq!(m.wrap(-1e-300), 0.0);
        let m = Modulo {
            start: -180.0,
            length: 360.0,
        };
        assert_eq!(m.wrap(180.0), -180.0);
        assert_eq!(m.wrap(190.0), -170.0);
    }

    #[test]
    fn directions() {
        let m = Modulo {
            start: 0.0,
            length: 360.0,
        };
        assert_eq!(m.shortest(350.0, 10.0), 20.0);
        assert_eq!(m.shortest(10.0, 350.0), -20.0);
        assert_eq!(m.forward(10.0, 350.0), 340.0);
        assert_eq!(m.forward(350.0 + 720.0, 10.0), 20.0);
    }
}
