//! The word of an S7 analog output and its normalized command (S7 analog value representation,
//! output ranges ±10 V): the scaling every analog output of tandem uses, the drive connection's
//! and the hydraulic drive stage's. A leaf: it imports nothing of the crate.

/// The word of an S7 analog output at its nominal value: ±27648 is ±10 V, ±100 % of the
/// reference speed (S7 analog value representation, output ranges ±10 V).
pub const NOMINAL_WORD: i16 = 27648;
/// The largest word an S7 analog output takes: 32511, the end of its overrange (11.759 V).
pub const OVERRANGE_WORD: i16 = 32511;
/// The word of an S7 analog output for normalized command `normalized` (1.0 = 100 % = 10 V):
/// `round(normalized * 27648)`, saturated at ±[`OVERRANGE_WORD`]. NaN gives 0.
#[doc(alias = "NSET")]
pub fn output_word(normalized: f64) -> i16 {
    if normalized.is_nan() {
        return 0;
    }
    let w = (normalized * f64::from(NOMINAL_WORD)).round();
    let max = f64::from(OVERRANGE_WORD);
    // Within ±32511 after the clamp: the conversion is exact.
    w.clamp(-max, max) as i16
}

/// The normalized command of an analog output word (the inverse of [`output_word`]).
pub fn word_to_normalized(word: i16) -> f64 {
    f64::from(word) / f64::from(NOMINAL_WORD)
}
