//! The modal states `M70` and `M73` save (`context` saves and restores them).

use crate::vocab::Plane;
use nc_geom::program::{Spindle, SrcPos};

/// One saved modal state.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Saved {
    pub plane: Plane,
    pub inch: bool,
    pub incremental: bool,
    pub inverse_time: bool,
    pub per_rev: bool,
    /// `G95`'s feed per revolution, mm.
    pub feed_per_rev: Option<f64>,
    pub arc_absolute: bool,
    pub path: nc_geom::program::PathMode,
    pub retract_to_r: bool,
    pub work: u8,
    pub feed: Option<f64>,
    pub spindle: Spindle,
    pub rpm: f64,
    pub mist: bool,
    pub flood: bool,
    /// Where it was saved (the restore's actions stand there when a return restores).
    pub pos: SrcPos,
}

/// What `M70` saved, and what each `M73` saved with the call level it was at.
#[derive(Clone, Debug, Default)]
pub(crate) struct SavedStates {
    pub m70: Option<Saved>,
    pub m73: Vec<(usize, Saved)>,
}
