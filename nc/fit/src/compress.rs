//! On-line compression (`[interpolation] compress` in the machine file, `--compress` on
//! `simulate` and `run`): the runs of `G01` moves of a parsed program replaced by G06.5
//! blocks with the same fit as `dnurbs fit`, before the segment builder and the planner see
//! it. The program's coordinates are already resolved here (work offsets, units, `G91`), so
//! every run of feed moves qualifies that has no program word (spindle, coolant, stop,
//! dwell) between its moves ([`super::find`] has the rest of the rules). The program's
//! path-control words (`G61`, `G64 P Q`) turn it on and off and set its tolerance where
//! the [`Policy`] follows them.

use super::find::{find_runs, moves_in};
use super::Fitted;
use crate::options::{Options, Policy, TOOL_MM};
use nc_geom::program::{ActionKind, Block, LinearMove, NurbsBlock, NurbsKind, Program};

/// What the compressor did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Compressed {
    /// Feed moves in, and those now inside a G06.5 block.
    pub moves_in: usize,
    pub moves_fitted: usize,
    /// Motion blocks in and out.
    pub blocks_in: usize,
    pub blocks_out: usize,
    /// G06.5 blocks written.
    pub fitted_blocks: usize,
    /// Runs the fit could not bring within the tolerances (left as G01).
    pub runs_kept: usize,
    /// Largest deviations the fit measured at the programmed points (mm, degrees).
    pub fit_mm: f64,
    pub fit_deg: f64,
}

/// How the compressor fits at each block of `program` (None: off there), and whether it is
/// on anywhere: the path-control words before each block decide ([`Policy::at`]).
fn fit_at(program: &Program, policy: &Policy) -> (Vec<Option<Options>>, bool) {
    let mut now = policy.at(None);
    let mut engaged = now.is_some();
    let mut changes = program.actions.iter().filter_map(|a| match a.kind {
        ActionKind::PathMode(m) => Some((a.before_block, m)),
        _ => None,
    });
    let mut next = changes.next();
    let mut at = Vec::with_capacity(program.blocks.len());
    for k in 0..=program.blocks.len() {
        while let Some((_, m)) = next.filter(|(b, _)| *b <= k) {
            now = policy.at(Some(m));
            engaged |= now.is_some();
            next = changes.next();
        }
        at.push(now);
    }
    (at, engaged)
}

/// `program` with its runs of moves fitted into G06.5 blocks, and what the compressor did
/// (None: it was never on).
pub fn compress(
    program: &Program,
    kin: &nc_geom::kinematics::MachineKinematics,
    policy: &Policy,
) -> (Program, Option<Compressed>) {
    let (at, engaged) = fit_at(program, policy);
    if !engaged {
        return (program.clone(), None);
    }
    let opts = &policy.opts;
    let n = program.blocks.len();
    // A program word before block k ends any run there.
    let mut word_before = vec![false; n + 1];
    for a in &program.actions {
        if let Some(w) = word_before.get_mut(a.before_block) {
            *w = true;
        }
    }
    // A run starts where the compressor is on, within the tolerance in effect there, and
    // ends at the next word (a path-control word among them): the whole run is under it.
    let runs = find_runs(
        program,
        kin,
        opts,
        |b| at[b].map(|o| o.tol),
        |k| !word_before[k],
        |_, _| true,
    );
    let mut out = Compressed {
        moves_in: moves_in(program),
        blocks_in: n,
        ..Compressed::default()
    };
    let mut blocks = Vec::with_capacity(n);
    // New index of each old block (and of the end, n).
    let mut index = vec![0; n + 1];
    let mut next = 0;
    for run in &runs {
        let (b, e) = run.blocks;
        let Some(f) = &run.fitted else {
            out.runs_kept += 1;
            continue;
        };
        let Some(Block::Linear(first)) = program.blocks.get(b) else {
            continue;
        };
        copy(&program.blocks[next..b], next, &mut blocks, &mut index);
        for slot in &mut index[b..=e] {
            *slot = blocks.len();
        }
        blocks.push(Block::Nurbs(fitted_block(first, f, run.feed_mm_min)));
        next = e + 1;
        out.fitted_blocks += 1;
        out.moves_fitted += e + 1 - b;
        out.fit_mm = out.fit_mm.max(f.dev_mm);
        out.fit_deg = out.fit_deg.max(f.dev_rad.to_degrees());
    }
    copy(&program.blocks[next..], next, &mut blocks, &mut index);
    index[n] = blocks.len();
    out.blocks_out = blocks.len();
    let mut actions = program.actions.clone();
    for a in &mut actions {
        a.before_block = index.get(a.before_block).copied().unwrap_or(blocks.len());
    }
    (
        Program {
            blocks,
            actions,
            end: program.end,
            tilt_word: program.tilt_word,
            rerun: program.rerun.clone(),
        },
        Some(out),
    )
}

/// The G06.5 block of a run fitted as `f`, whose first move is `first` (its position, `N`
/// and tooling), at the run's feed (mm/min, [`super::find::run_feed`]).
pub fn fitted_block(first: &LinearMove, f: &Fitted, feed_mm_min: f64) -> NurbsBlock {
    let tool_ctrl = f
        .ctrl
        .iter()
        .zip(&f.tool)
        .map(|(c, t)| core::array::from_fn(|i| c[i] + TOOL_MM * t[i]))
        .collect();
    NurbsBlock {
        pos: first.pos,
        n: first.n,
        kind: NurbsKind::G065,
        degree: f.degree as u8,
        ctrl: f.ctrl.clone(),
        tool_ctrl,
        ctrl_pos: vec![first.pos; f.ctrl.len()],
        weights: vec![1.0; f.ctrl.len()],
        knots: f.knots.clone(),
        feed_mm_min,
        tooling: first.tooling,
        turn_to: None,
    }
}

/// Blocks `from..` (given as `old`) copied as they are, their new indices noted.
fn copy(old: &[Block], from: usize, blocks: &mut Vec<Block>, index: &mut [usize]) {
    for (slot, b) in index[from..].iter_mut().zip(old) {
        *slot = blocks.len();
        blocks.push(b.clone());
    }
}
