//! The `G5.2` block being read (`g52` reads and closes it).

use nc_geom::program::SrcPos;

/// A `G5.2` block being read.
#[derive(Clone, Debug)]
pub(crate) struct OpenG52 {
    pub pos: SrcPos,
    pub n: Option<u32>,
    pub ctrl: Vec<[f64; 3]>,
    pub ctrl_pos: Vec<SrcPos>,
    pub weights: Vec<f64>,
    pub order: usize,
}
