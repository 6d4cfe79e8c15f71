//! The absolute encoder adjustment of an axis as the runtime retains it (S7-1500T Motion Control
//! V4.0 function manual, 'Drive and encoder connection' (actual value types: "after a one-time
//! absolute encoder adjustment the offset `StatusSensor[n].AbsEncoderOffset` is retentive"),
//! 'Direct homing and absolute adjustment' (MC_Home modes 6 and 7) and 'When Homed is lost').
//!
//! The axis keeps its adjustment as a small `Copy` value, [`AbsoluteOffset`], with a change
//! counter: the runtime compares the counter each cycle (no large struct is read) and retains
//! the adjustment when it changed; before the first cycle it gives back what it retained with
//! [`Axis::restore_absolute_offset`]. Nothing here does IO: where and how the adjustment is
//! kept is the runtime's business.

use core::fmt;

use super::{Axis, EncoderType};
use crate::kinematics::profile::State;

/// The absolute encoder adjustment of an axis (S7 `StatusSensor[n].AbsEncoderOffset` with
/// the adjusted state), as [`Axis::absolute_offset`] shows it.
#[derive(Copy, Clone, Debug, PartialEq)]
#[doc(alias = "AbsEncoderOffset")]
pub struct AbsoluteOffset {
    /// The offset (units): axis position = physical position of the drive + offset.
    /// Meaningful when [`adjusted`](Self::adjusted); 0 otherwise.
    pub offset: f64,
    /// The absolute encoder is adjusted: MC_Home mode 6 or 7 completed, or an adjustment was
    /// restored. An axis with an absolute encoder is homed exactly when it is adjusted (until
    /// a direct homing, mode 0 or 1, shifts it without being retained).
    pub adjusted: bool,
    /// Changes (wrapping) with every adjustment (MC_Home 6 or 7 done) and every restore: the
    /// runtime retains the adjustment when this differs from what it retained last.
    pub changes: u32,
}

impl AbsoluteOffset {
    /// The adjustment of a new axis: an axis with an absolute encoder counts as adjusted with
    /// offset 0 until the runtime restores its retained adjustment (the simulation's convention,
    /// `tandem sim` retains nothing); an incremental one is not adjusted.
    pub(super) fn initial(encoder: EncoderType) -> Self {
        Self {
            offset: 0.0,
            adjusted: encoder == EncoderType::Absolute,
            changes: 0,
        }
    }
}

/// Why [`Axis::restore_absolute_offset`] refused to restore (nothing changed).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RestoreOffsetError {
    /// The axis has an incremental encoder: it has no absolute adjustment (16#8011 for
    /// MC_Home 6/7).
    Incremental,
    /// The axis is enabled (or MC_Power.Enable is held): a restore is a restart of the
    /// technology object, which needs it disabled (S7-1500T Motion Control V4.0 function
    /// manual, 'Technology DB and restart').
    Enabled,
    /// The offset is not a finite number.
    NotFinite,
}

impl fmt::Display for RestoreOffsetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Incremental => "the axis has an incremental encoder: no absolute adjustment",
            Self::Enabled => "the axis is enabled: an adjustment is restored while it is disabled",
            Self::NotFinite => "the absolute encoder offset is not a finite number",
        })
    }
}

impl std::error::Error for RestoreOffsetError {}

impl Axis {
    /// The absolute encoder adjustment: offset, adjusted, change counter. `Copy` and cheap:
    /// read it every cycle and compare [`AbsoluteOffset::changes`].
    #[doc(alias = "AbsEncoderOffset")]
    pub fn absolute_offset(&self) -> AbsoluteOffset {
        self.absolute
    }

    /// Restores the retained adjustment of an absolute encoder before the axis runs (or while
    /// it is disabled): `Some(offset)` makes the axis adjusted and homed with that offset
    /// (axis position = physical position + `offset`); `None` (nothing retained, or an
    /// adjustment made under another encoder or mechanics configuration and so void, S7 'When
    /// Homed is lost') makes it not adjusted and not homed, at offset 0, until MC_Home mode 6
    /// or 7 adjusts it. Either counts as a change ([`AbsoluteOffset::changes`]).
    ///
    /// Refuses, changing nothing, an incremental encoder, an enabled axis (or one whose
    /// MC_Power.Enable is held) and a non-finite offset.
    pub fn restore_absolute_offset(
        &mut self,
        offset: Option<f64>,
    ) -> Result<(), RestoreOffsetError> {
        if self.cfg.encoder != EncoderType::Absolute {
            return Err(RestoreOffsetError::Incremental);
        }
        if self.enabled || self.power.enable {
            return Err(RestoreOffsetError::Enabled);
        }
        if offset.is_some_and(|o| !o.is_finite()) {
            return Err(RestoreOffsetError::NotFinite);
        }
        self.absolute = AbsoluteOffset {
            offset: offset.unwrap_or(0.0),
            adjusted: offset.is_some(),
            changes: self.absolute.changes.wrapping_add(1),
        };
        self.homed = self.absolute.adjusted;
        self.offset = self.absolute.offset;
        // As a restart: the axis stands where the drive is, in the restored coordinates.
        self.actual_p = self.drive_actual().p + self.offset;
        self.basic = State::rest(self.actual_p);
        self.extrapolator.reset(self.actual_p, self.actual_v);
        self.replan();
        // The status is built again when next read.
        self.status = std::cell::OnceCell::new();
        self.status_kept.set(false);
        Ok(())
    }

    /// MC_Home mode 6 or 7 completed: the axis's offset is the new adjustment.
    pub(super) fn note_absolute_adjustment(&mut self) {
        self.absolute = AbsoluteOffset {
            offset: self.offset,
            adjusted: true,
            changes: self.absolute.changes.wrapping_add(1),
        };
    }
}
