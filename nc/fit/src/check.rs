//! The streamed rewrite ([`super::rewrite`]) checked as it is written, independently of the
//! fit: the input's blocks and the written text, parsed again as `simulate` reads it, are
//! built into segments by the segment builder, and each piece (a stretch that no run
//! crosses, so both sides start and end on the same programmed point) is measured by
//! [`measure`]: the input's programmed points against the output path, the output's samples
//! against the input path, on a second thread while the rewrite goes on. Four pieces of
//! each side are held at most: the one being built, two waiting, one being measured.

use super::deviation::{measure, Deviation};
use crate::error::RewriteError;
use nc_geom::kinematics::MachineKinematics;
use nc_geom::program::{Action, Block, SrcPos};
use nc_geom::segment::{BuildError, BuildLimits, Builder, Path, Pose, Segment};
use nc_lang::{Entries, Entry, LineSource, ParseError, Setup};
use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;
use std::sync::mpsc::{sync_channel, SyncSender};
use std::thread::JoinHandle;

/// The written lines, as the output's parser reads them: each is parsed as soon as it is
/// written (a line continued with a backslash, with the next), so the queue holds a line
/// or two, and an empty queue is not the output's end until [`Check::finish`].
struct Queue {
    written: Rc<RefCell<VecDeque<String>>>,
    line: String,
    count: u32,
}

impl LineSource for Queue {
    fn next_line(&mut self) -> Option<Result<(u32, &str), ParseError>> {
        self.line = self.written.borrow_mut().pop_front()?;
        self.count = self.count.saturating_add(1);
        Some(Ok((self.count, &self.line)))
    }

    fn eof(&self) -> SrcPos {
        SrcPos {
            line: self.count.max(1),
            col: u32::try_from(self.line.chars().count() + 1).unwrap_or(u32::MAX),
        }
    }
}

/// Both sides of the rewrite, built a piece at a time, and what was measured so far.
pub(super) struct Check<'a> {
    kin: &'a MachineKinematics,
    /// Sampling step of the measurement (mm, or degrees on rotary-only segments).
    step: f64,
    /// The fit's distance tolerance: a point counts where the other path first passes
    /// within it ([`measure`]).
    tol_mm: f64,
    input: Builder<'a>,
    in_segs: Vec<Segment>,
    written: Rc<RefCell<VecDeque<String>>>,
    output: Entries<'a, Queue>,
    out_builder: Builder<'a>,
    out_segs: Vec<Segment>,
    /// Motion blocks of the output read so far.
    out_blocks: usize,
    /// Where the next piece starts (the same programmed point on both sides).
    start: Option<(Pose, SrcPos)>,
    measurer: Measurer,
}

/// The pieces' measurement, on a second thread while the rewrite reads, fits and builds
/// on (at most two pieces wait for it), or here if no thread can be started; either way in
/// the pieces' order, with the same result.
enum Measurer {
    Thread {
        pieces: Option<SyncSender<(Path, Path)>>,
        worker: Option<JoinHandle<Deviation>>,
    },
    Here(Sum),
}

/// The deviations of the pieces measured so far.
#[derive(Default)]
struct Sum {
    dev: Deviation,
    pieces: usize,
}

impl Sum {
    fn add(&mut self, d: &Deviation) {
        let dev = &mut self.dev;
        if d.point_mm > dev.point_mm {
            dev.point_mm = d.point_mm;
            dev.point_mm_line = d.point_mm_line;
        }
        if d.point_deg > dev.point_deg {
            dev.point_deg = d.point_deg;
            dev.point_deg_line = d.point_deg_line;
        }
        dev.path_mm = dev.path_mm.max(d.path_mm);
        // Each piece after the first starts on the point the last one ended on.
        dev.points += d.points - usize::from(self.pieces > 0 && d.points > 0);
        dev.samples += d.samples;
        self.pieces += 1;
    }
}

impl Measurer {
    fn new(kin: MachineKinematics, step: f64, tol_mm: f64) -> Self {
        let (tx, rx) = sync_channel::<(Path, Path)>(2);
        let spawned = std::thread::Builder::new()
            .name("dnurbs-fit-check".into())
            .spawn(move || {
                let mut sum = Sum::default();
                for (inp, out) in rx {
                    sum.add(&measure(&inp, &out, &kin, step, tol_mm));
                }
                sum.dev
            });
        match spawned {
            Ok(worker) => Measurer::Thread {
                pieces: Some(tx),
                worker: Some(worker),
            },
            Err(_) => Measurer::Here(Sum::default()),
        }
    }

    fn measure(&mut self, inp: Path, out: Path, kin: &MachineKinematics, step: f64, tol_mm: f64) {
        match self {
            Measurer::Thread { pieces, .. } => {
                // The worker ends only when the sender is dropped, or by a panic, which
                // `finish` passes on.
                if let Some(tx) = pieces {
                    let _ = tx.send((inp, out));
                }
            }
            Measurer::Here(sum) => sum.add(&measure(&inp, &out, kin, step, tol_mm)),
        }
    }

    /// Every piece measured: the largest deviations.
    fn finish(&mut self) -> Deviation {
        match self {
            Measurer::Thread { pieces, worker } => {
                drop(pieces.take());
                match worker.take().map(JoinHandle::join) {
                    Some(Ok(dev)) => dev,
                    Some(Err(panic)) => std::panic::resume_unwind(panic),
                    None => Deviation::default(),
                }
            }
            Measurer::Here(sum) => sum.dev,
        }
    }
}

impl<'a> Check<'a> {
    pub fn new(
        kin: &'a MachineKinematics,
        limits: &'a BuildLimits,
        setup: &'a Setup,
        step: f64,
        tol_mm: f64,
    ) -> Self {
        let written = Rc::new(RefCell::new(VecDeque::new()));
        let queue = Queue {
            written: Rc::clone(&written),
            line: String::new(),
            count: 0,
        };
        Check {
            kin,
            step,
            tol_mm,
            input: Builder::new(kin, limits),
            in_segs: Vec::new(),
            written,
            output: Entries::new(queue, setup),
            out_builder: Builder::new(kin, limits),
            out_segs: Vec::new(),
            out_blocks: 0,
            start: None,
            measurer: Measurer::new(*kin, step, tol_mm),
        }
    }

    /// An input action, before the next input block.
    pub fn action(&mut self, a: &Action) {
        self.input.action(a);
    }

    /// Input block `i` (from 0), built into the current piece.
    pub fn block(&mut self, i: usize, b: &Block) -> Result<(), BuildError> {
        self.input.block(i, b, &mut self.in_segs)
    }

    /// A line the rewrite wrote (without its ending): parsed, and its blocks built.
    pub fn written(&mut self, line: &str) -> Result<(), RewriteError> {
        self.written.borrow_mut().push_back(line.to_owned());
        if nc_lang::continues(line) {
            return Ok(());
        }
        while let Some(read) = self.output.read_line() {
            read.map_err(RewriteError::OutputParse)?;
        }
        while let Some(entry) = self.output.take_read() {
            self.output_entry(entry)?;
        }
        Ok(())
    }

    fn output_entry(&mut self, entry: Entry) -> Result<(), RewriteError> {
        match entry {
            Entry::Action(a) => self.out_builder.action(&a),
            Entry::Block(i, b) => {
                self.out_builder
                    .block(i, &b, &mut self.out_segs)
                    .map_err(RewriteError::OutputBuild)?;
                self.out_blocks += 1;
            }
        }
        Ok(())
    }

    /// The piece ends with the input's `in_blocks`-th motion block and the output's
    /// `out_blocks`-th, both written: both sides are measured (the segments of later
    /// blocks wait for the next piece).
    pub fn piece(&mut self, out_blocks: usize, in_blocks: usize) -> Result<(), RewriteError> {
        if self.output.held_moves() > 0 {
            // Moves under cutter compensation come out of the parser with the next move's
            // line: the piece ends at a later call, where nothing is held (or at the end).
            return Ok(());
        }
        if self.out_blocks < out_blocks {
            return Err(RewriteError::OutputBlocks {
                expected: out_blocks,
                read: self.out_blocks,
            });
        }
        // Segments know their block from 1.
        let upto = |n: usize| move |s: &Segment| usize::try_from(s.block).is_ok_and(|b| b <= n);
        let cut = self.in_segs.partition_point(upto(in_blocks));
        let out_cut = self.out_segs.partition_point(upto(out_blocks));
        if cut == 0 && out_cut == 0 {
            return Ok(());
        }
        let start = match self.start {
            Some(s) => s,
            None => match self.input.start() {
                Ok((pose, src, _)) => (pose, src),
                Err(e) => return Err(RewriteError::Build(e)),
            },
        };
        let path = |segments| Path {
            start: start.0,
            start_src: start.1,
            start_joints: [0.0; 5],
            segments,
        };
        let (later, out_later) = (
            self.in_segs.split_off(cut),
            self.out_segs.split_off(out_cut),
        );
        let (inp, out) = (
            path(std::mem::replace(&mut self.in_segs, later)),
            path(std::mem::replace(&mut self.out_segs, out_later)),
        );
        self.start = inp
            .segments
            .last()
            .map(|s| (s.pose(s.length), s.src))
            .or(Some(start));
        self.measurer
            .measure(inp, out, self.kin, self.step, self.tol_mm);
        Ok(())
    }

    /// The output is read to its end: it must hold `out_blocks` motion blocks, no more.
    /// The largest deviations of the whole program.
    pub fn finish(
        &mut self,
        out_blocks: usize,
        in_blocks: usize,
    ) -> Result<Deviation, RewriteError> {
        while let Some(entry) = self.output.next() {
            self.output_entry(entry.map_err(RewriteError::OutputParse)?)?;
        }
        self.piece(out_blocks, in_blocks)?;
        if self.out_blocks != out_blocks {
            return Err(RewriteError::OutputBlocks {
                expected: out_blocks,
                read: self.out_blocks,
            });
        }
        Ok(self.measurer.finish())
    }
}
