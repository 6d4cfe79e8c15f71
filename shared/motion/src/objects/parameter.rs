//! Parameters a technology object lets the user program read and write while it runs
//! (MC_ReadParameter / MC_WriteParameter): one table per object kind, each row a key (a tag
//! name or a parameter number), its type, when a write takes effect, the ErrorID of an invalid
//! value, and a getter and a setter on the object's parameter view.
//!
//! The write is the same for every table ([`write`]): look the key up (unknown:
//! `16#8080`), refuse a read-only or restart-only parameter (`16#8081`), one the object does
//! not have (`16#8086`), a value that is not a finite number (`16#808B`) or not a boolean for
//! a boolean parameter (the row's ErrorID); then set the value on a **copy** of the view and
//! run the object's own check on the copy (the configuration's check at load). Only when it
//! passes does the copy replace the view: a refused write changes nothing.
//!
//! The axis' table under the S7-1500T tag names is `axis::AXIS_PARAMETERS`
//! (docs/parameters.md); a numbered table (the Beckhoff hydraulic library's
//! `E_TcMCParameter`) uses the same row type with `u16` keys.

use crate::catalog::error_id::ErrorId;

/// The type of a parameter's value (S7-Technology MC_WriteParameter's `Value` or `ValueBool`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum ParamType {
    /// A real number (`LREAL`).
    Real,
    /// A boolean, written and read as `0.0` (FALSE) or `1.0` (TRUE).
    Bool,
}

/// When a write takes effect: the S7-1500T effectiveness codes (S7-1500T Motion Control V4.0
/// function manual, A.2 'Tags of the positioning axis/synchronous axis technology object',
/// legend of column W).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Effect {
    /// `DIR`: from the next cycle.
    #[doc(alias = "DIR")]
    NextCycle,
    /// `CAL`: from the next job that uses it (the running job keeps the value it started with).
    #[doc(alias = "CAL")]
    NextJob,
    /// `RES`: only with a restart of the technology object; refused at run time (`16#8081`).
    #[doc(alias = "RES")]
    Restart,
    /// `RON`: read-only (`16#8081`).
    #[doc(alias = "RON")]
    ReadOnly,
}

impl Effect {
    /// The reference's code: `DIR`, `CAL`, `RES`, `RON`.
    pub const fn code(self) -> &'static str {
        match self {
            Effect::NextCycle => "DIR",
            Effect::NextJob => "CAL",
            Effect::Restart => "RES",
            Effect::ReadOnly => "RON",
        }
    }

    /// Whether MC_WriteParameter may write it while the object runs.
    pub const fn writable(self) -> bool {
        matches!(self, Effect::NextCycle | Effect::NextJob)
    }
}

/// One parameter of a table: key, documentation, checks and access on the view `T`.
#[derive(Debug)]
pub struct ParamEntry<K: 'static, T: 'static> {
    /// The key: the tag name (`"DynamicLimits.MaxAcceleration"`) or a parameter number.
    pub key: K,
    /// The unit (`u` are the axis' position units).
    pub unit: &'static str,
    /// The value's type.
    pub ty: ParamType,
    /// When a write takes effect.
    pub effect: Effect,
    /// The range as the documentation states it (the check itself is the object's).
    pub range: &'static str,
    /// The ErrorID of an invalid value.
    pub invalid: ErrorId,
    /// The manual's section that defines it.
    pub reference: &'static str,
    /// Whether the object has the parameter (`16#8086` if not).
    pub available: fn(&T) -> bool,
    /// The current value.
    pub get: fn(&T) -> f64,
    /// Sets the value on the view (checked afterwards as a whole).
    pub set: fn(&mut T, f64),
}

/// The row of `key`, or `16#8080`.
pub fn find<K: PartialEq, T>(
    table: &'static [ParamEntry<K, T>],
    key: &K,
) -> Result<&'static ParamEntry<K, T>, ErrorId> {
    table
        .iter()
        .find(|e| e.key == *key)
        .ok_or(ErrorId::InvalidParameterNumber)
}

/// MC_ReadParameter: the current value of `key` on `view`.
#[doc(alias = "MC_ReadParameter")]
#[doc(alias = "MC_ReadSysParameter")]
pub fn read<K: PartialEq, T>(
    table: &'static [ParamEntry<K, T>],
    key: &K,
    view: &T,
) -> Result<f64, ErrorId> {
    let e = find(table, key)?;
    if !(e.available)(view) {
        return Err(ErrorId::ParameterNotAvailable);
    }
    Ok((e.get)(view))
}

/// MC_WriteParameter: sets `key` to `value` on `view` if the object's `check` accepts the
/// whole view with it; returns the row and the value before. Refused (nothing changed) with
/// the ErrorIDs of the module documentation; a `check` failure is answered with the row's
/// ErrorID. No allocation: the view is copied on the stack.
#[doc(alias = "MC_WriteParameter")]
pub fn write<K: PartialEq, T: Clone, E>(
    table: &'static [ParamEntry<K, T>],
    key: &K,
    view: &mut T,
    value: f64,
    check: impl FnOnce(&T) -> Result<(), E>,
) -> Result<(&'static ParamEntry<K, T>, f64), ErrorId> {
    let e = find(table, key)?;
    if !e.effect.writable() {
        return Err(ErrorId::ParameterNotWritable);
    }
    if !(e.available)(view) {
        return Err(ErrorId::ParameterNotAvailable);
    }
    if !value.is_finite() {
        return Err(ErrorId::InvalidRealFormat);
    }
    if e.ty == ParamType::Bool && value != 0.0 && value != 1.0 {
        return Err(e.invalid);
    }
    let old = (e.get)(view);
    let mut candidate = view.clone();
    (e.set)(&mut candidate, value);
    check(&candidate).map_err(|_| e.invalid)?;
    *view = candidate;
    Ok((e, old))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone, Debug, PartialEq)]
    struct View {
        lo: f64,
        hi: f64,
        on: bool,
    }

    const TABLE: &[ParamEntry<u16, View>] = &[
        ParamEntry {
            key: 1,
            unit: "u",
            ty: ParamType::Real,
            effect: Effect::NextCycle,
            range: "< hi",
            invalid: ErrorId::IllegalPosition,
            reference: "test",
            available: |_| true,
            get: |v| v.lo,
            set: |v, x| v.lo = x,
        },
        ParamEntry {
            key: 2,
            unit: "",
            ty: ParamType::Bool,
            effect: Effect::NextJob,
            range: "bool",
            invalid: ErrorId::IllegalParameterValue,
            reference: "test",
            available: |v| v.hi > 0.0,
            get: |v| f64::from(u8::from(v.on)),
            set: |v, x| v.on = x != 0.0,
        },
        ParamEntry {
            key: 3,
            unit: "u",
            ty: ParamType::Real,
            effect: Effect::Restart,
            range: "",
            invalid: ErrorId::IllegalPosition,
            reference: "test",
            available: |_| true,
            get: |v| v.hi,
            set: |v, x| v.hi = x,
        },
    ];

    fn check(v: &View) -> Result<(), ()> {
        if v.lo < v.hi {
            Ok(())
        } else {
            Err(())
        }
    }

    #[test]
    fn writes_checked_values_and_refuses_the_rest_unchanged() {
        let mut v = View {
            lo: 0.0,
            hi: 10.0,
            on: false,
        };
        let before = v.clone();
        assert_eq!(
            write(TABLE, &1, &mut v, 20.0, check).err(),
            Some(ErrorId::IllegalPosition)
        );
        assert_eq!(
            write(TABLE, &1, &mut v, f64::NAN, check).err(),
            Some(ErrorId::InvalidRealFormat)
        );
        assert_eq!(
            write(TABLE, &2, &mut v, 0.5, check).err(),
            Some(ErrorId::IllegalParameterValue)
        );
        assert_eq!(
            write(TABLE, &3, &mut v, 5.0, check).err(),
            Some(ErrorId::ParameterNotWritable)
        );
        assert_eq!(
            write(TABLE, &9, &mut v, 5.0, check).err(),
            Some(ErrorId::InvalidParameterNumber)
        );
        assert_eq!(v, before);
        let (e, old) = write(TABLE, &1, &mut v, 5.0, check).expect("valid");
        assert_eq!((e.key, old, v.lo), (1, 0.0, 5.0));
        assert_eq!(write(TABLE, &2, &mut v, 1.0, check).map(|r| r.1), Ok(0.0));
        assert_eq!(read(TABLE, &2, &v), Ok(1.0));
        v.hi = -1.0;
        assert_eq!(read(TABLE, &2, &v), Err(ErrorId::ParameterNotAvailable));
    }
}
