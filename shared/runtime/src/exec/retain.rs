//! The retained data of the executive's axes (S7-1500T Motion Control V4.0 function manual,
//! 'Drive and encoder connection' (actual value types), 'Direct homing and absolute adjustment',
//! 'When Homed is lost'): the absolute encoder adjustment of each owned axis on a drive of the
//! process image with an absolute or cyclic absolute encoder, and the count of traversed
//! ranges of a cyclic absolute encoder, as [`AbsoluteAdjustment`] records.
//!
//! The executive does no IO: the caller keeps the records (a node in files, docs/io.md
//! "Retained data"). Before the first step it restores each one
//! ([`Executive::restore_adjustment`]); after each step it takes the ones that changed
//! ([`Executive::take_adjustments`]), which costs a comparison per retaining axis and does not
//! allocate.

use core::fmt;

use tandem_config::AxisIndex;
use tandem_motion::objects::axis::RestoreOffsetError;
use tandem_motion::plant::mechanics::AbsoluteAdjustment;

use super::Executive;

/// What [`Executive::restore_adjustment`] did with a retained adjustment.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Restored {
    /// The adjustment was made under this configuration: the axis is homed at its offset (and
    /// a cyclic absolute encoder's count resumes from the retained one).
    Adjusted,
    /// Nothing was retained: the axis is not homed until MC_Home mode 6 or 7 adjusts it.
    NotAdjusted,
    /// The adjustment was made under another encoder or mechanics configuration: it is void
    /// (S7 'When Homed is lost': an encoder configuration change), the axis is not homed, and
    /// the next [`Executive::take_adjustments`] hands over the cleared adjustment, so the void
    /// one is not used again even if the configuration changes back.
    Void {
        /// The fingerprint the adjustment was made under.
        made_under: u64,
        /// The fingerprint of this configuration.
        now: u64,
    },
}

/// Why [`Executive::restore_adjustment`] refused (nothing changed).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum RestoreError {
    /// The axis retains no adjustment here: not one of this executive's, not on a drive of the
    /// process image, or its encoder is incremental.
    NotRetained {
        /// The axis.
        axis: AxisIndex,
    },
    /// The axis's drive was sampled already: adjustments are restored before the first step.
    Started {
        /// The axis.
        axis: AxisIndex,
    },
    /// The axis refused it.
    Axis {
        /// The axis.
        axis: AxisIndex,
        /// Its reason.
        reason: RestoreOffsetError,
    },
}

impl fmt::Display for RestoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotRetained { axis } => write!(
                f,
                "axis {}: no absolute encoder adjustment is retained for it (not on a drive of \
                 this node with an absolute or cyclic absolute encoder)",
                axis.0
            ),
            Self::Started { axis } => write!(
                f,
                "axis {}: its drive was sampled already; an adjustment is restored before the \
                 first step",
                axis.0
            ),
            Self::Axis { axis, reason } => write!(f, "axis {}: {reason}", axis.0),
        }
    }
}

impl std::error::Error for RestoreError {}

/// An axis's retained data changed: what to retain now.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdjustmentChange {
    /// The axis.
    pub axis: AxisIndex,
    /// The adjustment, with the drive's count now and the fingerprint of the configuration;
    /// `None`: the axis is not adjusted (a void adjustment was cleared), retain nothing.
    pub adjustment: Option<AbsoluteAdjustment>,
    /// Only the count of a cyclic absolute encoder moved by a quarter of its range
    /// (`RawCounter::retain_due`); the offset is the one retained before.
    pub count_only: bool,
}

impl Executive<'_> {
    /// The owned axes whose adjustment is retained: those on a drive of the process image with
    /// an absolute or cyclic absolute encoder.
    pub fn retained_axes(&self) -> impl Iterator<Item = AxisIndex> + '_ {
        self.drives
            .links
            .iter()
            .filter(|l| l.retention.is_some())
            .map(|l| AxisIndex(l.axis))
    }

    /// Restores the retained adjustment of axis `i` before the first step: `Some` as it was
    /// retained (applied if it was made under this configuration, else void), `None` if nothing
    /// was retained (or the record could not be read: never guess). A void or missing
    /// adjustment leaves the axis not homed.
    pub fn restore_adjustment(
        &mut self,
        i: AxisIndex,
        retained: Option<AbsoluteAdjustment>,
    ) -> Result<Restored, RestoreError> {
        let not_retained = RestoreError::NotRetained { axis: i };
        let link = self
            .drives
            .links
            .iter_mut()
            .find(|l| l.axis == i.0)
            .ok_or(not_retained)?;
        let mut r = link.retention.ok_or(not_retained)?;
        if link.started() {
            return Err(RestoreError::Started { axis: i });
        }
        let axis = self.axes.get_mut(i.0).ok_or(not_retained)?;
        let (offset, restored) = match retained {
            None => (None, Restored::NotAdjusted),
            Some(a) if a.fingerprint != r.fingerprint => (
                None,
                Restored::Void {
                    made_under: a.fingerprint,
                    now: r.fingerprint,
                },
            ),
            Some(a) => (Some(a.offset), Restored::Adjusted),
        };
        axis.restore_absolute_offset(offset)
            .map_err(|reason| RestoreError::Axis { axis: i, reason })?;
        if let Some(s) = self.status.get_mut(i.0) {
            *s = *axis.status();
        }
        if !matches!(restored, Restored::Void { .. }) {
            // What is retained already is not handed over again.
            r.changes = axis.absolute_offset().changes;
        }
        r.resume = None;
        if let (Restored::Adjusted, Some(a)) = (restored, retained) {
            r.count = a.count;
            r.resume = r.cyclic.then_some(a.count);
        }
        link.retention = Some(r);
        Ok(restored)
    }

    /// Hands each owned axis's retained data that changed since it was last handed over (or
    /// restored) to `take`: an adjustment by MC_Home mode 6 or 7, a void adjustment cleared,
    /// the count of a cyclic absolute encoder a quarter of its range away from the one last
    /// retained. `take` returns whether it took the change (e.g. a bounded queue had room); a
    /// change not taken is offered again at the next call, as it is then.
    pub fn take_adjustments(&mut self, mut take: impl FnMut(AdjustmentChange) -> bool) {
        for link in &mut self.drives.links {
            let Some(mut r) = link.retention else {
                continue;
            };
            let Some(a) = self.axes.get(link.axis).map(|x| x.absolute_offset()) else {
                continue;
            };
            let changed = a.changes != r.changes;
            let count_due = r.cyclic && a.adjusted && link.count_due(r.count);
            if !(changed || count_due) {
                continue;
            }
            let count = link.count().unwrap_or(r.count);
            let change = AdjustmentChange {
                axis: AxisIndex(link.axis),
                adjustment: a.adjusted.then_some(AbsoluteAdjustment {
                    offset: a.offset,
                    count,
                    fingerprint: r.fingerprint,
                }),
                count_only: !changed,
            };
            if take(change) {
                r.changes = a.changes;
                r.count = count;
                link.retention = Some(r);
            }
        }
    }
}
