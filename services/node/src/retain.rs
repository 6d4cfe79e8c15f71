//! The node's retained data (docs/io.md, "Retained data"): the absolute encoder adjustment of
//! each of its axes on a drive with an absolute or cyclic absolute encoder (S7-1500T Motion
//! Control V4.0 function manual, 'Drive and encoder connection': the retentive
//! `StatusSensor[n].AbsEncoderOffset` and, for a cyclic absolute encoder, the count of
//! traversed ranges), one record per axis in
//! `<retain_dir>/<cell name>/<node name>/absolute_adjustment/<axis name>`.
//!
//! - At start ([`restore`], on the main thread before the first cycle) each record is loaded
//!   and handed to the executive; a damaged record is reported (the file and the error) and
//!   never used: the axis is then not homed.
//! - While the node runs, the cyclic thread hands each changed adjustment to the recorder
//!   thread through the bounded diagnostics channel without blocking (a full channel is counted
//!   in `NodeHealth::diag_dropped` and the change is offered again the next cycle); the
//!   recorder ([`Retainer`]) keeps the newest change of each axis and stores it with
//!   [`RetainStore::store`], which replaces the record atomically: a node killed at any moment
//!   leaves the previous record or the new one, whole.
//!
//! Record payload: the 25 bytes of [`AbsoluteAdjustment::to_bytes`] (offset, the drive's count,
//! the fingerprint of the encoder and mechanics it was made under), or empty when the axis is
//! not adjusted (a void adjustment was cleared).

use std::path::Path;
use std::sync::Arc;
use tandem_config::{AxisIndex, Cell, DriveConnection};
use tandem_motion::plant::mechanics::{AbsoluteAdjustment, EncoderKind};
use tandem_rt::retain::RetainStore;
use tandem_runtime::exec::{AdjustmentChange, Executive, Restored};
use tracing::{debug, error, info, warn};

/// The sub-directory of a node's retained data that holds the absolute encoder adjustments.
pub(crate) const ADJUSTMENTS: &str = "absolute_adjustment";

/// Whether node `n` has an axis whose adjustment is retained: on a CiA 402 drive with an
/// absolute or cyclic absolute encoder.
fn retains(cell: &Cell, n: usize) -> bool {
    cell.axes.iter().any(|a| {
        a.node == n
            && matches!(&a.drive, DriveConnection::Cia402(c)
                if c.scaling.encoder().kind != EncoderKind::Incremental)
    })
}

/// Opens (creating it) the directory of node `n`'s adjustments, if it has an axis that retains
/// one. A directory that cannot be opened is reported: the node runs, its absolute encoders
/// are not homed, and nothing is retained.
pub(crate) fn open(cell: &Cell, n: usize) -> Option<Arc<RetainStore>> {
    if !retains(cell, n) {
        return None;
    }
    let dir = cell.node_retain_dir(n)?.join(ADJUSTMENTS);
    match RetainStore::open(&dir) {
        Ok(store) => {
            info!(dir = %dir.display(), "retained data in {}", dir.display());
            Some(Arc::new(store))
        }
        Err(e) => {
            error!(
                "{e}: the absolute encoder adjustments of this node's axes are neither \
                 restored nor retained; its absolute encoders are not homed"
            );
            None
        }
    }
}

/// What a node finds of an axis's record at start.
#[derive(Copy, Clone, Debug, PartialEq)]
enum Loaded {
    /// No record, or an empty one (not adjusted).
    Nothing,
    /// The adjustment.
    Adjustment(AbsoluteAdjustment),
    /// A record that cannot be used (reported with the file and the error).
    Damaged,
}

/// The record of axis `name`; a damaged one is reported here with the file and the error.
fn load(store: &RetainStore, name: &str) -> Loaded {
    let path = store.path(name);
    let damaged = |e: &dyn std::fmt::Display| {
        error!(
            axis = name,
            file = %path.display(),
            "axis {name}: {e}; the record is not used, the axis is not homed until MC_Home mode 6 \
             or 7 adjusts it (which replaces the record)"
        );
    };
    match store.load(name) {
        Ok(None) => Loaded::Nothing,
        Ok(Some(bytes)) if bytes.is_empty() => Loaded::Nothing,
        Ok(Some(bytes)) => match AbsoluteAdjustment::from_bytes(&bytes) {
            Ok(a) => Loaded::Adjustment(a),
            Err(e) => {
                damaged(&format_args!("retained record {}: {e}", path.display()));
                Loaded::Damaged
            }
        },
        Err(e) => {
            damaged(&e);
            Loaded::Damaged
        }
    }
}

/// Restores the retained adjustment of each of the executive's axes that retains one, before
/// the first cycle, and says what became of it.
pub(crate) fn restore(exec: &mut Executive<'_>, cell: &Cell, store: Option<&RetainStore>) {
    let axes: Vec<AxisIndex> = exec.retained_axes().collect();
    for i in axes {
        let name = cell.axes.get(i.0).map_or("?", |a| a.name.as_str());
        let loaded = store.map_or(Loaded::Damaged, |s| load(s, name));
        let retained = match loaded {
            Loaded::Adjustment(a) => Some(a),
            Loaded::Nothing | Loaded::Damaged => None,
        };
        let file = store.map(|s| s.path(name));
        let file = file
            .as_deref()
            .unwrap_or(Path::new("(no directory)"))
            .display();
        match exec.restore_adjustment(i, retained) {
            Ok(Restored::Adjusted) => {
                let a = retained.unwrap_or(AbsoluteAdjustment {
                    offset: 0.0,
                    count: 0,
                    fingerprint: 0,
                });
                info!(
                    axis = name,
                    offset = a.offset,
                    count = a.count,
                    "axis {name}: absolute encoder adjustment restored from {file}: offset {:?}, \
                     count {}; homed",
                    a.offset,
                    a.count
                );
            }
            // Why was said when the record (or its directory) was found unusable.
            Ok(Restored::NotAdjusted) if loaded == Loaded::Damaged => {}
            Ok(Restored::NotAdjusted) => info!(
                axis = name,
                "axis {name}: no absolute encoder adjustment retained ({file}); not homed until \
                 MC_Home mode 6 or 7"
            ),
            Ok(Restored::Void { made_under, now }) => warn!(
                axis = name,
                "axis {name}: the absolute encoder adjustment in {file} was made under another \
                 encoder or mechanics configuration (fingerprint {made_under:#018x}, now \
                 {now:#018x}): void, the axis is not homed until MC_Home mode 6 or 7 adjusts it \
                 again"
            ),
            Err(e) => error!(axis = name, "{e}"),
        }
    }
}

/// The recorder thread's side: the newest change of each axis, stored in batches.
#[derive(Debug)]
pub(crate) struct Retainer {
    store: Option<Arc<RetainStore>>,
    /// Changes taken since the last [`Retainer::flush`], the newest of each axis.
    pending: Vec<AdjustmentChange>,
}

impl Retainer {
    /// Stores into `store` (nothing is stored without one: the node said so at start).
    pub(crate) fn new(store: Option<Arc<RetainStore>>) -> Self {
        Self {
            store,
            pending: Vec::new(),
        }
    }

    /// Takes a change; a pending one of the same axis is replaced (only the newest is stored).
    pub(crate) fn push(&mut self, c: AdjustmentChange) {
        match self.pending.iter_mut().find(|p| p.axis == c.axis) {
            Some(p) => {
                *p = AdjustmentChange {
                    count_only: p.count_only && c.count_only,
                    ..c
                }
            }
            None => self.pending.push(c),
        }
    }

    /// Stores every pending change, each replacing its axis's record atomically; a failure is
    /// reported with the file and the error (the record keeps what it had).
    pub(crate) fn flush(&mut self, cell: &Cell) {
        let Some(store) = &self.store else {
            self.pending.clear();
            return;
        };
        for c in self.pending.drain(..) {
            let name = cell.axes.get(c.axis.0).map_or("?", |a| a.name.as_str());
            let bytes = c.adjustment.map(|a| a.to_bytes());
            let payload = bytes.as_ref().map_or(&[][..], |b| &b[..]);
            if let Err(e) = store.store(name, payload) {
                error!(axis = name, "{e}: the adjustment is not retained");
                continue;
            }
            let file = store.path(name);
            let file = file.display();
            match c.adjustment {
                None => info!(
                    axis = name,
                    "axis {name}: absolute encoder adjustment cleared in {file}"
                ),
                Some(a) if c.count_only => debug!(
                    axis = name,
                    count = a.count,
                    "axis {name}: cyclic absolute encoder count {} retained in {file}",
                    a.count
                ),
                Some(a) => info!(
                    axis = name,
                    offset = a.offset,
                    count = a.count,
                    "axis {name}: absolute encoder adjustment retained in {file}: offset {:?}, \
                     count {}",
                    a.offset,
                    a.count
                ),
            }
        }
    }
}
